//! `cdbo optimize`: optimise with an external lap evaluator, every lap saved to a study so that
//! an interrupted run resumes where it stopped.

use std::io::Write;
use std::path::PathBuf;
use std::time::Duration;

use clap::Args;

use super::CliResult;
use super::study::InitialPolicy;
use cdbo::evaluator::Evaluator;
use cdbo::evaluator::command::CommandEvaluator;
use cdbo::study::{Outcome, Study};

#[derive(Debug, Args)]
pub struct OptimizeArgs {
    /// The lap command, run by `sh -c`, with {policy} where the policy file's path goes; it
    /// prints the reward (a number or JSON with "reward").
    #[arg(long, value_name = "CMD")]
    evaluator: String,
    /// Trials to reach in the study (counting those already told).
    #[arg(long)]
    laps: usize,
    /// Study file: created on the first run (with --demo or --weights), resumed afterwards.
    #[arg(long, value_name = "FILE")]
    db: PathBuf,
    /// Seconds a lap may take before it counts as failed.
    #[arg(long, default_value_t = 600.0)]
    timeout: f64,
    #[command(flatten)]
    initial: InitialPolicy,
}

pub fn run(args: &OptimizeArgs) -> CliResult {
    if !(args.timeout.is_finite() && args.timeout > 0.0) {
        return Err(format!(
            "--timeout {}: must be a positive number of seconds",
            args.timeout
        )
        .into());
    }
    let mut study = if args.db.exists() {
        let s = Study::open(&args.db)?;
        if s.config().kernels != args.initial.kernels {
            return Err(format!(
                "{}: the study has {} kernels, not {}",
                args.db.display(),
                s.config().kernels,
                args.initial.kernels
            )
            .into());
        }
        s
    } else {
        Study::create(&args.db, args.initial.config()?)?
    };
    let mut evaluator = CommandEvaluator {
        template: args.evaluator.clone(),
        timeout: Duration::from_secs_f64(args.timeout),
        policy_file: PathBuf::new(),
        lengthscale: study.config().lengthscale,
    };
    let mut out = std::io::stdout().lock();
    loop {
        if study.told()? >= args.laps {
            break;
        }
        let trial = study.ask()?;
        // One file per trial and process: two processes on one study may drive the same
        // trial at once, and neither may read the other's half-written file.
        evaluator.policy_file = PathBuf::from(format!(
            "{}.trial-{}.pid-{}.json",
            args.db.display(),
            trial.id,
            std::process::id()
        ));
        let outcome = evaluator.evaluate(&trial.weights);
        let _ = std::fs::remove_file(&evaluator.policy_file);
        let outcome = outcome?;
        let reward = match study.tell(trial.id, &outcome) {
            Ok(r) => r,
            // Another process on the same study told this trial first: go on from there.
            Err(cdbo::Error::Conflict(msg)) => {
                eprintln!("note: {msg}");
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
        "{}: {} trials; best {}",
        args.db.display(),
        args.laps,
        best.map_or("none".into(), |t| format!(
            "{} (trial {})",
            t.reward.unwrap_or_default(),
            t.id
        ))
    );
    Ok(())
}
