//! Where the dashboard reads studies and experiments from, behind one small trait so that
//! another storage (a database server) can slot in beside the files. Every read is read-only.

use std::path::{Path, PathBuf};

use cdbo::experiment::record::RunRecord;
use cdbo::study::{Location, Study, StudyConfig, Trial};
use cdbo::{Error, Result};
use serde::Serialize;

/// What a source on show is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// A study: one optimiser's trials, told one at a time.
    Study,
    /// An experiment: a grid of finished runs.
    Experiment,
}

/// A study or experiment on show: what it is and where it lives.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Source {
    /// Study or experiment.
    pub kind: Kind,
    /// Where it lives, as shown (a file, a folder, a URL without its password).
    pub location: String,
    /// A study's place, to open it (never sent to the page: a URL may hold a password).
    #[serde(skip)]
    pub study: Option<Location>,
}

/// Read access to studies and experiments.
pub trait Store: Send + Sync {
    /// A study's settings and every trial so far, in asking order.
    fn study(&self, source: &Source) -> Result<(StudyConfig, Vec<Trial>)>;
    /// An experiment's finished runs, in grid order.
    fn runs(&self, source: &Source) -> Result<Vec<RunRecord>>;
}

/// Studies wherever they live (SQLite files, PostgreSQL databases) and experiments in folders
/// (`DIR/runs/ID.json`).
#[derive(Debug, Clone, Copy, Default)]
pub struct Files;

impl Files {
    /// Checks that `path` is a study file, opening it read-only.
    pub fn study_source(path: &Path) -> Result<Source> {
        Files::study_at(Location::Sqlite(path.to_owned()))
    }

    /// Checks that there is a study at `location`, opening it read-only.
    pub fn study_at(location: Location) -> Result<Source> {
        let study = Study::open_read_only_at(&location)?;
        Ok(Source {
            kind: Kind::Study,
            location: study.path().display().to_string(),
            study: Some(location),
        })
    }

    /// Checks that `dir` is a folder that can hold an experiment's runs. A grid that has not
    /// finished a run yet has no `runs/` folder: it shows as empty until one arrives.
    pub fn experiment_source(dir: &Path) -> Result<Source> {
        if !dir.is_dir() {
            let what = if dir.exists() {
                "not a folder"
            } else {
                "no such folder"
            };
            return Err(Error::Io {
                path: dir.to_owned(),
                source: std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    format!("{what} (expected the output folder of `cdbo experiment`)"),
                ),
            });
        }
        Ok(Source {
            kind: Kind::Experiment,
            location: dir.display().to_string(),
            study: None,
        })
    }
}

impl Store for Files {
    fn study(&self, source: &Source) -> Result<(StudyConfig, Vec<Trial>)> {
        let study = match &source.study {
            Some(location) => Study::open_read_only_at(location)?,
            None => Study::open_read_only(Path::new(&source.location))?,
        };
        Ok((study.config().clone(), study.history()?))
    }

    fn runs(&self, source: &Source) -> Result<Vec<RunRecord>> {
        let dir = PathBuf::from(&source.location);
        if !dir.join("runs").is_dir() {
            return Ok(Vec::new());
        }
        RunRecord::load_all(&[dir])
    }
}
