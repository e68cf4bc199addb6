//! Any bytes a lap command prints: an outcome (reward or failure), never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let _ = cdbo::evaluator::command::parse_output(&text);
});
