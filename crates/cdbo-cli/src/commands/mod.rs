//! One module per sub-command; shared argument groups here.

pub mod bench;
pub mod ceiling;
pub mod experiment;
pub mod lap;
pub mod limit;
pub mod optimize;
pub mod plot;
pub mod policy;
pub mod race;
pub mod report;
pub mod serve_sim;
pub mod study;
pub mod torcs;
pub mod torcs_compare;
pub mod track;

use clap::Args;

use cdbo::car::{Car, catalog as cars};
use cdbo::data_path::DataPath;
use cdbo::track::{Track, builtin, catalog as tracks};

/// The boxed error every command returns; printed as one line by `main`.
pub type CliResult = Result<(), Box<dyn std::error::Error>>;

/// Where laps are driven (`--simulator`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Simulator {
    /// cdbo's own simulator.
    #[default]
    Cdbo,
    /// The game TORCS, driven by cdbo's robot (`cdbo torcs setup` first); tracks and cars by
    /// their TORCS names, car1-trb1 by default.
    Torcs,
}

impl Simulator {
    /// The car to use: on TORCS the built-in default car becomes car1-trb1.
    pub fn car(self, spec: &str) -> &str {
        match self {
            Simulator::Torcs if spec == cars::DEFAULT => cdbo::torcs::DEFAULT_CAR,
            _ => spec,
        }
    }
}

/// `--track` and `--car`.
#[derive(Debug, Args, Clone)]
pub struct Setup {
    /// Track: a built-in name (ridgeway), a TORCS .xml or TUMFTM .csv file, or a track name in
    /// the data folders (forza, allondaz, ...).
    #[arg(long, default_value = builtin::DEFAULT)]
    pub track: String,
    /// Car: built-in spirit-300, a TORCS / Speed Dreams car .xml, or a car name in the data
    /// folders.
    #[arg(long, default_value = cars::DEFAULT)]
    pub car: String,
}

impl Setup {
    /// Loads the track and the car, printing the track's warnings to stderr.
    pub fn load(&self, data: &DataPath) -> Result<(Track, Car), cdbo::Error> {
        let track = load_track(&self.track, data)?;
        let car = cars::find(&self.car, data)?;
        Ok((track, car))
    }
}

/// Loads a track, printing its warnings to stderr.
pub fn load_track(spec: &str, data: &DataPath) -> Result<Track, cdbo::Error> {
    let track = tracks::find(spec, data)?;
    for w in &track.warnings {
        eprintln!("warning: {w}");
    }
    Ok(track)
}

/// cdbo's reading of a TORCS track for a lap in the game: from the data folders (where
/// `--data-dir` comes first), else from the game's own data.
pub fn game_track(
    name: &str,
    game: &cdbo::torcs::Game,
    data: &DataPath,
) -> Result<Track, cdbo::Error> {
    load_track(name, data).or_else(|e| {
        let game_data = DataPath::new(std::slice::from_ref(&game.install.data_dir));
        load_track(name, &game_data).map_err(|_| e)
    })
}

/// Prints a value as pretty JSON on stdout.
pub fn print_json<T: serde::Serialize>(value: &T) -> CliResult {
    println!("{}", serde_json::to_string_pretty(value)?);
    Ok(())
}
