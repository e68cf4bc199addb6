//! `cdbo torcs learn`: from a track to a race-ready policy in one command. cdbo's simulator
//! first (the ceiling's policy: the limit's speed profile tracked on the minimum-curvature line
//! and fitted with M, 2M and 4M kernels, or 50 m apart on a long track, the fastest fit kept;
//! where no fit completes, the recommended learner's best), then a bounded number of laps of
//! the recommended learner in the game from it (as many again from the next fastest fit where
//! none of them completes), the result beside the fastest shipped robot's laps on that track.

use std::cmp::Ordering;
use std::path::PathBuf;

use clap::Args;
use serde::Serialize;

use super::torcs::robots_on;
use super::{CliResult, game_track, print_json};
use cdbo::data_path::DataPath;
use cdbo::experiment::race::{BaseLine, RaceConfig, race};
use cdbo::method::Preset;
use cdbo::policy::{Policy, RacedPolicy};
use cdbo::sizes;
use cdbo::torcs::{self, Game, GamePedal};
use cdbo::venue::Venue;

#[derive(Debug, Args)]
pub struct LearnArgs {
    /// TORCS track names, comma-separated, or `road` for every road track installed.
    #[arg(long, default_value = "forza", value_delimiter = ',')]
    track: Vec<String>,
    /// TORCS car name.
    #[arg(long, default_value = torcs::DEFAULT_CAR)]
    car: String,
    /// Policy kernels M: the ceiling's policy is fitted with M, 2M and 4M kernels (at most
    /// 200, the pattern search's), and with kernels 50 m apart where the finest of those lie
    /// further apart; the fastest fit in cdbo's simulator is learned on (a finer one where a
    /// track's corners are closer together than M kernels brake for).
    #[arg(long, default_value_t = 50, value_parser = super::value::kernels)]
    kernels: usize,
    /// Laps of the recommended learner in the game, after cdbo's simulator (the game also
    /// drives one demonstration lap first, and the best policy's standing and flying laps at
    /// the end); where none of them completes, as many again from the next fastest fit.
    #[arg(long, default_value_t = 30, value_parser = super::value::laps)]
    game_laps: usize,
    /// Learn the flying lap (the second of two from the standing start, line to line)
    /// rather than the standing lap, in both simulators.
    #[arg(long)]
    flying: bool,
    /// Seed of every random choice.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Folder for each track's race-ready policy, TRACK.json (default: runs/torcs-learn).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// One track's way from cdbo's simulator to the game, and the robots beside it.
#[derive(Debug, Serialize)]
struct TrackResult {
    track: String,
    /// Where the game's laps started from: `ceiling` or `recommended learner`.
    start: &'static str,
    /// The policy's kernels.
    kernels: usize,
    /// The starting policy's lap in cdbo's simulator (s).
    sim_lap_s: Option<f64>,
    /// Faster fits learned from first, none of whose game laps completed.
    fits_before: usize,
    /// The game's laps of the learner (the demonstration not counted), and how many failed.
    game_laps: usize,
    game_failed_laps: usize,
    /// The best policy's standing and flying laps in the game, driven again (s).
    standing_lap_s: Option<f64>,
    flying_lap_s: Option<f64>,
    /// The fastest shipped robot's standing lap and best (flying) lap, with its name.
    robot_standing: Option<(String, f64)>,
    robot_flying: Option<(String, f64)>,
    /// The race-ready policy's file.
    policy: String,
}

pub fn run(args: &LearnArgs, data: &DataPath) -> CliResult {
    let game = Game::ready()?;
    let tracks: Vec<String> = if args.track.iter().any(|t| t == "road") {
        game.install.tracks("road")
    } else {
        args.track.clone()
    };
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("runs/torcs-learn"));
    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut results = Vec::new();
    for track in &tracks {
        let result = learn_on(&game, track, args, data, &out)?;
        if !args.json {
            eprintln!(
                "{track}: game's best standing lap {}, flying {}",
                cell(result.standing_lap_s),
                cell(result.flying_lap_s)
            );
        }
        results.push(result);
    }
    if args.json {
        return print_json(&results);
    }
    print!("{}", markdown(&results, args));
    Ok(())
}

