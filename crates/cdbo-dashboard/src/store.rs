//! Where the dashboard reads studies and experiments from, behind one small trait: studies in
//! SQLite files or PostgreSQL, experiments in folders or as grids in a database (filled by
//! `cdbo experiment --storage URL --worker`). Every read is read-only.

use std::path::{Path, PathBuf};

use cdbo::experiment::record::RunRecord;
use cdbo::experiment::shared::SharedGrid;
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
    /// A grid's place in a database, for an experiment not in a folder (never sent either).
    #[serde(skip)]
    pub grid: Option<Location>,
}

/// Read access to studies and experiments.
pub trait Store: Send + Sync {
    /// A study's settings and every trial so far, in asking order.
    fn study(&self, source: &Source) -> Result<(StudyConfig, Vec<Trial>)>;
    /// An experiment's finished runs, in grid order.
    fn runs(&self, source: &Source) -> Result<Vec<RunRecord>>;
    /// The studies and grids of `database` (a whole database, [`is_database`]) other than
    /// `known`: studies, then grids, each by name.
    fn database(&self, database: &str, known: &[Source]) -> Result<Vec<Source>>;
}

/// Whether `storage` names a whole PostgreSQL database (its URL without `#NAME`), every study
/// and grid of which is shown.
pub fn is_database(storage: &str) -> bool {
    ["postgresql://", "postgres://"]
        .iter()
        .any(|s| storage.starts_with(s))
        && !storage.contains('#')
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
            grid: None,
        })
    }

    /// Checks that there is a grid at `location`, opening it read-only.
    pub fn grid_at(location: Location) -> Result<Source> {
        let grid = SharedGrid::open_read_only(&location)?;
        Ok(Source {
            kind: Kind::Experiment,
            location: grid.path().display().to_string(),
            study: None,
            grid: Some(location),
        })
    }

    /// What `storage` names: a study or a grid (an SQLite file, or `DATABASE-URL#NAME`), or,
    /// for a PostgreSQL URL without a name, every study and grid the database holds.
    pub fn storage(storage: &str) -> Result<Vec<Source>> {
        if is_database(storage) {
            return Files.database(storage, &[]);
        }
        let location = Location::parse(storage, None)?;
        match Files::study_at(location.clone()) {
            Err(e @ (Error::NotAStudy { .. } | Error::NoStudy { .. })) => {
                match Files::grid_at(location) {
                    Err(Error::NotAGrid { .. } | Error::NoGrid { .. }) => Err(e),
                    grid => grid.map(|g| vec![g]),
                }
            }
            study => study.map(|s| vec![s]),
        }
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
            grid: None,
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

    fn database(&self, database: &str, known: &[Source]) -> Result<Vec<Source>> {
        let label = Location::parse(database, Some("*"))?.label();
        let (studies, grids) = cdbo::store::postgres::names(database, &label)?;
        let at = |name: &String| Location::parse(database, Some(name));
        let shown = |l: &Location| {
            known
                .iter()
                .any(|s| s.study.as_ref() == Some(l) || s.grid.as_ref() == Some(l))
        };
        let mut sources = Vec::new();
        for name in &studies {
            let location = at(name)?;
            if !shown(&location) {
                sources.push(Files::study_at(location)?);
            }
        }
        for name in &grids {
            let location = at(name)?;
            if !shown(&location) {
                sources.push(Files::grid_at(location)?);
            }
        }
        Ok(sources)
    }

    fn runs(&self, source: &Source) -> Result<Vec<RunRecord>> {
        if let Some(location) = &source.grid {
            return SharedGrid::open_read_only(location)?.records();
        }
        let dir = PathBuf::from(&source.location);
        if !dir.join("runs").is_dir() {
            return Ok(Vec::new());
        }
        RunRecord::load_all(&[dir])
    }
}
