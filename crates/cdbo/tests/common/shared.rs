//! The reference data the tests read from `../shared` beside the repository root (track, car
//! and robot files of TORCS and Speed Dreams, never copied into the repository).

use std::path::PathBuf;

/// The file or folder `rel` of `../shared` (`""`: the folder itself). When it is missing the
/// test fails with a message naming it and where to get it.
pub fn shared(rel: &str) -> PathBuf {
    let path = root().join(rel);
    if !path.exists() {
        panic!(
            "this test reads ../shared/{rel} ({}), which is missing: ../shared beside the \
             repository holds the reference data; {}",
            path.display(),
            source(rel)
        );
    }
    path
}

/// The file or folder `rel` of `../shared` if it is there, for a test that skips without it.
pub fn shared_if_present(rel: &str) -> Option<PathBuf> {
    let path = root().join(rel);
    path.exists().then_some(path)
}

/// `../shared` beside the repository root (every crate sits two folders below it).
fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared")
}

/// Where the file `rel` of `../shared` comes from.
fn source(rel: &str) -> &'static str {
    if rel.starts_with("torcs/") {
        "copy it from Debian's `torcs-data` package (apt-get install torcs-data), whose \
         /usr/share/games/torcs has the same layout"
    } else if rel.starts_with("speed-dreams/") {
        "copy it from a Speed Dreams 2 install's data folder (speed-dreams.net; Linux \
         packages put it in /usr/share/games/speed-dreams-2), which has the same layout"
    } else if rel.starts_with("tracks/csv/") {
        "copy it from the TUMFTM racetrack database (github.com/TUMFTM/racetrack-database, tracks/)"
    } else if rel.starts_with("torcs-sdk") {
        "it holds the TORCS 1.3.7 robot headers (the `torcs` source package's src/interfaces \
         and src/libs/tgf headers)"
    } else {
        "it holds TORCS's data (Debian's `torcs-data`, /usr/share/games/torcs) under torcs/, \
         Speed Dreams 2's data under speed-dreams/ and TUMFTM centre lines \
         under tracks/csv/, each in its original layout"
    }
}
