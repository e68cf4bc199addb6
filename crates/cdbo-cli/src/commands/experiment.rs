//! `cdbo experiment`: run a grid of races (the paper's Sec. V) in parallel, resumable, and
//! splittable into shards for many machines, or spread over workers through a database
//! (`--storage URL --worker`).

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use super::{CliResult, Simulator, from_flag, game_track, load_track};
use cdbo::bounded;
use cdbo::car::catalog as cars;
use cdbo::data_path::DataPath;
use cdbo::experiment::folder::{self, Session};
use cdbo::experiment::grid::{ExperimentConfig, PRESETS, Shard};
use cdbo::experiment::record::{Grounds, RunRecord, run_at};
use cdbo::experiment::shared::{Progress, SharedGrid, work};
use cdbo::study::Location;
use cdbo::study::claim::{DEFAULT_LEASE, Missed, Worker};
use cdbo::track::Track;

#[derive(Debug, Args)]
pub struct ExperimentArgs {
    /// A grid as a TOML file, or a preset: paper, paper-plus, quick.
    config: String,
    /// Output folder (default: runs/experiment-NAME); runs already in it are skipped.
    #[arg(long, value_name = "DIR", conflicts_with = "storage")]
    out: Option<PathBuf>,
    /// Keep the grid in a database instead of a folder, for workers on many machines: an
    /// SQLite file (FILE or sqlite://FILE) or a PostgreSQL database
    /// (postgresql://USER@HOST[:PORT]/DB, the grid named NAME or by URL#GRID). Without
    /// --worker, stores the grid there and runs nothing.
    #[arg(long, value_name = "URL|FILE")]
    storage: Option<String>,
    /// Run cells of the grid in --storage, each taken by one worker, until every cell is
    /// finished (start any number of workers, anywhere).
    #[arg(long, requires = "storage")]
    worker: bool,
    /// With --worker: seconds a claimed cell stays this worker's without a heartbeat
    /// (renewed six times per lease while it runs); after that another worker runs it.
    #[arg(long, default_value_t = DEFAULT_LEASE.as_secs_f64(), value_parser = super::value::positive, requires = "worker")]
    lease: f64,
    /// Runs in parallel (default: the number of cores).
    #[arg(long, value_parser = super::value::jobs)]
    jobs: Option<usize>,
    /// Run only shard I of N (0 ≤ I < N), e.g. --shard $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT.
    #[arg(long, value_name = "I/N", conflicts_with = "storage")]
    shard: Option<String>,
    /// Run only these methods' cells (comma-separated), e.g. one method again after a change,
    /// into the folder that holds the others' runs: the grid stays whole.
    #[arg(
        long,
        value_parser = super::method_parser(),
        value_delimiter = ',',
        value_name = "METHOD,...",
        conflicts_with = "storage"
    )]
    methods: Vec<cdbo::method::Method>,
    /// Car: built-in spirit-300, a car .xml, or a car name in the data folders.
    #[arg(long, default_value = cars::DEFAULT)]
    car: String,
}

/// Where to get the paper's tracks when they are missing.
fn track_hint(name: &str) -> &'static str {
    match name {
        "forza" => {
            " (Forza comes with TORCS: install Debian's torcs-data package, or pass --data-dir with a TORCS data folder)"
        }
        "allondaz" => {
            " (Allondaz comes with Speed Dreams: install it, or pass --data-dir with a Speed Dreams data folder)"
        }
        _ => "",
    }
}

/// The grid CONFIG names (a preset or a TOML file) and its name (the preset or file stem).
fn read_grid(args: &ExperimentArgs) -> Result<(ExperimentConfig, String), String> {
    Ok(match ExperimentConfig::preset(&args.config) {
        Some(c) => (c, args.config.clone()),
        None => {
            let path = PathBuf::from(&args.config);
            let text =
                bounded::read_text(&path, &bounded::EXPERIMENT_GRID).map_err(|e| match e {
                    cdbo::Error::Io { .. } => format!(
                        "{e} (CONFIG is a TOML file or a preset: {})",
                        PRESETS.join(", ")
                    ),
                    e => e.to_string(),
                })?;
            let stem = path
                .file_stem()
                .map_or("grid".into(), |s| s.to_string_lossy().into_owned());
            (
                ExperimentConfig::from_toml(&text, &path.display().to_string())
                    .map_err(|e| e.to_string())?,
                stem,
            )
        }
    })
}

/// The grid's tracks, each loaded once; in the game, cdbo's reading of the game's track,
/// checked to be one the game has.
fn load_tracks(
    runs: &[cdbo::experiment::grid::RunSpec],
    data: &DataPath,
    grounds: &Grounds,
) -> Result<BTreeMap<String, Track>, String> {
    let mut tracks: BTreeMap<String, Track> = BTreeMap::new();
    for r in runs {
        if !tracks.contains_key(&r.track) {
            let t = match grounds {
                Grounds::Simulator => load_track(&r.track, data)
                    .map_err(|e| format!("{e}{}", track_hint(&r.track)))?,
                Grounds::Torcs { game, .. } => {
                    game.install
                        .track_category(&r.track)
                        .map_err(|e| e.to_string())?;
                    game_track(&r.track, game, data).map_err(|e| e.to_string())?
                }
            };
            tracks.insert(r.track.clone(), t);
        }
    }
    Ok(tracks)
}

