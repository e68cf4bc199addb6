//! TORCS, the racing game, as a source of laps.
//!
//! [`Install`] finds the game Debian installs (`apt-get install torcs libplib-dev`);
//! [`setup`] compiles cdbo's robot driver (`torcs-robot/cdbo.cpp` and its TORCS-free
//! `drive.hpp`, built into this library) against the TORCS robot headers and lays out a private game tree in a cache folder —
//! symlinks to the installed game plus the robot, nothing written outside the cache, no root;
//! [`Game::lap`] drives one lap in a fresh game process ([`lap`]).
//!
//! The robot drives exactly what [`crate::sim::Simulator`] drives: the pedal a(x) (a policy,
//! the demonstrator or a constant), the look-ahead PI steering of
//! [`crate::drive::steering`] or the path tracker of [`crate::drive::tracker`] on the lap's
//! line (the centre line, or the base and policy line sampled by [`line`](mod@line)), the automatic
//! gearbox of [`crate::vehicle::powertrain`] (its shift points are handed over from the car's
//! [`crate::vehicle::Vehicle`]), and the same failure rules, judged from the game's car
//! state; its launch clutch, traction control and ABS act at the game's driver steps
//! ([`crate::vehicle::aids`]). Its decisions are the pure functions of [`ROBOT_HEADER`], which
//! `tests/robot_drive.rs` checks against the Rust ones on states recorded from laps of the
//! simulator.

pub mod evaluator;
pub mod lap;
pub mod line;
pub mod panel;
pub mod transfer;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

pub use lap::{GamePedal, LapRequest, RobotLaps};

use crate::bounded;
use crate::error::{Error, Result};

/// The robot's source, compiled by [`setup`]; it includes [`ROBOT_HEADER`].
pub const ROBOT_SOURCE: &str = include_str!("../../../../torcs-robot/cdbo.cpp");
/// The robot's decisions as pure functions of numbers (`drive.hpp`, no TORCS header needed),
/// written beside [`ROBOT_SOURCE`] by [`setup`].
pub const ROBOT_HEADER: &str = include_str!("../../../../torcs-robot/drive.hpp");
/// The file name [`ROBOT_SOURCE`] includes [`ROBOT_HEADER`] by.
pub const ROBOT_HEADER_NAME: &str = "drive.hpp";
/// The C++ compiler's flags for the robot's arithmetic: no fused multiply-adds, so that
/// [`ROBOT_HEADER`] computes what cdbo's Rust does, operation for operation.
pub const ROBOT_CXXFLAGS: &[&str] = &["-O2", "-ffp-contract=off"];
/// The robot module's name (`drivers/cdbo/cdbo.so`).
pub const ROBOT: &str = "cdbo";
/// The car TORCS laps use unless told otherwise.
pub const DEFAULT_CAR: &str = "car1-trb1";

/// Where Debian puts the game's programs and libraries.
const LIB_DIR: &str = "/usr/lib/x86_64-linux-gnu/torcs";
/// Where Debian puts the game's data.
const DATA_DIR: &str = "/usr/share/games/torcs";

/// An installed TORCS.
#[derive(Debug, Clone, PartialEq)]
pub struct Install {
    /// The game's programs and libraries (`torcs-bin`, `lib/`, `modules/`, `drivers/`).
    pub lib_dir: PathBuf,
    /// The game's data (`tracks/`, `cars/`, `config/`, `drivers/`).
    pub data_dir: PathBuf,
}

impl Install {
    /// The game at `CDBO_TORCS_LIB` / `CDBO_TORCS_DATA`, else where Debian installs it.
    pub fn find() -> Result<Install> {
        let var = |name: &str, default: &str| {
            PathBuf::from(std::env::var_os(name).unwrap_or_else(|| default.into()))
        };
        let install = Install {
            lib_dir: var("CDBO_TORCS_LIB", LIB_DIR),
            data_dir: var("CDBO_TORCS_DATA", DATA_DIR),
        };
        if !install.lib_dir.join("torcs-bin").is_file() {
            return Err(Error::Setup(format!(
                "TORCS is not installed: no {} (install it with `apt-get install torcs libplib-dev`, or set CDBO_TORCS_LIB)",
                install.lib_dir.join("torcs-bin").display()
            )));
        }
        if !install.data_dir.join("tracks").is_dir() {
            return Err(Error::Setup(format!(
                "TORCS's data is missing: no {} (install it with `apt-get install torcs-data`, or set CDBO_TORCS_DATA)",
                install.data_dir.join("tracks").display()
            )));
        }
        Ok(install)
    }

