//! `cdbo bench circuits`: every circuit of a folder raced with each stack the README
//! recommends, in one table — does a race start, when does its first lap complete, how close
//! to the centre-line limit does it get, how many laps fail.

use std::path::{Path, PathBuf};

use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde::Serialize;

use super::{CliResult, load_track, print_json};
use cdbo::car::Car;
use cdbo::data_path::DataPath;
use cdbo::drive::steering::SteeringLaw;
use cdbo::experiment::race::{RaceConfig, RaceOutcome, race};
use cdbo::line::{LineKind, LineSetting};
use cdbo::method::{Method, Preset};
use cdbo::venue::Venue;

#[derive(Debug, Args)]
pub struct CircuitsArgs {
    /// Circuits: a folder (each `.csv` or `.xml` track in it, and each NAME/NAME.xml below
    /// it), a track file or name, or `road` for every TORCS road track in the data folders.
    #[arg(required = true)]
    tracks: Vec<String>,
    /// Car: built-in spirit-300, a TORCS / Speed Dreams car .xml, or a car name in the data
    /// folders.
    #[arg(long, default_value = cdbo::car::catalog::DEFAULT)]
    car: String,
    /// Stacks raced, comma-separated: a preset (`fast-safe`) or a method on the paper's drive
    /// (PI steering, centre line). Default: the README's.
    #[arg(long, value_delimiter = ',', default_values_t = Stack::RECOMMENDED)]
    stacks: Vec<Stack>,
    /// Seed of each stack's first race on each circuit.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Races of each stack on each circuit, one a seed from --seed on (--seed, --seed + 1, …).
    #[arg(long, default_value_t = 1, value_parser = super::value::seeds)]
    seeds: u64,
    /// Laps per race.
    #[arg(long, default_value_t = 300, value_parser = super::value::laps)]
    laps: usize,
    /// Policy kernels M.
    #[arg(long, default_value_t = 30, value_parser = super::value::kernels)]
    kernels: usize,
    /// Failed laps allowed every race (a hard cap from its first lap); default: each
    /// method's own (30 for the safe pattern search, none for the others).
    #[arg(long, value_name = "N")]
    max_failed_laps: Option<usize>,
    /// Races run at once (default: one per core).
    #[arg(long, value_parser = super::value::jobs)]
    jobs: Option<usize>,
    /// Print JSON: every race and every row.
    #[arg(long)]
    json: bool,
}

/// A stack raced: a preset, or a method on the paper's drive.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(into = "String")]
pub enum Stack {
    /// A preset's learner, steering and line.
    Preset(Preset),
    /// A method with the paper's PI steering on the centre line.
    Method(Method),
}

impl Stack {
    /// The stacks the README recommends: the two presets (the safe pattern search, and the
    /// pattern search on the same drive), and the paper's CDBO.
    const RECOMMENDED: [Stack; 3] = [
        Stack::Preset(Preset::FastSafe),
        Stack::Preset(Preset::Fast),
        Stack::Method(Method::Cdbo),
    ];

    fn method(self) -> Method {
        match self {
            Stack::Preset(p) => p.method(),
            Stack::Method(m) => m,
        }
    }

    fn line(self) -> LineKind {
        match self {
            Stack::Preset(p) => p.line(),
            Stack::Method(_) => LineKind::Centre,
        }
    }

    fn steering(self) -> SteeringLaw {
        match self {
            Stack::Preset(p) => p.steering(),
            Stack::Method(_) => SteeringLaw::default(),
        }
    }
}

impl std::fmt::Display for Stack {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Stack::Preset(p) => write!(f, "{}", p.name()),
            Stack::Method(m) => write!(f, "{m}"),
        }
    }
}

impl From<Stack> for String {
    fn from(stack: Stack) -> String {
        stack.to_string()
    }
}

impl std::str::FromStr for Stack {
    type Err = String;

