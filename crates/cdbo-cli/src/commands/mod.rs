//! One module per sub-command; shared argument groups here.

pub mod bench;
pub mod bench_circuits;
pub mod ceiling;
pub mod dashboard;
pub mod experiment;
pub mod lap;
pub mod limit;
pub mod line;
pub mod optimize;
pub mod plot;
pub mod policy;
pub mod race;
pub mod replay;
pub mod report;
pub mod serve_sim;
pub mod study;
pub mod torcs;
pub mod torcs_calibrate;
pub mod torcs_compare;
pub mod torcs_learn;
pub mod torcs_panel;
pub mod torcs_transfer;
pub mod track;

use clap::Args;
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};

use cdbo::car::{Car, catalog as cars};
use cdbo::data_path::DataPath;
use cdbo::drive::steering::SteeringLaw;
use cdbo::method::{Method, Preset};
use cdbo::track::{Ends, Track, builtin, catalog as tracks};
use cdbo::venue::Venue;

/// `--method`'s parser: the registry's names, each with its one-line description in `--help`.
pub fn method_parser() -> impl clap::builder::TypedValueParser<Value = Method> {
    let names = Method::ALL.map(|m| PossibleValue::new(m.name()).help(m.description()));
    PossibleValuesParser::new(names).try_map(|name| name.parse::<Method>())
}

/// `--preset`'s parser: the presets by name, each with what it sets in `--help`.
pub fn preset_parser() -> impl clap::builder::TypedValueParser<Value = Preset> {
    let names = Preset::ALL.map(|p| PossibleValue::new(p.name()).help(p.description()));
    PossibleValuesParser::new(names).try_map(|name| name.parse::<Preset>())
}

/// The flags a preset sets, which clap refuses beside `--preset`: one name never mixes with a
/// flag of its own stack.
pub const PRESET_SETS: [&str; 5] = ["method", "steering", "line", "line_start", "line_kernels"];

/// `--steering`: a [`SteeringLaw`] by name, each listed with its description in `--help`.
pub fn steering_parser() -> impl clap::builder::TypedValueParser<Value = SteeringLaw> {
    let names = SteeringLaw::ALL.map(|s| PossibleValue::new(s.name()).help(s.description()));
    PossibleValuesParser::new(names).try_map(|name| name.parse::<SteeringLaw>())
}

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

    /// Its name, as `--simulator` takes it.
    pub fn name(self) -> &'static str {
        match self {
            Simulator::Cdbo => "cdbo",
            Simulator::Torcs => "torcs",
        }
    }
}

/// Where a lap leaves the road (`--off-track-margin`), as `race` and `lap` take it.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct OffTrackArgs {
    /// Where a lap leaves the road: once the car's centre is this far past the road's edge
    /// (m; negative: inside the road), nothing else kept in reserve. Default: the game's rule,
    /// 1, for a lap judged (`lap`) or learned in the game; for a policy learned in cdbo's
    /// simulator, a reserve the game's car will not take away: every wheel 0.25 m off
    /// slippery ground (grass, sand), the body 1 m off the walls, the car's centre on the road
    /// (1 m inside its edge where the track gives no verges): the pattern search's best policy
    /// learned so completes in the game on 21, 19 and 21 of TORCS's 21 road tracks (seeds 0–2),
    /// against 1 at 1 m (docs/results/torcs.md).
    #[arg(long, allow_negative_numbers = true, value_parser = value::off_track_margin)]
    pub off_track_margin: Option<f64>,
}

impl OffTrackArgs {
    /// The margin a lap is judged by: the one given, else the game's rule.
    pub fn judging(&self) -> f64 {
        self.off_track_margin
            .unwrap_or(cdbo::sim::lap::GAME_OFF_TRACK_MARGIN)
    }
}

/// Where a lap fails, in words: "at 1 m inside the road's edge", "at 1 m past the road's
/// edge, the game's rule", or "keeping …" the reserve ([`cdbo::sim::lap::Reserve`]).
pub fn edge_words(margin_m: f64, reserve: Option<cdbo::sim::lap::Reserve>) -> String {
    if let Some(r) = reserve {
        return format!(
            "keeping the wheels {} m off slippery ground and the body {} m off the walls",
            r.wheels_m, r.body_m
        );
    }
    match margin_m {
        m if m == cdbo::sim::lap::GAME_OFF_TRACK_MARGIN => {
            format!("at {m} m past the road's edge, the game's rule")
        }
        m if m < 0.0 => format!("at {} m inside the road's edge", -m),
        m => format!("at {m} m past the road's edge"),
    }
}

/// Where `--simulator` drives the laps of `setup`'s track and car, and cdbo's reading of them
/// (for the limit and the plots): in the game, the game's own track and car files.
pub fn venue(
    setup: &Setup,
    data: &DataPath,
    simulator: Simulator,
) -> Result<(Venue, Track, Car), Box<dyn std::error::Error>> {
    Ok(match simulator {
        Simulator::Cdbo => {
            let (track, car) = setup.load(data)?;
            (Venue::simulator(track.clone(), &car), track, car)
        }
        Simulator::Torcs => {
            let game = cdbo::torcs::Game::ready()?;
            let track = game_track(&setup.track, &game, data)?;
            let car_name = simulator.car(&setup.car);
            let venue = Venue::game(&game, &setup.track, car_name, track.clone())?;
            let car = venue.car().cloned().unwrap_or_else(Car::spirit_300);
            (venue, track, car)
        }
    })
}

