//! `cdbo bench`: simulator throughput on one core, an optimiser's suggestion, every method on
//! a test problem, and every circuit of a folder ([`super::bench_circuits`]).

use clap::{Args, Subcommand};
use serde::Serialize;

use super::{CliResult, Setup, print_json};
use cdbo::data_path::DataPath;
use cdbo::drive::demo::{DEFAULT_TARGET_SPEED, SpeedHold};
use cdbo::method::Method;
use cdbo::sim::Simulator;

#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Laps of the 15 m/s demonstrator on one thread: simulated time over wall time.
    Sim(SimArgs),
    /// Time of one CDBO suggestion on a GP with N observations in D dimensions, and of the
    /// pattern search's after as many laps.
    Suggest(SuggestArgs),
    /// Every method on a test problem: mean ± standard error of the best value, and time.
    Optimizers(OptimizersArgs),
    /// Every circuit of a folder raced with each stack the README recommends: started or
    /// not, first completed lap, best as % of the centre-line limit, failed laps, wall time.
    Circuits(super::bench_circuits::CircuitsArgs),
}

#[derive(Debug, Args)]
pub struct OptimizersArgs {
    /// Problem: hartmann6 or branin (embedded in --dims), rosenbrock, ackley.
    #[arg(long, default_value = "hartmann6")]
    problem: String,
    /// Dimensions.
    #[arg(long, default_value_t = 100, value_parser = super::value::dims)]
    dims: usize,
    /// Evaluations per run.
    #[arg(long, default_value_t = 60, value_parser = super::value::evals)]
    evals: usize,
    /// Seeds (runs per method).
    #[arg(long, default_value_t = 10, value_parser = super::value::seeds)]
    seeds: u64,
    /// Methods, comma-separated.
    #[arg(long, value_parser = super::method_parser(), value_delimiter = ',', default_values_t = Method::ALL)]
    methods: Vec<Method>,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, Serialize)]
struct MethodResult {
    method: Method,
    mean_best: f64,
    stderr_best: f64,
    mean_seconds: f64,
}

#[derive(Debug, Serialize)]
struct OptimizersBench {
    problem: String,
    dims: usize,
    evals: usize,
    seeds: u64,
    results: Vec<MethodResult>,
}

#[derive(Debug, Args)]
pub struct SuggestArgs {
    /// Observations in the GP.
    #[arg(long, default_value_t = 300, value_parser = super::value::observations)]
    observations: usize,
    /// Dimensions (policy weights).
    #[arg(long, default_value_t = 100, value_parser = super::value::dims)]
    dims: usize,
    /// Suggestions timed.
    #[arg(long, default_value_t = 20, value_parser = super::value::repeats)]
    repeats: usize,
    /// Values scanned per axis (default: the library's).
    #[arg(long, value_parser = super::value::repeats)]
    scan: Option<usize>,
    /// COBYLA evaluations per axis (default: the library's).
    #[arg(long, value_parser = super::value::repeats)]
    polish: Option<usize>,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, Serialize)]
struct SuggestBench {
    observations: usize,
    dims: usize,
    repeats: usize,
    median_ms: f64,
    p90_ms: f64,
    af_evals_per_suggest: f64,
    refit_ms: f64,
    /// The pattern search's suggestion after as many laps in as many weights.
    pattern_search_median_ms: f64,
}

#[derive(Debug, Args)]
pub struct SimArgs {
    #[command(flatten)]
    setup: Setup,
    /// Number of laps.
    #[arg(long, default_value_t = 10, value_parser = super::value::laps)]
    laps: usize,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, Serialize)]
struct SimBench {
    track: String,
    laps: usize,
    simulated_s: f64,
    wall_s: f64,
    realtime_factor: f64,
    laps_per_s: f64,
}

pub fn run(cmd: &BenchCommand, data: &DataPath) -> CliResult {
    match cmd {
        BenchCommand::Sim(args) => sim(args, data),
        BenchCommand::Suggest(args) => suggest(args),
        BenchCommand::Optimizers(args) => optimizers(args),
        BenchCommand::Circuits(args) => super::bench_circuits::circuits(args, data),
    }
}

/// Runs each method `seeds` times on the problem and reports the best values found.
fn optimizers(args: &OptimizersArgs) -> CliResult {
    use cdbo::benchmarks::{PROBLEMS, Problem};
    let problem = Problem::by_name(&args.problem, args.dims).ok_or_else(|| {
        format!(
            "unknown problem {:?} in {} dimensions (available: {})",
            args.problem,
            args.dims,
            PROBLEMS.join(", ")
        )
    })?;
    let mut results = Vec::new();
    for method in &args.methods {
        let (mut bests, mut seconds) = (Vec::new(), 0.0);
        for seed in 0..args.seeds {
            let spec = cdbo::method::Spec::problem(*method, problem.radius)?.seed(seed);
            let mut opt = spec.optimizer(problem.start.clone())?;
            let start = std::time::Instant::now();
            for _ in 0..args.evals {
                let w = opt.ask()?;
                opt.tell(&w, problem.reward(&w))?;
            }
            seconds += start.elapsed().as_secs_f64();
            bests.push(opt.best().map_or(f64::NAN, |b| b.1));
        }
        let k = bests.len() as f64;
        let mean = bests.iter().sum::<f64>() / k;
        let var = bests.iter().map(|b| (b - mean).powi(2)).sum::<f64>() / (k - 1.0).max(1.0);
        results.push(MethodResult {
            method: *method,
            mean_best: mean,
            stderr_best: (var / k).sqrt(),
            mean_seconds: seconds / k,
        });
    }
    let b = OptimizersBench {
        problem: args.problem.clone(),
        dims: args.dims,
        evals: args.evals,
        seeds: args.seeds,
        results,
    };
    if args.json {
        return print_json(&b);
    }
    println!(
        "{} in {} dimensions, {} evaluations, {} seeds (higher is better):",
        b.problem, b.dims, b.evals, b.seeds
    );
    for r in &b.results {
        println!(
            "  {:<8} best {:>10.4} ± {:.4}   {:.3} s per run",
            r.method, r.mean_best, r.stderr_best, r.mean_seconds
        );
    }
    Ok(())
}

