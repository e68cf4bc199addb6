//! One bounded reader for every input: files (tracks, cars, policies, demonstrations, grids,
//! run records, traces) and the output of external programs (a lap command, the TORCS game,
//! the C++ compiler). Each kind of input has its [`Bound`], a generous multiple of the largest
//! real one; an input past it is refused in one line naming it, what it is and the bound
//! ([`Error::InputTooLarge`]), after reading at most the bound and one byte. So a device, a
//! pipe or a runaway program (`cdbo lap --policy /dev/urandom`) can neither hang cdbo nor
//! fill its memory.
//!
//! The JSON-lines service bounds each request line the same way, at
//! [`serve::MAX_LINE_BYTES`](crate::serve::MAX_LINE_BYTES); SQLite study files are opened by
//! SQLite, which reads pages as it needs them, not as one stream.

use std::io::Read;
use std::path::Path;

use crate::error::{Error, MIB, Result};

/// One kind of input and the most of it cdbo reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Bound {
    /// What the input is, as the refusal names it (`policy file`).
    pub what: &'static str,
    /// The most bytes accepted.
    pub bytes: u64,
}

/// A TORCS / Speed Dreams track file (`tracks/road/NAME/NAME.xml`), 16 MiB: Forza's, the
/// largest of the game's tracks, is 180 KB.
pub const TRACK_FILE: Bound = Bound::new("track file", 16 * MIB);

/// A file a TORCS file includes as an external entity (`&default-surfaces;` is
/// `data/tracks/surfaces.xml`), 16 MiB: the surfaces are 50 KB. The expanded text has its
/// own bound (64 MiB, against entities that multiply each other).
pub const ENTITY_FILE: Bound = Bound::new("included entity file", 16 * MIB);

/// A TORCS / Speed Dreams car file (`cars/NAME/NAME.xml`), 16 MiB: the paper's car's is 20 KB.
pub const CAR_FILE: Bound = Bound::new("car file", 16 * MIB);

/// A car category file (`categories/CAT.xml`), 16 MiB: Supercars' is 19 KB.
pub const CAR_CATEGORY_FILE: Bound = Bound::new("car category file", 16 * MIB);

/// A TORCS driver's file (`drivers/bt/bt.xml`), 16 MiB: a few KB in the game.
pub const DRIVER_FILE: Bound = Bound::new("TORCS driver file", 16 * MIB);

/// A TUMFTM centre line (`x_m,y_m,w_tr_right_m,w_tr_left_m`), 64 MiB: Monza's is 40 KB (a
/// point every 5 m, 35 bytes a row); the longest track cdbo takes
/// ([`MAX_LENGTH_M`](crate::track::MAX_LENGTH_M), 100 km) with a point every 0.1 m is 35 MB.
pub const TRACK_CSV: Bound = Bound::new("track centre-line file", 64 * MIB);

/// Policy weights as JSON (`cdbo policy fit`), 1 MiB: the largest policy, 1000 weights
/// ([`KERNELS`](crate::sizes::KERNELS)) at 17 digits, is 25 KB, and the 1001-point table a lap
/// command's policy file adds is 50 KB.
pub const POLICY_FILE: Bound = Bound::new("policy file", MIB);

/// A policy as an `x,a` table, 64 MiB: the finest table, a million points
/// ([`POINTS`](crate::sizes::POINTS)), is 18 MB as `cdbo policy table` prints it and about
/// 45 MB at full precision.
pub const POLICY_TABLE: Bound = Bound::new("policy table", 64 * MIB);

/// A lap trace (`cdbo lap --trace`, the TORCS robot's trace), 256 MiB: a row of about 100 bytes
/// per 50 Hz driver step over the longest lap cdbo drives, a 100 km track's time limit of
/// 30 s + L / (4 m/s) ≈ 7 h, is 125 MB.
pub const TRACE_FILE: Bound = Bound::new("trace file", 256 * MIB);

/// A demonstration's (x, a) pairs, often a lap trace: the bound of [`TRACE_FILE`].
pub const DEMO_FILE: Bound = Bound::new("demonstration file", TRACE_FILE.bytes);

/// An experiment grid (TOML), 1 MiB: the paper's grids are under 1 KB.
pub const EXPERIMENT_GRID: Bound = Bound::new("experiment grid file", MIB);

/// A finished run's record (`runs/ID.json`), 64 MiB: 10,000 laps
/// ([`LAPS`](crate::sizes::LAPS)) of about 200 bytes and 1000 best weights are 2 MB.
pub const RUN_RECORD: Bound = Bound::new("run record", 64 * MIB);

/// A transfer report read as a reference (`cdbo torcs transfer --against`), 16 MiB: a row of
/// about 600 bytes per track and seed, 38 tracks over 100 seeds, is 2.3 MB.
pub const TRANSFER_REPORT: Bound = Bound::new("transfer report", 16 * MIB);

/// An experiment's session log (`sessions.jsonl`), 64 MiB: a session is a line of 100 bytes.
pub const SESSION_LOG: Bound = Bound::new("session log", 64 * MIB);

/// What a lap command writes on its standard output or error, each, 16 MiB: the reward is a
/// number or a short JSON object on its last line, after whatever log the command prints.
pub const LAP_COMMAND_OUTPUT: Bound = Bound::new("lap command's output", 16 * MIB);

/// What the TORCS game and its robot write for a lap (the robot's result line, the game's
/// output and result files), each file 64 MiB: a few KB for a lap.
pub const GAME_OUTPUT: Bound = Bound::new("game's output", 64 * MIB);

