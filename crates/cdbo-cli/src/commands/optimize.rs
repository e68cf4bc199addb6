//! `cdbo optimize`: optimise with an external lap evaluator, every lap saved to a study so that
//! an interrupted run resumes where it stopped.

use std::io::Write;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use clap::Args;

use super::study::InitialPolicy;
use super::{CliResult, Simulator};
use cdbo::data_path::DataPath;
use cdbo::evaluator::Evaluator;
use cdbo::evaluator::command::CommandEvaluator;
use cdbo::study::claim::{DEFAULT_LEASE, Worker};
use cdbo::study::run::Event;
use cdbo::study::{Location, Outcome, Study};
use cdbo::torcs::GamePedal;
use cdbo::torcs::evaluator::TorcsEvaluator;

#[derive(Debug, Args)]
pub struct OptimizeArgs {
    /// The lap command, run by `sh -c`, with {policy} where the policy file's path goes; it
    /// prints the reward (a number or JSON with "reward"). Not with `--simulator torcs`,
    /// which drives the game itself.
    #[arg(long, value_name = "CMD", required_unless_present = "track")]
    evaluator: Option<String>,
    /// With `--simulator torcs`: the TORCS track each lap is driven on (forza, e-track-2, ...).
    #[arg(long, conflicts_with = "evaluator")]
    track: Option<String>,
    /// With `--simulator torcs`: the TORCS car.
    #[arg(long, default_value = cdbo::torcs::DEFAULT_CAR, requires = "track")]
    car: String,
    /// With `--simulator torcs`: time and learn the flying lap, the second of two from the
    /// standing start, line to line (with an --evaluator, its command times the lap it
    /// drives: `cdbo lap --policy {policy} --flying --json`).
    #[arg(long, requires = "track")]
    flying: bool,
    /// Trials the study should have told when this run ends: a total, counting those already
    /// told (a study with 31 told trials and --laps 40 drives 9 more; with --laps 5, none).
    #[arg(long, value_parser = super::value::total_laps)]
    laps: usize,
    /// Where the study lives, created on the first run (with --demo or --weights) and resumed
    /// afterwards: an SQLite file (FILE or sqlite://FILE) or a PostgreSQL database
    /// (postgresql://USER@HOST[:PORT]/DB, the study named by --study).
    #[arg(long, visible_alias = "db", value_name = "URL|FILE")]
    storage: String,
    /// The study's name in a database (or DB-URL#STUDY); a file holds one study.
    #[arg(long, value_name = "NAME")]
    study: Option<String>,
    /// Seconds a lap may take before it counts as failed.
    #[arg(long, default_value_t = 600.0, allow_negative_numbers = true, value_parser = super::value::positive)]
    timeout: f64,
    /// Seconds a claimed trial stays this worker's without a heartbeat (renewed six times per
    /// lease while the lap is driven); after that another worker drives it.
    #[arg(long, default_value_t = DEFAULT_LEASE.as_secs_f64(), value_parser = super::value::positive)]
    lease: f64,
    #[command(flatten)]
    initial: InitialPolicy,
}