    /// The installed package's version (`dpkg-query`, its output read through
    /// [`bounded::SYSTEM_LINE`]), or "unknown".
    pub fn version(&self) -> String {
        let Ok(mut child) = Command::new("dpkg-query")
            .args(["-W", "-f", "${Version}", "torcs"])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
        else {
            return "unknown".into();
        };
        let version = child
            .stdout
            .take()
            .map(|out| bounded::read(out, "dpkg-query", &bounded::SYSTEM_LINE));
        if !matches!(version, Some(Ok(_))) {
            let _ = child.kill();
        }
        match (child.wait(), version) {
            (Ok(status), Some(Ok(v))) if status.success() && !v.is_empty() => {
                String::from_utf8_lossy(&v).into_owned()
            }
            _ => "unknown".into(),
        }
    }

    /// The category folder of a track (`road` for forza), from `tracks/CATEGORY/NAME/NAME.xml`.
    pub fn track_category(&self, name: &str) -> Result<String> {
        let tracks = self.data_dir.join("tracks");
        let mut names = Vec::new();
        for category in read_dir_names(&tracks) {
            let dir = tracks.join(&category);
            if valid_name(name) && dir.join(name).join(format!("{name}.xml")).is_file() {
                return Ok(category);
            }
            names.extend(read_dir_names(&dir));
        }
        names.sort();
        Err(Error::NotFound {
            what: "TORCS track",
            name: format!("{name:?}"),
            detail: format!("not in {} (there: {})", tracks.display(), names.join(", ")),
        })
    }

    /// The tracks of a category (`road`, `dirt`, `oval`), by name, sorted: the folders of
    /// `tracks/CATEGORY` that hold their `NAME.xml`.
    pub fn tracks(&self, category: &str) -> Vec<String> {
        let dir = self.data_dir.join("tracks").join(category);
        let mut names: Vec<String> = read_dir_names(&dir)
            .into_iter()
            .filter(|n| dir.join(n).join(format!("{n}.xml")).is_file())
            .collect();
        names.sort();
        names
    }

    /// Checks that the game has a car of this name (`cars/NAME/NAME.xml`).
    pub fn check_car(&self, name: &str) -> Result<()> {
        let cars = self.data_dir.join("cars");
        if valid_name(name) && cars.join(name).join(format!("{name}.xml")).is_file() {
            return Ok(());
        }
        let mut names = read_dir_names(&cars);
        names.sort();
        Err(Error::NotFound {
            what: "TORCS car",
            name: format!("{name:?}"),
            detail: format!("not in {} (there: {})", cars.display(), names.join(", ")),
        })
    }
}

/// A plain file name: no path separators, not `.` or `..`.
fn valid_name(name: &str) -> bool {
    !name.is_empty() && !name.contains('/') && name != "." && name != ".."
}

/// The names in a folder (empty if it cannot be read).
fn read_dir_names(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| !n.starts_with('.'))
                .collect()
        })
        .unwrap_or_default()
}

/// The cache folder of the private game tree: `CDBO_TORCS_CACHE`, else
/// `$XDG_CACHE_HOME/cdbo/torcs`, else `~/.cache/cdbo/torcs`.
pub fn cache_dir() -> Result<PathBuf> {
    if let Some(dir) = std::env::var_os("CDBO_TORCS_CACHE") {
        return Ok(PathBuf::from(dir));
    }
    if let Some(dir) = std::env::var_os("XDG_CACHE_HOME").filter(|d| !d.is_empty()) {
        return Ok(PathBuf::from(dir).join("cdbo").join("torcs"));
    }
    match std::env::var_os("HOME").filter(|d| !d.is_empty()) {
        Some(home) => Ok(PathBuf::from(home)
            .join(".cache")
            .join("cdbo")
            .join("torcs")),
        None => Err(Error::Setup(
            "no cache folder for TORCS: set CDBO_TORCS_CACHE (or HOME)".into(),
        )),
    }
}

/// The TORCS robot headers: `CDBO_TORCS_SDK`, else `../shared/torcs-sdk` when it exists.
pub fn sdk_dir() -> Result<PathBuf> {
    let dir = match std::env::var_os("CDBO_TORCS_SDK") {
        Some(d) => PathBuf::from(d),
        None => PathBuf::from("../shared/torcs-sdk"),
    };
    if dir.join("include").join("robot.h").is_file() {
        return Ok(dir);
    }
    Err(Error::Setup(format!(
        "the TORCS robot headers are not at {}: set CDBO_TORCS_SDK to a folder whose include/ holds \
         robot.h, car.h, track.h, tgf.h, ... (they come with the TORCS source: `apt-get source torcs`, \
         see torcs-robot/README.md)",
        dir.display()
    )))
}

