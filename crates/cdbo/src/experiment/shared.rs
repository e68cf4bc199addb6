//! A grid spread over workers through a database: any number of processes, on any number of
//! machines (a Slurm job array, `ssh host cdbo … --worker`), fill one grid. The grid lives
//! where a study does ([`Location`]: an SQLite file, or a PostgreSQL database holding grids
//! by name), with one row per cell (one run: method × track × kernels × seed) in the grid's
//! fixed order, holding the cell's claim and, once finished, its [`RunRecord`] (the same JSON
//! as an experiment folder's `runs/ID.json`).
//!
//! A worker pulls the next cell no one holds by the rules of [`claim::hand_out`], a cell
//! standing for a trial: its own cell first, then one never claimed, or whose lease ran out
//! (its worker stopped renewing it), or whose worker was a process of this host that no
//! longer exists; while every unfinished cell is held by a live worker it waits, and it stops
//! when every cell is finished. Every cell is a row from the start, so nothing new is ever
//! suggested. A finished cell is never run again, and a cell finished twice (a worker whose
//! lease ran out while it ran) keeps its first record.

#[cfg(feature = "postgres")]
mod postgres;
mod sqlite;
mod storage;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::folder::Session;
use super::grid::{ExperimentConfig, RunSpec};
use super::record::{RunRecord, run};
use crate::car::Car;
use crate::error::{Error, Result};
use crate::store::claim::{self, Handout, Missed, Worker};
use crate::store::{Location, unix_now};
use crate::track::Track;
use storage::GridStorage;

/// A cell of the grid to run: its row id and its run.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    /// The row id: the run's position in [`ExperimentConfig::runs`], from 1.
    pub id: i64,
    /// The run.
    pub spec: RunSpec,
}

/// What a worker is to do next.
#[derive(Debug, Clone, PartialEq)]
pub enum Next {
    /// Run this cell (claimed for the worker), then finish it.
    Run(Cell),
    /// Every unfinished cell is held by another live worker: wait, then claim again.
    Wait,
    /// Every cell is finished.
    Done,
}

/// An open grid in a database.
pub struct SharedGrid {
    location: Location,
    label: PathBuf,
    storage: Box<dyn GridStorage>,
    config: ExperimentConfig,
    runs: Vec<RunSpec>,
}

impl SharedGrid {
    /// Opens the grid at `location` to work on it, storing `config` there first if it holds
    /// none (workers started at once store it once); refuses a different grid under the same
    /// name ([`Error::DifferentGrid`]), a database of a newer cdbo, or a file that is not a
    /// grid, writing nothing then.
    pub fn join(location: &Location, config: &ExperimentConfig) -> Result<SharedGrid> {
        let mut storage = open_storage(location, true)?;
        let label = storage.label().to_owned();
        let runs = config.runs();
        let text = toml::to_string(config).map_err(|e| Error::NotAGrid {
            path: label.clone(),
            reason: format!("the grid does not serialise: {e}"),
        })?;
        {
            let mut tx = storage.begin()?;
            match tx.grid()? {
                Some(stored) => {
                    if parse_grid(&stored, &label)? != *config {
                        return Err(Error::DifferentGrid { path: label });
                    }
                }
                None => {
                    tx.create(&text, &runs.iter().map(RunSpec::id).collect::<Vec<_>>())?;
                    tx.commit()?;
                }
            }
        }
        Ok(SharedGrid {
            location: location.clone(),
            label,
            storage,
            config: config.clone(),
            runs,
        })
    }

    /// Opens the grid at `location` to read it: writes nothing.
    pub fn open_read_only(location: &Location) -> Result<SharedGrid> {
        let mut storage = open_storage(location, false)?;
        let label = storage.label().to_owned();
        let stored = storage.grid()?.ok_or_else(|| Error::NoGrid {
            path: label.clone(),
        })?;
        let config = parse_grid(&stored, &label)?;
        Ok(SharedGrid {
            location: location.clone(),
            label,
            storage,
            runs: config.runs(),
            config,
        })
    }

