//! The VRML97 reader on arbitrary bytes, then the scene writer on what it read: see `radiosity_fuzz::vrml`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| radiosity_fuzz::vrml(data));
