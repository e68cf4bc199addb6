//! `cdbo track info TRACK`.

use clap::Subcommand;
use serde::Serialize;

use super::{CliResult, load_track_with, print_json};
use cdbo::data_path::DataPath;
use cdbo::track::Ends;

#[derive(Debug, Subcommand)]
pub enum TrackCommand {
    /// Length, width, tightest corner and elevation of a track.
    Info {
        /// Track name or file.
        track: String,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Load a TORCS track whose end misses its start (by more than 1 m or 2°) with a
        /// warning instead of refusing it: an open track can be inspected, not raced.
        #[arg(long)]
        open: bool,
    },
}

#[derive(Debug, Serialize)]
struct Info {
    name: String,
    source: String,
    length_m: f64,
    width_m: f64,
    min_radius_m: f64,
    z_min_m: f64,
    z_max_m: f64,
    closure_gap_m: f64,
    closure_heading_deg: f64,
}

pub fn run(cmd: &TrackCommand, data: &DataPath) -> CliResult {
    let TrackCommand::Info { track, json, open } = cmd;
    let ends = if *open { Ends::MayMiss } else { Ends::MustMeet };
    let t = load_track_with(track, data, ends)?;
    let (z_min_m, z_max_m) = t.z_range();
    let info = Info {
        name: t.name.clone(),
        source: t.source.clone(),
        length_m: t.length,
        width_m: t.min_width(),
        min_radius_m: t.min_radius(),
        z_min_m,
        z_max_m,
        closure_gap_m: t.closure.gap_m,
        closure_heading_deg: t.closure.heading_deg,
    };
    if *json {
        return print_json(&info);
    }
    println!("{} ({})", info.name, info.source);
    println!("  length      {:>9.2} m", info.length_m);
    println!("  width       {:>9.2} m", info.width_m);
    println!("  min radius  {:>9.2} m", info.min_radius_m);
    println!(
        "  elevation   {:>9.2} .. {:.2} m",
        info.z_min_m, info.z_max_m
    );
    println!(
        "  closure     {:>9.3} m, {:.3}°",
        info.closure_gap_m, info.closure_heading_deg
    );
    Ok(())
}
