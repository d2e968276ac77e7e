//! `radiosity-mpi` under `mpirun` on this machine: the files of 1, 2 and 4 ranks are byte
//! for byte those of `radiosity` (run in this process through the `radiosity_cli`
//! library, the very code of the `radiosity` binary), a job whose rank is killed is resumed
//! from its checkpoint to the same file, and a rank that dies ends the job with a message
//! naming the blocks out.
//!
//! Needs `mpirun` (Debian: openmpi-bin): skipped with a message where it is missing, and
//! failed instead when CI is set (.ci/run installs it).

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use clap::Parser;
use radiosity_cli::args::{FormFactorArgs, RenderArgs, SolveArgs};

const BIN: &str = env!("CARGO_BIN_EXE_radiosity-mpi");

/// The repository's examples/occluder.scene: a closed room, a light, and a quad that
/// shadows the floor (occlusion matters, so the visibility code runs).
fn scene() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/occluder.scene")
}

/// `mpirun`, or `None` (with a message) where it is missing outside CI.
fn mpirun() -> Option<PathBuf> {
    let found = std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|p| p.join("mpirun"))
            .find(|p| p.is_file())
    });
    if found.is_none() {
        assert!(
            std::env::var_os("CI").is_none(),
            "mpirun is missing (Debian: apt-get install openmpi-bin libopenmpi-dev)"
        );
        eprintln!("skipped: mpirun is not installed (Debian: openmpi-bin)");
    }
    found
}

/// `mpirun -np N radiosity-mpi ARGS` as the tests run it: oversubscribed (more ranks than
/// cores) and as root where the CI runs as root.
fn mpi_command(mpirun: &Path, np: usize, args: &[&str]) -> Command {
    let mut cmd = Command::new(mpirun);
    cmd.args([
        "--oversubscribe",
        "--allow-run-as-root",
        "-np",
        &np.to_string(),
        BIN,
    ])
    .args(args)
    // One rayon thread a rank: 4 ranks on 2 cores stay responsive.
    .env("RAYON_NUM_THREADS", "1")
    .stdin(Stdio::null());
    cmd
}