pub fn run(args: &OptimizeArgs, simulator: Simulator, data: &DataPath) -> CliResult {
    if let Some(w) = cdbo::method::cost::slow_study_warning(
        args.initial.method(),
        args.initial.kernels,
        args.laps,
    ) {
        eprintln!("warning: {w}");
    }
    // The game is set up (or refused) before the study is touched: nothing half-made.
    let game = match (simulator, &args.track) {
        (Simulator::Torcs, Some(track)) => {
            let game = cdbo::torcs::Game::ready()?;
            let request = game.request(track, &args.car, GamePedal::Constant(0.0))?;
            let track = super::game_track(track, &game, data)?;
            Some((game, request, track))
        }
        (Simulator::Torcs, None) => {
            return Err("--simulator torcs optimize drives the game itself: name its --track (and --car), not an --evaluator".into());
        }
        (Simulator::Cdbo, Some(_)) => {
            return Err("--track drives laps in the game: add --simulator torcs, or give an --evaluator command".into());
        }
        (Simulator::Cdbo, None) => None,
    };
    let location = Location::parse(&args.storage, args.study.as_deref())?;
    let (mut study, created) = match Study::open_at(&location) {
        Err(cdbo::Error::NoStudy { .. }) => {
            let mut config = args.initial.config()?;
            // The game's track, recorded (the dashboard re-drives trials on it).
            config.track = config.track.or_else(|| args.track.clone());
            Study::open_or_create_at(&location, config)?
        }
        opened => (opened?, false),
    };
    if !created {
        args.initial.check_resume(study.path(), study.config())?;
    }
    let worker = Worker::this_process(Duration::from_secs_f64(args.lease));
    let told_before = study.told()?;
    let mut out = std::io::stdout().lock();
    if told_before >= args.laps {
        let _ = writeln!(
            out,
            "{}: {told_before} trials told already, --laps {} is the total to reach: nothing to drive",
            study.path().display(),
            args.laps
        );
    } else {
        let _ = writeln!(
            out,
            "{}: {told_before} trials told, driving up to {} more to reach --laps {}",
            study.path().display(),
            args.laps - told_before,
            args.laps
        );
    }
    let mut evaluator: Box<dyn Evaluator> = match (game, &args.evaluator) {
        (Some((game, mut request, track)), _) => {
            request.timeout = Duration::from_secs_f64(args.timeout);
            // The study's line on its base line, held as cdbo's simulator holds it.
            request.config.line = study.config().base_line.line(&track, &request.car)?;
            request.config.steering = study.config().steering.steering();
            request.config.flying = args.flying;
            Box::new(TorcsEvaluator {
                game,
                request,
                track: Arc::new(track),
                shape: study.config().shape()?,
                target: None,
            })
        }
        (None, Some(template)) => Box::new(CommandEvaluator {
            template: template.clone(),
            timeout: Duration::from_secs_f64(args.timeout),
            files: policy_files(&location),
            shape: study.config().shape()?,
            base_line: study.config().base_line,
            steering: study.config().steering,
        }),
        (None, None) => {
            return Err("give an --evaluator command or --track (with --simulator torcs)".into());
        }
    };
    study.run(evaluator.as_mut(), &worker, args.laps, &mut |event| {
        print_event(&mut out, event)
    })?;
    let best = study.best()?;
    let _ = writeln!(
        out,
        "{}: {} trials told; best {}",
        study.path().display(),
        study.told()?,
        best.map_or("none".into(), |t| format!(
            "{} (trial {})",
            t.reward.unwrap_or_default(),
            t.id
        ))
    );
    Ok(())
}

/// The stem of the policy files written for the evaluator: beside a study file, or in the
/// temporary folder for a study in a database.
fn policy_files(location: &Location) -> PathBuf {
    match location {
        Location::Sqlite(path) => path.clone(),
        Location::Postgres { study, .. } => {
            let safe: String = study
                .chars()
                .map(|c| if c.is_alphanumeric() { c } else { '_' })
                .collect();
            std::env::temp_dir().join(format!("cdbo-study-{safe}"))
        }
    }
}

/// Prints what the lap loop reports: told trials and waits on standard output, notes on
/// standard error.
fn print_event(out: &mut impl Write, event: Event<'_>) {
    match event {
        Event::Told {
            trial,
            outcome,
            reward,
            ..
        } => {
            let note = match outcome {
                Outcome::Failed { reason, .. } => {
                    format!(" (failed: {})", reason.as_deref().unwrap_or("failed"))
                }
                _ => String::new(),
            };
            // Reported only once the result is committed: "saved" means durable.
            let _ = writeln!(out, "trial {}: reward {reward} saved{note}", trial.id);
            let _ = out.flush();
        }
        Event::Waiting => {
            let _ = writeln!(
                out,
                "waiting: the remaining trials are out with other workers"
            );
        }
        Event::Conflict { error, .. } => eprintln!("note: {error}"),
        Event::ClaimLost { trial } => {
            eprintln!("note: trial {trial}: the claim ran out and another worker took it over")
        }
        Event::HeartbeatFailed { trial, error } => {
            eprintln!("note: trial {trial}: heartbeat failed: {error}")
        }
        Event::LeftoverRemoved { path, pid } => eprintln!(
            "note: removed {}, left by process {pid} (killed while driving)",
            path.display()
        ),
    }
}
