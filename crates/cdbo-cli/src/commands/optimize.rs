//! `cdbo optimize`: optimise with an external lap evaluator, every lap saved to a study so that
//! an interrupted run resumes where it stopped.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Duration;

use clap::Args;

use super::CliResult;
use super::study::InitialPolicy;
use cdbo::evaluator::Evaluator;
use cdbo::evaluator::command::CommandEvaluator;
use cdbo::study::claim::{DEFAULT_LEASE, Worker, process_exists};
use cdbo::study::{Next, Outcome, Study};

#[derive(Debug, Args)]
pub struct OptimizeArgs {
    /// The lap command, run by `sh -c`, with {policy} where the policy file's path goes; it
    /// prints the reward (a number or JSON with "reward").
    #[arg(long, value_name = "CMD")]
    evaluator: String,
    /// Trials the study should have told when this run ends: a total, counting those already
    /// told (a study with 31 told trials and --laps 40 drives 9 more; with --laps 5, none).
    #[arg(long, value_parser = super::value::total_laps)]
    laps: usize,
    /// Study file: created on the first run (with --demo or --weights), resumed afterwards.
    #[arg(long, value_name = "FILE")]
    db: PathBuf,
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

pub fn run(args: &OptimizeArgs) -> CliResult {
    let (mut study, created) = if args.db.exists() {
        (Study::open(&args.db)?, false)
    } else {
        Study::open_or_create(&args.db, args.initial.config()?)?
    };
    if !created {
        args.initial.check_resume(&args.db, study.config())?;
    }
    remove_leftover_policy_files(&args.db);
    let worker = Worker::this_process(Duration::from_secs_f64(args.lease));
    let told_before = study.told()?;
    let mut out = std::io::stdout().lock();
    if told_before >= args.laps {
        let _ = writeln!(
            out,
            "{}: {told_before} trials told already, --laps {} is the total to reach: nothing to drive",
            args.db.display(),
            args.laps
        );
    } else {
        let _ = writeln!(
            out,
            "{}: {told_before} trials told, driving up to {} more to reach --laps {}",
            args.db.display(),
            args.laps - told_before,
            args.laps
        );
    }
    let mut evaluator = CommandEvaluator {
        template: args.evaluator.clone(),
        timeout: Duration::from_secs_f64(args.timeout),
        policy_file: PathBuf::new(),
        lengthscale: study.config().lengthscale,
    };
    let poll = worker
        .heartbeat_interval()
        .clamp(Duration::from_millis(100), Duration::from_secs(1));
    let mut waiting = false;
    loop {
        let trial = match study.claim(&worker, Some(args.laps))? {
            Next::Done => break,
            Next::Wait => {
                if !waiting {
                    let _ = writeln!(
                        out,
                        "waiting: the remaining trials are out with other workers"
                    );
                    waiting = true;
                }
                std::thread::sleep(poll);
                continue;
            }
            Next::Drive(t) => t,
        };
        waiting = false;
        // One file per trial and process, so that no worker reads another's half-written file.
        evaluator.policy_file = policy_file(&args.db, trial.id, std::process::id());
        let outcome = with_heartbeat(&args.db, &worker, trial.id, || {
            evaluator.evaluate(&trial.weights)
        });
        let _ = std::fs::remove_file(&evaluator.policy_file);
        let outcome = outcome?;
        let reward = match study.tell(trial.id, &outcome) {
            Ok(r) => r,
            // Another worker told this trial first (ours had lost its lease): go on.
            Err(e @ cdbo::Error::Conflict { .. }) => {
                eprintln!("note: {e}");
                continue;
            }
            Err(e) => return Err(e.into()),
        };
        let note = match &outcome {
            Outcome::Failed { reason, .. } => {
                format!(" (failed: {})", reason.as_deref().unwrap_or("failed"))
            }
            _ => String::new(),
        };
        // Printed only once the result is committed: "saved" means durable.
        let _ = writeln!(out, "trial {}: reward {reward} saved{note}", trial.id);
        let _ = out.flush();
    }
    let best = study.best()?;
    let _ = writeln!(
        out,
        "{}: {} trials told; best {}",
        args.db.display(),
        study.told()?,
        best.map_or("none".into(), |t| format!(
            "{} (trial {})",
            t.reward.unwrap_or_default(),
            t.id
        ))
    );
    Ok(())
}

/// Where trial `id`'s policy is written for the evaluator, by process `pid`.
fn policy_file(db: &Path, id: i64, pid: u32) -> PathBuf {
    PathBuf::from(format!("{}.trial-{id}.pid-{pid}.json", db.display()))
}

/// Removes the policy files of processes that no longer exist (killed while driving); a live
/// worker's file stays.
fn remove_leftover_policy_files(db: &Path) {
    let Some(name) = db.file_name().map(|n| n.to_string_lossy().into_owned()) else {
        return;
    };
    let folder = match db.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
        _ => PathBuf::from("."),
    };
    let Ok(entries) = std::fs::read_dir(&folder) else {
        return;
    };
    let prefix = format!("{name}.trial-");
    for entry in entries.flatten() {
        let file = entry.file_name().to_string_lossy().into_owned();
        let Some(rest) = file
            .strip_prefix(&prefix)
            .and_then(|r| r.strip_suffix(".json"))
        else {
            continue;
        };
        let pid = rest
            .split_once(".pid-")
            .and_then(|(_, p)| p.parse::<u32>().ok());
        if let Some(pid) = pid.filter(|p| *p != std::process::id() && !process_exists(*p)) {
            if std::fs::remove_file(entry.path()).is_ok() {
                eprintln!(
                    "note: removed {}, left by process {pid} (killed while driving)",
                    entry.path().display()
                );
            }
        }
    }
}

/// Runs `drive` while a thread renews the worker's claim on trial `id` every heartbeat
/// interval, through its own connection to the study.
fn with_heartbeat<T>(db: &Path, worker: &Worker, id: i64, drive: impl FnOnce() -> T) -> T {
    let stop = std::sync::atomic::AtomicBool::new(false);
    std::thread::scope(|scope| {
        let beat = scope.spawn(|| {
            let Ok(study) = Study::open(db) else { return };
            loop {
                std::thread::park_timeout(worker.heartbeat_interval());
                if stop.load(std::sync::atomic::Ordering::Acquire) {
                    return;
                }
                match study.heartbeat(id, worker) {
                    Ok(true) => {}
                    Ok(false) => {
                        eprintln!(
                            "note: trial {id}: the claim ran out and another worker took it over"
                        );
                        return;
                    }
                    Err(e) => eprintln!("note: trial {id}: heartbeat failed: {e}"),
                }
            }
        });
        let result = drive();
        stop.store(true, std::sync::atomic::Ordering::Release);
        beat.thread().unpark();
        result
    })
}
