//! `cdbo policy fit` and `cdbo policy table`: the paper's RKHS policies as files.

use std::path::{Path, PathBuf};

use clap::Subcommand;

use super::CliResult;
use cdbo::bounded;
use cdbo::policy::RacedPolicy;
use cdbo::policy::rkhs::{DEFAULT_RIDGE, default_lengthscale};
use cdbo::policy::{Policy, RkhsPolicy};

#[derive(Debug, Subcommand)]
pub enum PolicyCommand {
    /// Fit w₀ to a demonstration's (x, a) pairs by ridge regression (paper eq. 9).
    Fit {
        /// CSV rows `x,a` (a header line is skipped), e.g. from `cdbo lap --trace` columns.
        #[arg(long, value_name = "FILE.csv")]
        demo: PathBuf,
        /// Number of kernels M.
        #[arg(long, value_parser = super::value::kernels)]
        kernels: usize,
        /// Kernel length-scale (default 1/(M − 1)).
        #[arg(long, allow_negative_numbers = true, value_parser = super::value::positive)]
        lengthscale: Option<f64>,
        /// Ridge factor λ.
        #[arg(long, default_value_t = DEFAULT_RIDGE, allow_negative_numbers = true, value_parser = super::value::non_negative)]
        ridge: f64,
        /// Output weights (JSON).
        #[arg(short, long, value_name = "FILE.json")]
        output: PathBuf,
    },
    /// Print a policy's (x, a) table as CSV (x, a, d with a line: its offset d(x) in metres).
    Table {
        /// Weights written by `cdbo policy fit` (JSON).
        weights: PathBuf,
        /// Points in the table.
        #[arg(long, default_value_t = 101, value_parser = super::value::points)]
        points: usize,
    },
}

pub fn run(cmd: &PolicyCommand) -> CliResult {
    match cmd {
        PolicyCommand::Fit {
            demo,
            kernels,
            lengthscale,
            ridge,
            output,
        } => {
            let pairs = read_demo(demo)?;
            let l = lengthscale.unwrap_or_else(|| default_lengthscale(*kernels));
            let policy = RkhsPolicy::fit(&pairs, *kernels, l, *ridge)
                .map_err(|e| format!("{}: {e}", demo.display()))?;
            std::fs::write(output, serde_json::to_string_pretty(&policy)?)
                .map_err(|e| format!("{}: {e}", output.display()))?;
            let rms = (pairs
                .iter()
                .map(|(x, a)| (policy.action(*x) - a).powi(2))
                .sum::<f64>()
                / pairs.len() as f64)
                .sqrt();
            eprintln!(
                "fitted {kernels} kernels (l = {l:.4}) to {} pairs, rms error {rms:.4}: {}",
                pairs.len(),
                output.display()
            );
            Ok(())
        }
        PolicyCommand::Table { weights, points } => {
            let policy = read_policy(weights)?;
            if policy.line.is_some() {
                println!("x,a,d");
                for (x, a, d) in policy.table(*points) {
                    println!("{x:.6},{a:.6},{d:.6}");
                }
            } else {
                println!("x,a");
                for (x, a, _) in policy.table(*points) {
                    println!("{x:.6},{a:.6}");
                }
            }
            Ok(())
        }
    }
}

/// Reads a policy written by `cdbo policy fit` or `cdbo race` (a one-action policy is the
/// paper's file; a line adds its own block).
pub fn read_policy(path: &Path) -> Result<Policy, Box<dyn std::error::Error>> {
    let text = bounded::read_text(path, &bounded::POLICY_FILE)?;
    Ok(Policy::from_json(&text, &path.display().to_string())?)
}

/// Reads a policy with the base line it was raced on ([`RacedPolicy`]): from a policy file, or
/// a race's folder (its `best_policy.json`). A file that does not name its base line (written
/// before it was stored) takes the one of the `summary.json` beside it, where a race wrote
/// one; else it is on the centre line.
pub fn read_raced_policy(path: &Path) -> Result<RacedPolicy, Box<dyn std::error::Error>> {
    let file = if path.is_dir() {
        path.join("best_policy.json")
    } else {
        path.to_owned()
    };
    let text = bounded::read_text(&file, &bounded::POLICY_FILE)?;
    let mut raced = RacedPolicy::from_json(&text, &file.display().to_string())?;
    let names_base = serde_json::from_str::<serde_json::Value>(&text)
        .is_ok_and(|v| v.get("base_line").is_some());
    let summary = file.with_file_name("summary.json");
    if !names_base && summary.is_file() {
        #[derive(serde::Deserialize)]
        struct Raced {
            #[serde(default)]
            base_line: cdbo::line::BaseLine,
        }
        let text = bounded::read_text(&summary, &bounded::POLICY_FILE)?;
        let raced_on: Raced = serde_json::from_str(&text)
            .map_err(|e| format!("{}: not a race's summary: {e}", summary.display()))?;
        raced.base_line = raced_on.base_line;
    }
    Ok(raced)
}

/// Reads a demonstration's (x, a) pairs ([`cdbo::policy::demo`]).
pub fn read_demo(path: &Path) -> Result<Vec<(f64, f64)>, Box<dyn std::error::Error>> {
    let text = bounded::read_text(path, &bounded::DEMO_FILE)?;
    Ok(cdbo::policy::demo::parse(
        &text,
        &path.display().to_string(),
    )?)
}
