//! `cdbo torcs compare`: cdbo's simulator against the game TORCS, the same car on the same
//! tracks — demonstration laps, full throttle, policies drawn around a learned one, speed along
//! the lap, and the quasi-steady-state limit against a built-in robot of the game.

use std::fmt::Write as _;
use std::path::PathBuf;

use clap::Args;
use plotters::style::{BLUE, GREEN};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use serde::Serialize;

use super::CliResult;
use cdbo::data_path::DataPath;
use cdbo::drive::ConstantPedal;
use cdbo::drive::demo::SpeedHold;
use cdbo::experiment::race::{RaceConfig, race};
use cdbo::policy::RkhsPolicy;
use cdbo::sim::{LapResult, Simulator};
use cdbo::torcs::panel::{Outcome, PanelLap};
use cdbo::torcs::{Game, GamePedal, LapRequest};
use cdbo::venue::Venue;

#[derive(Debug, Args)]
pub struct CompareArgs {
    /// TORCS tracks, comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "forza,e-track-2,aalborg,alpine-1"
    )]
    tracks: Vec<String>,
    /// TORCS car.
    #[arg(long, default_value = cdbo::torcs::DEFAULT_CAR)]
    car: String,
    /// The car of cdbo's simulator side, if not the game's car file: e.g. a calibrated car
    /// (`cdbo torcs calibrate`'s car.toml); the game drives --car.
    #[arg(long, value_name = "CAR")]
    sim_car: Option<String>,
    /// Demonstration speeds (m/s), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "10,15,20")]
    demo: Vec<f64>,
    /// Policies drawn around the learned one, per track.
    #[arg(long, default_value_t = 100)]
    policies: usize,
    /// Standard deviation of the weights' perturbation.
    #[arg(long, default_value_t = 0.03)]
    sigma: f64,
    /// Kernels of the policy learned in cdbo's simulator.
    #[arg(long, default_value_t = 30)]
    kernels: usize,
    /// Laps of that race.
    #[arg(long, default_value_t = 300)]
    laps: usize,
    /// Seed of the race and of the drawn policies.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Learned policies to draw around, one a seed from --seed on (--seed, --seed + 1, …),
    /// --policies around each: the agreement and the errors pool them. One learned policy
    /// moves the agreement by several points (docs/results/torcs.md); three give a steadier
    /// measure for three times the laps.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=100))]
    seeds: u64,
    /// Where the learned policies' laps fail while they learn in cdbo's simulator, as `cdbo
    /// race --off-track-margin` (m past the road's edge; default as `cdbo race`: the learning
    /// reserve, the wheels off slippery ground and the body off the walls; 1: the game's rule). Every drawn policy is judged at the game's rule in
    /// both simulators.
    #[arg(long, allow_negative_numbers = true, value_parser = super::value::off_track_margin)]
    off_track_margin: Option<f64>,
    /// The game's built-in robot to compare the limit with.
    #[arg(long, default_value = "bt")]
    robot: String,
    /// Games running at once.
    #[arg(long, default_value_t = 2)]
    jobs: usize,
    /// Output folder: compare.json, compare.md, speed_TRACK.png/.svg, every drawn policy
    /// with the game's lap as panel_TRACK.jsonl (`cdbo torcs panel` scores cdbo's simulator
    /// against it again, without the game), and each drawn policy the two simulators
    /// disagree on as disagreements/TRACK/policy-I.json (with several seeds
    /// seed-S-policy-I.json; `cdbo lap --policy` and `cdbo --simulator torcs lap --policy`
    /// drive it again, `--trace` traces it).
    #[arg(long, default_value = "runs/torcs-compare")]
    out: PathBuf,
}

/// One lap in both simulators.
#[derive(Debug, Serialize)]
struct Pair {
    what: String,
    cdbo: Outcome,
    torcs: Outcome,
}

