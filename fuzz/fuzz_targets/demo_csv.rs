//! Any bytes given as a demonstration: an error or finite (x, a) pairs, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data)
        && let Ok(pairs) = cdbo::policy::demo::parse(text, "fuzz.csv")
    {
        assert!(pairs.iter().all(|(x, a)| x.is_finite() && a.is_finite()));
    }
});