    fn from_str(name: &str) -> Result<Stack, String> {
        if let Ok(preset) = name.parse::<Preset>() {
            return Ok(Stack::Preset(preset));
        }
        name.parse::<Method>().map(Stack::Method).map_err(|_| {
            format!(
                "{name:?} is neither a preset ({}) nor a method ({})",
                Preset::ALL.map(Preset::name).join(", "),
                Method::ALL.map(Method::name).join(", ")
            )
        })
    }
}

/// One race of the benchmark.
#[derive(Debug, Serialize)]
struct Run {
    circuit: String,
    stack: Stack,
    seed: u64,
    /// Why the race did not start, if it did not.
    error: Option<String>,
    /// The first lap that completed (1 = the first), if any.
    first_completed_lap: Option<usize>,
    best_mps: f64,
    limit_mps: f64,
    failed_laps: usize,
    wall_s: f64,
}

/// A circuit's row for one stack, over its seeds.
#[derive(Debug, Serialize)]
struct Row {
    circuit: String,
    stack: Stack,
    started: usize,
    seeds: usize,
    /// The latest first completed lap over the seeds; `None` where a seed completed none.
    first_completed_lap: Option<usize>,
    /// Mean and lowest best lap over the seeds, as a share of the centre-line limit.
    best_of_limit: f64,
    lowest_of_limit: f64,
    max_failed_laps: usize,
    wall_s: f64,
}

#[derive(Debug, Serialize)]
struct Report {
    car: String,
    laps: usize,
    kernels: usize,
    /// The first seed.
    seed: u64,
    seeds: u64,
    runs: Vec<Run>,
    rows: Vec<Row>,
}

pub fn circuits(args: &CircuitsArgs, data: &DataPath) -> CliResult {
    let last_seed = super::last_seed(args.seed, args.seeds)?;
    let files = circuit_files(&args.tracks, data)?;
    let car = cdbo::car::catalog::find(&args.car, data)?;
    let mut circuits = Vec::new();
    for file in &files {
        let track = load_track(file, data).map_err(|e| format!("{file}: {e}"))?;
        circuits.push(track);
    }
    let mut races = Vec::new();
    for (i, _) in circuits.iter().enumerate() {
        for &stack in &args.stacks {
            for seed in args.seed..=last_seed {
                races.push((i, stack, seed));
            }
        }
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs.unwrap_or(0))
        .build()?;
    let bar = if args.json {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(races.len() as u64)
    };
    bar.set_style(
        ProgressStyle::with_template("races [{bar:30}] {pos}/{len} ({elapsed})")?
            .progress_chars("=> "),
    );
    let runs: Vec<Run> = pool.install(|| {
        races
            .par_iter()
            .map(|&(i, stack, seed)| {
                let run = race_one(&circuits[i], &car, stack, seed, args);
                bar.inc(1);
                run
            })
            .collect()
    });
    bar.finish_and_clear();
    let rows = rows(&runs, &args.stacks);
    let report = Report {
        car: car.name.clone(),
        laps: args.laps,
        kernels: args.kernels,
        seed: args.seed,
        seeds: args.seeds,
        runs,
        rows,
    };
    if args.json {
        return print_json(&report);
    }
    print!("{}", markdown(&report, &args.stacks));
    Ok(())
}

/// The tracks `specs` name: a folder's track files (sorted), `road`'s TORCS road tracks, or
/// a spec as it is.
fn circuit_files(specs: &[String], data: &DataPath) -> Result<Vec<String>, String> {
    let mut files = Vec::new();
    for spec in specs {
        let path = Path::new(spec);
        if spec == "road" && !path.exists() {
            let found = road_tracks(data);
            if found.is_empty() {
                return Err(format!(
                    "road: no TORCS road track (tracks/road/NAME/NAME.xml) in {}",
                    data.describe()
                ));
            }
            files.extend(found);
        } else if path.is_dir() {
            let found = folder_tracks(path).map_err(|e| format!("{spec}: {e}"))?;
            if found.is_empty() {
                return Err(format!(
                    "{spec}: no track in this folder (.csv or .xml files, or NAME/NAME.xml)"
                ));
            }
            files.extend(found);
        } else {
            files.push(spec.clone());
        }
    }
    Ok(files)
}