/// Policies drawn around the learned ones, in both simulators.
#[derive(Debug, Serialize)]
struct Policies {
    /// The seeds of the learned policies, each of its race and of the policies drawn around it.
    seeds: Vec<u64>,
    drawn: usize,
    sigma: f64,
    /// Where the learned policies' laps failed while they learned (m past the road's edge).
    learned_off_track_margin_m: f64,
    /// What they kept in reserve of the road while they learned.
    learned_reserve: Option<cdbo::sim::lap::Reserve>,
    /// The learned policies' mean best reward in cdbo's simulator.
    learned_reward_mps: f64,
    completed_cdbo: usize,
    completed_torcs: usize,
    agree: usize,
    both_completed: usize,
    lap_time_error_mean: Option<f64>,
    lap_time_error_max: Option<f64>,
    lap_time_bias: Option<f64>,
    torcs_wall_s: f64,
    /// The drawn policies one simulator completes and the other does not, with both outcomes:
    /// where and why each failed.
    disagreements: Vec<Pair>,
}

#[derive(Debug, Serialize)]
struct TrackReport {
    track: String,
    length_m: f64,
    demos: Vec<Pair>,
    full_throttle: Pair,
    learned: Pair,
    policies: Policies,
    limit_lap_time_s: f64,
    robot: String,
    robot_first_lap_s: Option<f64>,
    robot_best_lap_s: Option<f64>,
}

pub fn run(args: &CompareArgs, data: &DataPath) -> CliResult {
    if args.policies == 0 || args.jobs == 0 || !(args.sigma.is_finite() && args.sigma >= 0.0) {
        return Err("--policies and --jobs must be positive, --sigma non-negative".into());
    }
    if args.seed.checked_add(args.seeds - 1).is_none() {
        return Err(format!(
            "--seed {} with --seeds {}: the last seed would pass {}",
            args.seed,
            args.seeds,
            u64::MAX
        )
        .into());
    }
    let game = Game::ready()?;
    std::fs::create_dir_all(&args.out).map_err(|e| format!("{}: {e}", args.out.display()))?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.jobs)
        .build()?;
    let mut reports = Vec::new();
    for track in &args.tracks {
        let r = compare_track(&game, track, args, &pool, data)?;
        eprintln!(
            "{}: demo {}; policies agree {}/{}, lap-time error {}",
            r.track,
            r.demos
                .iter()
                .map(|d| format!("{} {} / {}", d.what, d.cdbo, d.torcs))
                .collect::<Vec<_>>()
                .join(", "),
            r.policies.agree,
            r.policies.drawn,
            percent(r.policies.lap_time_error_mean)
        );
        reports.push(r);
    }
    std::fs::write(
        args.out.join("compare.json"),
        serde_json::to_string_pretty(&reports)?,
    )?;
    let md = markdown(&reports, args);
    std::fs::write(args.out.join("compare.md"), &md)?;
    print!("{md}");
    Ok(())
}

