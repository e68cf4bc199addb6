//! Any bytes given as a TORCS track file: an error or a track, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data)
        && let Ok(params) = cdbo::params::Params::parse(text, "fuzz.xml", None)
    {
        let _ = cdbo::track::torcs::from_params(&params, "fuzz.xml", cdbo::track::Ends::MayMiss);
    }
});
