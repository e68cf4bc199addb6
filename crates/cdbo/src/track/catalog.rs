//! Finds a track by name: built-in, a file path, or a name in the data folders.

use std::path::Path;

use super::{Ends, Track, builtin};
use crate::data_path::DataPath;
use crate::error::{Error, Result};

/// TORCS track categories searched under `tracks/`.
const CATEGORIES: &[&str] = &[
    "road",
    "dirt",
    "oval",
    "speedway",
    "circuit",
    "development",
    "gprix",
];

/// Resolves `spec`: a built-in name, a `.xml` (TORCS) or `.csv` (TUMFTM) path, or a track
/// name in the data folders (`tracks/CATEGORY/NAME/NAME.xml` or `tracks/csv/NAME.csv`).
pub fn find(spec: &str, data: &DataPath) -> Result<Track> {
    find_with(spec, data, Ends::MustMeet)
}

/// [`find`], with what to do when a TORCS track does not close (a CSV centre line always does).
pub fn find_with(spec: &str, data: &DataPath, ends: Ends) -> Result<Track> {
    if let Some(t) = builtin::load(spec) {
        return t;
    }
    let path = Path::new(spec);
    match path.extension().and_then(|e| e.to_str()) {
        Some("xml") => return super::torcs::read(path, ends),
        Some("csv") => return super::csv::read(path),
        _ => {}
    }
    let mut rels: Vec<String> = CATEGORIES
        .iter()
        .map(|c| format!("tracks/{c}/{spec}/{spec}.xml"))
        .collect();
    rels.push(format!("tracks/csv/{spec}.csv"));
    // TUMFTM files are capitalised (Monza.csv): also try the capitalised name.
    let mut cap = spec.to_owned();
    if let Some(first) = cap.get_mut(0..1) {
        first.make_ascii_uppercase();
    }
    rels.push(format!("tracks/csv/{cap}.csv"));
    match data.find(&rels) {
        Some(p) if p.extension().is_some_and(|e| e == "csv") => super::csv::read(&p),
        Some(p) => super::torcs::read(&p, ends),
        None => Err(Error::NotFound {
            what: "track",
            name: format!("{spec:?}"),
            detail: format!(
                "not built in ({}), not a .xml or .csv file, and not found in {}",
                builtin::names().collect::<Vec<_>>().join(", "),
                data.describe()
            ),
        }),
    }
}