/// A GP of `observations` points around w₀ = 0 with a smooth synthetic reward, hyperparameters
/// fitted once (timed), then `repeats` suggestions from clones of the same state.
fn suggest(args: &SuggestArgs) -> CliResult {
    use cdbo::optimizers::Optimizer;
    use cdbo::optimizers::bo::{Bo, BoConfig, Maximiser};
    use cdbo::optimizers::coordinate_ascent::AxisSearch;
    if args.observations < 2 {
        return Err("--observations must be at least 2".into());
    }
    let defaults = AxisSearch::default();
    let search = AxisSearch {
        scan: args.scan.unwrap_or(defaults.scan),
        polish: args.polish.unwrap_or(defaults.polish),
        ..defaults
    };
    let config = BoConfig {
        initial_samples: 0,
        refit_every: 0,
        maximiser: Maximiser::CoordinateAscent(search),
        ..BoConfig::default()
    };
    let reward = |w: &[f64]| {
        30.0 - w
            .iter()
            .enumerate()
            .map(|(i, v)| (v - 0.1 * (i % 5) as f64).powi(2))
            .sum::<f64>()
    };
    let mut opt = Bo::new(vec![0.0; args.dims], config)?;
    let mut rng = cdbo::optimizers::rng_for(7, 0);
    let normal = rand_distr::Normal::new(0.0, 0.3)?;
    for _ in 0..args.observations {
        let w: Vec<f64> = (0..args.dims)
            .map(|_| rand_distr::Distribution::sample(&normal, &mut rng))
            .collect();
        opt.tell(&w, reward(&w))?;
    }
    let start = std::time::Instant::now();
    opt.fit_hyperparameters()?;
    let refit_ms = start.elapsed().as_secs_f64() * 1e3;
    let mut times = Vec::with_capacity(args.repeats);
    let mut evals = 0usize;
    for _ in 0..args.repeats {
        let mut c = opt.clone();
        let t = std::time::Instant::now();
        c.ask()?;
        times.push(t.elapsed().as_secs_f64() * 1e3);
        evals += c.last_af_evaluations;
    }
    times.sort_by(f64::total_cmp);
    let pick = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize];
    let spec = cdbo::method::Spec::told(Method::PatternSearch, 7, 1.0, None)?;
    let mut ps = spec.optimizer(vec![0.0; args.dims])?;
    for _ in 0..args.observations {
        let w = ps.ask()?;
        ps.tell(&w, reward(&w))?;
    }
    let mut ps_times: Vec<f64> = (0..args.repeats)
        .map(|_| {
            let t = std::time::Instant::now();
            let w = ps.ask();
            let elapsed = t.elapsed().as_secs_f64() * 1e3;
            std::hint::black_box(w).map(|_| elapsed)
        })
        .collect::<Result<_, _>>()?;
    ps_times.sort_by(f64::total_cmp);
    let b = SuggestBench {
        observations: args.observations,
        dims: args.dims,
        repeats: args.repeats,
        median_ms: pick(0.5),
        p90_ms: pick(0.9),
        af_evals_per_suggest: evals as f64 / args.repeats as f64,
        refit_ms,
        pattern_search_median_ms: ps_times[ps_times.len() / 2],
    };
    if args.json {
        return print_json(&b);
    }
    println!(
        "CDBO suggestion, {} observations in {} dimensions: median {:.2} ms, p90 {:.2} ms, {:.0} acquisition evaluations; hyperparameter fit {:.0} ms",
        b.observations, b.dims, b.median_ms, b.p90_ms, b.af_evals_per_suggest, b.refit_ms
    );
    println!(
        "pattern-search suggestion after as many laps: median {:.1e} ms ({:.1e} × CDBO's)",
        b.pattern_search_median_ms,
        b.pattern_search_median_ms / b.median_ms
    );
    Ok(())
}

fn sim(args: &SimArgs, data: &DataPath) -> CliResult {
    let (track, car) = args.setup.load(data)?;
    let sim = Simulator::new(track, &car);
    sim.lap(&mut SpeedHold::new(DEFAULT_TARGET_SPEED)); // warm-up
    let start = std::time::Instant::now();
    let simulated_s: f64 = (0..args.laps)
        .map(|_| {
            sim.lap(&mut SpeedHold::new(DEFAULT_TARGET_SPEED))
                .simulated_s
        })
        .sum();
    let wall_s = start.elapsed().as_secs_f64();
    let b = SimBench {
        track: sim.track.name.clone(),
        laps: args.laps,
        simulated_s,
        wall_s,
        realtime_factor: simulated_s / wall_s,
        laps_per_s: args.laps as f64 / wall_s,
    };
    if args.json {
        return print_json(&b);
    }
    println!(
        "{}: {} laps, {:.1} s simulated in {:.3} s wall: {:.0}x real time, {:.1} laps/s (one thread)",
        b.track, b.laps, b.simulated_s, b.wall_s, b.realtime_factor, b.laps_per_s
    );
    Ok(())
}
