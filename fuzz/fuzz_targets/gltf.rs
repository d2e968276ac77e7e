//! The glTF reader on arbitrary bytes (JSON or .glb), then the scene writer on what it read: see `radiosity_fuzz::gltf`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| radiosity_fuzz::gltf(data));