/// The finer policies the ceiling is also fitted with: 2M and 4M kernels, as many as the
/// pattern search pushes ([`MAX_KERNELS`](cdbo::learner::pattern_search::push::MAX_KERNELS)),
/// and, on a track so long that the finest of them lies more than [`FINEST_SPACING_M`] apart,
/// one with its kernels that far apart (learned on in the game without pushes).
fn finer_kernels(kernels: usize, track_length: f64) -> Vec<usize> {
    let mut finer: Vec<usize> = [2 * kernels, 4 * kernels]
        .into_iter()
        .filter(|&m| m <= cdbo::learner::pattern_search::push::MAX_KERNELS)
        .collect();
    let finest = finer.last().copied().unwrap_or(kernels);
    let spaced = (track_length / FINEST_SPACING_M).ceil() as usize;
    if spaced > finest && sizes::KERNELS.check(spaced).is_ok() {
        finer.push(spaced);
    }
    finer
}

/// The widest spacing of the finest fit (m): a braking zone of a trb1 car, 150–250 m, then
/// holds three to five kernels. On TORCS's road tracks only Spring (22 km) is long enough
/// for 200 kernels to lie further apart.
const FINEST_SPACING_M: f64 = 50.0;

/// A policy the game's laps may start from.
struct Start {
    policy: Policy,
    /// `ceiling` or `recommended learner`.
    name: &'static str,
    kernels: usize,
    /// Its lap in cdbo's simulator (s).
    sim_lap_s: Option<f64>,
}

/// The starts learned from in turn ([`in_turn`]): the last, how many came before it, its
/// outcome, and the laps of all and how many of them failed.
struct InTurn<S, O> {
    start: S,
    before: usize,
    outcome: O,
    laps: usize,
    failed: usize,
}

/// Learns from each of `starts` in turn, `learn` giving its laps, failed laps and outcome,
/// until one's laps do not all fail (or the starts run out); `None` without starts.
fn in_turn<S, O>(
    starts: Vec<S>,
    mut learn: impl FnMut(&S) -> Result<(usize, usize, O), Box<dyn std::error::Error>>,
) -> Result<Option<InTurn<S, O>>, Box<dyn std::error::Error>> {
    let (mut laps, mut failed) = (0, 0);
    let mut last = None;
    for (before, start) in starts.into_iter().enumerate() {
        let (n, f, outcome) = learn(&start)?;
        (laps, failed) = (laps + n, failed + f);
        last = Some(InTurn {
            start,
            before,
            outcome,
            laps,
            failed,
        });
        if f < n {
            break;
        }
    }
    Ok(last)
}

/// A lap time in a cell: `83.85 s`, or `fails`.
fn cell(lap: Option<f64>) -> String {
    lap.map_or("fails".into(), |t| format!("{t:.2} s"))
}

