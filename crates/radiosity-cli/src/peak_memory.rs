//! The process's peak resident memory, for `radiosity compare`: reset the high-water mark
//! before a solve, read it after.
//!
//! Hand-written because no small crate does both halves: `memory-stats` reads only the
//! current resident size, `getrusage` wrappers (`app-memory-usage-fetcher`) give a peak that
//! cannot be reset, and allocator wrappers (`peakmem-alloc`, `peak_alloc`) count heap bytes,
//! not resident memory, and replace the global allocator. `procfs` can do both
//! (`Process::clear_refs(ClearRefs::PeakRSS)` and `status().vmhwm`) but is a large,
//! Linux-only dependency for one write and one read of `/proc/self`, all that is needed here.

/// Resets the process's peak resident memory (Linux: `/proc/self/clear_refs`), so that
/// [`peak_memory_bytes`] measures from now; false where that is not possible.
pub fn reset_peak_memory() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// The process's peak resident memory (VmHWM) in bytes, where the system reports it.
pub fn peak_memory_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}
