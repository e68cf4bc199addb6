//! `cdbo torcs transfer`: learn in cdbo's simulator, race in the game. On each track, a policy
//! is learned as `cdbo race` learns it (its method, budget, line, steering and reserve of the
//! road), and its best is driven once in TORCS, judged at the game's rule: does the lap the
//! simulator promised survive the game, and how far apart are the two laps?

use std::fmt::Write as _;
use std::path::PathBuf;

use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde::Serialize;

use super::CliResult;
use cdbo::car::Car;
use cdbo::data_path::DataPath;
use cdbo::drive::steering::SteeringLaw;
use cdbo::experiment::race::{RaceConfig, race};
use cdbo::line::BaseLine;
use cdbo::method::{Method, Preset};
use cdbo::policy::RacedPolicy;
use cdbo::torcs::Game;
use cdbo::torcs::panel::Outcome;
use cdbo::track::Track;
use cdbo::venue::Venue;

#[derive(Debug, Args)]
pub struct TransferArgs {
    /// TORCS tracks, comma-separated (default: every road track the game has installed).
    #[arg(long, value_delimiter = ',')]
    tracks: Vec<String>,
    /// TORCS car.
    #[arg(long, default_value = cdbo::torcs::DEFAULT_CAR)]
    car: String,
    /// The car cdbo's simulator learns with, if not the game's car file: e.g. a calibrated car
    /// (`cdbo torcs calibrate`'s car.toml); the game drives --car.
    #[arg(long, value_name = "CAR")]
    sim_car: Option<String>,
    /// A stack by one name, in place of the flags it sets (not with them): fast-safe, the one
    /// we recommend, is `--method safe-pattern-search --steering tracker --line
    /// min-curvature` (the safe search's budget: 30 failed laps a race).
    #[arg(long, value_parser = super::preset_parser(), conflicts_with_all = super::PRESET_SETS)]
    preset: Option<Preset>,
    /// Optimiser.
    #[arg(long, value_parser = super::method_parser(), default_value_t = Method::PatternSearch)]
    method: Method,
    /// Policy kernels M.
    #[arg(long, default_value_t = 30, value_parser = super::value::kernels)]
    kernels: usize,
    /// Laps of each race in cdbo's simulator.
    #[arg(long, default_value_t = 300, value_parser = super::value::laps)]
    laps: usize,
    /// Seed of the first race on each track.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Races on each track, one a seed from --seed on (--seed, --seed + 1, …).
    #[arg(long, default_value_t = 1, value_parser = super::value::seeds)]
    seeds: u64,
    /// How the car steers, in both simulators.
    #[arg(long, value_parser = super::steering_parser(), default_value_t)]
    steering: SteeringLaw,
    /// Where the races' laps fail while they learn in cdbo's simulator, as `cdbo race
    /// --off-track-margin` (default as `cdbo race`: the learning reserve). The game judges
    /// every best policy at its own rule (1 m past the road's edge).
    #[arg(long, allow_negative_numbers = true, value_parser = super::value::off_track_margin)]
    off_track_margin: Option<f64>,
    #[command(flatten)]
    line: super::line::LineArgs,
    /// Races, and games, running at once.
    #[arg(long, default_value_t = 2, value_parser = super::value::jobs)]
    jobs: usize,
    /// Output folder: transfer.json, transfer.md, and each best policy as
    /// policies/TRACK-sSEED.json (`cdbo --simulator torcs lap --track TRACK --policy FILE`
    /// drives it again in the game, `cdbo lap` in cdbo's simulator).
    #[arg(long, default_value = "runs/torcs-transfer")]
    out: PathBuf,
    /// A transfer report (an earlier run's transfer.json, or a file of its shape) to read the
    /// best rewards against: each track's as a share of the report's on that track (the mean
    /// over its seeds), and each seed's count of tracks at ≥ 95 % of it (the pace line;
    /// docs/results/torcs/transfer-bc6f3c4.json is the reference, the transfer measured at
    /// bc6f3c4).
    #[arg(long, value_name = "transfer.json")]
    against: Option<PathBuf>,
    /// Print transfer.json rather than the table.
    #[arg(long)]
    json: bool,
}

/// One track's venues: its races learn in `learning` (cdbo's simulator, `car` on `track`),
/// and the game judges their best policies in `judging`.
struct TrackVenues {
    name: String,
    track: Track,
    car: Car,
    learning: Venue,
    judging: Venue,
}

