//! `cdbo bench sim`: simulator throughput on one core.

use clap::{Args, Subcommand};
use serde::Serialize;

use super::{CliResult, Setup, print_json};
use cdbo::data_path::DataPath;
use cdbo::drive::demo::{DEFAULT_TARGET_SPEED, SpeedHold};
use cdbo::sim::Simulator;

#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Laps of the 15 m/s demonstrator on one thread: simulated time over wall time.
    Sim(SimArgs),
}

#[derive(Debug, Args)]
pub struct SimArgs {
    #[command(flatten)]
    setup: Setup,
    /// Number of laps.
    #[arg(long, default_value_t = 10)]
    laps: usize,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, Serialize)]
struct SimBench {
    track: String,
    laps: usize,
    simulated_s: f64,
    wall_s: f64,
    realtime_factor: f64,
    laps_per_s: f64,
}

pub fn run(cmd: &BenchCommand, data: &DataPath) -> CliResult {
    let BenchCommand::Sim(args) = cmd;
    if args.laps == 0 {
        return Err("--laps must be at least 1".into());
    }
    let (track, car) = args.setup.load(data)?;
    let sim = Simulator::new(track, &car);
    sim.lap(&mut SpeedHold::new(DEFAULT_TARGET_SPEED)); // warm-up
    let start = std::time::Instant::now();
    let simulated_s: f64 = (0..args.laps)
        .map(|_| {
            sim.lap(&mut SpeedHold::new(DEFAULT_TARGET_SPEED))
                .simulated_s
        })
        .sum();
    let wall_s = start.elapsed().as_secs_f64();
    let b = SimBench {
        track: sim.track.name.clone(),
        laps: args.laps,
        simulated_s,
        wall_s,
        realtime_factor: simulated_s / wall_s,
        laps_per_s: args.laps as f64 / wall_s,
    };
    if args.json {
        return print_json(&b);
    }
    println!(
        "{}: {} laps, {:.1} s simulated in {:.3} s wall: {:.0}x real time, {:.1} laps/s (one thread)",
        b.track, b.laps, b.simulated_s, b.wall_s, b.realtime_factor, b.laps_per_s
    );
    Ok(())
}
