//! `cdbo plot track`: the track map, drawn by [`crate::figures`].

use std::path::PathBuf;
use std::sync::Arc;

use clap::{Subcommand, ValueEnum};

use super::{CliResult, load_track, value};
use crate::figures::{TrackMap, draw, read_trace_speeds};
use cdbo::car::Car;
use cdbo::car::catalog as cars;
use cdbo::data_path::DataPath;
use cdbo::line::{LineOptions, RacingLine, SAFETY_MARGIN};
use cdbo::policy::RacedPolicy;
use cdbo::sim::Simulator;
use cdbo::track::Track;

#[derive(Debug, Subcommand)]
pub enum PlotCommand {
    /// The track map with both edges, coloured by curvature (or by speed with --trace).
    Track {
        /// Track name or file.
        track: String,
        /// Output file, .png or .svg.
        #[arg(short, long, value_name = "FILE.png|.svg")]
        output: PathBuf,
        /// A lap trace written by `cdbo lap --trace`: colour by its speed.
        #[arg(long, value_name = "FILE.csv")]
        trace: Option<PathBuf>,
        /// Draw a racing line beside the centre line (in magenta).
        #[arg(long)]
        line: Option<Line>,
        /// Draw the line a policy holds beside the centre line (in magenta): a policy file
        /// (`best_policy.json`) or a race's folder; its base line plus its learned line d(x),
        /// clamped to the road less half --car's width, as the simulator drives it.
        #[arg(long, value_name = "POLICY.json|DIR", conflicts_with = "line")]
        policy: Option<PathBuf>,
        /// The car whose width (plus --safety-margin each side) the racing line leaves to the
        /// road's edges.
        #[arg(long, default_value = cars::DEFAULT)]
        car: String,
        /// Clearance (m) the racing line keeps between the car's side and the road's edge (a
        /// metre more where the track gives no verges: laps learned there fail a metre inside it).
        #[arg(long, default_value_t = SAFETY_MARGIN, value_parser = value::non_negative)]
        safety_margin: f64,
    },
}

/// A racing line to draw.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Line {
    /// The minimum-curvature line (`cdbo limit`).
    MinCurvature,
}

pub fn run(cmd: &PlotCommand, data: &DataPath) -> CliResult {
    let PlotCommand::Track {
        track,
        output,
        trace,
        line,
        policy,
        car,
        safety_margin,
    } = cmd;
    let t = load_track(track, data)?;
    let speeds = match trace {
        Some(p) => Some(read_trace_speeds(p)?),
        None => None,
    };
    let racing_line = match (line, policy) {
        (Some(Line::MinCurvature), _) => {
            let car = cars::find(car, data)?;
            let options = LineOptions::for_track(&car, &t, *safety_margin);
            let line = RacingLine::minimum_curvature(&t, &options)?;
            Some(("minimum-curvature line".to_owned(), line.points))
        }
        (None, Some(path)) => {
            let raced = super::policy::read_raced_policy(path)?;
            let car = cars::find(car, data)?;
            let base = raced.base_line.line(&t, &car)?;
            Some(policy_line(&t, &car, base, &raced))
        }
        (None, None) => None,
    };
    draw(
        output,
        &TrackMap {
            track: &t,
            speeds: speeds.as_deref(),
            line: racing_line
                .as_ref()
                .map(|(name, points)| (name.as_str(), points.as_slice())),
        },
    )
}

/// The line `raced` holds on `track` with `car` ([`Simulator::held_line`]), `base` its base
/// line computed there, and the line's name.
pub fn policy_line(
    track: &Track,
    car: &Car,
    base: Option<Arc<RacingLine>>,
    raced: &RacedPolicy,
) -> (String, Vec<[f64; 2]>) {
    let mut sim = Simulator::new(track.clone(), car);
    sim.config.line = base;
    let points = sim
        .held_line(|x| raced.policy.line_offset(x))
        .iter()
        .map(|p| [p.x, p.y])
        .collect();
    let base = raced.base_line.name();
    let name = match &raced.policy.line {
        Some(_) => format!("learned line (from the {base} line)"),
        None => format!("{base} line the policy holds"),
    };
    (name, points)
}
