//! `errln!` and `outln!`: `eprintln!` and `println!` that ignore a closed or failing
//! stream. Declared first in `lib.rs` (`#[macro_use]`), so every module can use them;
//! exported for the binaries (`#[macro_use] extern crate radiosity_cli`).

/// `eprintln!` that ignores a closed or failing stderr (a `| head` must not abort a run).
#[macro_export]
macro_rules! errln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

/// `println!` that ignores a closed or failing stdout.
#[macro_export]
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout(), $($arg)*);
    }};
}
