//! Any text given as `--storage` (and `--study`): a location or an error, never a panic; a
//! database's label and any error keep a password out (`USER:***@`).
#![no_main]

use cdbo::store::{Location, redact};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let (storage, study) = match text.split_once('\n') {
        Some((storage, study)) => (storage, Some(study)),
        None => (text, None),
    };
    let shown = match Location::parse(storage, study) {
        Ok(location) => location.label().display().to_string(),
        Err(e) => e.to_string(),
    };
    assert_eq!(redact(&redact(storage)), redact(storage));
    // A database's password, in the authority `USER:PASSWORD@HOST`, is shown as `***` (an
    // SQLite path is a file's name, shown as it is).
    if let Some((scheme, rest)) = storage.split_once("://")
        && scheme != "sqlite"
        && !storage.contains('#')
        && let Some(authority) = rest.split('/').next()
        && let Some(at) = authority.rfind('@')
        && let Some((user, _)) = authority[..at].split_once(':')
    {
        let hidden = format!("{scheme}://{user}:***@");
        assert!(shown.contains(&hidden), "{shown}");
    }
});
