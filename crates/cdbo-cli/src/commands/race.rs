//! `cdbo race`: the main job — learn a fast pedal policy for a track in a few hundred laps.

use std::io::Write;
use std::path::{Path, PathBuf};

use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;

use super::policy::read_policy;
use super::{CliResult, Setup, Simulator, from_flag, print_json};
use cdbo::data_path::DataPath;
use cdbo::drive::steering::SteeringLaw;
use cdbo::experiment::race::{BaseLine, RaceConfig, RaceOutcome, check_warm_start, race};
use cdbo::method::{KnobKind, Method, Preset};
use cdbo::policy::Policy;
use cdbo::policy::RacedPolicy;

/// Policy kernels M when neither `--kernels` nor a warm start gives them.
const DEFAULT_KERNELS: usize = 30;

#[derive(Debug, Args)]
pub struct RaceArgs {
    #[command(flatten)]
    setup: Setup,
    /// Policy kernels M (the paper: 10 to 100; default 30, or the warm start's).
    #[arg(long, value_parser = super::value::kernels)]
    kernels: Option<usize>,
    /// Start from this policy (JSON, as `cdbo race` writes `best_policy.json`) instead of the
    /// demonstration's fitted w₀: say, one learned in cdbo's simulator, continued in the game.
    /// Its kernels must be `--kernels` at the paper's length-scale; the search box is centred
    /// on it, and the pattern search skips its push (the policy is pushed already) and
    /// repairs it where its first lap fails (docs/results/torcs.md, "Sim, then game").
    #[arg(long, value_name = "POLICY.json")]
    warm_start: Option<PathBuf>,
    /// A stack by one name, in place of the flags it sets (not with them): fast-safe, the one
    /// we recommend, is `--method safe-pattern-search --steering tracker --line
    /// min-curvature` (the safe search's budget: 30 failed laps, or --max-failed-laps).
    #[arg(long, value_parser = super::preset_parser(), conflicts_with_all = super::PRESET_SETS)]
    preset: Option<Preset>,
    /// Optimiser.
    #[arg(long, value_parser = super::method_parser(), default_value_t = Method::Cdbo)]
    method: Method,
    /// Laps (the paper: 300).
    #[arg(long, default_value_t = 300, value_parser = super::value::laps)]
    laps: usize,
    /// Seed of every random choice.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// UCB exploration weight β (the paper: 0.5 to 2).
    #[arg(long, default_value_t = cdbo::acquisition::ucb::DEFAULT_BETA, allow_negative_numbers = true, value_parser = super::value::non_negative)]
    beta: f64,
    /// Speed of the demonstrator (m/s), held exactly. Default: the paper's 15 m/s, or where
    /// that lap leaves the road, the fastest constant speed that completes (a short search,
    /// said in one line); the safe pattern search instead holds 0.8 of the largest share of
    /// the limit's speed profile on the line, braking gently, whose lap completes (said in
    /// one line).
    #[arg(long, allow_negative_numbers = true, value_parser = super::value::positive)]
    demo_speed: Option<f64>,
    /// The method's main knob: σ₀ (CDBO's initial samples, CMA-ES's and random search's σ, the
    /// pattern search's first step), TuRBO's initial trust-region side L_init, LineBO's step
    /// (each line's half-length), REMBO's box half-width b; default: its race value, tuned on
    /// the training tracks where swept (`cdbo race --help` lists them in the methods).
    #[arg(long, allow_negative_numbers = true)]
    knob: Option<f64>,
    /// The knob of the methods whose knob is σ₀, by its older name (the same as `--knob`).
    #[arg(long, conflicts_with = "knob", allow_negative_numbers = true)]
    sigma0: Option<f64>,
    /// Failed laps allowed: once they have failed, only the best completed lap is driven
    /// again (in the simulator a hard cap; default: no budget, except the safe pattern
    /// search's own, 30).
    #[arg(long, value_name = "N")]
    max_failed_laps: Option<usize>,
    /// Half-width r of the box [w₀ − r, w₀ + r] the method searches (default 1.5). A wider box
    /// lets the pedal brake sharper where corners come close (docs/methods.md).
    #[arg(long, value_name = "R", allow_negative_numbers = true, value_parser = super::value::box_radius)]
    box_radius: Option<f64>,
    /// How the car steers.
    #[arg(long, value_parser = super::steering_parser(), default_value_t)]
    steering: SteeringLaw,
    #[command(flatten)]
    off_track: super::OffTrackArgs,
    #[command(flatten)]
    line: super::line::LineArgs,
    /// Output folder (default: runs/race-TRACK-METHOD-mM-sSEED).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Learn on the flying lap: the second of two laps from the standing start, timed line
    /// to line, as the game times a robot's best lap. Either way the summary gives the best
    /// policy's standing and flying laps.
    #[arg(long)]
    flying: bool,
    /// Print the summary as JSON (no progress bar).
    #[arg(long)]
    json: bool,
}