/// A folder's `.csv` and `.xml` files and its NAME/NAME.xml tracks, sorted.
fn folder_tracks(dir: &Path) -> std::io::Result<Vec<String>> {
    let mut found: Vec<PathBuf> = Vec::new();
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        let nested = path.join(format!(
            "{}.xml",
            path.file_name().unwrap_or_default().to_string_lossy()
        ));
        if path.is_dir() && nested.is_file() {
            found.push(nested);
        } else if path.extension().is_some_and(|e| e == "csv" || e == "xml") {
            found.push(path);
        }
    }
    found.sort();
    Ok(found.iter().map(|p| p.display().to_string()).collect())
}

/// Every TORCS road track in the data folders, by name, the first folder's where two have it.
fn road_tracks(data: &DataPath) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    let mut files = Vec::new();
    for dir in data.dirs() {
        let Ok(tracks) = folder_tracks(&dir.join("tracks/road")) else {
            continue;
        };
        for file in tracks {
            let name = Path::new(&file)
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned());
            if let Some(name) = name.filter(|n| !names.contains(n)) {
                names.push(name);
                files.push(file);
            }
        }
    }
    let mut both: Vec<(String, String)> = names.into_iter().zip(files).collect();
    both.sort();
    both.into_iter().map(|(_, f)| f).collect()
}

/// One race as `cdbo race` runs it with `stack` (the learning rule's default reserve).
fn race_one(
    track: &cdbo::track::Track,
    car: &Car,
    stack: Stack,
    seed: u64,
    args: &CircuitsArgs,
) -> Run {
    let start = std::time::Instant::now();
    let outcome = configured_race(track, car, stack, seed, args);
    let wall_s = start.elapsed().as_secs_f64();
    let mut run = Run {
        circuit: track.name.clone(),
        stack,
        seed,
        error: None,
        first_completed_lap: None,
        best_mps: 0.0,
        limit_mps: 0.0,
        failed_laps: 0,
        wall_s,
    };
    match outcome {
        Ok(outcome) => {
            run.first_completed_lap = outcome
                .laps
                .iter()
                .find(|l| l.failure.is_none())
                .map(|l| l.lap);
            run.best_mps = outcome.best_reward_mps;
            run.limit_mps = outcome.limit.reward_mps;
            run.failed_laps = outcome.laps.iter().filter(|l| l.failure.is_some()).count();
        }
        Err(e) => {
            run.limit_mps = cdbo::limit::limit_lap(track, car).reward_mps;
            run.error = Some(e);
        }
    }
    run
}

fn configured_race(
    track: &cdbo::track::Track,
    car: &Car,
    stack: Stack,
    seed: u64,
    args: &CircuitsArgs,
) -> Result<RaceOutcome, String> {
    let setting = LineSetting {
        line: stack.line(),
        kernels: None,
        start: None,
    };
    let (base_line, line_kernels) = setting.resolve(args.kernels).map_err(|e| e.to_string())?;
    let config = RaceConfig {
        method: stack.method(),
        kernels: args.kernels,
        laps: args.laps,
        seed,
        max_failed_laps: args.max_failed_laps,
        line_kernels,
        base_line,
        ..RaceConfig::default()
    };
    let venue = Venue::simulator(track.clone(), car)
        .steered(stack.steering().steering())
        .for_learning(None);
    race(&venue, track, car, &config, |_| {}).map_err(|e| e.to_string())
}

