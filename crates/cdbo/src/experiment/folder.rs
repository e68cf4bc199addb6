//! An experiment's folder: `experiment.toml`, its grid (written by the first session; every
//! later session must bring the same grid, so that the runs resume and report together),
//! `runs/ID.json`, one [`RunRecord`](super::record::RunRecord) per finished run, and
//! `sessions.jsonl`, one [`Session`] line per invocation that ran part of the grid.

use std::io::Write;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::grid::ExperimentConfig;
use crate::bounded;
use crate::error::{Error, Result};

/// The grid's file in an experiment folder.
pub const GRID_FILE: &str = "experiment.toml";

/// The session log's file in an experiment folder.
pub const SESSIONS_FILE: &str = "sessions.jsonl";

/// Makes `dir` the folder of `config`: writes the grid to `DIR/experiment.toml`, or checks
/// that the grid already there is the same ([`Error::DifferentGrid`] if not).
pub fn claim(dir: &Path, config: &ExperimentConfig) -> Result<()> {
    let io = |path: &Path| {
        let path = path.to_owned();
        move |source| Error::Io { path, source }
    };
    std::fs::create_dir_all(dir).map_err(io(dir))?;
    let file = dir.join(GRID_FILE);
    match bounded::read_text(&file, &bounded::EXPERIMENT_GRID) {
        Ok(old) => {
            if ExperimentConfig::from_toml(&old, &file.display().to_string())? != *config {
                return Err(Error::DifferentGrid { path: file });
            }
            Ok(())
        }
        Err(Error::Io { source, .. }) if source.kind() == std::io::ErrorKind::NotFound => {
            let text = toml::to_string(config).map_err(|e| Error::Io {
                path: file.clone(),
                source: std::io::Error::other(e),
            })?;
            std::fs::write(&file, text).map_err(io(&file))
        }
        Err(e) => Err(e),
    }
}

/// One invocation that ran part of a grid, a line of `sessions.jsonl`: what the report
/// needs to say how long the grid took.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Session {
    /// Runs it ran.
    #[serde(default)]
    pub runs: usize,
    /// Runs of its shard found already done.
    #[serde(default)]
    pub skipped: usize,
    /// Parallel jobs.
    #[serde(default)]
    pub jobs: usize,
    /// Its shard (`K/N`), if any.
    #[serde(default)]
    pub shard: Option<String>,
    /// Its wall-clock seconds.
    #[serde(default)]
    pub wall_s: f64,
}

impl Session {
    /// Appends this session as one line to `DIR/sessions.jsonl`.
    pub fn append(&self, dir: &Path) -> Result<()> {
        let path = dir.join(SESSIONS_FILE);
        let line =
            serde_json::to_string(self).map_err(|e| Error::json(path.display().to_string(), e))?;
        std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .and_then(|mut f| f.write_all(format!("{line}\n").as_bytes()))
            .map_err(|source| Error::Io { path, source })
    }

    /// The sessions logged in the folders, in order; a folder without a log has none.
    pub fn load_all(dirs: &[PathBuf]) -> Result<Vec<Session>> {
        let mut sessions = Vec::new();
        for dir in dirs {
            let path = dir.join(SESSIONS_FILE);
            let text = match bounded::read_text(&path, &bounded::SESSION_LOG) {
                Ok(text) => text,
                Err(Error::Io { source, .. }) if source.kind() == std::io::ErrorKind::NotFound => {
                    continue;
                }
                Err(e) => return Err(e),
            };
            sessions.extend(Session::parse_log(&text, &path.display().to_string())?);
        }
        Ok(sessions)
    }

    /// The sessions of one log's text, one JSON object per line (blank lines skipped); `file`
    /// names the log in the error, with the line.
    pub fn parse_log(text: &str, file: &str) -> Result<Vec<Session>> {
        text.lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty())
            .map(|(i, line)| {
                serde_json::from_str(line).map_err(|e| Error::Parse {
                    file: file.to_string(),
                    line: u32::try_from(i + 1).ok(),
                    element: "session".into(),
                    message: format!("not a session line: {e}"),
                })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        crate::scratch::dir(&format!("folder-{name}"))
    }

    #[test]
    fn a_folder_keeps_one_grid_and_its_sessions() {
        let dir = scratch("grid");
        let text = "laps = 5\nrepeats = 1\nmethods = [\"cdbo\"]\n\n[[tracks]]\ntrack = \"ridgeway\"\nkernels = [10]\n";
        let grid = ExperimentConfig::from_toml(text, "grid").unwrap();
        claim(&dir, &grid).unwrap();
        claim(&dir, &grid).unwrap();
        let mut other = grid.clone();
        other.laps += 1;
        let e = claim(&dir, &other).unwrap_err();
        assert!(matches!(e, Error::DifferentGrid { .. }), "{e}");
        assert!(e.to_string().contains("experiment.toml"), "{e}");
        let s = Session {
            runs: 3,
            skipped: 1,
            jobs: 2,
            shard: Some("1/2".into()),
            wall_s: 4.5,
        };
        s.append(&dir).unwrap();
        s.append(&dir).unwrap();
        assert_eq!(
            Session::load_all(&[dir.clone(), scratch("none")]).unwrap(),
            vec![s.clone(), s]
        );
        std::fs::write(dir.join(SESSIONS_FILE), "{\"runs\": 1}\nnot json\n").unwrap();
        let e = Session::load_all(std::slice::from_ref(&dir))
            .unwrap_err()
            .to_string();
        assert!(e.contains("sessions.jsonl:2: session"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// An endless grid file or session log is refused at its bound, naming it.
    #[test]
    fn an_endless_grid_or_session_log_is_refused() {
        let dir = scratch("endless");
        for file in [GRID_FILE, SESSIONS_FILE] {
            std::os::unix::fs::symlink("/dev/zero", dir.join(file)).unwrap();
        }
        let grid = ExperimentConfig::preset("quick").unwrap();
        let e = claim(&dir, &grid).unwrap_err().to_string();
        assert!(
            e.ends_with(
                "experiment.toml: the experiment grid file is larger than its bound of 1 MiB"
            ),
            "{e}"
        );
        let e = Session::load_all(std::slice::from_ref(&dir))
            .unwrap_err()
            .to_string();
        assert!(
            e.ends_with("sessions.jsonl: the session log is larger than its bound of 64 MiB"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