#[derive(Debug, Serialize)]
struct Summary {
    method: Method,
    track: String,
    /// The car, as `--car` named it (the game's car name in TORCS).
    car: String,
    /// Where the laps were driven: `cdbo` or `torcs`.
    simulator: &'static str,
    /// The steering the car drove with.
    steering: SteeringLaw,
    /// Where a lap left the road: the car's centre this far past the road's edge (m; where
    /// the road's verges are not known, if a reserve was kept).
    off_track_margin_m: f64,
    /// What the laps kept in reserve of the road (learning in cdbo's simulator by default).
    reserve: Option<cdbo::sim::lap::Reserve>,
    /// The failed laps allowed (`--max-failed-laps`), if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    max_failed_laps: Option<usize>,
    /// The search box's half-width r around w₀.
    box_radius: f64,
    kernels: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    line_kernels: Option<usize>,
    #[serde(skip_serializing_if = "BaseLine::is_centre")]
    base_line: BaseLine,
    laps: usize,
    seed: u64,
    /// The policy file the race started from, if warm-started.
    #[serde(skip_serializing_if = "Option::is_none")]
    warm_start: Option<String>,
    /// The first lap's reward: the starting policy's lap where the race was driven.
    first_lap_reward_mps: f64,
    /// Its lap time, if it completed.
    first_lap_time_s: Option<f64>,
    demo_reward_mps: f64,
    /// The speed the demonstrator held (m/s).
    demo_speed_mps: f64,
    /// Where the asked speed's demonstration failed: what was chosen instead, and why.
    #[serde(skip_serializing_if = "Option::is_none")]
    demo_choice: Option<cdbo::experiment::start::DemoChoice>,
    /// The profile start's demonstration (the safe pattern search's), where the race began
    /// with one: its scale of the limit's profile.
    #[serde(skip_serializing_if = "Option::is_none")]
    demo_profile: Option<cdbo::experiment::profile_start::ProfileChoice>,
    /// Laps of the first policy π(w₀) that failed before its repaired lap completed (the
    /// race's first laps, among the failed ones).
    start_failed_laps: usize,
    /// Whether the race learned on flying laps (`--flying`).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    flying: bool,
    best_reward_mps: f64,
    /// The best lap learned on (flying with `--flying`, else standing).
    best_lap_time_s: Option<f64>,
    /// The best policy's standing lap and flying lap, driven again where the race was.
    #[serde(skip_serializing_if = "Option::is_none")]
    best_standing_lap_s: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    best_flying_lap_s: Option<f64>,
    limit_reward_mps: f64,
    limit_lap_time_s: f64,
    best_fraction_of_limit: f64,
    ceiling_reward_mps: f64,
    best_fraction_of_ceiling: f64,
    failed_laps: usize,
    wall_s: f64,
    optimizer_s: f64,
    simulator_s: f64,
    out: String,
}