/// Each circuit's row for each stack, in the order of the runs.
fn rows(runs: &[Run], stacks: &[Stack]) -> Vec<Row> {
    let mut rows = Vec::new();
    let mut circuits: Vec<&str> = Vec::new();
    for run in runs {
        if !circuits.contains(&run.circuit.as_str()) {
            circuits.push(&run.circuit);
        }
    }
    for circuit in circuits {
        for &stack in stacks {
            let of: Vec<&Run> = runs
                .iter()
                .filter(|r| r.circuit == circuit && r.stack == stack)
                .collect();
            let shares: Vec<f64> = of.iter().map(|r| r.best_mps / r.limit_mps).collect();
            rows.push(Row {
                circuit: circuit.to_owned(),
                stack,
                started: of.iter().filter(|r| r.error.is_none()).count(),
                seeds: of.len(),
                first_completed_lap: of
                    .iter()
                    .map(|r| r.first_completed_lap)
                    .collect::<Option<Vec<_>>>()
                    .and_then(|laps| laps.into_iter().max()),
                best_of_limit: mean(&shares),
                lowest_of_limit: shares.iter().copied().fold(f64::INFINITY, f64::min),
                max_failed_laps: of.iter().map(|r| r.failed_laps).max().unwrap_or(0),
                wall_s: of.iter().map(|r| r.wall_s).sum(),
            });
        }
    }
    rows
}

fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len().max(1) as f64
}

/// The table: a row per circuit and stack, then each stack over every circuit, then the
/// races that did not start with why.
fn markdown(report: &Report, stacks: &[Stack]) -> String {
    let last = report.seed + (report.seeds - 1);
    let seeds = if last == report.seed {
        format!("seed {last}")
    } else {
        format!("seeds {}–{last}", report.seed)
    };
    let mut out = format!(
        "{} circuits, {}, {} laps, {} kernels, {seeds}: best lap as % of the centre-line \
         limit (mean over seeds, lowest)\n\n",
        report.rows.len() / stacks.len().max(1),
        report.car,
        report.laps,
        report.kernels,
    );
    out += "| circuit | stack | started | first lap completed (latest) | best / limit | lowest | failed laps (max) | wall (s) |\n";
    out += "| --- | --- | --- | --- | --- | --- | --- | --- |\n";
    for r in &report.rows {
        out += &format!(
            "| {} | {} | {}/{} | {} | {:.1} % | {:.1} % | {} | {:.1} |\n",
            r.circuit,
            r.stack,
            r.started,
            r.seeds,
            r.first_completed_lap
                .map_or("never".to_owned(), |l| l.to_string()),
            100.0 * r.best_of_limit,
            100.0 * r.lowest_of_limit,
            r.max_failed_laps,
            r.wall_s
        );
    }
    for &stack in stacks {
        let of: Vec<&Row> = report.rows.iter().filter(|r| r.stack == stack).collect();
        let started: usize = of.iter().map(|r| r.started).sum();
        let seeds: usize = of.iter().map(|r| r.seeds).sum();
        let never = of
            .iter()
            .filter(|r| r.first_completed_lap.is_none())
            .count();
        out += &format!(
            "| **all** | **{stack}** | {started}/{seeds} | never on {never} | **{:.1} %** | {:.1} % | {} | {:.1} |\n",
            100.0 * mean(&of.iter().map(|r| r.best_of_limit).collect::<Vec<_>>()),
            100.0
                * of.iter()
                    .map(|r| r.lowest_of_limit)
                    .fold(f64::INFINITY, f64::min),
            of.iter().map(|r| r.max_failed_laps).max().unwrap_or(0),
            of.iter().map(|r| r.wall_s).sum::<f64>()
        );
    }
    for run in report.runs.iter().filter(|r| r.error.is_some()) {
        out += &format!(
            "\n{} with {}, seed {}, did not start: {}",
            run.circuit,
            run.stack,
            run.seed,
            run.error.as_deref().unwrap_or_default()
        );
    }
    out
}
