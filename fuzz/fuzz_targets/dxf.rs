//! The DXF reader on arbitrary bytes (its materials TOML after a %%TOML line), then the scene writer on what it read: see `radiosity_fuzz::dxf`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| radiosity_fuzz::dxf(data));
