//! `cdbo plot track`: the track map, drawn by [`crate::figures`].

use std::path::PathBuf;

use clap::{Subcommand, ValueEnum};

use super::{CliResult, load_track, value};
use crate::figures::{TrackMap, draw, read_trace_speeds};
use cdbo::car::catalog as cars;
use cdbo::data_path::DataPath;
use cdbo::line::{LineOptions, RacingLine, SAFETY_MARGIN};

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
        /// The car whose width (plus --safety-margin each side) the racing line leaves to the
        /// road's edges.
        #[arg(long, default_value = cars::DEFAULT)]
        car: String,
        /// Clearance (m) the racing line keeps between the car's side and the road's edge.
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
        car,
        safety_margin,
    } = cmd;
    let t = load_track(track, data)?;
    let speeds = match trace {
        Some(p) => Some(read_trace_speeds(p)?),
        None => None,
    };
    let racing_line = match line {
        Some(Line::MinCurvature) => {
            let car = cars::find(car, data)?;
            let options = LineOptions::for_car(&car, *safety_margin);
            Some(RacingLine::minimum_curvature(&t, &options)?)
        }
        None => None,
    };
    draw(
        output,
        &TrackMap {
            track: &t,
            speeds: speeds.as_deref(),
            line: racing_line
                .as_ref()
                .map(|l| ("minimum-curvature line", l.points.as_slice())),
        },
    )
}
