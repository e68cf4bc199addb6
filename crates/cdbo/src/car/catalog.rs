//! Finds a car by name: built-in, a file path, or a name in the data folders.

use std::path::Path;

use super::Car;
use crate::data_path::DataPath;
use crate::error::{Error, Result};

/// The built-in car names.
pub const BUILTIN: &[&str] = &["spirit-300"];

/// The default car.
pub const DEFAULT: &str = "spirit-300";

/// Resolves `spec`: a built-in name, a car XML path, a calibrated car (`.toml`, a base car and
/// scales: [`super::calibration`]), or a car name in the data folders (`cars/NAME/NAME.xml`
/// for TORCS, `cars/models/NAME/NAME.xml` for Speed Dreams).
pub fn find(spec: &str, data: &DataPath) -> Result<Car> {
    if matches!(spec, "spirit-300" | "sc-spirit-300-builtin") {
        return Ok(Car::spirit_300());
    }
    let path = Path::new(spec);
    if path.extension().is_some_and(|e| e == "toml") {
        return super::calibration::read(path, &|base| find(base, data));
    }
    if path.extension().is_some_and(|e| e == "xml") || path.is_file() {
        return super::torcs::read(path, None);
    }
    let rels = [
        format!("cars/{spec}/{spec}.xml"),
        format!("cars/models/{spec}/{spec}.xml"),
    ];
    match data.find(&rels) {
        Some(p) => super::torcs::read(&p, None),
        None => Err(Error::NotFound {
            what: "car",
            name: format!("{spec:?}"),
            detail: format!(
                "not built in ({}), not a file, and not found in {}",
                BUILTIN.join(", "),
                data.describe()
            ),
        }),
    }
}
