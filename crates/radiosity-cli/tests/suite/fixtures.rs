//! What the suite's modules share: the `radiosity` program, scratch directories and the
//! example scenes.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The `radiosity` program under test, not yet run.
pub fn radiosity_command() -> Command {
    Command::new(env!("CARGO_BIN_EXE_radiosity"))
}

/// Runs `radiosity` with `args` in `dir` and returns what it did.
pub fn radiosity(args: &[&str], dir: &Path) -> Output {
    radiosity_command()
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the radiosity binary runs")
}

/// A fresh empty directory for the test `name` (the test removes it when it passes).
pub fn scratch_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("radiosity-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The path of the committed example scene `name` (in the workspace's `examples/`).
pub fn example(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name)
        .display()
        .to_string()
}

/// What the program wrote to standard error.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// What the program wrote to standard output.
pub fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}