    /// The grid.
    pub fn config(&self) -> &ExperimentConfig {
        &self.config
    }

    /// Where the grid lives, for messages: the file, or the database URL and grid name.
    pub fn path(&self) -> &Path {
        &self.label
    }

    /// The cell `worker` is to run next, claimed for it until its lease runs out (renewed
    /// by [`SharedGrid::run_cell`] while it runs), or whether to wait or stop.
    pub fn claim(&mut self, worker: &Worker) -> Result<Next> {
        let mut tx = self.storage.begin()?;
        let now = unix_now();
        let unfinished = tx.claims()?;
        let finished = tx.count(true)?;
        match claim::hand_out(&unfinished, finished, Some(self.runs.len()), worker, now) {
            Handout::Done => Ok(Next::Done),
            // Every cell is a row from the start (finished + unfinished = all): never new.
            Handout::Wait | Handout::New => Ok(Next::Wait),
            Handout::Pending(id) => {
                let spec = usize::try_from(id - 1)
                    .ok()
                    .and_then(|k| self.runs.get(k))
                    .cloned()
                    .ok_or_else(|| Error::NotAGrid {
                        path: self.label.clone(),
                        reason: format!("cell {id} is not a run of its grid"),
                    })?;
                tx.set_claim(id, &worker.id, now + worker.lease.as_secs_f64())?;
                tx.commit()?;
                Ok(Next::Run(Cell { id, spec }))
            }
        }
    }

    /// Runs `cell` (a race of the grid on `track` with `car`) while a heartbeat renews
    /// `worker`'s claim on it, then stores its record; returns the record, whether it was
    /// stored (false: another worker finished the cell first) and what the heartbeat met.
    pub fn run_cell(
        &mut self,
        cell: &Cell,
        worker: &Worker,
        track: Track,
        car: &Car,
    ) -> Result<(RunRecord, bool, Vec<Missed>)> {
        let location = &self.location;
        let renewer = move || -> Result<Box<dyn FnMut() -> Result<bool> + '_>> {
            let mut storage = open_storage(location, true)?;
            Ok(Box::new(move || {
                storage.heartbeat(cell.id, &worker.id, unix_now() + worker.lease.as_secs_f64())
            }))
        };
        let (record, missed) = claim::while_renewing(worker.heartbeat_interval(), renewer, || {
            run(&cell.spec, &self.config, track, car, |_| {})
        });
        let record = record?;
        let json = serde_json::to_string(&record).map_err(|e| {
            Error::json(
                format!("{}: run {}", self.label.display(), cell.spec.id()),
                e,
            )
        })?;
        let mut tx = self.storage.begin()?;
        let stored = tx.finish(cell.id, &json, unix_now())?;
        tx.commit()?;
        Ok((record, stored, missed))
    }

    /// (finished, all) cells.
    pub fn progress(&mut self) -> Result<(usize, usize)> {
        let mut tx = self.storage.begin()?;
        Ok((tx.count(true)?, self.runs.len()))
    }

    /// The finished runs, in the grid's order: what an experiment folder's `runs/` holds.
    pub fn records(&mut self) -> Result<Vec<RunRecord>> {
        let label = self.label.display().to_string();
        let mut records = self
            .storage
            .records()?
            .iter()
            .map(|json| RunRecord::parse(json, &label))
            .collect::<Result<Vec<_>>>()?;
        records.sort_by(|a, b| a.spec.cmp(&b.spec));
        Ok(records)
    }

    /// The sessions logged, in order: what an experiment folder's `sessions.jsonl` holds.
    pub fn sessions(&mut self) -> Result<Vec<Session>> {
        let text = self.storage.sessions()?.join("\n");
        Session::parse_log(&text, &self.label.display().to_string())
    }

    /// Logs a worker's session.
    pub fn add_session(&mut self, session: &Session) -> Result<()> {
        let json = serde_json::to_string(session)
            .map_err(|e| Error::json(format!("{}: session", self.label.display()), e))?;
        self.storage.add_session(&json)
    }

    /// Writes the grid as an experiment folder (`experiment.toml`, `runs/ID.json`,
    /// `sessions.jsonl`), as `cdbo experiment --out DIR` would have; returns the runs
    /// written. The folder must not hold another grid.
    pub fn export(&mut self, dir: &Path) -> Result<usize> {
        super::folder::claim(dir, &self.config)?;
        let records = self.records()?;
        for r in &records {
            r.save(dir)?;
        }
        let path = dir.join(super::folder::SESSIONS_FILE);
        let _ = std::fs::remove_file(&path);
        for s in self.sessions()? {
            s.append(dir)?;
        }
        Ok(records.len())
    }
}

