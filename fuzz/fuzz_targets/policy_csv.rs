//! Any bytes given as an `x,a` policy table: an error or a table, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data)
        && let Ok(table) = cdbo::policy::PolicyTable::parse_csv(text, "fuzz.csv")
    {
        let _ = table.action(0.5);
    }
});
