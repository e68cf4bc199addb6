//! Any bytes given as policy weights (`cdbo lap --policy w.json`): an error or a policy whose
//! pedal and line are finite, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data)
        && let Ok(p) = cdbo::policy::Policy::from_json(text, "fuzz")
    {
        for x in [0.0, 0.37, 1.0] {
            assert!(p.pedal.action(x).is_finite());
            assert!(p.line_offset(x).is_finite());
        }
    }
});