/// What [`work`] reports.
#[derive(Debug)]
pub enum Progress<'a> {
    /// This worker ran a cell and stored its record.
    Ran(&'a RunRecord),
    /// This worker ran a cell that another worker finished first (its record was kept).
    FinishedElsewhere(&'a RunSpec),
    /// Every unfinished cell is held by another worker: waiting (reported once per wait).
    Waiting,
    /// The heartbeat of a cell's claim missed (a renewal failed, or the claim was lost).
    Heartbeat(&'a RunSpec, Missed),
}

/// Runs cells of the grid as `worker` until every cell is finished; returns the number of
/// cells it ran. `tracks` holds every track of the grid, loaded.
pub fn work(
    grid: &mut SharedGrid,
    worker: &Worker,
    tracks: &BTreeMap<String, Track>,
    car: &Car,
    on_progress: &mut dyn FnMut(Progress<'_>),
) -> Result<usize> {
    let mut ran = 0;
    let mut waiting = false;
    loop {
        let cell = match grid.claim(worker)? {
            Next::Done => return Ok(ran),
            Next::Wait => {
                if !waiting {
                    on_progress(Progress::Waiting);
                    waiting = true;
                }
                // Claims again (to take over a cell whose lease runs out) once per heartbeat
                // interval, between 0.1 and 1 s; meanwhile polls every 50 ms, without the
                // grid's write lock, for the last cell's end, so that a waiting worker stops
                // as the grid is done and not up to a second later.
                let interval = worker.heartbeat_interval().clamp(
                    std::time::Duration::from_millis(100),
                    std::time::Duration::from_secs(1),
                );
                let start = std::time::Instant::now();
                while start.elapsed() < interval {
                    std::thread::sleep(std::time::Duration::from_millis(50));
                    if grid.storage.count(false)? == 0 {
                        return Ok(ran);
                    }
                }
                continue;
            }
            Next::Run(cell) => cell,
        };
        waiting = false;
        let track = tracks
            .get(&cell.spec.track)
            .cloned()
            .ok_or_else(|| Error::NotFound {
                what: "track",
                name: cell.spec.track.clone(),
                detail: "not among the grid's loaded tracks".into(),
            })?;
        let (record, stored, missed) = grid.run_cell(&cell, worker, track, car)?;
        for m in missed {
            on_progress(Progress::Heartbeat(&cell.spec, m));
        }
        ran += 1;
        if stored {
            on_progress(Progress::Ran(&record));
        } else {
            on_progress(Progress::FinishedElsewhere(&cell.spec));
        }
    }
}

/// The storage `location` names, opened to write (tables created where missing) or to read.
fn open_storage(location: &Location, writable: bool) -> Result<Box<dyn GridStorage>> {
    Ok(match location {
        Location::Sqlite(path) => Box::new(sqlite::open(path, writable)?),
        #[cfg(feature = "postgres")]
        Location::Postgres { url, study } => Box::new(postgres::PostgresGrid::open(
            url,
            study,
            &location.label(),
            writable,
        )?),
        #[cfg(not(feature = "postgres"))]
        Location::Postgres { .. } => return Err(location.without_postgres()),
    })
}

/// A stored grid, read back.
fn parse_grid(text: &str, label: &Path) -> Result<ExperimentConfig> {
    ExperimentConfig::from_toml(text, &label.display().to_string()).map_err(|e| Error::NotAGrid {
        path: label.to_owned(),
        reason: format!("its stored grid does not read: {e}"),
    })
}
