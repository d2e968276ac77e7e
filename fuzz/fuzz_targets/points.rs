//! The illuminance command's points CSV reader on arbitrary bytes: see `radiosity_fuzz::points`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| radiosity_fuzz::points(data));
