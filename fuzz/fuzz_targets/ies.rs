//! The IES LM-63 photometric file reader on arbitrary bytes: see `radiosity_fuzz::ies`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| radiosity_fuzz::ies(data));
