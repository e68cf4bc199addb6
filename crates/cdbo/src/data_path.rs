//! The data folders searched for tracks and cars by name.
//!
//! In order: each `--data-dir`, each entry of `CDBO_DATA_PATH` (colon-separated), then the
//! usual TORCS and Speed Dreams install folders. Each folder is searched itself and one level
//! below it, so `../shared` finds `../shared/torcs/tracks/road/forza/forza.xml`.

use std::path::{Path, PathBuf};

/// Install folders of TORCS (Debian's `torcs-data`) and Speed Dreams.
pub const SYSTEM_DIRS: &[&str] = &[
    "/usr/share/games/torcs",
    "/usr/local/share/games/torcs",
    "/usr/share/games/speed-dreams-2",
    "/usr/local/share/games/speed-dreams-2",
    "/usr/share/speed-dreams-2",
];

/// An ordered list of data folders.
#[derive(Debug, Clone, Default)]
pub struct DataPath {
    dirs: Vec<PathBuf>,
}

impl DataPath {
    /// `extra` folders first, then `CDBO_DATA_PATH`, then the system folders.
    pub fn new(extra: &[PathBuf]) -> DataPath {
        let env = std::env::var("CDBO_DATA_PATH").unwrap_or_default();
        DataPath::with_env(extra, &env)
    }

    /// As [`DataPath::new`] with the variable's value given.
    pub fn with_env(extra: &[PathBuf], env: &str) -> DataPath {
        let mut dirs: Vec<PathBuf> = extra.to_vec();
        dirs.extend(env.split(':').filter(|s| !s.is_empty()).map(PathBuf::from));
        dirs.extend(SYSTEM_DIRS.iter().map(PathBuf::from));
        DataPath { dirs }
    }

    /// The folders searched, in order.
    pub fn dirs(&self) -> &[PathBuf] {
        &self.dirs
    }

    /// The first existing file `root/rel` for each root (a folder or one of its sub-folders)
    /// and each candidate relative path, in order.
    pub fn find(&self, rels: &[String]) -> Option<PathBuf> {
        self.roots()
            .into_iter()
            .find_map(|root| rels.iter().map(|r| root.join(r)).find(|p| p.is_file()))
    }

    /// Each data folder followed by its immediate sub-folders.
    fn roots(&self) -> Vec<PathBuf> {
        let mut roots = Vec::new();
        for d in self.dirs.iter().filter(|d| d.is_dir()) {
            roots.push(d.clone());
            if let Ok(entries) = std::fs::read_dir(d) {
                let mut subs: Vec<PathBuf> = entries
                    .filter_map(|e| e.ok())
                    .map(|e| e.path())
                    .filter(|p| p.is_dir())
                    .collect();
                subs.sort();
                roots.extend(subs);
            }
        }
        roots
    }

    /// A one-line description of what was searched, for "not found" errors.
    pub fn describe(&self) -> String {
        let list: Vec<String> = self.dirs.iter().map(|d| display(d)).collect();
        format!(
            "the data folders [{}] (add one to CDBO_DATA_PATH)",
            list.join(", ")
        )
    }
}

fn display(p: &Path) -> String {
    if p.is_dir() {
        p.display().to_string()
    } else {
        format!("{} (absent)", p.display())
    }
}
