//! Any bytes given as a lap's trace (`cdbo lap --trace`, the game's robot): an error, or rows of
//! finite numbers that write out and read back as the same rows' text.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data)
        && let Ok(trace) = cdbo::sim::trace::parse(text, "fuzz.csv")
    {
        assert!(
            trace
                .iter()
                .all(|p| p.values().iter().all(|v| v.is_finite()))
        );
        let mut written = Vec::new();
        cdbo::sim::trace::write(&mut written, &trace).expect("writing to memory");
        let written = String::from_utf8(written).expect("a trace is text");
        let again =
            cdbo::sim::trace::parse(&written, "again.csv").expect("a written trace reads back");
        assert_eq!(again.len(), trace.len());
    }
});
