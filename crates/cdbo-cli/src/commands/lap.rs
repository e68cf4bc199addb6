//! `cdbo lap`: drive one lap.

use std::path::PathBuf;

use clap::Args;
use serde::Serialize;

use super::{CliResult, Setup, Simulator, print_json};
use cdbo::data_path::DataPath;
use cdbo::drive::demo::{DEFAULT_TARGET_SPEED, SpeedHold};
use cdbo::drive::steering::SteeringLaw;
use cdbo::drive::{ConstantPedal, Pedal};
use cdbo::limit::limit_lap;
use cdbo::line::BaseLine;
use cdbo::policy::PolicyTable;
use cdbo::sim::{Failure, LapResult};
use cdbo::torcs::{Game, GamePedal};

#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("driver").args(["demo", "throttle", "policy"])))]
pub struct LapArgs {
    #[command(flatten)]
    setup: Setup,
    /// Drive the demonstrator: a PI controller holding this speed (m/s). The default.
    #[arg(long, value_name = "SPEED", allow_negative_numbers = true, value_parser = super::value::positive)]
    demo: Option<f64>,
    /// Hold this pedal command everywhere (1 = full throttle, -1 = full brake).
    #[arg(long, value_name = "A", allow_negative_numbers = true, value_parser = super::value::pedal)]
    throttle: Option<f64>,
    /// Drive a policy: a table of CSV rows `x,a`, or weights as JSON (`.json`, as written by
    /// `cdbo race`, `cdbo policy fit` and `cdbo optimize`), or a race's folder (its
    /// `best_policy.json`); a policy is driven on the line and with the steering it was raced
    /// with (`race --line`, `--steering`).
    #[arg(long, value_name = "FILE")]
    policy: Option<PathBuf>,
    /// How the car steers (default: as the policy file says it was raced, else the PI).
    #[arg(long, value_parser = super::steering_parser())]
    steering: Option<SteeringLaw>,
    #[command(flatten)]
    off_track: super::OffTrackArgs,
    /// Time the flying lap: the second of two from the standing start, line to line, as the
    /// game times a robot's best lap (the standing lap before it is reported beside it).
    #[arg(long)]
    flying: bool,
    /// Print JSON.
    #[arg(long)]
    json: bool,
    /// Write every driver step (50 Hz) as CSV.
    #[arg(long, value_name = "FILE.csv")]
    trace: Option<PathBuf>,
    /// Plot the speed along the lap against the limit (PNG or SVG).
    #[arg(long, value_name = "FILE.png|.svg")]
    plot: Option<PathBuf>,
}

#[derive(Debug, Serialize)]
struct LapReport {
    track: String,
    car: String,
    completed: bool,
    lap_time_s: Option<f64>,
    reward_mps: f64,
    failure: Option<Failure>,
    /// Of a flying lap (`--flying`), the standing lap before it, if completed.
    #[serde(skip_serializing_if = "Option::is_none")]
    standing_lap_s: Option<f64>,
    limit_lap_time_s: f64,
    limit_reward_mps: f64,
    fraction_of_limit: f64,
    /// Where the lap was driven: `cdbo` or `torcs`.
    simulator: &'static str,
    ceiling_reward_mps: f64,
    fraction_of_ceiling: f64,
}

impl LapReport {
    fn new(
        track: &str,
        car: &str,
        lap: &LapResult,
        limit: &cdbo::limit::Limit,
        ceiling_mps: f64,
        simulator: &'static str,
    ) -> LapReport {
        LapReport {
            track: track.to_owned(),
            car: car.to_owned(),
            completed: lap.completed,
            lap_time_s: lap.lap_time_s,
            reward_mps: lap.reward_mps,
            failure: lap.failure,
            standing_lap_s: lap.standing_lap_s,
            limit_lap_time_s: limit.lap_time_s,
            limit_reward_mps: limit.reward_mps,
            fraction_of_limit: lap.reward_mps / limit.reward_mps,
            simulator,
            ceiling_reward_mps: ceiling_mps,
            fraction_of_ceiling: lap.reward_mps / ceiling_mps,
        }
    }
}