fn compare_track(
    game: &Game,
    name: &str,
    args: &CompareArgs,
    pool: &rayon::ThreadPool,
    data: &DataPath,
) -> Result<TrackReport, Box<dyn std::error::Error>> {
    let base = game.request(name, &args.car, GamePedal::Demo(15.0))?;
    let track = super::game_track(name, game, data)?;
    let car = match &args.sim_car {
        Some(spec) => cdbo::car::catalog::find(spec, data)?,
        None => base.car.clone(),
    };
    let mut sim = Simulator::new(track.clone(), &car);
    let in_game = |pedal: GamePedal, record: bool| -> Result<LapResult, cdbo::Error> {
        let mut req: LapRequest = base.clone();
        req.pedal = pedal;
        req.record = record;
        cdbo::torcs::evaluator::drive(game, &req)
    };
    let mut demos = Vec::new();
    for &v in &args.demo {
        demos.push(Pair {
            what: format!("{v} m/s"),
            cdbo: Outcome::of(&sim.lap(&mut SpeedHold::new(v))),
            torcs: Outcome::of(&in_game(GamePedal::Demo(v), false)?),
        });
    }
    let full_throttle = Pair {
        what: "full throttle".into(),
        cdbo: Outcome::of(&sim.lap(&mut ConstantPedal(1.0))),
        torcs: Outcome::of(&in_game(GamePedal::Constant(1.0), false)?),
    };

    // Policies learned in cdbo's simulator, one a seed, then policies drawn around each,
    // named by their seed when there are several.
    let seeds: Vec<u64> = (0..args.seeds).map(|k| args.seed + k).collect();
    // Learned as `cdbo race` learns (its margin, by default the simulator's reserve).
    let learning = Venue::simulator(track.clone(), &car).for_learning(args.off_track_margin);
    let mut races = Vec::with_capacity(seeds.len());
    let mut drawn: Vec<(String, RkhsPolicy)> = Vec::new();
    for &seed in &seeds {
        let config = RaceConfig {
            kernels: args.kernels,
            laps: args.laps,
            seed,
            ..RaceConfig::default()
        };
        let outcome = race(&learning, &track, &car, &config, |_| {})?;
        let best = outcome.best.pedal.clone();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        for i in 0..args.policies {
            let w = best
                .weights
                .iter()
                .map(|w| w + args.sigma * Distribution::<f64>::sample(&StandardNormal, &mut rng))
                .collect();
            let what = match seeds.len() {
                1 => format!("policy {i}"),
                _ => format!("seed {seed} policy {i}"),
            };
            drawn.push((what, RkhsPolicy::new(w, best.lengthscale)?));
        }
        races.push((outcome, best));
    }
    let learned_reward_mps =
        races.iter().map(|(o, _)| o.best_reward_mps).sum::<f64>() / races.len() as f64;
    // The first seed's policy is the one traced and charted (--seeds is at least 1).
    let (learned, best) = races.swap_remove(0);
    let ours: Vec<LapResult> = drawn.iter().map(|(_, p)| sim.lap(&mut p.pedal())).collect();
    let start = std::time::Instant::now();
    let theirs: Vec<LapResult> = pool.install(|| {
        drawn
            .par_iter()
            .map(|(_, p)| in_game(GamePedal::Rkhs(p.clone()), false))
            .collect::<Result<_, _>>()
    })?;
    let torcs_wall_s = start.elapsed().as_secs_f64();
    // Every drawn policy with the game's lap, kept as the panel (`cdbo torcs panel` scores
    // the simulator against it again without the game), and scored as it would score it.
    let panel: Vec<PanelLap> = drawn
        .iter()
        .zip(&theirs)
        .map(|((what, p), lap)| PanelLap {
            track: name.to_owned(),
            what: what.clone(),
            policy: cdbo::policy::Policy::from(p.clone()),
            torcs: Outcome::of(lap),
        })
        .collect();
    let outcomes: Vec<Outcome> = ours.iter().map(Outcome::of).collect();
    let score = cdbo::torcs::panel::score(name, &panel.iter().collect::<Vec<_>>(), &outcomes);
    let errors: Vec<f64> = ours
        .iter()
        .zip(&theirs)
        .filter_map(|(o, t)| Some((t.lap_time_s? - o.lap_time_s?) / o.lap_time_s?))
        .collect();
    // The drawn policies one simulator completes and the other does not.
    let parted: Vec<usize> = (0..drawn.len())
        .filter(|&i| ours[i].completed != theirs[i].completed)
        .collect();
    let policies = Policies {
        seeds: seeds.clone(),
        drawn: drawn.len(),
        sigma: args.sigma,
        learned_off_track_margin_m: learning.off_track_margin(),
        learned_reserve: learning.reserve(),
        learned_reward_mps,
        completed_cdbo: ours.iter().filter(|l| l.completed).count(),
        completed_torcs: theirs.iter().filter(|l| l.completed).count(),
        agree: score.agree,
        both_completed: errors.len(),
        lap_time_error_mean: score.lap_time_error_mean,
        lap_time_error_max: errors.iter().map(|e| e.abs()).reduce(f64::max),
        lap_time_bias: score.lap_time_bias,
        torcs_wall_s,
        disagreements: parted
            .iter()
            .map(|&i| Pair {
                what: drawn[i].0.clone(),
                cdbo: Outcome::of(&ours[i]),
                torcs: Outcome::of(&theirs[i]),
            })
            .collect(),
    };

    std::fs::create_dir_all(&args.out)?;
    let mut lines = String::new();
    for lap in &panel {
        lines += &cdbo::torcs::panel::line(lap)?;
        lines.push('\n');
    }
    std::fs::write(args.out.join(format!("panel_{name}.jsonl")), lines)?;

    let folder = args.out.join("disagreements").join(name);
    for &i in &parted {
        let (what, p) = &drawn[i];
        std::fs::create_dir_all(&folder)?;
        let policy = cdbo::policy::Policy::from(p.clone());
        std::fs::write(
            folder.join(format!("{}.json", what.replace(' ', "-"))),
            serde_json::to_string_pretty(&policy)?,
        )?;
    }

    // Speed along the lap of the learned policy, in both.
    sim.config.trace = true;
    let ours_best = sim.lap(&mut best.pedal());
    let theirs_best = in_game(GamePedal::Rkhs(best.clone()), true)?;
    let chart = crate::figures::speed_chart(
        &track,
        &[
            ("cdbo's simulator", BLUE, &ours_best),
            ("TORCS", GREEN, &theirs_best),
        ],
        &learned.limit,
    );
    for ext in ["png", "svg"] {
        crate::figures::draw(&args.out.join(format!("speed_{name}.{ext}")), &chart)?;
    }
    let robot = game.robot_laps(&args.robot, name, &args.car);
    if let Err(e) = &robot {
        eprintln!("warning: {e}");
    }
    Ok(TrackReport {
        track: name.to_owned(),
        length_m: track.length,
        demos,
        full_throttle,
        learned: Pair {
            what: "learned".into(),
            cdbo: Outcome::of(&ours_best),
            torcs: Outcome::of(&theirs_best),
        },
        policies,
        limit_lap_time_s: learned.limit.lap_time_s,
        robot: args.robot.clone(),
        robot_first_lap_s: robot.as_ref().ok().map(|r| r.first),
        robot_best_lap_s: robot.as_ref().ok().and_then(|r| r.best),
    })
}