/// Where the grid's laps are driven, and the car as cdbo reads it: in the game, the game's
/// car (car1-trb1 unless --car names another) from the game's own files.
fn grounds(
    args: &ExperimentArgs,
    data: &DataPath,
    simulator: Simulator,
) -> Result<(Grounds, cdbo::car::Car), Box<dyn std::error::Error>> {
    match simulator {
        Simulator::Cdbo => Ok((Grounds::Simulator, cars::find(&args.car, data)?)),
        Simulator::Torcs => {
            let game = cdbo::torcs::Game::ready()?;
            let car = simulator.car(&args.car).to_owned();
            let read = game.car(&car)?;
            Ok((Grounds::Torcs { game, car }, read))
        }
    }
}

pub fn run_grid(args: &ExperimentArgs, data: &DataPath, simulator: Simulator) -> CliResult {
    let (config, name) = read_grid(args)?;
    if let Some(storage) = &args.storage {
        if simulator == Simulator::Torcs {
            return Err(
                "--simulator torcs runs a grid in a folder (--out, with --jobs games at once), not over --storage workers"
                    .into(),
            );
        }
        return shared_grid(args, data, &config, &name, storage);
    }
    // A grid in the game keeps its own folder: its runs are not cdbo's simulator's.
    let suffix = if simulator == Simulator::Torcs {
        "-torcs"
    } else {
        ""
    };
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("runs").join(format!("experiment-{name}{suffix}")));
    folder::claim(&out, &config).map_err(|e| match e {
        cdbo::Error::DifferentGrid { .. } => format!("{e}; choose another --out"),
        e => e.to_string(),
    })?;
    // The grid's costliest run: its largest policy, raced by its costliest method.
    let largest = config.tracks.iter().flat_map(|t| t.kernels.iter()).max();
    let slow = largest.and_then(|&k| {
        let cost = |m| cdbo::method::cost::race_seconds(m, k, config.laps);
        let costliest = config
            .methods
            .iter()
            .copied()
            .max_by(|a, b| cost(*a).total_cmp(&cost(*b)))?;
        cdbo::method::cost::slow_race_warning(costliest, k, config.laps)
    });
    if let Some(w) = slow {
        eprintln!("warning: {name}: each of its largest runs: {w}");
    }
    let mut runs = config.runs();
    let total = runs.len();
    if let Some(s) = &args.shard {
        runs = Shard::parse(s).map_err(from_flag("--shard"))?.select(runs);
    }
    if let Some(m) = args.methods.iter().find(|m| !config.methods.contains(m)) {
        return Err(format!(
            "--methods: {m} is not a method of the grid {name} ({})",
            config
                .methods
                .iter()
                .map(|m| m.name())
                .collect::<Vec<_>>()
                .join(", ")
        )
        .into());
    }
    if !args.methods.is_empty() {
        runs.retain(|r| args.methods.iter().any(|m| m.name() == r.method));
    }
    let shard_size = runs.len();
    // A run is done when its record reads back; one cut short (a kill, a full disk) runs again.
    runs.retain(|r| {
        let path = RunRecord::path(&out, r);
        if !path.exists() {
            return true;
        }
        match RunRecord::load(&path) {
            Ok(_) => false,
            Err(e) => {
                eprintln!("warning: {e}; running {} again", r.id());
                true
            }
        }
    });
    let skipped = shard_size - runs.len();
    let (grounds, car) = grounds(args, data, simulator)?;
    let tracks = load_tracks(&runs, data, &grounds)?;
    let jobs = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    println!(
        "{} runs in the grid, {shard_size} selected: {skipped} already done, {} to run on {jobs} threads into {}",
        total,
        runs.len(),
        out.display()
    );
    let bar = ProgressBar::new((runs.len() * config.laps) as u64);
    bar.set_style(
        ProgressStyle::with_template("[{bar:30}] {pos}/{len} laps, {msg} ({elapsed}, eta {eta})")?
            .progress_chars("=> "),
    );
    let done = AtomicUsize::new(0);
    bar.set_message(format!("0/{} runs", runs.len()));
    let start = std::time::Instant::now();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(jobs).build()?;
    pool.install(|| {
        runs.par_iter().try_for_each(|spec| -> Result<(), String> {
            let track = tracks[&spec.track].clone();
            let record = run_at(spec, &config, track, &car, &grounds, |_| bar.inc(1))
                .map_err(|e| format!("{}: {e}", spec.id()))?;
            record.save(&out).map_err(|e| e.to_string())?;
            let k = done.fetch_add(1, Ordering::Relaxed) + 1;
            bar.set_message(format!("{k}/{} runs", runs.len()));
            let line = format!(
                "{k}/{}: {}: best {:.2} m/s ({:.0} % of the centre-line limit) in {:.1} s",
                runs.len(),
                spec.id(),
                record.best_reward_mps,
                100.0 * record.best_reward_mps / record.limit_reward_mps,
                record.wall_s
            );
            // Without a terminal (a batch job's log) the bar is hidden: print plainly.
            if bar.is_hidden() {
                println!("{line}");
            } else {
                bar.println(line);
            }
            Ok(())
        })
    })?;
    bar.finish_and_clear();
    let wall_s = start.elapsed().as_secs_f64();
    // One line per invocation, so that the report can say how long the grid took.
    let session = Session {
        runs: runs.len(),
        skipped,
        jobs,
        shard: args.shard.clone(),
        wall_s,
    };
    session.append(&out)?;
    println!(
        "{} runs done in {wall_s:.1} s; figures and tables: cdbo report {}",
        runs.len(),
        out.display()
    );
    Ok(())
}

