//! `cdbo torcs calibrate`: fit the simulator's uncertain car parameters to laps driven in the
//! game (or logged on a real car), write the calibrated car, and report the agreement before
//! and after on the calibration tracks and on check tracks the fit never saw.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use clap::Args;
use rayon::prelude::*;
use serde::Serialize;

use super::CliResult;
use cdbo::calibrate::{self, Agreement, Fit, FitConfig, Observed, TrackLaps};
use cdbo::car::calibration::Calibration;
use cdbo::car::{Car, Scales};
use cdbo::data_path::DataPath;
use cdbo::sim::log;
use cdbo::torcs::Game;

#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// Track to calibrate on (repeatable): the game drives the probes there, or `--log` gives
    /// its laps. Two tracks fit a car rather than a track.
    #[arg(long = "track", required = true)]
    tracks: Vec<String>,
    /// Track to check the calibrated car on, not used in the fit (repeatable).
    #[arg(long = "check-track")]
    check_tracks: Vec<String>,
    /// The car: a TORCS car name in the game; with `--log`, any car `--car` takes.
    #[arg(long, default_value = cdbo::torcs::DEFAULT_CAR)]
    car: String,
    /// A real car's logged laps on the matching `--track` (one per --track, in order; CSV,
    /// columns in docs/results/torcs.md): fit to them instead of driving the game.
    #[arg(long = "log", value_name = "FILE.csv")]
    logs: Vec<PathBuf>,
    /// Logged laps on the matching `--check-track` (one per --check-track, with --log).
    #[arg(long = "check-log", value_name = "FILE.csv")]
    check_logs: Vec<PathBuf>,
    /// The scales to fit, comma-separated (grip, peak_slip, drag, downforce, rolling, launch).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "grip,peak_slip,drag,downforce,rolling,launch"
    )]
    fit: Vec<String>,
    /// Cost evaluations at most (each drives every calibration lap once in cdbo's simulator).
    #[arg(long, default_value_t = cdbo::calibrate::DEFAULT_EVALUATIONS, value_parser = super::value::evals)]
    evaluations: usize,
    /// Games running at once.
    #[arg(long, default_value_t = 2, value_parser = super::value::jobs)]
    jobs: usize,
    /// Output folder: car.toml (the calibrated car, for --car), calibration.json, and the
    /// game's laps as logs (log_TRACK.csv, which --log reads back).
    #[arg(long, default_value = "runs/calibrate")]
    out: PathBuf,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// The report written to calibration.json.
#[derive(Debug, Serialize)]
struct Report {
    car: String,
    source: &'static str,
    calibration_tracks: Vec<String>,
    check_tracks: Vec<String>,
    probes: Vec<Vec<String>>,
    fit: Fit,
    before: Vec<Agreement>,
    after: Vec<Agreement>,
    check_before: Vec<Agreement>,
    check_after: Vec<Agreement>,
    wall_s: f64,
}