/// Prefixes a library error with the command-line flag its value came from (the library
/// names no flags).
pub fn from_flag(flag: &'static str) -> impl Fn(cdbo::Error) -> Box<dyn std::error::Error> {
    move |e| format!("{flag}: {e}").into()
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
    load_track_with(spec, data, Ends::MustMeet)
}

/// [`load_track`], saying what to do with a track that does not close.
pub fn load_track_with(spec: &str, data: &DataPath, ends: Ends) -> Result<Track, cdbo::Error> {
    let track = tracks::find_with(spec, data, ends)?;
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

/// The last of `seeds` seeds from `seed` on (`--seed` and `--seeds`), or why there is none.
pub fn last_seed(seed: u64, seeds: u64) -> Result<u64, String> {
    seed.checked_add(seeds.saturating_sub(1)).ok_or_else(|| {
        format!(
            "--seed {seed} with --seeds {seeds}: the last seed would pass {}",
            u64::MAX
        )
    })
}

/// Value parsers for numeric flags: clap reports a bad value as one line naming the flag, the
/// value and the bound, and exits with status 2 before the command allocates anything.
pub mod value {
    use cdbo::sizes::{self, Size};

    fn size(text: &str, size: &Size) -> Result<usize, String> {
        let v: usize = text
            .trim()
            .parse()
            .map_err(|_| "not a whole number".to_string())?;
        size.check(v)
    }

    fn number(text: &str) -> Result<f64, String> {
        let v: f64 = text
            .trim()
            .parse()
            .map_err(|_| "not a number".to_string())?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err("must be a finite number".into())
        }
    }

    /// Policy kernels M, within [`sizes::KERNELS`].
    pub fn kernels(text: &str) -> Result<usize, String> {
        size(text, &sizes::KERNELS)
    }
    /// Laps, within [`sizes::LAPS`].
    pub fn laps(text: &str) -> Result<usize, String> {
        size(text, &sizes::LAPS)
    }
    /// A study's total of told trials: 0 (open or create the study, drive nothing) up to
    /// [`sizes::LAPS`].
    pub fn total_laps(text: &str) -> Result<usize, String> {
        if text.trim() == "0" {
            return Ok(0);
        }
        laps(text)
    }
    /// Table points, within [`sizes::POINTS`].
    pub fn points(text: &str) -> Result<usize, String> {
        size(text, &sizes::POINTS)
    }
    /// Parallel jobs, within [`sizes::JOBS`].
    pub fn jobs(text: &str) -> Result<usize, String> {
        size(text, &sizes::JOBS)
    }
    /// Problem dimensions, within [`sizes::DIMS`].
    pub fn dims(text: &str) -> Result<usize, String> {
        size(text, &sizes::DIMS)
    }
    /// Evaluations per run, within [`sizes::EVALUATIONS`].
    pub fn evals(text: &str) -> Result<usize, String> {
        size(text, &sizes::EVALUATIONS)
    }
    /// GP observations, within [`sizes::OBSERVATIONS`].
    pub fn observations(text: &str) -> Result<usize, String> {
        size(text, &sizes::OBSERVATIONS)
    }
    /// Repeats, seeds, scan points, within [`sizes::REPEATS`].
    pub fn repeats(text: &str) -> Result<usize, String> {
        size(text, &sizes::REPEATS)
    }
    /// Seeds of a benchmark (a count, as [`repeats`]).
    pub fn seeds(text: &str) -> Result<u64, String> {
        repeats(text).map(|v| v as u64)
    }
    /// A finite number (a reward, a seed-free setting).
    pub fn finite(text: &str) -> Result<f64, String> {
        number(text)
    }
    /// A finite number above zero (speeds, seconds, length-scales, lengths).
    pub fn positive(text: &str) -> Result<f64, String> {
        let v = number(text)?;
        if v > 0.0 {
            Ok(v)
        } else {
            Err("must be above 0".into())
        }
    }
    /// A search box's half-width: above 0, at most [`cdbo::optimizers::MAX_BOX_RADIUS`].
    pub fn box_radius(text: &str) -> Result<f64, String> {
        let v = positive(text)?;
        if v <= cdbo::optimizers::MAX_BOX_RADIUS {
            Ok(v)
        } else {
            Err(format!(
                "must be at most {}: the weights saturate within a few units",
                cdbo::optimizers::MAX_BOX_RADIUS
            ))
        }
    }
    /// A finite number of at least zero (β, the ridge factor).
    pub fn non_negative(text: &str) -> Result<f64, String> {
        let v = number(text)?;
        if v >= 0.0 {
            Ok(v)
        } else {
            Err("must be at least 0".into())
        }
    }
    /// Where a lap leaves the road: metres past the road's edge, within [−3, 5].
    pub fn off_track_margin(text: &str) -> Result<f64, String> {
        let v = number(text)?;
        if cdbo::sim::lap::OFF_TRACK_MARGINS.contains(&v) {
            Ok(v)
        } else {
            Err("must be within [-3, 5] m past the road's edge (negative: inside it)".into())
        }
    }
    /// A pedal command in [−1, 1].
    pub fn pedal(text: &str) -> Result<f64, String> {
        let v = number(text)?;
        if (-1.0..=1.0).contains(&v) {
            Ok(v)
        } else {
            Err("must be within [-1, 1] (1 = full throttle, -1 = full brake)".into())
        }
    }
    /// A fraction of the lap in [0, 1].
    pub fn fraction(text: &str) -> Result<f64, String> {
        let v = number(text)?;
        if (0.0..=1.0).contains(&v) {
            Ok(v)
        } else {
            Err("must be a fraction of the lap within [0, 1]".into())
        }
    }
}
