//! Any bytes given as an experiment grid (`cdbo experiment grid.toml`): an error or a checked
//! grid, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = cdbo::experiment::grid::ExperimentConfig::from_toml(text, "fuzz.toml");
    }
});