pub fn run(args: &CalibrateArgs, data: &DataPath) -> CliResult {
    let start = std::time::Instant::now();
    let free = args
        .fit
        .iter()
        .map(|n| {
            Scales::index(n).ok_or_else(|| {
                format!(
                    "--fit {n}: not a scale (choose from {})",
                    Scales::NAMES.join(", ")
                )
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let from_logs = !args.logs.is_empty() || !args.check_logs.is_empty();
    // Everything is read and checked before anything is written.
    let (base, cal, check) = if from_logs {
        if args.logs.len() != args.tracks.len() || args.check_logs.len() != args.check_tracks.len()
        {
            return Err(format!(
                "--log: one log per --track ({} tracks, {} logs) and one --check-log per --check-track ({} and {})",
                args.tracks.len(),
                args.logs.len(),
                args.check_tracks.len(),
                args.check_logs.len()
            )
            .into());
        }
        let base = cdbo::car::catalog::find(&args.car, data)?;
        let cal = logged(&args.tracks, &args.logs, data)?;
        let check = logged(&args.check_tracks, &args.check_logs, data)?;
        (base, cal, check)
    } else {
        let game = Game::ready()?;
        let base = game.car(&args.car)?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(args.jobs)
            .build()?;
        let drive = |names: &[String]| -> Result<Vec<TrackLaps>, Box<dyn std::error::Error>> {
            names
                .iter()
                .map(|t| in_game(&game, t, &args.car, &base, &pool, data))
                .collect()
        };
        let (cal, check) = (drive(&args.tracks)?, drive(&args.check_tracks)?);
        (base, cal, check)
    };
    let before = calibrate::agreement(&base, &cal);
    let check_before = calibrate::agreement(&base, &check);
    let config = FitConfig {
        free,
        max_evaluations: args.evaluations,
        ..FitConfig::default()
    };
    let fit = calibrate::fit(&base, &cal, &config)?;
    let car = fit.scales.apply(&base);
    let after = calibrate::agreement(&car, &cal);
    let check_after = calibrate::agreement(&car, &check);
    let report = Report {
        car: args.car.clone(),
        source: if from_logs { "logs" } else { "TORCS" },
        calibration_tracks: args.tracks.clone(),
        check_tracks: args.check_tracks.clone(),
        probes: cal
            .iter()
            .chain(&check)
            .map(|t| t.laps.iter().map(|l| l.probe.name.clone()).collect())
            .collect(),
        fit,
        before,
        after,
        check_before,
        check_after,
        wall_s: start.elapsed().as_secs_f64(),
    };

    std::fs::create_dir_all(&args.out).map_err(|e| format!("{}: {e}", args.out.display()))?;
    let write = |name: &str, text: &str| -> CliResult {
        let path = args.out.join(name);
        std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()).into())
    };
    let calibration = Calibration {
        base: base_spec(&args.car),
        scales: report.fit.scales,
    };
    let comment = format!(
        "cdbo torcs calibrate on {} ({}), cost {:.4} -> {:.4}; load with --car {}",
        args.tracks.join(", "),
        report.source,
        report.fit.cost_start,
        report.fit.cost,
        args.out.join("car.toml").display()
    );
    write("car.toml", &calibration.to_toml(&comment))?;
    write("calibration.json", &serde_json::to_string_pretty(&report)?)?;
    if !from_logs {
        for t in cal.iter().chain(&check) {
            let laps: Vec<_> = (0..).zip(&t.laps).map(|(i, l)| l.logged(i)).collect();
            write(&format!("log_{}.csv", t.track.name), &log::write(&laps))?;
        }
    }
    if args.json {
        return super::print_json(&report);
    }
    print!("{}", markdown(&report, &car));
    Ok(())
}

/// The base as the calibrated file names it: a car file by its absolute path, else the name.
fn base_spec(spec: &str) -> String {
    let path = Path::new(spec);
    match path.is_file().then(|| path.canonicalize()) {
        Some(Ok(p)) => p.display().to_string(),
        _ => spec.to_owned(),
    }
}

/// The laps of `logs`, each on the matching track.
fn logged(
    tracks: &[String],
    logs: &[PathBuf],
    data: &DataPath,
) -> Result<Vec<TrackLaps>, Box<dyn std::error::Error>> {
    tracks
        .iter()
        .zip(logs)
        .map(|(name, path)| {
            let track = super::load_track(name, data)?;
            let text = cdbo::bounded::read_text(path, &cdbo::bounded::TRACE_FILE)?;
            let file = path.display().to_string();
            let laps = log::parse(&text, &file, track.length)?
                .iter()
                .map(|l| Observed::of_log(l, track.length, &file))
                .collect::<Result<_, _>>()?;
            Ok(TrackLaps { track, laps })
        })
        .collect()
}

/// The probes of `car` on the game's `track`, driven in the game, traced.
fn in_game(
    game: &Game,
    name: &str,
    car_name: &str,
    car: &Car,
    pool: &rayon::ThreadPool,
    data: &DataPath,
) -> Result<TrackLaps, Box<dyn std::error::Error>> {
    let track = super::game_track(name, game, data)?;
    let probes = calibrate::probes(&track, car)?;
    let mut req = game.request(name, car_name, cdbo::torcs::GamePedal::Demo(15.0))?;
    req.record = true;
    let laps = pool.install(|| {
        probes
            .into_par_iter()
            .map(|p| {
                let req = cdbo::torcs::LapRequest {
                    pedal: p.game_pedal(track.length),
                    ..req.clone()
                };
                let lap = cdbo::torcs::evaluator::drive(game, &req)?;
                Ok(Observed::of_lap(p, &lap))
            })
            .collect::<Result<Vec<_>, cdbo::Error>>()
    })?;
    eprintln!(
        "{name}: {}",
        laps.iter()
            .map(|l| format!(
                "{} {}",
                l.probe.name,
                l.lap_time_s
                    .map_or("failed".into(), |t| format!("{t:.2} s"))
            ))
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(TrackLaps { track, laps })
}

fn markdown(r: &Report, car: &Car) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{} calibrated on {} ({} laps): cost {:.4} -> {:.4} in {} evaluations, {:.0} s",
        r.car,
        r.calibration_tracks.join(", "),
        r.source,
        r.fit.cost_start,
        r.fit.cost,
        r.fit.evaluations,
        r.wall_s
    );
    let scales: Vec<String> = Scales::NAMES
        .iter()
        .enumerate()
        .map(|(i, n)| format!("{n} {:.3}", r.fit.scales.get(i)))
        .collect();
    let _ = writeln!(s, "scales: {} ({})\n", scales.join(", "), car.name);
    let _ = writeln!(
        s,
        "| track | role | RMS speed error before / after | lap-time error before / after | completion agreement before / after |\n| --- | --- | --- | --- | --- |"
    );
    let rows = r
        .before
        .iter()
        .zip(&r.after)
        .map(|p| (p, "calibration"))
        .chain(
            r.check_before
                .iter()
                .zip(&r.check_after)
                .map(|p| (p, "check")),
        );
    for ((b, a), role) in rows {
        let pct = |e: Option<f64>| e.map_or("–".into(), |e| format!("{:.2} %", 100.0 * e));
        let _ = writeln!(
            s,
            "| {} | {role} | {:.2} / {:.2} m/s | {} / {} | {}/{} / {}/{} |",
            b.track,
            b.rms_speed_mps,
            a.rms_speed_mps,
            pct(b.lap_time_error),
            pct(a.lap_time_error),
            b.completion_agree,
            b.laps,
            a.completion_agree,
            a.laps
        );
    }
    s
}