/// A set-up private game tree, ready to drive laps.
#[derive(Debug, Clone)]
pub struct Game {
    /// The installed game.
    pub install: Install,
    /// The tree: `lib/` and `data/` (symlinks plus the robot), `conf/` (the local config
    /// template) and `laps/` (one folder per lap in flight).
    pub root: PathBuf,
}

/// The stamp file naming the robot source a tree was built from.
const STAMP: &str = "robot.stamp";

/// A fingerprint of the robot source and its header (FNV-1a), written when the tree is built.
fn robot_stamp() -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in ROBOT_SOURCE.bytes().chain(ROBOT_HEADER.bytes()) {
        h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}\n")
}

impl Game {
    /// The tree in `cache` (`cache/tree`), when it has been set up with this robot.
    pub fn open(install: Install, cache: &Path) -> Result<Game> {
        let root = cache.join("tree");
        let stamp =
            bounded::read_text(&root.join(STAMP), &bounded::SYSTEM_LINE).unwrap_or_default();
        if stamp != robot_stamp() {
            let why = if stamp.is_empty() {
                "is not set up"
            } else {
                "was built from another version of the robot"
            };
            return Err(Error::Setup(format!(
                "TORCS {why} in {}: run `cdbo torcs setup`",
                root.display()
            )));
        }
        Ok(Game { install, root })
    }

    /// The tree in the default cache, set up first if it is missing or stale.
    pub fn ready() -> Result<Game> {
        let install = Install::find()?;
        let cache = cache_dir()?;
        match Game::open(install.clone(), &cache) {
            Ok(game) => Ok(game),
            Err(_) => setup(&install, &sdk_dir()?, &cache),
        }
    }

    /// The game's programs: `lib/`.
    pub fn lib_dir(&self) -> PathBuf {
        self.root.join("lib")
    }

    /// The game's data: `data/`.
    pub fn data_dir(&self) -> PathBuf {
        self.root.join("data")
    }

    /// The compiled robot.
    pub fn robot(&self) -> PathBuf {
        self.lib_dir()
            .join("drivers")
            .join(ROBOT)
            .join(format!("{ROBOT}.so"))
    }
}