/// One track and seed: the best policy's lap in both simulators.
#[derive(Debug, Serialize)]
struct Transfer {
    track: String,
    seed: u64,
    /// The race's best reward in cdbo's simulator (m/s).
    best_reward_mps: f64,
    /// The race's failed laps in cdbo's simulator.
    failed_laps: usize,
    /// The best policy's lap in cdbo's simulator, at the rule it learned with.
    cdbo: Outcome,
    /// The same policy's lap in the game, at the game's rule.
    torcs: Outcome,
    /// (game − cdbo) / cdbo lap time, where both complete.
    lap_time_difference: Option<f64>,
    /// The best reward as a share of the reference's on this track (`--against`).
    #[serde(skip_serializing_if = "Option::is_none")]
    of_reference: Option<f64>,
    /// The policy file, for `lap --policy`.
    policy: String,
}

/// The transfer of one seed's races over the tracks.
#[derive(Debug, Serialize)]
struct SeedSummary {
    seed: u64,
    tracks: usize,
    /// The best policies that complete their lap in the game.
    completed_torcs: usize,
    /// The largest |(game − cdbo) / cdbo| lap time over those.
    lap_time_difference_max: Option<f64>,
    /// The races' mean best reward in cdbo's simulator (m/s).
    mean_best_reward_mps: f64,
    /// Their mean failed laps in cdbo's simulator.
    mean_failed_laps: f64,
    /// Against the reference (`--against`): the mean share of its best rewards, over the
    /// tracks it has.
    #[serde(skip_serializing_if = "Option::is_none")]
    mean_of_reference: Option<f64>,
    /// The tracks at ≥ 95 % of the reference's best reward, of those it has.
    #[serde(skip_serializing_if = "Option::is_none")]
    tracks_at_95_percent: Option<usize>,
}

#[derive(Debug, Serialize)]
struct Report {
    car: String,
    sim_car: Option<String>,
    method: Method,
    kernels: usize,
    laps: usize,
    steering: SteeringLaw,
    #[serde(skip_serializing_if = "BaseLine::is_centre")]
    base_line: BaseLine,
    #[serde(skip_serializing_if = "Option::is_none")]
    line_kernels: Option<usize>,
    /// Where the races' laps failed while they learned (m past the road's edge).
    learned_off_track_margin_m: f64,
    /// What they kept in reserve of the road while they learned.
    learned_reserve: Option<cdbo::sim::lap::Reserve>,
    /// Where the game's laps fail (m past the road's edge).
    judged_off_track_margin_m: f64,
    /// The reference the best rewards are read against (`--against`).
    #[serde(skip_serializing_if = "Option::is_none")]
    against: Option<String>,
    seeds: Vec<SeedSummary>,
    transfers: Vec<Transfer>,
    torcs_wall_s: f64,
}

