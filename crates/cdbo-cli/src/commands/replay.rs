//! `cdbo replay`: a logged lap's own commands driven through cdbo's car, window by window, to
//! say where the model and the car that drove the lap part ([`cdbo::sim::replay`]).

use std::path::PathBuf;

use clap::Args;

use super::{CliResult, Setup, print_json};
use cdbo::data_path::DataPath;
use cdbo::sim::log;
use cdbo::sim::replay::{RegimeSummary, Replay, ReplayConfig, SLIDE_ANGLE, replay};

#[derive(Debug, Args)]
pub struct ReplayArgs {
    #[command(flatten)]
    setup: Setup,
    /// The logged lap: a `cdbo lap --trace` file from either simulator, the game's log that
    /// `cdbo torcs calibrate` writes, or a real car's (the calibration log's columns, with
    /// `t_s` and `steer_rad`; `slip_angle_rad` and `gear` where known).
    #[arg(long, value_name = "LOG.csv")]
    log: PathBuf,
    /// Length of each window (s).
    #[arg(long, default_value_t = 1.0, value_parser = super::value::positive)]
    window: f64,
    /// Time between the windows' starts (s).
    #[arg(long, default_value_t = 0.5, value_parser = super::value::positive)]
    every: f64,
    /// How many of the windows where the two part most to list.
    #[arg(long, default_value_t = 10)]
    worst: usize,
    /// Print JSON: every window of every lap, and the means over all and by what the logged
    /// car did (`by_regime`).
    #[arg(long)]
    json: bool,
}

/// `--json`: one lap's replay.
#[derive(serde::Serialize)]
struct LapReplay {
    lap: i64,
    #[serde(flatten)]
    replay: Replay,
}

pub fn run(args: &ReplayArgs, data: &DataPath) -> CliResult {
    let (track, car) = args.setup.load(data)?;
    let text = cdbo::bounded::read_text(&args.log, &cdbo::bounded::TRACE_FILE)?;
    let file = args.log.display().to_string();
    let config = ReplayConfig {
        window_s: args.window,
        every_s: args.every,
    };
    let replays = log::parse(&text, &file, track.length)?
        .iter()
        .map(|lap| {
            Ok(LapReplay {
                lap: lap.lap,
                replay: replay(&track, &car, lap, &config, &file)?,
            })
        })
        .collect::<Result<Vec<_>, cdbo::Error>>()?;
    if args.json {
        return print_json(&replays);
    }
    for LapReplay { lap, replay: r } in &replays {
        println!(
            "{} on {}, lap {lap} of {file}: {} windows of {} s, one every {} s",
            car.name,
            track.name,
            r.windows.len(),
            args.window,
            args.every
        );
        println!(
            "  yaw rate {:.4} rad/s rms; at a window's end the lateral offset {:.3} m apart (mean |cdbo - log|), the speed {:+.3} m/s (mean cdbo - log)",
            r.all.yaw_rate_rms, r.all.mean_abs_lateral_m, r.all.mean_speed_error_mps
        );
        println!(
            "  by what the logged car did (past the edge, sliding past {SLIDE_ANGLE} rad, braking, driving):"
        );
        println!(
            "  | the car | windows | yaw rate rms (rad/s) | lateral, mean of abs(cdbo - log) (m) | speed, mean of cdbo - log (m/s) |"
        );
        println!("  | --- | ---: | ---: | ---: | ---: |");
        for RegimeSummary { regime, summary: s } in &r.by_regime {
            println!(
                "  | {} | {} | {:.4} | {:.3} | {:+.3} |",
                regime.name(),
                s.count,
                s.yaw_rate_rms,
                s.mean_abs_lateral_m,
                s.mean_speed_error_mps
            );
        }
        let mut worst: Vec<_> = r.windows.iter().collect();
        worst.sort_by(|a, b| b.lateral_error_m.abs().total_cmp(&a.lateral_error_m.abs()));
        worst.truncate(args.worst);
        if worst.is_empty() {
            continue;
        }
        println!("  where they part most, by the lateral offset at the window's end:");
        println!(
            "  | from (m) | t (s) | speed (m/s) | yaw rate rms (rad/s) | lateral, cdbo - log (m) | speed, cdbo - log (m/s) |"
        );
        println!("  | ---: | ---: | ---: | ---: | ---: | ---: |");
        for w in worst {
            println!(
                "  | {:.1} | {:.2} | {:.2} | {:.4} | {:+.3} | {:+.3} |",
                w.start_m,
                w.start_s,
                w.speed_mps,
                w.yaw_rate_rms,
                w.lateral_error_m,
                w.speed_error_mps
            );
        }
    }
    Ok(())
}
