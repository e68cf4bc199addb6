//! Any bytes given as a transfer's reference (`cdbo torcs transfer --against`): an error, or
//! named tracks whose references are finite rewards above 0 m/s.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data)
        && let Ok(reference) = cdbo::torcs::transfer::reference(text, "fuzz.json")
    {
        assert!(!reference.is_empty());
        for (track, r) in &reference {
            assert!(!track.trim().is_empty());
            assert!(r.is_finite() && *r > 0.0, "{track}: {r}");
        }
    }
});
