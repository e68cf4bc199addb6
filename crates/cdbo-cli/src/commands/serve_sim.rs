//! `cdbo serve-sim`: the simulator as a JSON-lines service, so that any optimiser in any
//! language can race on our tracks. Each input line is answered by one output line:
//! - `{"info": true}` → `{"dim", "w0", "lower", "upper", "lengthscale", "track", "length_m",
//!   "limit_reward_mps"}`,
//! - `{"weights": [...]}` → `{"reward_mps", "lap_time_s", "failure"}`,
//! - anything else → `{"error": "..."}` naming the line and what was wrong: not UTF-8, longer
//!   than [`MAX_LINE_BYTES`], not JSON, wrong types, a wrong number of weights, a weight that
//!   is not a finite number. The service keeps answering the next line.

use std::io::{BufRead, Read, Write};

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
    #[arg(long, value_parser = super::value::kernels)]
    kernels: usize,
    /// Speed of the demonstrator whose fit is w₀ (m/s).
    #[arg(long, default_value_t = 15.0, allow_negative_numbers = true, value_parser = super::value::positive)]
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
    let mut input = std::io::stdin().lock();
    let mut out = std::io::stdout().lock();
    let mut line = Vec::new();
    for k in 1.. {
        let Some(read) = read_line(&mut input, &mut line)? else {
            break;
        };
        let answer = match read {
            Line::TooLong => Err(format!(
                "longer than {MAX_LINE_BYTES} bytes (the cap on a request line); skipped"
            )),
            Line::Complete => match std::str::from_utf8(&line) {
                Err(e) => Err(format!("not UTF-8 text: {e}")),
                Ok(text) if text.trim().is_empty() => continue,
                Ok(text) => answer(text, &info, &sim, lengthscale, args.kernels),
            },
        };
        let answer = answer.unwrap_or_else(|e| json!({ "error": format!("line {k}: {e}") }));
        if writeln!(out, "{answer}").and_then(|_| out.flush()).is_err() {
            break; // The client hung up.
        }
    }
    Ok(())
}

/// The longest request line: 1 MiB, forty times the 1000 weights of the largest policy.
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// How a line was read.
enum Line {
    /// Whole, in the buffer (without its newline).
    Complete,
    /// Over [`MAX_LINE_BYTES`]: read to its end and dropped.
    TooLong,
}

/// Reads the next line as bytes into `line`, never holding more than the cap; `None` at the
/// end of the input.
fn read_line(input: &mut impl BufRead, line: &mut Vec<u8>) -> std::io::Result<Option<Line>> {
    line.clear();
    let cap = MAX_LINE_BYTES as u64 + 1;
    let n = input.by_ref().take(cap).read_until(b'\n', line)?;
    if n == 0 {
        return Ok(None);
    }
    if line.last() == Some(&b'\n') {
        line.pop();
        return Ok(Some(Line::Complete));
    }
    if line.len() <= MAX_LINE_BYTES {
        return Ok(Some(Line::Complete)); // The last line, without a newline.
    }
    // Drop the rest of the over-long line, a buffer at a time.
    loop {
        line.clear();
        let n = input.by_ref().take(cap).read_until(b'\n', line)?;
        if n == 0 || line.last() == Some(&b'\n') {
            line.clear();
            return Ok(Some(Line::TooLong));
        }
    }
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