/// `--storage URL [--worker]`: stores the grid in the database (or checks that the grid stored
/// under its name is this one), then, as a worker, runs cells until every cell is finished,
/// on `--jobs` threads, each a worker of its own; logs the session with the grid.
fn shared_grid(
    args: &ExperimentArgs,
    data: &DataPath,
    config: &ExperimentConfig,
    name: &str,
    storage: &str,
) -> CliResult {
    let location = Location::parse(storage, Some(name))?;
    // Everything a worker needs is checked before the grid is stored.
    let car = cars::find(&args.car, data)?;
    let tracks = if args.worker {
        load_tracks(&config.runs(), data, &Grounds::Simulator)?
    } else {
        BTreeMap::new()
    };
    let mut grid = SharedGrid::join(&location, config).map_err(|e| match e {
        cdbo::Error::DifferentGrid { path } => format!(
            "{}: holds a different grid under this name; store this one elsewhere (another file, or DATABASE-URL#OTHER-NAME)",
            path.display()
        ),
        e => e.to_string(),
    })?;
    let (finished, total) = grid.progress()?;
    if !args.worker {
        println!(
            "{total} runs in the grid at {}: {finished} finished; start workers with --worker",
            grid.path().display()
        );
        return Ok(());
    }
    let jobs = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    println!(
        "{total} runs in the grid at {}: {finished} finished; working on {jobs} threads",
        grid.path().display()
    );
    let process = Worker::this_process(Duration::from_secs_f64(args.lease));
    let start = std::time::Instant::now();
    let ran = AtomicUsize::new(0);
    let out = Mutex::new(());
    let say = |line: String| {
        let _lock = out.lock();
        println!("{line}");
    };
    std::thread::scope(|scope| -> CliResult {
        let threads: Vec<_> = (0..jobs)
            .map(|k| {
                let worker = Worker {
                    id: format!("{}/{k}", process.id),
                    lease: process.lease,
                };
                let (location, tracks, car, ran, say) = (&location, &tracks, &car, &ran, &say);
                scope.spawn(move || -> Result<(), String> {
                    let mut grid =
                        SharedGrid::join(location, config).map_err(|e| e.to_string())?;
                    work(&mut grid, &worker, tracks, car, &mut |p| match p {
                        Progress::Ran(r) => {
                            let k = ran.fetch_add(1, Ordering::Relaxed) + 1;
                            say(format!(
                                "ran {}: best {:.2} m/s ({:.0} % of the centre-line limit) in {:.1} s ({k} by this worker)",
                                r.spec.id(),
                                r.best_reward_mps,
                                100.0 * r.best_reward_mps / r.limit_reward_mps,
                                r.wall_s
                            ));
                        }
                        Progress::FinishedElsewhere(spec) => say(format!(
                            "{}: another worker finished it first; its record is kept",
                            spec.id()
                        )),
                        Progress::Waiting => {
                            say("waiting: every cell left is running on another worker".into())
                        }
                        Progress::Heartbeat(spec, Missed::Lost) => say(format!(
                            "warning: {}: its claim ran out and another worker took it",
                            spec.id()
                        )),
                        Progress::Heartbeat(spec, Missed::Failed(e)) => {
                            say(format!("warning: {}: heartbeat: {e}", spec.id()))
                        }
                    })
                    .map(|_| ())
                    .map_err(|e| e.to_string())
                })
            })
            .collect();
        for t in threads {
            t.join().map_err(|_| "a worker thread panicked")??;
        }
        Ok(())
    })?;
    let wall_s = start.elapsed().as_secs_f64();
    let runs = ran.load(Ordering::Relaxed);
    grid.add_session(&Session {
        runs,
        skipped: finished,
        jobs,
        shard: None,
        wall_s,
    })?;
    println!(
        "{runs} runs done by this worker in {wall_s:.1} s; the grid is finished; figures and tables: cdbo report --storage {}",
        location.label().display()
    );
    Ok(())
}
