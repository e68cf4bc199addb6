//! `cdbo plot track`: the track map, drawn by [`crate::figures`].

use std::path::PathBuf;

use clap::Subcommand;

use super::{CliResult, load_track};
use crate::figures::{TrackMap, draw, read_trace_speeds};
use cdbo::data_path::DataPath;

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
    },
}

pub fn run(cmd: &PlotCommand, data: &DataPath) -> CliResult {
    let PlotCommand::Track {
        track,
        output,
        trace,
    } = cmd;
    let t = load_track(track, data)?;
    let speeds = match trace {
        Some(p) => Some(read_trace_speeds(p)?),
        None => None,
    };
    draw(
        output,
        &TrackMap {
            track: &t,
            speeds: speeds.as_deref(),
        },
    )
}