pub fn run(args: &RaceArgs, data: &DataPath, simulator: Simulator) -> CliResult {
    // The stack: the preset's, or the flags' (clap refuses both).
    let method = args.preset.map_or(args.method, Preset::method);
    let steering = args.preset.map_or(args.steering, Preset::steering);
    let line = args.line.with_preset(args.preset);
    let knob = method.knob();
    if args.sigma0.is_some() && knob.kind != KnobKind::Sigma0 {
        return Err(format!(
            "--sigma0: {}'s main knob is not σ₀ but its {} ({}); give it with --knob",
            method,
            knob.kind.name(),
            knob.meaning
        )
        .into());
    }
    let warm_start = match &args.warm_start {
        Some(path) => Some(read_policy(path)?),
        None => None,
    };
    let kernels = args
        .kernels
        .or(warm_start.as_ref().map(|p| p.pedal.kernels()))
        .unwrap_or(DEFAULT_KERNELS);
    if let (Some(path), Some(policy)) = (&args.warm_start, &warm_start) {
        check_warm_start(policy, kernels).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    let (base_line, line_kernels) = line.resolve(kernels)?;
    let config = RaceConfig {
        method,
        kernels,
        laps: args.laps,
        seed: args.seed,
        beta: args.beta,
        demo_speed: args
            .demo_speed
            .unwrap_or(cdbo::drive::demo::DEFAULT_TARGET_SPEED),
        fixed_demo_speed: args.demo_speed.is_some(),
        knob: args.knob.or(args.sigma0),
        max_failed_laps: args.max_failed_laps,
        line_kernels,
        warm_start,
        base_line,
        box_radius: args.box_radius,
        flying: args.flying,
    };
    // A knob the method cannot take is refused before any lap is driven.
    config.spec()?;
    if let Some(w) = cdbo::method::cost::slow_race_warning(method, kernels, args.laps) {
        eprintln!("warning: {w}");
    }
    let (venue, track, car) = super::venue(&args.setup, data, simulator)?;
    let venue = venue
        .steered(steering.steering())
        .for_learning(args.off_track.off_track_margin);
    let track_name = track.name.clone();
    let car_name = simulator.car(&args.setup.car).to_owned();
    let out = args.out.clone().unwrap_or_else(|| {
        PathBuf::from("runs").join(format!(
            "race-{}-{}-m{}{}{}-s{}",
            slug(&track_name),
            method,
            kernels,
            config
                .line_kernels
                .map_or(String::new(), |m| format!("-line{m}")),
            if config.base_line.is_centre() {
                ""
            } else {
                "-mincurv"
            },
            args.seed
        ))
    });
    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let bar = if args.json {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(args.laps as u64)
    };
    bar.set_style(
        ProgressStyle::with_template("{prefix} [{bar:30}] lap {pos}/{len} {msg} ({elapsed})")?
            .progress_chars("=> "),
    );
    bar.set_prefix(format!("{method} on {track_name}"));
    let limit_reward = cdbo::limit::limit_lap(&track, &car).reward_mps;
    let start = std::time::Instant::now();
    let progress = |r: &cdbo::experiment::race::LapRecord| {
        bar.set_position(r.lap as u64);
        bar.set_message(format!(
            "best {:.2} m/s ({:.0}% of the centre-line limit)",
            r.best_mps,
            100.0 * r.best_mps / limit_reward
        ));
    };
    let outcome = race(&venue, &track, &car, &config, progress).map_err(|e| match e {
        cdbo::Error::DemoFailed { .. } => from_flag("--demo-speed")(e),
        e => e.into(),
    })?;
    bar.finish_and_clear();
    let wall_s = start.elapsed().as_secs_f64();
    // The ceiling is driven as the race's laps were: its steering and failure rules.
    let mut ceiling_sim = cdbo::sim::Simulator::new(track.clone(), &car);
    ceiling_sim.config = venue.config().clone();
    let profile = cdbo::ceiling::profile(&track, &car, None);
    let (_, ceiling_mps) = cdbo::ceiling::tracked_profile(&ceiling_sim, &profile)?;
    write_outputs(&out, &outcome, config.base_line, steering)?;
    let best_lap = outcome.best_lap_time_s();
    // The speed plots re-drive the initial and best policies where the race was driven, on
    // its base line.
    let venue = match &outcome.line {
        Some(line) => venue.on_line(line.clone()),
        None => venue,
    };
    let drive = |p: &Policy| venue.drive(p);
    // The best policy's standing and flying laps, driven again where the race was.
    let best_standing_lap_s = venue.drive(&outcome.best)?.lap_time_s;
    let best_flying_lap_s = venue.clone().flying().drive(&outcome.best)?.lap_time_s;
    // The map draws the line the best policy holds, where it is not the centre line.
    let held = (outcome.line.is_some() || outcome.best.line.is_some()).then(|| {
        let raced = RacedPolicy {
            policy: outcome.best.clone(),
            base_line: config.base_line,
            steering,
        };
        super::plot::policy_line(&track, &car, outcome.line.clone(), &raced)
    });
    let held = held.as_ref().map(|(n, p)| (n.as_str(), p.as_slice()));
    write_plots(&out, &track, &outcome, &drive, held)?;
    let summary = Summary {
        method,
        track: track_name,
        car: car_name,
        simulator: simulator.name(),
        steering,
        off_track_margin_m: venue.off_track_margin(),
        reserve: venue.reserve(),
        max_failed_laps: args.max_failed_laps,
        box_radius: args
            .box_radius
            .unwrap_or(cdbo::optimizers::DEFAULT_BOX_RADIUS),
        kernels,
        line_kernels: config.line_kernels,
        base_line: config.base_line,
        laps: args.laps,
        seed: args.seed,
        warm_start: args.warm_start.as_ref().map(|p| p.display().to_string()),
        first_lap_reward_mps: outcome.laps.first().map_or(0.0, |l| l.reward_mps),
        first_lap_time_s: outcome.laps.first().and_then(|l| l.lap_time_s),
        demo_reward_mps: outcome.demo.reward_mps,
        demo_speed_mps: match (&outcome.demo_choice, &outcome.profile_choice) {
            (_, Some(p)) => p.speed_mps,
            (Some(c), None) => c.chosen_mps,
            (None, None) => config.demo_speed,
        },
        demo_choice: outcome.demo_choice.clone(),
        demo_profile: outcome.profile_choice,
        start_failed_laps: outcome.start_failed_laps,
        flying: args.flying,
        best_reward_mps: outcome.best_reward_mps,
        best_lap_time_s: best_lap,
        best_standing_lap_s,
        best_flying_lap_s,
        limit_reward_mps: outcome.limit.reward_mps,
        limit_lap_time_s: outcome.limit.lap_time_s,
        best_fraction_of_limit: outcome.best_reward_mps / outcome.limit.reward_mps,
        ceiling_reward_mps: ceiling_mps,
        best_fraction_of_ceiling: outcome.best_reward_mps / ceiling_mps,
        failed_laps: outcome.laps.iter().filter(|l| l.failure.is_some()).count(),
        wall_s,
        optimizer_s: outcome.laps.iter().map(|l| l.optimizer_s).sum(),
        simulator_s: outcome.laps.iter().map(|l| l.simulator_s).sum(),
        out: out.display().to_string(),
    };
    std::fs::write(
        out.join("summary.json"),
        serde_json::to_string_pretty(&summary)?,
    )?;
    if args.json {
        return print_json(&summary);
    }
    if let Some(choice) = &summary.demo_choice {
        println!("{}", capitalised(&choice.sentence(&summary.track)));
    }
    if let Some(choice) = &summary.demo_profile {
        println!("{}", capitalised(&choice.sentence()));
    }
    if summary.start_failed_laps > 0 {
        println!(
            "The first policy π(w₀) was repaired where it failed: {} laps failed before {}",
            summary.start_failed_laps,
            if outcome.best_reward_mps > 0.0 {
                "one completed"
            } else {
                "the failed laps allowed ran out; the race stopped"
            }
        );
    }
    println!(
        "{} on {}, {} kernels, {} laps: best {} at {:.2} m/s, {:.1} % of the centre-line limit ({:.2} m/s), {:.1} % of the ceiling ({:.2} m/s), {:.2}x the demonstration ({:.2} m/s); {} laps failed {}",
        summary.method,
        summary.track,
        summary.kernels,
        summary.laps,
        lap_words(&summary),
        summary.best_reward_mps,
        100.0 * summary.best_fraction_of_limit,
        summary.limit_reward_mps,
        100.0 * summary.best_fraction_of_ceiling,
        summary.ceiling_reward_mps,
        summary.best_reward_mps / summary.demo_reward_mps,
        summary.demo_reward_mps,
        summary.failed_laps,
        // A reserve keeps to what the track gives: without verges it is the margin alone.
        super::edge_words(
            summary.off_track_margin_m,
            summary.reserve.filter(|_| track.has_verges())
        )
    );
    if let Some(file) = &summary.warm_start {
        println!(
            "Warm-started from {file}: its first lap here {}",
            summary
                .first_lap_time_s
                .map_or("failed".into(), |t| format!("{t:.2} s")),
        );
    }
    println!(
        "{:.1} s wall: optimiser {:.1} s, simulator {:.1} s. Results in {}",
        summary.wall_s,
        summary.optimizer_s,
        summary.simulator_s,
        out.display()
    );
    if method == Method::Cdbo {
        println!(
            "That is the paper's CDBO; the recommended stack learns faster within a budget of \
             failed laps: `cdbo race --preset {}` ({}).",
            Preset::FastSafe,
            Preset::FastSafe.flags()
        );
    }
    Ok(())
}

/// The best lap as the race learned it, and the other kind beside it: "lap 104.02 s (flying
/// 98.31 s)", "flying lap 98.31 s (standing 104.02 s)".
fn lap_words(summary: &Summary) -> String {
    let time = |t: Option<f64>| t.map_or("-".into(), |t| format!("{t:.2} s"));
    let (kind, other, other_time) = if summary.flying {
        ("flying lap", "standing", summary.best_standing_lap_s)
    } else {
        ("lap", "flying", summary.best_flying_lap_s)
    };
    let best = time(summary.best_lap_time_s);
    match other_time {
        Some(t) => format!("{kind} {best} ({other} {})", time(Some(t))),
        None => format!("{kind} {best} ({other}: fails)"),
    }
}

/// `text` with its first letter in capitals.
fn capitalised(text: &str) -> String {
    let mut chars = text.chars();
    chars
        .next()
        .map_or(String::new(), |c| c.to_uppercase().chain(chars).collect())
}

fn slug(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect()
}

/// The laps as CSV and the best and initial policies, each with how it was driven.
fn write_outputs(
    out: &Path,
    o: &RaceOutcome,
    base_line: BaseLine,
    steering: SteeringLaw,
) -> CliResult {
    let mut laps = std::io::BufWriter::new(std::fs::File::create(out.join("laps.csv"))?);
    writeln!(
        laps,
        "lap,reward_mps,best_mps,lap_time_s,failure,x_fail,optimizer_s,simulator_s"
    )?;
    for l in &o.laps {
        let failure = l
            .failure
            .map(|f| {
                serde_json::to_value(f)
                    .ok()
                    .and_then(|v| v.as_str().map(str::to_owned))
                    .unwrap_or_default()
            })
            .unwrap_or_default();
        writeln!(
            laps,
            "{},{:.6},{:.6},{},{},{},{:.6},{:.6}",
            l.lap,
            l.reward_mps,
            l.best_mps,
            l.lap_time_s.map_or(String::new(), |t| format!("{t:.4}")),
            failure,
            l.x_fail.map_or(String::new(), |x| format!("{x:.5}")),
            l.optimizer_s,
            l.simulator_s
        )?;
    }
    laps.flush()?;
    for (name, policy) in [("best_policy", &o.best), ("initial_policy", &o.initial)] {
        let raced = RacedPolicy {
            policy: policy.clone(),
            base_line,
            steering,
        };
        write_policy(out, name, &raced)?;
    }
    Ok(())
}

/// The learning curve, the policies (paper Fig. 3a), the speeds (Fig. 3b) and the map, as PNG
/// and SVG.
fn write_plots(
    out: &Path,
    track: &cdbo::track::Track,
    o: &RaceOutcome,
    drive: &dyn Fn(&Policy) -> Result<cdbo::sim::LapResult, cdbo::Error>,
    line: Option<(&str, &[[f64; 2]])>,
) -> CliResult {
    use crate::figures::{LineChart, draw, speed_chart, speed_map};
    use plotters::style::{BLACK, BLUE, GREEN, RED};
    let initial_lap = drive(&o.initial)?;
    let best_lap = drive(&o.best)?;
    let n = o.laps.len() as f64;
    let flat = |v: f64| vec![(1.0, v), (n, v)];
    let curve = LineChart {
        title: format!("{}: best reward per lap", track.name),
        x_label: "lap".into(),
        y_label: "reward L/T (m/s)".into(),
        series: vec![
            (
                "best so far".into(),
                BLUE,
                o.laps.iter().map(|l| (l.lap as f64, l.best_mps)).collect(),
            ),
            ("demonstration".into(), BLACK, flat(o.demo.reward_mps)),
            ("limit (QSS)".into(), RED, flat(o.limit.reward_mps)),
        ],
    };
    let xs = (0..=500).map(|i| i as f64 / 500.0);
    // With a target the action asks for a speed: (k₀ + s·a)·v_g.
    let (title, y_label) = match &o.best.target {
        Some(t) => (
            "Policies: the speed asked for along the lap".into(),
            format!("a (speed ({:.2} + {:.2}·a) × the profile)", t.scale, t.span),
        ),
        None => (
            "Policies: throttle (+) / brake (−) along the lap".into(),
            "a".into(),
        ),
    };
    let policies = LineChart {
        title,
        x_label: "x (fraction of the lap)".into(),
        y_label,
        series: vec![
            (
                "demonstration".into(),
                BLACK,
                o.demo_pairs.iter().step_by(5).copied().collect(),
            ),
            (
                "initial π(w₀)".into(),
                GREEN,
                xs.clone().map(|x| (x, o.initial.pedal.action(x))).collect(),
            ),
            (
                "best".into(),
                BLUE,
                xs.map(|x| (x, o.best.pedal.action(x))).collect(),
            ),
        ],
    };
    let speeds = speed_chart(
        track,
        &[
            ("initial policy", GREEN, &initial_lap),
            ("best policy", BLUE, &best_lap),
        ],
        &o.limit,
    );
    for ext in ["png", "svg"] {
        draw(&out.join(format!("learning_curve.{ext}")), &curve)?;
        draw(&out.join(format!("policy.{ext}")), &policies)?;
        draw(&out.join(format!("speed.{ext}")), &speeds)?;
        speed_map(&out.join(format!("map.{ext}")), track, &best_lap, line)?;
    }
    Ok(())
}

/// The policy as JSON, with the base line it was raced on ([`RacedPolicy`]), and as its (x, a)
/// table, with the line's offset d (m) when it has one.
fn write_policy(out: &Path, name: &str, raced: &RacedPolicy) -> CliResult {
    std::fs::write(
        out.join(format!("{name}.json")),
        serde_json::to_string_pretty(raced)?,
    )?;
    let p = &raced.policy;
    let line = p.line.is_some();
    let mut csv = String::from(if line { "x,a,d\n" } else { "x,a\n" });
    for (x, a, d) in p.table(1001) {
        csv += &if line {
            format!("{x:.6},{a:.6},{d:.6}\n")
        } else {
            format!("{x:.6},{a:.6}\n")
        };
    }
    std::fs::write(out.join(format!("{name}.csv")), csv)?;
    Ok(())
}
