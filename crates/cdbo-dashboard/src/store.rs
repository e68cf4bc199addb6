//! Where the dashboard reads studies and experiments from, behind one small trait so that
//! another storage (a database server) can slot in beside the files. Every read is read-only.

use std::path::{Path, PathBuf};

use cdbo::experiment::record::RunRecord;
use cdbo::study::{Study, StudyConfig, Trial};
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
    /// Where it lives (a file, a folder, a URL).
    pub location: String,
}

/// Read access to studies and experiments.
pub trait Store: Send + Sync {
    /// A study's settings and every trial so far, in asking order.
    fn study(&self, source: &Source) -> Result<(StudyConfig, Vec<Trial>)>;
    /// An experiment's finished runs, in grid order.
    fn runs(&self, source: &Source) -> Result<Vec<RunRecord>>;
}

/// Studies in SQLite files and experiments in folders (`DIR/runs/ID.json`).
#[derive(Debug, Clone, Copy, Default)]
pub struct Files;

impl Files {
    /// Checks that `path` is a study, opening it read-only.
    pub fn study_source(path: &Path) -> Result<Source> {
        Study::open_read_only(path)?;
        Ok(Source {
            kind: Kind::Study,
            location: path.display().to_string(),
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
        })
    }
}

impl Store for Files {
    fn study(&self, source: &Source) -> Result<(StudyConfig, Vec<Trial>)> {
        let study = Study::open_read_only(Path::new(&source.location))?;
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
