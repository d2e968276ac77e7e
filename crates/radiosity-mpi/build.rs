//! Says why `cargo build -p radiosity-mpi --no-default-features` builds no program.
//!
//! The program needs the `mpi` crate, whose build script (mpi-sys) fails without an MPI
//! installation, and a dependency cannot be switched on or off by a build script's probe:
//! so the program is behind the default feature `mpi`, and a machine without MPI builds the
//! library alone with `--no-default-features`. Then this script looks for `mpicc` ($MPICC
//! first, as the mpi crate's probe does) and prints one warning with the command that would
//! build the program, or the packages it needs.

use std::process::Command;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=MPICC");
    if std::env::var_os("CARGO_FEATURE_MPI").is_some() {
        return;
    }
    let mpicc = std::env::var("MPICC").unwrap_or_else(|_| "mpicc".into());
    let found = Command::new(&mpicc)
        .arg("-show")
        .output()
        .is_ok_and(|out| out.status.success());
    let next = if found {
        format!("MPI was found (`{mpicc}`): build it with `cargo build --release -p radiosity-mpi`")
    } else {
        "no MPI was found (no `mpicc`): install Open MPI (Debian: libopenmpi-dev openmpi-bin \
         libclang-dev), then build it with `cargo build --release -p radiosity-mpi`"
            .to_string()
    };
    println!(
        "cargo:warning=the program radiosity-mpi is built only with the default feature `mpi` \
         (this build has its library alone); {next}"
    );
}
