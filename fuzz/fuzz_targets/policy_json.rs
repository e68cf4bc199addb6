//! Any bytes given as policy weights (`cdbo lap --policy w.json`): an error or a policy whose
//! pedal and line are finite, and whose driver's pedal (a target speed's hold, where it has
//! one) is in [−1, 1], never a panic.
#![no_main]

use cdbo::drive::{Observation, Pedal};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data)
        && let Ok(p) = cdbo::policy::Policy::from_json(text, "fuzz")
    {
        for x in [0.0, 0.37, 1.0] {
            assert!(p.pedal.action(x).is_finite());
            assert!(p.line_offset(x).is_finite());
        }
        let mut driver = p.driver();
        for (x, speed) in [(0.0, 0.0), (0.37, 30.0), (1.0, 90.0)] {
            let a = driver.pedal(&Observation {
                x,
                speed,
                time: 1.0,
            });
            assert!((-1.0..=1.0).contains(&a), "{a}");
        }
    }
});