pub fn run(args: &LapArgs, data: &DataPath, simulator: Simulator) -> CliResult {
    if simulator == Simulator::Torcs {
        return run_torcs(args, data);
    }
    let (track, car) = args.setup.load(data)?;
    // A policy raced on a line, or with a steering, is driven so.
    let mut base_line = BaseLine::Centre;
    let mut steering = SteeringLaw::Pi;
    let mut pedal: Box<dyn Pedal> = match (args.demo, args.throttle, &args.policy) {
        (_, Some(a), _) => {
            if !(-1.0..=1.0).contains(&a) {
                return Err(format!("--throttle {a}: must be in [-1, 1]").into());
            }
            Box::new(ConstantPedal(a))
        }
        (_, _, Some(path)) if path.is_dir() || path.extension().is_some_and(|e| e == "json") => {
            let raced = super::policy::read_raced_policy(path)?;
            (base_line, steering) = (raced.base_line, raced.steering);
            Box::new(raced.policy.driver())
        }
        (_, _, Some(path)) => Box::new(PolicyTable::read_csv(path)?),
        (speed, _, _) => {
            let speed = speed.unwrap_or(DEFAULT_TARGET_SPEED);
            if !(speed > 0.0 && speed.is_finite()) {
                return Err(
                    format!("--demo {speed}: the target speed must be positive (m/s)").into(),
                );
            }
            Box::new(SpeedHold::new(speed))
        }
    };
    let limit = limit_lap(&track, &car);
    let line = base_line.line(&track, &car)?;
    let mut sim = cdbo::sim::Simulator::new(track, &car);
    sim.config.steering = args.steering.unwrap_or(steering).steering();
    sim.config.off_track_margin = args.off_track.judging();
    sim.config.line = line;
    sim.config.trace = args.trace.is_some() || args.plot.is_some();
    sim.config.flying = args.flying;
    let lap = sim.lap(pedal.as_mut());
    if let Some(path) = &args.trace {
        write_trace(path, &lap.trace)?;
    }
    if let Some(path) = &args.plot {
        crate::figures::lap_speed(path, &sim.track, &lap, &limit)?;
    }
    sim.config.trace = false;
    sim.config.flying = false;
    // The ceiling is the centre line's, as `cdbo race` reports it.
    sim.config.line = None;
    let profile = cdbo::ceiling::profile(&sim.track, &car, None);
    let (_, ceiling_mps) = cdbo::ceiling::tracked_profile(&sim, &profile)?;
    print_report(
        LapReport::new(
            &sim.track.name,
            &car.name,
            &lap,
            &limit,
            ceiling_mps,
            "cdbo",
        ),
        args.json,
    )
}

