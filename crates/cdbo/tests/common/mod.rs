//! Helpers shared by the integration tests.
#![allow(dead_code)]

mod shared;

use cdbo::data_path::DataPath;
use cdbo::track::Track;

#[allow(unused_imports)] // each test file uses some of them
pub use shared::{shared, shared_if_present};

/// A track from ../shared, found by name.
pub fn shared_track(name: &str) -> Track {
    let data = DataPath::with_env(&[shared("")], "");
    cdbo::track::catalog::find(name, &data).unwrap_or_else(|e| panic!("{e}"))
}

/// A car from ../shared, found by name.
pub fn shared_car(name: &str) -> cdbo::car::Car {
    let data = DataPath::with_env(&[shared("")], "");
    cdbo::car::catalog::find(name, &data).unwrap_or_else(|e| panic!("{e}"))
}

/// A built-in track.
pub fn builtin(name: &str) -> Track {
    cdbo::track::builtin::load(name)
        .expect("built-in")
        .expect("loads")
}
