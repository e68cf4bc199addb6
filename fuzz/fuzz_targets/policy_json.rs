//! Any bytes given as policy weights (`cdbo lap --policy w.json`): an error or a policy whose
//! pedal is finite, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(p) = serde_json::from_slice::<cdbo::policy::RkhsPolicy>(data)
        && let Ok(p) = cdbo::policy::RkhsPolicy::new(p.weights, p.lengthscale)
    {
        for x in [0.0, 0.37, 1.0] {
            assert!(p.action(x).is_finite());
        }
    }
});
