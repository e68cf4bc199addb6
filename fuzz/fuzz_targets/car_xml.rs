//! Any bytes given as a TORCS car file: an error or a car, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data)
        && let Ok(params) = cdbo::params::Params::parse(text, "fuzz.xml", None)
    {
        let _ = cdbo::car::torcs::from_params(&params);
    }
});
