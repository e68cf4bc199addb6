//! `cdbo limit`: the quasi-steady-state minimum lap time on the centre line (the reference of
//! every "% of the limit") and on the minimum-curvature racing line.

use std::time::Instant;

use clap::Args;
use serde::Serialize;

use super::{CliResult, Setup, print_json, value};
use cdbo::data_path::DataPath;
use cdbo::limit::{Limit, LineLimit, limit_lap, line_limit};
use cdbo::line::{LineOptions, RacingLine, SAFETY_MARGIN};

#[derive(Debug, Args)]
pub struct LimitArgs {
    #[command(flatten)]
    setup: Setup,
    /// Clearance (m) the racing line keeps between the car's side and the road's edge (a
    /// metre more where the track gives no verges: laps learned there fail a metre inside it).
    #[arg(long, default_value_t = SAFETY_MARGIN, value_parser = value::non_negative)]
    safety_margin: f64,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// `--json`: the centre line's limit at the top level, the racing line's beside it.
#[derive(Serialize)]
struct Report {
    #[serde(flatten)]
    centre_line: Limit,
    /// The centre line's length (m): both rewards are this over their lap time.
    track_length_m: f64,
    min_curvature_line: LineLimit,
}

pub fn run(args: &LimitArgs, data: &DataPath) -> CliResult {
    let (track, car) = args.setup.load(data)?;
    let centre = limit_lap(&track, &car);
    let start = Instant::now();
    let line = RacingLine::minimum_curvature(
        &track,
        &LineOptions::for_track(&car, &track, args.safety_margin),
    )?;
    let on_line = line_limit(&track, &line, &car);
    let ms = start.elapsed().as_secs_f64() * 1e3;
    if args.json {
        return print_json(&Report {
            centre_line: centre,
            track_length_m: track.length,
            min_curvature_line: on_line,
        });
    }
    println!(
        "{} on {} ({:.1} m): limit lap {:.2} s, {:.2} m/s ({:.1} km/h) on the centre line",
        car.name,
        track.name,
        track.length,
        centre.lap_time_s,
        centre.reward_mps,
        centre.reward_mps * 3.6
    );
    let l = &on_line.limit;
    println!(
        "minimum-curvature line ({:.1} m, up to {:.2} m off the centre, {:.2} m from the edges): limit lap {:.2} s, {:.2} m/s ({:.1} km/h), {:+.1} % ({} QPs and the lap in {ms:.0} ms)",
        on_line.line_length_m,
        on_line.max_offset_m,
        on_line.margin_m,
        l.lap_time_s,
        l.reward_mps,
        l.reward_mps * 3.6,
        100.0 * (l.reward_mps / centre.reward_mps - 1.0),
        on_line.iterations,
    );
    println!(
        "Both speeds are the centre line's length over the lap time; every \"% of the limit\" cdbo reports is of the centre-line limit."
    );
    Ok(())
}
