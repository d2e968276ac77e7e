//! The OBJ + MTL reader on arbitrary bytes (the MTL after a `%%MTL` line), then the scene
//! writer on what it read: see `radiosity_fuzz::obj`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| radiosity_fuzz::obj(data));