pub fn run(args: &TransferArgs, data: &DataPath) -> CliResult {
    let last_seed = super::last_seed(args.seed, args.seeds)?;
    // The stack: the preset's, or the flags' (clap refuses both).
    let method = args.preset.map_or(args.method, Preset::method);
    let steering = args.preset.map_or(args.steering, Preset::steering);
    let (base_line, line_kernels) = args.line.with_preset(args.preset).resolve(args.kernels)?;
    let config = RaceConfig {
        method,
        kernels: args.kernels,
        laps: args.laps,
        line_kernels,
        base_line,
        ..RaceConfig::default()
    };
    config.spec()?;
    let reference = match &args.against {
        Some(path) => {
            let text = cdbo::bounded::read_text(path, &cdbo::bounded::TRANSFER_REPORT)?;
            Some(cdbo::torcs::transfer::reference(
                &text,
                &path.display().to_string(),
            )?)
        }
        None => None,
    };
    let game = Game::ready()?;
    let tracks = if args.tracks.is_empty() {
        game.install.tracks("road")
    } else {
        args.tracks.clone()
    };
    if tracks.is_empty() {
        return Err(format!(
            "no road tracks in the game's {}: name them with --tracks",
            game.install.data_dir.join("tracks/road").display()
        )
        .into());
    }
    // Every track and car is read before any lap is driven: a name the game does not have
    // stops here, with nothing written.
    game.install.check_car(&args.car)?;
    let mut venues = Vec::with_capacity(tracks.len());
    for name in &tracks {
        let track = super::game_track(name, &game, data)?;
        let in_game = Venue::game(&game, name, &args.car, track.clone())?;
        let car = match &args.sim_car {
            Some(spec) => cdbo::car::catalog::find(spec, data)?,
            None => in_game
                .car()
                .cloned()
                .ok_or("the game's venue has its car")?,
        };
        let learning = Venue::simulator(track.clone(), &car)
            .steered(steering.steering())
            .for_learning(args.off_track_margin);
        let judging = in_game.steered(steering.steering()).for_learning(None);
        venues.push(TrackVenues {
            name: name.clone(),
            track,
            car,
            learning,
            judging,
        });
    }
    let policies = args.out.join("policies");
    std::fs::create_dir_all(&policies).map_err(|e| format!("{}: {e}", policies.display()))?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs)
        .build()?;

    // The races, in cdbo's simulator; then each best policy once in the game.
    let jobs: Vec<(usize, u64)> = (0..venues.len())
        .flat_map(|t| (args.seed..=last_seed).map(move |s| (t, s)))
        .collect();
    // One bar: every race's laps in cdbo's simulator, then the games.
    let bar = if args.json {
        ProgressBar::hidden()
    } else {
        ProgressBar::new((jobs.len() * (args.laps + 1)) as u64)
    };
    bar.set_style(
        ProgressStyle::with_template("[{bar:30}] {msg} ({elapsed}, eta {eta})")?
            .progress_chars("=> "),
    );
    let raced = std::sync::atomic::AtomicUsize::new(0);
    bar.set_message(format!("races in cdbo 0/{}", jobs.len()));
    let races = pool.install(|| {
        jobs.par_iter()
            .map(|&(t, seed)| {
                let TrackVenues {
                    name,
                    track,
                    car,
                    learning,
                    ..
                } = &venues[t];
                let config = RaceConfig {
                    seed,
                    ..config.clone()
                };
                let outcome = race(learning, track, car, &config, |_| bar.inc(1))?;
                // Kept as soon as it is learned: a game that fails later loses no race.
                let kept = RacedPolicy {
                    policy: outcome.best.clone(),
                    base_line,
                    steering,
                };
                let file = policy_file(&policies, name, seed);
                let text =
                    serde_json::to_string_pretty(&kept).map_err(|source| cdbo::Error::Json {
                        what: file.display().to_string(),
                        source,
                    })?;
                std::fs::write(&file, text).map_err(|source| cdbo::Error::Io {
                    path: file.clone(),
                    source,
                })?;
                let k = raced.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                bar.set_message(format!("races in cdbo {k}/{}", jobs.len()));
                let line = format!(
                    "{k}/{}: {name} seed {seed}: best {:.2} m/s in cdbo's simulator",
                    jobs.len(),
                    outcome.best_reward_mps
                );
                // Without a terminal (a batch job's log) the bar is hidden: print plainly.
                if bar.is_hidden() {
                    eprintln!("{line}");
                } else {
                    bar.println(line);
                }
                Ok(outcome)
            })
            .collect::<Result<Vec<_>, cdbo::Error>>()
    })?;
    bar.set_message(format!("game laps of {} best policies", jobs.len()));
    let start = std::time::Instant::now();
    let laps = pool.install(|| {
        jobs.par_iter()
            .zip(&races)
            .map(|(&(t, _), outcome)| {
                let TrackVenues {
                    learning, judging, ..
                } = &venues[t];
                let on_line = |v: &Venue| match &outcome.line {
                    Some(line) => v.clone().on_line(line.clone()),
                    None => v.clone(),
                };
                let ours = on_line(learning).drive(&outcome.best)?;
                let theirs = on_line(judging).drive(&outcome.best)?;
                bar.inc(1);
                Ok((ours, theirs))
            })
            .collect::<Result<Vec<_>, cdbo::Error>>()
    })?;
    bar.finish_and_clear();
    let torcs_wall_s = start.elapsed().as_secs_f64();

    let mut transfers = Vec::with_capacity(jobs.len());
    for ((&(t, seed), outcome), (ours, theirs)) in jobs.iter().zip(&races).zip(&laps) {
        let name = &venues[t].name;
        transfers.push(Transfer {
            track: name.clone(),
            seed,
            best_reward_mps: outcome.best_reward_mps,
            failed_laps: outcome.laps.iter().filter(|l| l.failure.is_some()).count(),
            cdbo: Outcome::of(ours),
            torcs: Outcome::of(theirs),
            lap_time_difference: ours
                .lap_time_s
                .zip(theirs.lap_time_s)
                .map(|(o, t)| (t - o) / o),
            of_reference: reference
                .as_ref()
                .and_then(|r| r.get(name))
                .map(|r| outcome.best_reward_mps / r),
            policy: policy_file(&policies, name, seed).display().to_string(),
        });
    }
    let TrackVenues {
        learning, judging, ..
    } = &venues[0];
    let report = Report {
        car: args.car.clone(),
        sim_car: args.sim_car.clone(),
        method,
        kernels: args.kernels,
        laps: args.laps,
        steering,
        base_line,
        line_kernels,
        learned_off_track_margin_m: learning.off_track_margin(),
        learned_reserve: learning.reserve(),
        judged_off_track_margin_m: judging.off_track_margin(),
        against: args.against.as_ref().map(|p| p.display().to_string()),
        seeds: (args.seed..=last_seed)
            .map(|s| summary(s, &transfers))
            .collect(),
        transfers,
        torcs_wall_s,
    };
    std::fs::write(
        args.out.join("transfer.json"),
        serde_json::to_string_pretty(&report)?,
    )?;
    let md = markdown(&report);
    std::fs::write(args.out.join("transfer.md"), &md)?;
    if args.json {
        return super::print_json(&report);
    }
    print!("{md}");
    Ok(())
}

