//! `cdbo limit`: the quasi-steady-state minimum lap time.

use clap::Args;

use super::{CliResult, Setup, print_json};
use cdbo::data_path::DataPath;
use cdbo::limit::limit_lap;

#[derive(Debug, Args)]
pub struct LimitArgs {
    #[command(flatten)]
    setup: Setup,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &LimitArgs, data: &DataPath) -> CliResult {
    let (track, car) = args.setup.load(data)?;
    let limit = limit_lap(&track, &car);
    if args.json {
        return print_json(&limit);
    }
    println!(
        "{} on {} ({:.1} m): limit lap {:.2} s, {:.2} m/s ({:.1} km/h)",
        car.name,
        track.name,
        track.length,
        limit.lap_time_s,
        limit.reward_mps,
        limit.reward_mps * 3.6
    );
    Ok(())
}
