//! Any bytes given as a TUMFTM centre line: an error or a track, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = cdbo::track::csv::parse(text, "fuzz", "fuzz.csv");
    }
});