/// The C++ compiler's messages while building the TORCS robot, 16 MiB: a failed build's
/// template errors reach a few hundred KB.
pub const COMPILER_OUTPUT: Bound = Bound::new("compiler's output", 16 * MIB);

/// A short line from the system (the host's name, a package version, the game tree's stamp),
/// 4 KiB: Linux host names are at most 64 bytes, the stamp 17.
pub const SYSTEM_LINE: Bound = Bound::new("system line", 4096);

impl Bound {
    /// Inputs that are `what`, at most `bytes` long.
    pub const fn new(what: &'static str, bytes: u64) -> Bound {
        Bound { what, bytes }
    }

    /// The refusal of `input` (a file, a program's output) as larger than this bound.
    fn refuse(&self, input: &str) -> Error {
        Error::InputTooLarge {
            input: input.to_owned(),
            what: self.what,
            bound: self.bytes,
        }
    }
}

/// Reads all of `input`, named `name` in errors, at most `bound` bytes: past that, refused
/// ([`Error::InputTooLarge`]) after reading the bound and one byte, whatever the input's
/// length, endless included.
pub fn read(input: impl Read, name: &str, bound: &Bound) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    input
        .take(bound.bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|source| Error::Io {
            path: name.into(),
            source,
        })?;
    if bytes.len() as u64 > bound.bytes {
        return Err(bound.refuse(name));
    }
    Ok(bytes)
}

/// Reads the file at `path` through [`read`]; a regular file longer than the bound is refused
/// before it is read.
pub fn read_file(path: &Path, bound: &Bound) -> Result<Vec<u8>> {
    let name = path.display().to_string();
    let io = |source| Error::Io {
        path: path.to_owned(),
        source,
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if meta.is_file() && meta.len() > bound.bytes {
        return Err(bound.refuse(&name));
    }
    read(file, &name, bound)
}

/// Reads the file at `path` through [`read_file`] as UTF-8 text (other bytes are an
/// [`Error::Io`] of kind `InvalidData`, as [`std::fs::read_to_string`] says).
pub fn read_text(path: &Path, bound: &Bound) -> Result<String> {
    String::from_utf8(read_file(path, bound)?).map_err(|_| Error::Io {
        path: path.to_owned(),
        source: std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            "stream did not contain valid UTF-8",
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An endless input is refused in one line naming it, what it is and the bound, after
    /// reading no more than the bound and one byte.
    #[test]
    fn an_endless_stream_is_refused_in_one_line() {
        let e = read(std::io::repeat(b'x'), "policy.json", &POLICY_FILE).unwrap_err();
        assert!(matches!(e, Error::InputTooLarge { bound, .. } if bound == MIB));
        assert_eq!(
            e.to_string(),
            "policy.json: the policy file is larger than its bound of 1 MiB"
        );
        let mut endless = std::io::repeat(b'x');
        let small = Bound::new("test input", 10);
        let e = read(&mut endless, "test", &small).unwrap_err().to_string();
        assert_eq!(
            e,
            "test: the test input is larger than its bound of 10 bytes"
        );
        assert!(!e.contains('\n'));
    }

    #[test]
    fn an_input_up_to_its_bound_is_read_whole() {
        let bound = Bound::new("test input", 4);
        assert_eq!(read(&b"abcd"[..], "t", &bound).unwrap(), b"abcd");
        assert_eq!(read(&b""[..], "t", &bound).unwrap(), b"");
        assert!(read(&b"abcde"[..], "t", &bound).is_err());
    }

    /// A regular file past its bound is refused from its length, unread (a sparse file of
    /// 16 MiB and one byte); one within it is read, and bad UTF-8 or a missing file are the
    /// usual I/O errors.
    #[test]
    fn files_are_read_within_their_bound() {
        let dir = crate::scratch::dir("bounded");
        let big = dir.join("big.xml");
        std::fs::File::create(&big)
            .and_then(|f| f.set_len(TRACK_FILE.bytes + 1))
            .unwrap();
        let e = read_text(&big, &TRACK_FILE).unwrap_err().to_string();
        assert_eq!(
            e,
            format!(
                "{}: the track file is larger than its bound of 16 MiB",
                big.display()
            )
        );
        let small = dir.join("small.csv");
        std::fs::write(&small, "x,a\n0,1\n").unwrap();
        assert_eq!(read_text(&small, &POLICY_TABLE).unwrap(), "x,a\n0,1\n");
        std::fs::write(&small, b"\xff\xfe").unwrap();
        let e = read_text(&small, &POLICY_TABLE).unwrap_err();
        assert!(
            e.to_string()
                .ends_with("stream did not contain valid UTF-8"),
            "{e}"
        );
        assert_eq!(read_file(&small, &POLICY_TABLE).unwrap(), b"\xff\xfe");
        let gone = read_file(&dir.join("gone"), &POLICY_TABLE).unwrap_err();
        assert!(
            matches!(&gone, Error::Io { source, .. } if source.kind() == std::io::ErrorKind::NotFound)
        );
    }

    #[test]
    fn sizes_are_said_in_their_unit() {
        assert_eq!(crate::error::show_bytes(256 * MIB), "256 MiB");
        assert_eq!(crate::error::show_bytes(4096), "4 KiB");
        assert_eq!(crate::error::show_bytes(1000), "1000 bytes");
    }
}