fn pct(a: Option<f64>, b: Option<f64>) -> String {
    match (a, b) {
        (Some(a), Some(b)) => format!("{:+.2} %", 100.0 * (a - b) / b),
        _ => "–".into(),
    }
}

fn markdown(reports: &[TrackReport], args: &CompareArgs) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "Car {}; tracks {}.\n\n### Demonstration laps (PI speed hold)\n\n| track | target | cdbo | TORCS | TORCS − cdbo |\n| --- | --- | --- | --- | --- |",
        args.car,
        args.tracks.join(", ")
    );
    for r in reports {
        for d in &r.demos {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} |",
                r.track,
                d.what,
                d.cdbo,
                d.torcs,
                pct(d.torcs.lap_time_s, d.cdbo.lap_time_s)
            );
        }
    }
    let _ = writeln!(
        s,
        "\n### Full throttle\n\n| track | cdbo | TORCS |\n| --- | --- | --- |"
    );
    for r in reports {
        let _ = writeln!(
            s,
            "| {} | {} | {} |",
            r.track, r.full_throttle.cdbo, r.full_throttle.torcs
        );
    }
    let _ = writeln!(
        s,
        "\n### Policies around a learned one\n\nLearned in cdbo's simulator ({} kernels, {} laps, {}, laps failing {}); {} policies w = w* + {}·N(0, I){}; their laps judged at the game's rule in both.\n\n| track | learned: cdbo | learned: TORCS | completed cdbo / TORCS | completion agreement | both completed | lap-time error mean / max | bias (TORCS − cdbo) | TORCS wall |\n| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
        args.kernels,
        args.laps,
        match args.seeds {
            1 => format!("seed {}", args.seed),
            n => format!("seeds {}–{}", args.seed, args.seed + n - 1),
        },
        // Every track learns at the same margin, the flag's.
        reports.first().map_or("–".into(), |r| super::edge_words(
            r.policies.learned_off_track_margin_m,
            r.policies.learned_reserve
        )),
        args.policies,
        args.sigma,
        match args.seeds {
            1 => String::new(),
            _ => format!(
                " around each, pooled; the learned lap is seed {}'s",
                args.seed
            ),
        }
    );
    for r in reports {
        let p = &r.policies;
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} / {} | {} / {} ({}) | {} | {} / {} | {} | {:.1} s |",
            r.track,
            r.learned.cdbo,
            r.learned.torcs,
            p.completed_cdbo,
            p.completed_torcs,
            p.agree,
            p.drawn,
            (p.drawn > 0)
                .then(|| p.agree as f64 / p.drawn as f64)
                .map_or("–".into(), |f| format!("{:.0} %", 100.0 * f)),
            p.both_completed,
            percent(p.lap_time_error_mean),
            percent(p.lap_time_error_max),
            p.lap_time_bias
                .map_or("–".into(), |v| format!("{:+.2} %", 100.0 * v)),
            p.torcs_wall_s
        );
    }
    let _ = writeln!(
        s,
        "\n### Where they part\n\nThe drawn policies one simulator completes and the other does not, by where (to 10 m) and why the failing side failed; `compare.json` lists each (`policies.disagreements`).\n\n| track | cdbo fails, TORCS completes | TORCS fails, cdbo completes |\n| --- | --- | --- |"
    );
    for r in reports {
        let d = &r.policies.disagreements;
        let _ = writeln!(
            s,
            "| {} | {} | {} |",
            r.track,
            failure_places(d.iter().map(|p| &p.cdbo)),
            failure_places(d.iter().map(|p| &p.torcs))
        );
    }
    let _ = writeln!(
        s,
        "\n### cdbo's limit against the game's `{}` robot (same car)\n\n| track | QSS limit (standing start, centre line) | {} first lap (standing start) | {} best lap (flying) | limit vs first lap |\n| --- | --- | --- | --- | --- |",
        args.robot, args.robot, args.robot
    );
    for r in reports {
        let t = |v: Option<f64>| v.map_or("–".into(), |v| format!("{v:.2} s"));
        let _ = writeln!(
            s,
            "| {} | {:.2} s | {} | {} | {} |",
            r.track,
            r.limit_lap_time_s,
            t(r.robot_first_lap_s),
            t(r.robot_best_lap_s),
            pct(Some(r.limit_lap_time_s), r.robot_first_lap_s)
        );
    }
    s
}

