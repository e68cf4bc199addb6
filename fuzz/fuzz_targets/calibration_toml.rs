//! Any bytes given as a calibration (`cdbo torcs calibrate` writes one): an error, or a base car
//! and six scales within their bounds that write out and read back as the same calibration.
#![no_main]

use cdbo::car::calibration::Calibration;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data)
        && let Ok(c) = Calibration::parse(text, "fuzz.toml")
    {
        assert!(c.scales.check().is_ok());
        let again = Calibration::parse(&c.to_toml("fuzz"), "again.toml")
            .expect("a calibration's own TOML reads back");
        assert_eq!(again, c);
    }
});