/// Where the best policy of `track`'s race with `seed` is kept.
fn policy_file(folder: &std::path::Path, track: &str, seed: u64) -> PathBuf {
    folder.join(format!("{track}-s{seed}.json"))
}

fn summary(seed: u64, transfers: &[Transfer]) -> SeedSummary {
    let of_seed: Vec<&Transfer> = transfers.iter().filter(|t| t.seed == seed).collect();
    let n = of_seed.len().max(1) as f64;
    let shares: Vec<f64> = of_seed.iter().filter_map(|t| t.of_reference).collect();
    SeedSummary {
        seed,
        tracks: of_seed.len(),
        completed_torcs: of_seed
            .iter()
            .filter(|t| t.torcs.lap_time_s.is_some())
            .count(),
        lap_time_difference_max: of_seed
            .iter()
            .filter_map(|t| t.lap_time_difference.map(f64::abs))
            .reduce(f64::max),
        mean_best_reward_mps: of_seed.iter().map(|t| t.best_reward_mps).sum::<f64>() / n,
        mean_failed_laps: of_seed.iter().map(|t| t.failed_laps as f64).sum::<f64>() / n,
        mean_of_reference: (!shares.is_empty())
            .then(|| shares.iter().sum::<f64>() / shares.len() as f64),
        tracks_at_95_percent: (!shares.is_empty())
            .then(|| shares.iter().filter(|&&s| s >= 0.95).count()),
    }
}

fn markdown(r: &Report) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "The {} method's best policy of {} laps ({} kernels, {} steering{}), learned in cdbo's \
         simulator with {} {}, then driven once in TORCS with car {} {}.\n",
        r.method,
        r.laps,
        r.kernels,
        match r.steering {
            SteeringLaw::Pi => "the PI",
            SteeringLaw::Tracker => "the path tracker's",
        },
        if r.base_line.is_centre() {
            String::new()
        } else {
            format!(", the {} line", r.base_line.name())
        },
        r.sim_car
            .as_ref()
            .map_or(format!("{}'s car file", r.car), |c| format!("car {c}")),
        super::edge_words(r.learned_off_track_margin_m, r.learned_reserve),
        r.car,
        super::edge_words(r.judged_off_track_margin_m, None),
    );
    let against = r.against.is_some();
    let _ = writeln!(
        s,
        "| track | seed | cdbo: best lap | failed laps in cdbo | the game | game − cdbo |{}\n| --- | ---: | --- | ---: | --- | ---: |{}",
        if against {
            " best reward against the reference |"
        } else {
            ""
        },
        if against { " ---: |" } else { "" },
    );
    for t in &r.transfers {
        let _ = write!(
            s,
            "| {} | {} | {} | {} | {} | {} |",
            t.track,
            t.seed,
            t.cdbo,
            t.failed_laps,
            t.torcs,
            t.lap_time_difference
                .map_or("–".into(), |d| format!("{:+.2} %", 100.0 * d))
        );
        if against {
            let _ = write!(s, " {} |", share(t.of_reference));
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(s);
    for seed in &r.seeds {
        let _ = write!(
            s,
            "Seed {}: {} of {} complete in the game, each within {} of cdbo's lap; mean best \
             reward in cdbo {:.2} m/s, {:.1} failed laps a race",
            seed.seed,
            seed.completed_torcs,
            seed.tracks,
            seed.lap_time_difference_max
                .map_or("–".into(), |d| format!("{:.2} %", 100.0 * d)),
            seed.mean_best_reward_mps,
            seed.mean_failed_laps,
        );
        if let (Some(mean), Some(at_95)) = (seed.mean_of_reference, seed.tracks_at_95_percent) {
            let _ = write!(
                s,
                "; {} of the reference's best reward on average, {at_95} tracks at ≥ 95 % of it",
                share(Some(mean))
            );
        }
        let _ = writeln!(s, ".");
    }
    if let Some(file) = &r.against {
        let _ = writeln!(s, "\nThe reference: {file}.");
    }
    s
}

/// A share as a percentage, or "–" where there is none.
fn share(of: Option<f64>) -> String {
    of.map_or("–".into(), |f| format!("{:.1} %", 100.0 * f))
}
