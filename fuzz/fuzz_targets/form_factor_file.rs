//! The form-factor file reader on arbitrary bytes, then a solve on any matrix it accepts:
//! see `radiosity_fuzz::form_factor_file`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| radiosity_fuzz::form_factor_file(data));