/// A lap in the game TORCS, driven by cdbo's robot; the limit is cdbo's, on the game's track
/// and car files.
fn run_torcs(args: &LapArgs, data: &DataPath) -> CliResult {
    if args.plot.is_some() {
        return Err(
            "--plot needs cdbo's simulator; with --simulator torcs write --trace and plot it"
                .into(),
        );
    }
    // A policy with a line (or raced on a base line) holds it in the game as in cdbo's
    // simulator.
    let mut policy = None;
    let pedal = match (args.demo, args.throttle, &args.policy) {
        (_, Some(a), _) => {
            if !(-1.0..=1.0).contains(&a) {
                return Err(format!("--throttle {a}: must be in [-1, 1]").into());
            }
            GamePedal::Constant(a)
        }
        (_, _, Some(path)) if path.is_dir() || path.extension().is_some_and(|e| e == "json") => {
            let raced = super::policy::read_raced_policy(path)?;
            let pedal = cdbo::torcs::evaluator::game_pedal(&raced.policy);
            policy = Some(raced);
            pedal
        }
        (_, _, Some(path)) => GamePedal::Table(PolicyTable::read_csv(path)?.points().to_vec()),
        (speed, _, _) => {
            let speed = speed.unwrap_or(DEFAULT_TARGET_SPEED);
            if !(speed > 0.0 && speed.is_finite()) {
                return Err(
                    format!("--demo {speed}: the target speed must be positive (m/s)").into(),
                );
            }
            GamePedal::Demo(speed)
        }
    };
    let game = Game::ready()?;
    let car_name = Simulator::Torcs.car(&args.setup.car);
    let mut req = game.request(&args.setup.track, car_name, pedal)?;
    let steering = args
        .steering
        .or(policy.as_ref().map(|p| p.steering))
        .unwrap_or_default();
    req.config.steering = steering.steering();
    req.config.off_track_margin = args.off_track.judging();
    req.config.flying = args.flying;
    let track = super::game_track(&args.setup.track, &game, data)?;
    // The policy's line on the base line it was raced on (none: the centre line, no table).
    if let Some(raced) = policy {
        req.config.line = raced.base_line.line(&track, &req.car)?;
        req = cdbo::torcs::evaluator::with_policy(&req, &track, &raced.policy);
    }
    if let Some(path) = &args.trace {
        req.trace =
            Some(std::path::absolute(path).map_err(|e| format!("{}: {e}", path.display()))?);
    }
    let lap = game
        .lap(&req)?
        .map_err(|reason| format!("TORCS drove no lap: {reason}"))?;
    let limit = limit_lap(&track, &req.car);
    let mut ours = cdbo::sim::Simulator::new(track.clone(), &req.car);
    ours.config.steering = steering.steering();
    let profile = cdbo::ceiling::profile(&track, &req.car, None);
    let (_, ceiling_mps) = cdbo::ceiling::tracked_profile(&ours, &profile)?;
    print_report(
        LapReport::new(&track.name, car_name, &lap, &limit, ceiling_mps, "torcs"),
        args.json,
    )
}

/// One line: the lap time and reward, or where and why the lap failed.
pub fn describe(lap: &LapResult) -> String {
    match (lap.lap_time_s, lap.failure) {
        (Some(t), _) => format!("lap {t:.2} s, reward {:.2} m/s", lap.reward_mps),
        (None, Some(f)) => format!(
            "failed ({}) at x = {:.4} ({:.1} m, {:.2} s); reward 0",
            f.reason.name(),
            f.x,
            f.distance_m,
            f.time_s
        ),
        (None, None) => "no lap".into(),
    }
}

fn print_report(report: LapReport, json: bool) -> CliResult {
    if json {
        return print_json(&report);
    }
    match (report.lap_time_s, report.failure) {
        (Some(t), _) => println!(
            "{} on {}: {} {:.2} s, reward {:.2} m/s ({:.1} % of the centre-line limit {:.2} s, {:.2} m/s; {:.1} % of the ceiling {:.2} m/s)",
            report.car,
            report.track,
            match report.standing_lap_s {
                Some(standing) => format!("standing lap {standing:.2} s, flying lap"),
                None => "lap".into(),
            },
            t,
            report.reward_mps,
            100.0 * report.fraction_of_limit,
            report.limit_lap_time_s,
            report.limit_reward_mps,
            100.0 * report.fraction_of_ceiling,
            report.ceiling_reward_mps
        ),
        (None, Some(f)) => println!(
            "{} on {}: failed ({:?}) at x = {:.4} ({:.1} m, {:.2} s); reward 0 (limit {:.2} s, {:.2} m/s)",
            report.car,
            report.track,
            f.reason,
            f.x,
            f.distance_m,
            f.time_s,
            report.limit_lap_time_s,
            report.limit_reward_mps
        ),
        (None, None) => unreachable!("a lap either completes or fails"),
    }
    Ok(())
}

fn write_trace(path: &std::path::Path, trace: &[cdbo::sim::TracePoint]) -> CliResult {
    use std::io::Write;
    let file = std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut w = std::io::BufWriter::new(file);
    cdbo::sim::trace::write(&mut w, trace)?;
    w.flush()?;
    Ok(())
}
