//! A clean stop when an allocation fails. Rust's default aborts the process with a
//! backtrace and status 134 ("memory allocation of 2048 bytes failed"), which reads as a
//! crash; a run under `ulimit -v` (or on a machine out of memory) can meet that wherever
//! the library's own estimates fall short of what the process maps (threads' stacks and
//! malloc arenas, the binary itself). This allocator is the system's, and when it returns
//! nothing it says what happened and exits with status 1, as other errors do.
//!
//! A failed `try_reserve` ends the program too (it reaches the allocator as any
//! allocation): the library's graceful path there (a form-factor file too large to read,
//! `FormFactorFileError::OutOfMemory`) stays for its other callers, and the memory
//! estimates refuse most such work before it starts. A run ended here may leave its
//! temporary output file (`.NAME.PID.RANDOM.tmp`), removed as stale by the next run.
//!
//! Written by hand because no crate does this, and `std::alloc::set_alloc_error_hook` is
//! not stable. Nothing may allocate here (the allocator has just failed), so the message
//! is written with `write(2)` from a stack buffer and the process leaves with `_exit`.

use std::alloc::{GlobalAlloc, Layout, System};

/// The system allocator, stopping the process cleanly where it fails.
pub struct CleanOutOfMemory;

/// Writes the message for a failed allocation of `size` bytes and exits with status 1.
fn fail(size: usize) -> ! {
    const HEAD: &[u8] = b"error: out of memory: an allocation of ";
    const TAIL: &[u8] = b" bytes failed (the address-space limit of `ulimit -v`, or the \
machine's memory, is reached); a coarser mesh (a larger MAX_PATCH_AREA or --max-area) or a \
smaller picture needs less, or raise the limit\n";
    let mut digits = [0u8; 20];
    let mut at = digits.len();
    let mut n = size;
    loop {
        at -= 1;
        digits[at] = b'0' + (n % 10) as u8;
        n /= 10;
        if n == 0 {
            break;
        }
    }
    for part in [HEAD, &digits[at..], TAIL] {
        // SAFETY: `part` is a valid buffer of `part.len()` bytes; fd 2 is stderr (a
        // failed write leaves nothing better to do).
        unsafe {
            libc::write(2, part.as_ptr().cast(), part.len());
        }
    }
    // SAFETY: `_exit` ends the process at once, running nothing that could allocate.
    unsafe { libc::_exit(1) }
}

// SAFETY: every call is passed to `System` unchanged; only a null result is acted on, by
// ending the process.
unsafe impl GlobalAlloc for CleanOutOfMemory {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if p.is_null() {
            fail(layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(layout) };
        if p.is_null() {
            fail(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if p.is_null() {
            fail(new_size);
        }
        p
    }
}
