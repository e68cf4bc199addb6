//! `cdbo serve-sim`: the simulator as a JSON-lines service, so that any optimiser in any
//! language can race on our tracks. Each input line is answered by one output line:
//! - `{"info": true}` → `{"dim", "w0", "lower", "upper", "lengthscale", "track", "length_m",
//!   "limit_reward_mps"}`,
//! - `{"weights": [...]}` → `{"reward_mps", "lap_time_s", "failure"}`,
//! - anything else → `{"error": "..."}` (the service keeps going).

use std::io::{BufRead, Write};

use clap::Args;
use serde_json::{Value, json};

use super::{CliResult, Setup};
use cdbo::data_path::DataPath;
use cdbo::experiment::race::demonstrate;
use cdbo::optimizers::{DEFAULT_BOX_RADIUS, SearchBox};
use cdbo::policy::RkhsPolicy;
use cdbo::policy::rkhs::{DEFAULT_RIDGE, default_lengthscale};
use cdbo::sim::Simulator;

#[derive(Debug, Args)]
pub struct ServeSimArgs {
    #[command(flatten)]
    setup: Setup,
    /// Policy kernels M.
    #[arg(long)]
    kernels: usize,
    /// Speed of the demonstrator whose fit is w₀ (m/s).
    #[arg(long, default_value_t = 15.0)]
    demo_speed: f64,
}

pub fn run(args: &ServeSimArgs, data: &DataPath) -> CliResult {
    let (track, car) = args.setup.load(data)?;
    let limit = cdbo::limit::limit_lap(&track, &car);
    let sim = Simulator::new(track, &car);
    let (_, demo) = demonstrate(&sim, args.demo_speed);
    let lengthscale = default_lengthscale(args.kernels);
    let w0 = RkhsPolicy::fit(&demo, args.kernels, lengthscale, DEFAULT_RIDGE)?;
    let bounds = SearchBox::around(&w0.weights, DEFAULT_BOX_RADIUS)?;
    let info = json!({
        "dim": args.kernels,
        "w0": w0.weights,
        "lower": bounds.lower,
        "upper": bounds.upper,
        "lengthscale": lengthscale,
        "track": sim.track.name,
        "length_m": sim.track.length,
        "limit_reward_mps": limit.reward_mps,
    });
    let stdin = std::io::stdin();
    let mut out = std::io::stdout().lock();
    for (k, line) in stdin.lock().lines().enumerate() {
        let line = line?;
        if line.trim().is_empty() {
            continue;
        }
        let answer = answer(&line, &info, &sim, lengthscale, args.kernels)
            .unwrap_or_else(|e| json!({ "error": format!("line {}: {e}", k + 1) }));
        if writeln!(out, "{answer}").and_then(|_| out.flush()).is_err() {
            break; // The client hung up.
        }
    }
    Ok(())
}

fn answer(
    line: &str,
    info: &Value,
    sim: &Simulator,
    lengthscale: f64,
    dim: usize,
) -> Result<Value, String> {
    let v: Value = serde_json::from_str(line).map_err(|e| format!("not JSON: {e}"))?;
    if v.get("info").and_then(Value::as_bool) == Some(true) {
        return Ok(info.clone());
    }
    let Some(ws) = v.get("weights").and_then(Value::as_array) else {
        return Err(r#"expected {"weights": [...]} or {"info": true}"#.into());
    };
    let weights: Vec<f64> = ws
        .iter()
        .enumerate()
        .map(|(i, w)| w.as_f64().ok_or(format!("weight {i} is not a number: {w}")))
        .collect::<Result<_, _>>()?;
    if weights.len() != dim {
        return Err(format!("expected {dim} weights, got {}", weights.len()));
    }
    let policy = RkhsPolicy::new(weights, lengthscale).map_err(|e| e.to_string())?;
    let lap = sim.lap(&mut policy.pedal());
    Ok(json!({
        "reward_mps": lap.reward_mps,
        "lap_time_s": lap.lap_time_s,
        "failure": lap.failure.map(|f| json!({
            "reason": f.reason.name(),
            "x": f.x,
            "distance_m": f.distance_m,
        })),
    }))
}
