//! Any bytes given as a calibration log (`cdbo torcs calibrate --log`): an error, or laps of at
//! least two finite samples each, on the track, whose pedal tables load as policies.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let length = 1000.0;
    if let Ok(text) = std::str::from_utf8(data)
        && let Ok(laps) = cdbo::sim::log::parse(text, "fuzz.csv", length)
    {
        for lap in &laps {
            assert!(lap.samples.len() >= 2);
            for s in &lap.samples {
                assert!(s.distance_m.is_finite() && s.speed.is_finite() && s.pedal.abs() <= 1.0);
                assert!(s.distance_m >= -5.0 && s.distance_m <= 1.02 * length);
            }
            assert!(cdbo::calibrate::Observed::of_log(lap, length, "fuzz.csv").is_ok());
        }
    }
});
