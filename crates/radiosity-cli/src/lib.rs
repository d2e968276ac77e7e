//! The `radiosity` command line as a library: the flags ([`args`]), the objects built from
//! them ([`setup`]), the commands and the progress bar, so that other front ends (the MPI
//! program `radiosity-mpi`) parse the same flags and run the same code. The binary
//! `radiosity` (src/main.rs) is `main` over it.
//!
//! `args` holds the flags as clap parses them, `setup` builds the library's objects from
//! them, `commands` has one file per command, `report` prints what they report.

#[macro_use]
pub mod macros;

pub mod args;
pub mod commands;
pub mod errors;
pub mod peak_memory;
pub mod progress_bar;
pub mod report;
pub mod runtime_dir;
pub mod setup;