fn learn_on(
    game: &Game,
    track: &str,
    args: &LearnArgs,
    data: &DataPath,
    out: &std::path::Path,
) -> Result<TrackResult, Box<dyn std::error::Error>> {
    let car = game.request(track, &args.car, GamePedal::Demo(15.0))?.car;
    let ours = game_track(track, game, data)?;
    let stack = Preset::FastSafe;
    let base_line = BaseLine::MinCurvature;
    let line = base_line.line(&ours, &car)?;
    // 1. cdbo's simulator: the ceiling's policy on the race's line and steering.
    let mut sim = cdbo::sim::Simulator::new(ours.clone(), &car);
    sim.config.steering = stack.steering().steering();
    sim.config.line = line.clone();
    sim.config.flying = args.flying;
    let limit = match &line {
        Some(line) => cdbo::limit::line_limit_on_centre(&ours, line, &car),
        None => cdbo::limit::limit_lap(&ours, &car),
    };
    let profile = if args.flying {
        cdbo::ceiling::flying_profile(&ours, &car, line.as_deref())
    } else {
        cdbo::ceiling::profile(&ours, &car, line.as_deref())
    };
    // The ceiling's fits with M, 2M and 4M kernels (or finer) to one tracked lap; those that
    // complete, the fastest first (of equally fast ones the coarser).
    let tracked = cdbo::ceiling::TrackedLap::of(&sim, &profile)?;
    let mut fits = Vec::new();
    for kernels in std::iter::once(args.kernels).chain(finer_kernels(args.kernels, ours.length)) {
        let fit = cdbo::ceiling::ceiling_from(&sim, &limit, &tracked, kernels)?;
        if let Some(policy) = fit.policy {
            let start = Start {
                policy: policy.into(),
                name: "ceiling",
                kernels,
                sim_lap_s: Some(ours.length / fit.policy_mps),
            };
            fits.push((fit.policy_mps, start));
        }
    }
    fits.sort_by(|a, b| b.0.partial_cmp(&a.0).unwrap_or(Ordering::Equal));
    let fits: Vec<Start> = fits.into_iter().map(|(_, start)| start).collect();
    let config = RaceConfig {
        method: stack.method(),
        kernels: args.kernels,
        seed: args.seed,
        base_line,
        flying: args.flying,
        ..RaceConfig::default()
    };
    let starts = if fits.is_empty() {
        // No fit completes: the recommended learner's best in cdbo's simulator.
        let venue = Venue::simulator(ours.clone(), &car)
            .steered(stack.steering().steering())
            .for_learning(None);
        let learned = race(&venue, &ours, &car, &config, |_| {})?;
        vec![Start {
            sim_lap_s: learned.best_lap_time_s(),
            policy: learned.best,
            name: "recommended learner",
            kernels: args.kernels,
        }]
    } else {
        fits
    };
    // 2. The game: the recommended learner from the fastest start, its laps bounded; where
    // none of them completes, as many again from the next start.
    let venue = Venue::game(game, track, &args.car, ours.clone())?
        .steered(stack.steering().steering())
        .for_learning(None);
    let learned = in_turn(starts, |start| {
        let in_game = RaceConfig {
            laps: args.game_laps,
            kernels: start.kernels,
            warm_start: Some(start.policy.clone()),
            ..config.clone()
        };
        let outcome = race(&venue, &ours, &car, &in_game, |_| {})?;
        let failed = outcome.laps.iter().filter(|l| l.failure.is_some()).count();
        Ok((outcome.laps.len(), failed, outcome))
    })?;
    let Some(InTurn {
        start,
        before: fits_before,
        outcome,
        laps: game_laps,
        failed: game_failed_laps,
    }) = learned
    else {
        return Err(format!("{track}: no policy to start the game's laps from").into());
    };
    // 3. Its best policy, driven again standing and flying in the game (on the race's line).
    let venue = match &outcome.line {
        Some(line) => venue.on_line(line.clone()),
        None => venue,
    };
    let standing = venue.drive(&outcome.best)?.lap_time_s;
    let flying = venue.clone().flying().drive(&outcome.best)?.lap_time_s;
    let file = out.join(format!("{track}.json"));
    let raced = RacedPolicy {
        policy: outcome.best.clone(),
        base_line,
        steering: stack.steering(),
    };
    std::fs::write(&file, serde_json::to_string_pretty(&raced)?)
        .map_err(|e| format!("{}: {e}", file.display()))?;
    // 4. The robots on the same track and car.
    let robots = robots_on(game, track, &args.car, true)?;
    let (robot_standing, robot_flying) = robots.fastest();
    let owned = |lap: Option<(&str, f64)>| lap.map(|(r, t)| (r.to_owned(), t));
    Ok(TrackResult {
        track: track.to_owned(),
        start: start.name,
        kernels: start.kernels,
        sim_lap_s: start.sim_lap_s,
        fits_before,
        game_laps,
        game_failed_laps,
        standing_lap_s: standing,
        flying_lap_s: flying,
        robot_standing: owned(robot_standing),
        robot_flying: owned(robot_flying),
        policy: file.display().to_string(),
    })
}

