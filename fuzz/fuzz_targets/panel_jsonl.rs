//! Any bytes given as a panel of the game's laps (`cdbo torcs panel`): an error, or laps whose
//! policies are sound and whose game laps either completed in a positive time or failed at a
//! finite distance, which write back to the same laps.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data)
        && let Ok(laps) = cdbo::torcs::panel::parse(text, "fuzz.jsonl")
    {
        for lap in &laps {
            assert!(lap.policy.weights().iter().all(|w| w.is_finite()));
            let t = &lap.torcs;
            assert!(
                t.lap_time_s.is_some_and(|s| s > 0.0)
                    || t.distance_fail_m.is_some_and(f64::is_finite)
            );
            let line = cdbo::torcs::panel::line(lap).unwrap();
            assert_eq!(&cdbo::torcs::panel::parse(&line, "again").unwrap()[0], lap);
        }
    }
});
