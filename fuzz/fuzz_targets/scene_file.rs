//! The scene file reader (Appendix A format) on arbitrary bytes, then meshing, form factors
//! and a solve on the small scenes that parse: see `radiosity_fuzz::scene_file`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| radiosity_fuzz::scene_file(data));