fn run_mpi(mpirun: &Path, np: usize, args: &[&str]) -> Output {
    let out = mpi_command(mpirun, np, args).output().unwrap();
    assert!(
        out.status.success(),
        "mpirun -np {np} radiosity-mpi {args:?} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

#[derive(Parser)]
struct Radiosity {
    #[command(subcommand)]
    command: Sub,
}

#[derive(clap::Subcommand)]
enum Sub {
    Formfactors(FormFactorArgs),
    Solve(SolveArgs),
    Render(RenderArgs),
}

/// `radiosity ARGS`, in this process.
fn single(args: &[&str]) {
    let cli = Radiosity::try_parse_from(std::iter::once("radiosity").chain(args.iter().copied()))
        .unwrap();
    let result = match cli.command {
        Sub::Formfactors(a) => radiosity_cli::commands::formfactors::run(a),
        Sub::Solve(a) => radiosity_cli::commands::solve::run(a),
        Sub::Render(a) => radiosity_cli::commands::render::run(a),
    };
    result.unwrap();
}

fn same_bytes(a: &Path, b: &Path) -> bool {
    std::fs::read(a).unwrap() == std::fs::read(b).unwrap()
}

/// The mesh of the tests: occluder.scene at MAX_PATCH_AREA 0.5 (about 100 elements).
const MESH: [&str; 2] = ["--max-area", "0.5"];

/// Every method on 1, 2 and 4 ranks (4 on 2 cores: oversubscribed) writes the file of
/// `radiosity formfactors` with the same flags, byte for byte; blocks of 7 rows, so that
/// every rank gets several and they arrive out of order.
#[test]
fn every_method_on_1_2_and_4_ranks_writes_the_single_process_file() {
    let Some(mpirun) = mpirun() else { return };
    let dir = tempfile::tempdir().unwrap();
    let scene = scene();
    let scene = scene.to_str().unwrap();
    let methods: [&[&str]; 5] = [
        &["--method", "area"],
        &["--method", "contour"],
        &["--method", "analytic", "--steps", "1"],
        &["--method", "hemicube", "--resolution", "16"],
        &["--method", "montecarlo", "--samples", "16", "--seed", "11"],
    ];
    for method in methods {
        let reference = dir.path().join("single.ff");
        let mut args = vec![
            "formfactors",
            scene,
            "-q",
            "-o",
            reference.to_str().unwrap(),
        ];
        args.extend(MESH);
        args.extend(method);
        single(&args);
        for np in [1, 2, 4] {
            let out = dir.path().join(format!("mpi{np}.ff"));
            let mut args = vec!["formfactors", scene, "-q", "-o", out.to_str().unwrap()];
            args.extend(MESH);
            args.extend(method);
            args.extend(["--block-rows", "7"]);
            run_mpi(&mpirun, np, &args);
            assert!(
                same_bytes(&reference, &out),
                "{method:?} on {np} ranks: not the bytes of radiosity formfactors"
            );
        }
    }
}

/// `solve` and `render` with the form factors dealt over 2 ranks write what `radiosity`
/// writes (the solve then runs on rank 0 from those form factors, with the solver `auto`
/// picks for this mesh).
#[test]
fn solve_and_render_on_2_ranks_write_the_single_process_files() {
    let Some(mpirun) = mpirun() else { return };
    let dir = tempfile::tempdir().unwrap();
    let scene = scene();
    let scene = scene.to_str().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let (csv1, csv2) = (path("single.csv"), path("mpi.csv"));
    let mut args = vec!["solve", scene, "-q", "-o", &csv1];
    args.extend(MESH);
    single(&args);
    let mut args = vec!["solve", scene, "-q", "-o", &csv2];
    args.extend(MESH);
    run_mpi(&mpirun, 2, &args);
    assert!(
        same_bytes(Path::new(&csv1), Path::new(&csv2)),
        "solve differs"
    );
    let (png1, png2) = (path("single.png"), path("mpi.png"));
    let size = ["--width", "48", "--height", "32", "--supersample", "1"];
    let mut args = vec!["render", scene, "-q", "-o", &png1];
    args.extend(MESH);
    args.extend(size);
    single(&args);
    let mut args = vec!["render", scene, "-q", "-o", &png2];
    args.extend(MESH);
    args.extend(size);
    run_mpi(&mpirun, 2, &args);
    assert!(
        same_bytes(Path::new(&png1), Path::new(&png2)),
        "render differs"
    );
    // Nothing left beside the outputs (the scratch form-factor file is removed).
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["mpi.csv", "mpi.png", "single.csv", "single.png"]);
}

/// The process id of rank `rank` of a job of this binary (from /proc: its command line and
/// the OMPI_COMM_WORLD_RANK Open MPI gives it).
fn pid_of_rank(rank: usize) -> Option<u32> {
    let want = format!("OMPI_COMM_WORLD_RANK={rank}");
    for entry in std::fs::read_dir("/proc").ok()?.flatten() {
        let Ok(pid) = entry.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        let Ok(exe) = std::fs::read_link(entry.path().join("exe")) else {
            continue;
        };
        if exe != Path::new(BIN).canonicalize().ok()? {
            continue;
        }
        let environ = std::fs::read(entry.path().join("environ")).unwrap_or_default();
        if environ.split(|&b| b == 0).any(|v| v == want.as_bytes()) {
            return Some(pid);
        }
    }
    None
}

/// Waits for `child` at most `limit`; its output, or a panic saying it hung.
fn wait_bounded(mut child: std::process::Child, limit: Duration, what: &str) -> Output {
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("{what}: still running after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

fn block_files(dir: &Path) -> usize {
    std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .flatten()
                .filter(|e| e.file_name().to_string_lossy().ends_with(".blk"))
                .count()
        })
        .unwrap_or(0)
}

/// SIGKILL to rank 1 once blocks are in the checkpoint: the job ends (within 60 s, not a
/// hang) without writing the output, naming the blocks out; resumed on 2 ranks from the
/// checkpoint it writes the bytes of `radiosity formfactors`, computing only what was
/// missing.
#[test]
fn a_rank_killed_midway_then_resumed_gives_the_same_file() {
    let Some(mpirun) = mpirun() else { return };
    let dir = tempfile::tempdir().unwrap();
    let scene = scene();
    let scene = scene.to_str().unwrap();
    let reference = dir.path().join("single.ff");
    let out = dir.path().join("mpi.ff");
    let checkpoint = dir.path().join("checkpoint");
    // A finer mesh (about 2,200 elements), blocks of 2 rows: long enough to be killed
    // midway. At --max-area 0.1 (882 elements) the job took 0.49 s on an idle machine and
    // once finished before rank 1 could be found and killed.
    let mesh = ["--max-area", "0.04", "--steps", "1"];
    let mut args = vec![
        "formfactors",
        scene,
        "-q",
        "-o",
        reference.to_str().unwrap(),
    ];
    args.extend(mesh);
    single(&args);
    let mut args = vec![
        "formfactors",
        scene,
        "-o",
        out.to_str().unwrap(),
        "--block-rows",
        "2",
        "--checkpoint",
        checkpoint.to_str().unwrap(),
    ];
    args.extend(mesh);
    let child = mpi_command(&mpirun, 2, &args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while block_files(&checkpoint) < 3 {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "no block after 60 s"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    let pid = pid_of_rank(1).expect("rank 1 runs");
    let killed = Command::new("kill")
        .args(["-KILL", &pid.to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let result = wait_bounded(child, Duration::from_secs(60), "the job after SIGKILL");
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(!result.status.success(), "the job succeeded:\n{stderr}");
    assert!(
        !out.exists(),
        "the job finished before rank 1 was killed, or wrote an incomplete file: make the \
         mesh finer\n{stderr}"
    );
    // Rank 0 names the blocks out when mpirun stops it with SIGTERM; under load mpirun
    // has also been seen to end rank 0 before it could write (one run in three of CI's
    // suite here: "Read -1, expected ..."), and then its own message names the dead rank.
    assert!(
        (stderr.contains("the job was stopped") && stderr.contains("rows "))
            || (stderr.contains("rank 1") && stderr.contains("signal 9")),
        "no message naming the blocks out or the rank that died:\n{stderr}"
    );
    let kept = block_files(&checkpoint);
    assert!(kept >= 3, "{kept} blocks kept");
    // Resume: the same bytes as one process.
    args.push("--resume");
    let resumed = run_mpi(&mpirun, 2, &args);
    let stderr = String::from_utf8_lossy(&resumed.stderr);
    assert!(stderr.contains("resumed from"), "{stderr}");
    assert!(same_bytes(&reference, &out), "the resumed file differs");
}

/// A rank that dies (exits with status 3 at its second block, without a word, as a node
/// that disappears) makes the job fail within 60 s, with a message naming the blocks out,
/// and no output file (nor a temporary file beside it).
#[test]
fn a_rank_exiting_early_fails_the_job_naming_its_block() {
    let Some(mpirun) = mpirun() else { return };
    let dir = tempfile::tempdir().unwrap();
    let scene = scene();
    let out = dir.path().join("mpi.ff");
    let mut args = vec![
        "formfactors",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--block-rows",
        "2",
    ];
    args.extend(MESH);
    let child = mpi_command(&mpirun, 2, &args)
        .env("RADIOSITY_MPI_TEST_EXIT", "1:1")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let result = wait_bounded(child, Duration::from_secs(60), "the job with a dead rank");
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(!result.status.success(), "the job succeeded:\n{stderr}");
    assert!(
        stderr.contains("rank 1 had rows "),
        "no message naming rank 1's block:\n{stderr}"
    );
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert!(left.is_empty(), "left behind: {left:?}");
}

/// A finished checkpoint resumed with another method, or another mesh, is refused saying
/// why; the same job resumed computes nothing and writes the same file.
#[test]
fn a_checkpoint_of_another_method_or_mesh_is_refused() {
    let Some(mpirun) = mpirun() else { return };
    let dir = tempfile::tempdir().unwrap();
    let scene = scene();
    let scene = scene.to_str().unwrap();
    let out = dir.path().join("a.ff");
    let checkpoint = dir.path().join("cp");
    let cp = checkpoint.to_str().unwrap();
    let base = vec![
        "formfactors",
        scene,
        "-q",
        "-o",
        out.to_str().unwrap(),
        "--checkpoint",
        cp,
    ];
    let with = |extra: &[&'static str]| -> Vec<&str> {
        let mut a = base.clone();
        a.extend(extra);
        a
    };
    let args = with(&["--max-area", "0.5"]);
    run_mpi(&mpirun, 1, &args);
    let first = std::fs::read(&out).unwrap();
    let refused = |extra: &[&'static str]| {
        let mut a = with(extra);
        a.push("--resume");
        let out = mpi_command(&mpirun, 2, &a).output().unwrap();
        assert!(!out.status.success());
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let err = refused(&["--max-area", "0.5", "--method", "contour"]);
    assert!(
        err.contains(
            "was made with form-factor method `area k=2`, but this job computes `contour k=2`"
        ),
        "{err}"
    );
    let err = refused(&["--max-area", "0.4"]);
    assert!(err.contains("but this scene meshes to"), "{err}");
    // Without --resume, a directory holding a job is refused too.
    let out2 = mpi_command(&mpirun, 1, &args).output().unwrap();
    let err = String::from_utf8_lossy(&out2.stderr);
    assert!(
        err.contains("already holds a job") && err.contains("--resume"),
        "{err}"
    );
    // The same job resumed: nothing to compute, the same file.
    let mut again = args.clone();
    again.push("--resume");
    run_mpi(&mpirun, 2, &again);
    assert_eq!(std::fs::read(&out).unwrap(), first);
}

/// Outputs that cannot be written are refused on rank 0 before any rank reads the scene,
/// by `radiosity`'s own checks (QA of issue #16: every rank read and meshed the scene, or
/// the whole job ran, first). The scene named does not exist, so a rank that read it would
/// fail on that instead; the refusal names the output, comes once, and comes within the
/// limit (a job that read a scene would still stop, but say so).
#[test]
fn outputs_are_refused_before_any_rank_reads_the_scene() {
    let Some(mpirun) = mpirun() else { return };
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("absent.scene");
    let missing = missing.to_str().unwrap();
    let real = dir.path().join("room.scene");
    std::fs::copy(scene(), &real).unwrap();
    let real = real.to_str().unwrap();
    let nowhere = dir.path().join("nowhere").join("x.ff");
    let txt = dir.path().join("x.txt");
    let (txt, nowhere) = (txt.to_str().unwrap(), nowhere.to_str().unwrap());
    let csv = dir.path().join("x.csv").to_str().unwrap().to_string();
    let cases: [(&[&str], &str); 6] = [
        (&["formfactors", missing, "-o", txt], "binary matrix format"),
        (&["formfactors", missing, "-o", nowhere], "does not exist"),
        (&["formfactors", real, "-o", real], "is the scene file"),
        (
            &["solve", missing, "-o", txt],
            "give it a .csv or .json name",
        ),
        (
            &["render", missing, "-o", txt],
            "give it a .png name, or .exr",
        ),
        (
            &["solve", missing, "-o", &csv, "--epsilon", "-1"],
            "--epsilon",
        ),
    ];
    for (args, expect) in cases {
        let start = Instant::now();
        let child = mpi_command(&mpirun, 2, args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let out = wait_bounded(child, Duration::from_secs(60), "a refused output");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} was not refused:\n{err}");
        assert!(
            err.contains(expect),
            "{args:?}: expected {expect:?} in:\n{err}"
        );
        assert!(
            !err.contains("absent.scene"),
            "{args:?}: a rank read the scene before the output was checked:\n{err}"
        );
        assert_eq!(
            err.matches("error:").count(),
            1,
            "{args:?}: one rank should say it, once:\n{err}"
        );
        assert!(
            std::fs::read_dir(dir.path()).unwrap().count() == 1,
            "{args:?} wrote a file"
        );
        eprintln!("{args:?}: refused in {:.2?}", start.elapsed());
    }
    assert_eq!(
        std::fs::read(real).unwrap(),
        std::fs::read(scene()).unwrap(),
        "the scene given as its own output was changed"
    );
}