/// The table: each track's game laps beside the fastest robot's, and how many tracks ours
/// beats.
fn markdown(results: &[TrackResult], args: &LearnArgs) -> String {
    let mut out = format!(
        "{}, {} kernels or finer, seed {}: cdbo's simulator, then {} laps of the recommended learner in \
         the game{}; the best policy's laps in the game beside the fastest shipped robot's\n\n",
        args.car,
        args.kernels,
        args.seed,
        args.game_laps,
        if args.flying {
            ", learning the flying lap"
        } else {
            ""
        }
    );
    out += "| track | start | in cdbo | game laps (failed) | our standing lap | fastest robot's standing lap | our flying lap | fastest robot's flying lap |\n";
    out += "| --- | --- | --- | --- | --- | --- | --- | --- |\n";
    let against = |ours: Option<f64>, robot: &Option<(String, f64)>| match (ours, robot) {
        (Some(t), Some((name, r))) => (
            format!("{t:.2} s ({:+.1} %)", 100.0 * (t / r - 1.0)),
            format!("{r:.2} s ({name})"),
        ),
        (ours, robot) => (
            cell(ours),
            robot
                .as_ref()
                .map_or("–".into(), |(name, r)| format!("{r:.2} s ({name})")),
        ),
    };
    let beats = |ours: Option<f64>, robot: &Option<(String, f64)>| matches!((ours, robot), (Some(t), Some((_, r))) if t < *r);
    for r in results {
        let (ours_s, robot_s) = against(r.standing_lap_s, &r.robot_standing);
        let (ours_f, robot_f) = against(r.flying_lap_s, &r.robot_flying);
        let after = match r.fits_before {
            0 => String::new(),
            n => format!(" (after {n} faster, no game lap completed)"),
        };
        out += &format!(
            "| {} | {}, {} kernels{after} | {} | {} ({}) | {ours_s} | {robot_s} | {ours_f} | {robot_f} |\n",
            r.track,
            r.start,
            r.kernels,
            cell(r.sim_lap_s),
            r.game_laps,
            r.game_failed_laps
        );
    }
    out += &format!(
        "\nOurs beat the fastest robot's standing lap on {} of {} tracks, its flying lap on {}.\n",
        results
            .iter()
            .filter(|r| beats(r.standing_lap_s, &r.robot_standing))
            .count(),
        results.len(),
        results
            .iter()
            .filter(|r| beats(r.flying_lap_s, &r.robot_flying))
            .count()
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 2M and 4M kernels up to the pattern search's 200; on a track so long that 200 lie
    /// more than 50 m apart (Spring, 22 km), one more fit with kernels 50 m apart.
    /// A start whose laps all failed gives way to the next, its laps counted; the first
    /// start with a completed lap ends the turns.
    #[test]
    fn the_next_start_is_learned_from_only_where_every_lap_failed() {
        let laps = |failed: &usize| Ok((30, *failed, *failed));
        let learned = in_turn(vec![30, 30, 12, 0], laps).unwrap().unwrap();
        assert_eq!(
            (learned.start, learned.before, learned.laps, learned.failed),
            (12, 2, 90, 72)
        );
        let first = in_turn(vec![29, 30], laps).unwrap().unwrap();
        assert_eq!((first.start, first.before, first.laps), (29, 0, 30));
        let none = in_turn(vec![30, 30], laps).unwrap().unwrap();
        assert_eq!((none.start, none.before, none.failed), (30, 1, 60));
        assert!(in_turn(Vec::<usize>::new(), laps).unwrap().is_none());
    }

    #[test]
    fn the_finest_fit_has_its_kernels_at_most_50_m_apart_on_a_long_track() {
        assert_eq!(finer_kernels(50, 4_000.0), [100, 200]);
        assert_eq!(finer_kernels(100, 4_000.0), [200]);
        assert_eq!(finer_kernels(50, 22_130.0), [100, 200, 443]);
        assert_eq!(finer_kernels(50, 10_000.0), [100, 200]);
    }
}