/// Compiles the robot against `sdk` and lays out the private game tree in `cache/tree`.
///
/// Everything is built in a staging folder first and moved into place only when complete: a
/// failure (no compiler, no plib headers, a compile error) leaves nothing behind and the
/// previous tree untouched.
pub fn setup(install: &Install, sdk: &Path, cache: &Path) -> Result<Game> {
    if !Path::new("/usr/include/plib/sg.h").is_file() {
        return Err(Error::Setup(
            "plib's headers are missing (/usr/include/plib/sg.h): install them with `apt-get install libplib-dev`"
                .into(),
        ));
    }
    let io = |path: &Path| {
        let path = path.to_owned();
        move |source| Error::Io { path, source }
    };
    std::fs::create_dir_all(cache).map_err(io(cache))?;
    let staging = cache.join(format!(".setup-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&staging);
    let built = build_tree(install, sdk, &staging);
    if let Err(e) = built {
        let _ = std::fs::remove_dir_all(&staging);
        return Err(e);
    }
    let root = cache.join("tree");
    let old = cache.join(format!(".old-{}", std::process::id()));
    if root.exists() {
        std::fs::rename(&root, &old).map_err(io(&root))?;
    }
    std::fs::rename(&staging, &root).map_err(io(&root))?;
    let _ = std::fs::remove_dir_all(&old);
    Ok(Game {
        install: install.clone(),
        root,
    })
}

/// Builds the tree in `dir` (which must not exist).
fn build_tree(install: &Install, sdk: &Path, dir: &Path) -> Result<()> {
    let io = |path: &Path| {
        let path = path.to_owned();
        move |source| Error::Io { path, source }
    };
    let lib = dir.join("lib");
    let data = dir.join("data");
    let robot_lib = lib.join("drivers").join(ROBOT);
    let robot_data = data.join("drivers").join(ROBOT);
    for d in [
        &robot_lib,
        &robot_data,
        &dir.join("conf/config"),
        &dir.join("laps"),
    ] {
        std::fs::create_dir_all(d).map_err(io(d))?;
    }
    link_contents(&install.lib_dir, &lib)?;
    link_contents(&install.data_dir, &data)?;
    link_contents(&install.lib_dir.join("drivers"), &lib.join("drivers"))?;
    link_contents(&install.data_dir.join("drivers"), &data.join("drivers"))?;
    let engine = install.data_dir.join("config/raceengine.xml");
    let conf = dir.join("conf/config/raceengine.xml");
    std::fs::copy(&engine, &conf).map_err(io(&engine))?;
    std::fs::write(
        robot_data.join(format!("{ROBOT}.xml")),
        lap::robot_xml(DEFAULT_CAR, "lap.txt"),
    )
    .map_err(io(&robot_data))?;

    let source = dir.join("cdbo.cpp");
    std::fs::write(&source, ROBOT_SOURCE).map_err(io(&source))?;
    let header = dir.join(ROBOT_HEADER_NAME);
    std::fs::write(&header, ROBOT_HEADER).map_err(io(&header))?;
    let include = sdk.join("include");
    let mut compiler = Command::new("c++")
        .args(ROBOT_CXXFLAGS)
        .args(["-shared", "-fPIC", "-o"])
        .arg(robot_lib.join(format!("{ROBOT}.so")))
        .arg(&source)
        .arg("-I")
        .arg(&include)
        .arg("-L")
        .arg(install.lib_dir.join("lib"))
        .args(["-lrobottools", "-ltgf"])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| {
            Error::Setup(format!(
                "cannot run the C++ compiler `c++` ({e}): install it with `apt-get install g++`"
            ))
        })?;
    // Its messages through their bound; the compiler is stopped if they pass it.
    let messages = match compiler.stderr.take() {
        Some(pipe) => bounded::read(pipe, "c++ (standard error)", &bounded::COMPILER_OUTPUT),
        None => Ok(Vec::new()),
    };
    if messages.is_err() {
        let _ = compiler.kill();
    }
    let status = compiler.wait().map_err(|source| Error::Command {
        line: "c++".into(),
        source,
    })?;
    let messages = messages?;
    if !status.success() {
        let stderr = String::from_utf8_lossy(&messages);
        let first = stderr
            .lines()
            .find(|l| l.contains("error"))
            .or_else(|| stderr.lines().next())
            .unwrap_or("no message");
        return Err(Error::Setup(format!(
            "the TORCS robot did not compile against {}: {}",
            include.display(),
            first.trim()
        )));
    }
    std::fs::remove_file(&source).map_err(io(&source))?;
    std::fs::remove_file(&header).map_err(io(&header))?;
    let stamp = dir.join(STAMP);
    std::fs::write(&stamp, robot_stamp()).map_err(io(&stamp))?;
    Ok(())
}

/// Symlinks every entry of `from` into `to`, except those `to` already has.
fn link_contents(from: &Path, to: &Path) -> Result<()> {
    let entries = std::fs::read_dir(from).map_err(|source| Error::Io {
        path: from.to_owned(),
        source,
    })?;
    for entry in entries.filter_map(|e| e.ok()) {
        let target = to.join(entry.file_name());
        if target.exists() {
            continue;
        }
        std::os::unix::fs::symlink(entry.path(), &target).map_err(|source| Error::Io {
            path: target.clone(),
            source,
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::ROBOT_SOURCE;
    use crate::sim::lap::{
        BACKWARDS_DISTANCE, INV_TAN_SPIN_SLIP_ANGLE, SPIN_MIN_SPEED, STALL_SPEED, STALL_TIME,
    };
    use crate::vehicle::SLIP_SPEED_FLOOR;

    /// The value of `const double NAME = VALUE;` in the robot's source.
    fn robot_constant(name: &str) -> f64 {
        let prefix = format!("const double {name} = ");
        let line = ROBOT_SOURCE
            .lines()
            .find_map(|l| l.trim().strip_prefix(prefix.as_str()))
            .unwrap_or_else(|| panic!("no `{prefix}…;` in torcs-robot/cdbo.cpp"));
        let value = line.split(';').next().unwrap_or_default().trim();
        value
            .parse()
            .unwrap_or_else(|e| panic!("{name} = {value:?}: {e}"))
    }

    /// The robot ends a game's lap by the rules a lap of cdbo's simulator ends by: its copies
    /// of the spin, backwards and stall thresholds and of the slip's speed floor are these.
    #[test]
    fn the_robot_fails_a_lap_by_the_simulators_rules() {
        for (name, ours) in [
            ("kSpinSlipTan", INV_TAN_SPIN_SLIP_ANGLE),
            ("kSpinMinSpeed", SPIN_MIN_SPEED),
            ("kBackwardsDistance", BACKWARDS_DISTANCE),
            ("kStallSpeed", STALL_SPEED),
            ("kStallTime", STALL_TIME),
            ("kSlipSpeedFloor", SLIP_SPEED_FLOOR),
        ] {
            assert_eq!(robot_constant(name), ours, "{name}");
        }
    }
}
