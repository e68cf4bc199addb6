//! `cdbo torcs panel`: cdbo's simulator scored again against the game's laps that `cdbo torcs
//! compare` kept (panel_TRACK.jsonl), without the game ([`cdbo::torcs::panel`]).

use std::collections::BTreeMap;
use std::path::PathBuf;

use clap::Args;
use rayon::prelude::*;

use super::{CliResult, load_track, print_json};
use cdbo::car::catalog as cars;
use cdbo::data_path::DataPath;
use cdbo::torcs::panel::{self, Outcome, PanelLap, Score};
use cdbo::venue::Venue;

#[derive(Debug, Args)]
pub struct PanelArgs {
    /// Panels written by `cdbo torcs compare` (OUT/panel_TRACK.jsonl).
    #[arg(required = true, value_name = "PANEL.jsonl")]
    panels: Vec<PathBuf>,
    /// The car cdbo's simulator drives: the game's by name, or a calibrated car (car.toml).
    #[arg(long, default_value = cdbo::torcs::DEFAULT_CAR)]
    car: String,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &PanelArgs, data: &DataPath) -> CliResult {
    // The data folders end with the game's install folder, where its tracks and cars are.
    let car = cars::find(&args.car, data)?;
    let mut by_track: BTreeMap<String, Vec<PanelLap>> = BTreeMap::new();
    for path in &args.panels {
        let text = cdbo::bounded::read_text(path, &cdbo::bounded::TRACE_FILE)?;
        for lap in panel::parse(&text, &path.display().to_string())? {
            by_track.entry(lap.track.clone()).or_default().push(lap);
        }
    }
    let mut scores = Vec::new();
    for (name, laps) in &by_track {
        let venue = Venue::simulator(load_track(name, data)?, &car);
        let ours = laps
            .par_iter()
            .map(|l| venue.drive(&l.policy).map(|lap| Outcome::of(&lap)))
            .collect::<Result<Vec<_>, _>>()?;
        scores.push(panel::score(name, &laps.iter().collect::<Vec<_>>(), &ours));
    }
    if args.json {
        return print_json(&scores);
    }
    println!("{} against the game's laps ({}):", car.name, args.car);
    println!();
    println!(
        "| track | laps | agree | cdbo fails, TORCS completes | TORCS fails, cdbo completes | lap-time error (mean / bias) |"
    );
    println!("| --- | ---: | ---: | ---: | ---: | ---: |");
    let percent = |v: Option<f64>| v.map_or("–".into(), |v| format!("{:+.2} %", 100.0 * v));
    for s in &scores {
        println!(
            "| {} | {} | {} ({:.1} %) | {} | {} | {} / {} |",
            s.track,
            s.laps,
            s.agree,
            100.0 * s.agree as f64 / s.laps as f64,
            s.cdbo_fails,
            s.torcs_fails,
            percent(s.lap_time_error_mean).trim_start_matches('+'),
            percent(s.lap_time_bias)
        );
    }
    let (agree, laps) = scores
        .iter()
        .fold((0, 0), |(a, n), s: &Score| (a + s.agree, n + s.laps));
    println!();
    println!(
        "all: {agree} of {laps} ({:.2} %); {} of {} tracks at 95 % or more",
        100.0 * agree as f64 / laps.max(1) as f64,
        scores
            .iter()
            .filter(|s| s.agree as f64 >= 0.95 * s.laps as f64)
            .count(),
        scores.len()
    );
    Ok(())
}