/// The failed laps among `laps`, grouped by reason and place (to 10 m), most frequent first:
/// "hit_wall at 5210 m (4), stalled at 2710 m (1)", or "–" when none failed.
fn failure_places<'a>(laps: impl Iterator<Item = &'a Outcome>) -> String {
    let mut counts: std::collections::BTreeMap<(String, i64), usize> = Default::default();
    for lap in laps {
        if let (Some(reason), Some(at)) = (&lap.failure, lap.distance_fail_m) {
            *counts
                .entry((reason.clone(), (at / 10.0).round() as i64 * 10))
                .or_default() += 1;
        }
    }
    let mut places: Vec<_> = counts.into_iter().collect();
    places.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    if places.is_empty() {
        return "–".into();
    }
    places
        .iter()
        .map(|((reason, at), n)| format!("{reason} at {at} m ({n})"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A fraction as a percentage with two decimals, or "–" where nothing could be computed (no
/// policy completed in both simulators): never "NaN".
fn percent(fraction: Option<f64>) -> String {
    fraction
        .filter(|f| f.is_finite())
        .map_or("–".into(), |f| format!("{:.2} %", 100.0 * f))
}

#[cfg(test)]
mod tests {
    use super::{Outcome, percent};

    /// Failures grouped by reason and place to 10 m, the most frequent first; completed laps
    /// are not counted.
    #[test]
    fn failures_are_grouped_by_reason_and_place() {
        let lap = |failure: Option<(&str, f64)>| Outcome {
            lap_time_s: failure.is_none().then_some(100.0),
            failure: failure.map(|(r, _)| r.to_owned()),
            x_fail: failure.map(|(_, d)| d / 5000.0),
            distance_fail_m: failure.map(|(_, d)| d),
        };
        let laps = [
            lap(Some(("stalled", 2712.0))),
            lap(Some(("hit_wall", 5212.0))),
            lap(None),
            lap(Some(("hit_wall", 5208.0))),
        ];
        assert_eq!(
            super::failure_places(laps.iter()),
            "hit_wall at 5210 m (2), stalled at 2710 m (1)"
        );
        assert_eq!(super::failure_places([lap(None)].iter()), "–");
    }

    #[test]
    fn a_percentage_that_cannot_be_computed_is_a_dash_not_nan() {
        assert_eq!(percent(Some(0.0123)), "1.23 %");
        assert_eq!(percent(None), "–");
        assert_eq!(percent(Some(f64::NAN)), "–");
    }
}
