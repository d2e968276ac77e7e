//! The checkpoint directory reader of `radiosity-mpi --resume` on arbitrary manifests and
//! block files: see `radiosity_fuzz::checkpoint`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| radiosity_fuzz::checkpoint(data));
