//! `cdbo experiment`: run a grid of races (the paper's Sec. V) in parallel, resumable, and
//! splittable into shards for many machines.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use super::{CliResult, from_flag, load_track};
use cdbo::car::catalog as cars;
use cdbo::data_path::DataPath;
use cdbo::experiment::folder::{self, Session};
use cdbo::experiment::grid::{ExperimentConfig, PRESETS, Shard};
use cdbo::experiment::record::{RunRecord, run};
use cdbo::track::Track;

#[derive(Debug, Args)]
pub struct ExperimentArgs {
    /// A grid as a TOML file, or a preset: paper, paper-plus, quick.
    config: String,
    /// Output folder (default: runs/experiment-NAME); runs already in it are skipped.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Runs in parallel (default: the number of cores).
    #[arg(long, value_parser = super::value::jobs)]
    jobs: Option<usize>,
    /// Run only shard I of N (0 ≤ I < N), e.g. --shard $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT.
    #[arg(long, value_name = "I/N")]
    shard: Option<String>,
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

pub fn run_grid(args: &ExperimentArgs, data: &DataPath) -> CliResult {
    let (config, name) = match ExperimentConfig::preset(&args.config) {
        Some(c) => (c, args.config.clone()),
        None => {
            let path = PathBuf::from(&args.config);
            let text = std::fs::read_to_string(&path).map_err(|e| {
                format!(
                    "{}: {e} (CONFIG is a TOML file or a preset: {})",
                    path.display(),
                    PRESETS.join(", ")
                )
            })?;
            let stem = path
                .file_stem()
                .map_or("grid".into(), |s| s.to_string_lossy().into_owned());
            (
                ExperimentConfig::from_toml(&text, &path.display().to_string())?,
                stem,
            )
        }
    };
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("runs").join(format!("experiment-{name}")));
    folder::claim(&out, &config).map_err(|e| match e {
        cdbo::Error::DifferentGrid { .. } => format!("{e}; choose another --out"),
        e => e.to_string(),
    })?;
    let largest = config.tracks.iter().flat_map(|t| t.kernels.iter()).max();
    if let Some(w) = largest.and_then(|&k| cdbo::sizes::slow_race_warning(k, config.laps)) {
        eprintln!("warning: {name}: each of its largest runs: {w}");
    }
    let mut runs = config.runs();
    let total = runs.len();
    if let Some(s) = &args.shard {
        runs = Shard::parse(s).map_err(from_flag("--shard"))?.select(runs);
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
    let car = cars::find(&args.car, data)?;
    let mut tracks: BTreeMap<String, Track> = BTreeMap::new();
    for r in &runs {
        if !tracks.contains_key(&r.track) {
            let t =
                load_track(&r.track, data).map_err(|e| format!("{e}{}", track_hint(&r.track)))?;
            tracks.insert(r.track.clone(), t);
        }
    }
    let jobs = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    println!(
        "{} runs in the grid, {shard_size} in this shard: {skipped} already done, {} to run on {jobs} threads into {}",
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
            let record = run(spec, &config, track, &car, |_| bar.inc(1))
                .map_err(|e| format!("{}: {e}", spec.id()))?;
            record.save(&out).map_err(|e| e.to_string())?;
            let k = done.fetch_add(1, Ordering::Relaxed) + 1;
            bar.set_message(format!("{k}/{} runs", runs.len()));
            let line = format!(
                "{k}/{}: {}: best {:.2} m/s ({:.0} % of the limit) in {:.1} s",
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
