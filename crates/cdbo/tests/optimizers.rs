//! Every method behind the `Optimizer` trait: determinism, save/resume, and the qualitative
//! results of the papers that introduced the peers (TuRBO, LineBO, REMBO).

use cdbo::benchmarks::Problem;
use cdbo::method::{Method, Spec, resume};
use cdbo::optimizers::{FailedLap, Optimizer, Saved};

fn optimiser(method: &str, problem: &Problem, seed: u64) -> Box<dyn Optimizer + Send> {
    Spec::problem(method.parse().unwrap(), problem.radius)
        .unwrap()
        .seed(seed)
        .optimizer(problem.start.clone())
        .unwrap()
}

/// The best reward of `evals` laps.
fn best_of(method: &str, problem: &Problem, evals: usize, seed: u64) -> f64 {
    let mut opt = optimiser(method, problem, seed);
    for _ in 0..evals {
        let w = opt.ask().unwrap();
        opt.tell(&w, problem.reward(&w)).unwrap();
    }
    opt.best().unwrap().1
}

fn mean_best(method: &str, problem: &Problem, evals: usize, seeds: u64) -> f64 {
    (0..seeds)
        .map(|s| best_of(method, problem, evals, s))
        .sum::<f64>()
        / seeds as f64
}

/// Asks and tells `evals` laps; returns the asked weights.
fn drive(opt: &mut dyn Optimizer, problem: &Problem, evals: usize) -> Vec<Vec<f64>> {
    (0..evals)
        .map(|_| {
            let w = opt.ask().unwrap();
            opt.tell(&w, problem.reward(&w)).unwrap();
            w
        })
        .collect()
}

#[test]
fn every_method_is_deterministic_and_resumes_exactly() {
    let problem = Problem::by_name("ackley", 6).unwrap();
    for method in Method::ALL.map(Method::name) {
        let mut a = optimiser(method, &problem, 11);
        let mut b = optimiser(method, &problem, 11);
        let first = drive(a.as_mut(), &problem, 23);
        assert_eq!(first, drive(b.as_mut(), &problem, 23), "{method}");
        // Save mid-run with a pending suggestion, resume from JSON, continue both.
        let pending = a.ask().unwrap();
        let json = serde_json::to_string(&a.save()).unwrap();
        let saved: Saved = serde_json::from_str(&json).unwrap();
        let mut resumed = resume(saved).unwrap();
        assert_eq!(resumed.name(), method);
        assert_eq!(resumed.evaluations(), 23, "{method}");
        assert_eq!(resumed.best(), a.best(), "{method}");
        assert_eq!(resumed.ask().unwrap(), pending, "{method}");
        let rest_a = drive(a.as_mut(), &problem, 12);
        let rest_b = drive(resumed.as_mut(), &problem, 12);
        assert_eq!(rest_a, rest_b, "{method}: resumed run diverged");
    }
}

/// Past `BACKGROUND_FITS_FROM` observations CDBO's fits run on their own thread: a run saved
/// while one is in flight resumes (its replay redoes the fits) and continues bit for bit, and
/// a clone taken mid-flight (which redoes the fit on its own thread) agrees too.
#[test]
fn cdbo_with_fits_in_flight_is_deterministic_and_resumes_exactly() {
    use cdbo::optimizers::bo::{BACKGROUND_FITS_FROM, Bo, BoConfig};
    let problem = Problem::by_name("ackley", 3).unwrap();
    let config = BoConfig {
        seed: 5,
        box_radius: problem.radius,
        ..BoConfig::default()
    };
    let mut a = Bo::new(problem.start.clone(), config.clone()).unwrap();
    let mut b = Bo::new(problem.start.clone(), config).unwrap();
    let n = BACKGROUND_FITS_FROM + 7;
    assert_eq!(drive(&mut a, &problem, n), drive(&mut b, &problem, n));
    let mut clone = a.clone();
    let saved: Saved = serde_json::from_str(&serde_json::to_string(&a.save()).unwrap()).unwrap();
    let mut resumed = resume(saved).unwrap();
    let rest = drive(&mut a, &problem, 12);
    assert_eq!(
        rest,
        drive(resumed.as_mut(), &problem, 12),
        "resumed run diverged"
    );
    assert_eq!(rest, drive(&mut clone, &problem, 12), "clone diverged");
}

/// While every lap has scored the same, CDBO keeps drawing from N(w₀, σ₀²I) (a flat GP would
/// send it to the box's corners); the first different score ends the initial design.
#[test]
fn cdbo_keeps_its_initial_design_while_every_lap_fails() {
    use cdbo::optimizers::bo::{Bo, BoConfig};
    let config = BoConfig::default();
    let (sigma, radius) = (config.initial_sigma, config.box_radius);
    let w0 = vec![0.2; 12];
    let mut bo = Bo::new(w0.clone(), config).unwrap();
    let distance = |w: &[f64]| {
        w.iter()
            .zip(&w0)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    };
    for _ in 0..40 {
        let w = bo.ask().unwrap();
        assert!(
            distance(&w) < 6.0 * sigma,
            "lap {}: {w:?}",
            bo.evaluations() + 1
        );
        bo.tell(&w, 0.0).unwrap();
    }
    let w = bo.ask().unwrap();
    bo.tell(&w, 1.0).unwrap();
    let far = (0..10).any(|_| {
        let w = bo.ask().unwrap();
        bo.tell(&w, 0.0).unwrap();
        distance(&w) > 0.5 * radius
    });
    assert!(far, "the search never left the initial design");
}

#[test]
fn every_method_refuses_bad_tells_and_keeps_its_state() {
    let problem = Problem::by_name("ackley", 4).unwrap();
    for method in Method::ALL.map(Method::name) {
        let mut opt = optimiser(method, &problem, 3);
        drive(opt.as_mut(), &problem, 5);
        let before = serde_json::to_string(&opt.save()).unwrap();
        let w = opt.ask().unwrap();
        assert!(opt.tell(&w[..3], 1.0).is_err(), "{method}: wrong dimension");
        assert!(opt.tell(&w, f64::NAN).is_err(), "{method}: NaN reward");
        assert!(opt.tell(&w, f64::INFINITY).is_err(), "{method}: infinite");
        let mut bad = w.clone();
        bad[0] = f64::NAN;
        assert!(opt.tell(&bad, 1.0).is_err(), "{method}: NaN weight");
        assert_eq!(
            serde_json::to_string(&opt.save()).unwrap(),
            before,
            "{method}"
        );
        assert_eq!(
            opt.ask().unwrap(),
            w,
            "{method}: the pending suggestion changed"
        );
    }
    assert!("simplex".parse::<Method>().is_err());
}

/// TuRBO (Eriksson et al. 2019, Fig. 3) and LineBO (Kirschner et al. 2019, Fig. 2) beat
/// random search on Ackley in 20 dimensions; here over 10 seeds of 150 evaluations, against
/// Gaussian random search around the best point.
#[test]
#[ignore = "slow (30 runs of 150 evaluations with GPs): .ci/run runs it with --ignored"]
fn turbo_and_linebo_beat_random_search_on_ackley20() {
    let problem = Problem::by_name("ackley", 20).unwrap();
    let (evals, seeds) = (150, 10);
    let random = mean_best("random", &problem, evals, seeds);
    for method in ["turbo", "linebo"] {
        let m = mean_best(method, &problem, evals, seeds);
        eprintln!("ackley-20, {evals} evaluations: {method} {m:.3}, random {random:.3}");
        assert!(
            m > random,
            "{method} {m} did not beat random search {random}"
        );
    }
}

/// Evaluations until the best reward is within `tolerance` of `optimum` (None: not within
/// `budget`).
fn evaluations_to_reach(
    next: &mut dyn FnMut() -> f64,
    optimum: f64,
    tolerance: f64,
    budget: usize,
) -> Option<usize> {
    (1..=budget).find(|_| next() >= optimum - tolerance)
}

/// REMBO (Wang et al. 2016, Fig. 3) finds the optimum of Branin embedded in 100 dimensions
/// far faster than uniform random search over the box, the baseline of that paper.
#[test]
#[ignore = "slow (10 REMBO runs of up to 150 evaluations): .ci/run runs it with --ignored"]
fn rembo_finds_branin_in_100d_far_faster_than_random_search() {
    use rand::{Rng, SeedableRng};
    let problem = Problem::by_name("branin", 100).unwrap();
    let (optimum, tolerance, budget, seeds) = (-0.397_887, 0.5, 150, 10);
    let mut rembo_counts = Vec::new();
    let mut random_counts = Vec::new();
    for seed in 0..seeds {
        let mut opt = optimiser("rembo-5d", &problem, seed);
        let mut next = || {
            let w = opt.ask().unwrap();
            let r = problem.reward(&w);
            opt.tell(&w, r).unwrap();
            opt.best().unwrap().1
        };
        rembo_counts.push(evaluations_to_reach(&mut next, optimum, tolerance, budget));
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut best = f64::NEG_INFINITY;
        let mut next = || {
            let w: Vec<f64> = (0..100).map(|_| rng.random::<f64>()).collect();
            best = best.max(problem.reward(&w));
            best
        };
        random_counts.push(evaluations_to_reach(&mut next, optimum, tolerance, budget));
    }
    eprintln!(
        "branin-100d, evaluations to come within {tolerance} of the optimum: \
         rembo-5d {rembo_counts:?}, uniform random {random_counts:?}"
    );
    // Medians, counting a run that never came close as budget + 1.
    let median = |counts: &[Option<usize>]| {
        let mut c: Vec<usize> = counts.iter().map(|c| c.unwrap_or(budget + 1)).collect();
        c.sort();
        (c[c.len() / 2 - 1] + c[c.len() / 2]) as f64 / 2.0
    };
    let (rembo, random) = (median(&rembo_counts), median(&random_counts));
    assert!(
        4.0 * rembo <= random,
        "REMBO needed {rembo} evaluations (median), random search {random}"
    );
    assert!(rembo_counts.iter().filter(|c| c.is_some()).count() >= 7);
}

/// CMA-ES told where its failed laps failed climbs towards laps that get further even while
/// every lap fails (reward 0 throughout, the car getting to x = 0.5 + 0.1·Σw); told only the
/// zeros, it has nothing to follow.
#[test]
fn cmaes_follows_the_failure_places_while_every_lap_fails() {
    let run = |with_places: bool| -> f64 {
        let mut es = Spec::problem(Method::Cmaes, 5.0)
            .unwrap()
            .seed(1)
            .optimizer(vec![0.0; 5])
            .unwrap();
        let mut last = Vec::new();
        for lap in 0..200 {
            let w = es.ask().unwrap();
            let at = (0.5 + 0.1 * w.iter().sum::<f64>()).clamp(0.0, 1.0);
            if with_places {
                es.tell_lap(&w, 0.0, Some(FailedLap::too_fast(at))).unwrap();
            } else {
                es.tell(&w, 0.0).unwrap();
            }
            if lap >= 180 {
                last.push(w.iter().sum::<f64>());
            }
        }
        last.iter().sum::<f64>() / last.len() as f64
    };
    let (with, without) = (run(true), run(false));
    eprintln!(
        "mean sum of weights over the last 20 laps: with places {with:.3}, without {without:.3}"
    );
    assert!(with > 3.0, "{with}");
    // (Σw = 5 is x = 1: the end of the lap.)
    assert!(without < 1.5, "{without}");
}

/// The largest |wᵢ − w₀ᵢ| (max norm) and Euclidean distance from w₀ over `laps` laps scored
/// by `reward`.
fn reach(spec: Spec, w0: &[f64], laps: usize, reward: impl Fn(&[f64]) -> f64) -> (f64, f64) {
    let mut opt = spec.optimizer(w0.to_vec()).unwrap();
    let (mut max_norm, mut euclid) = (0.0f64, 0.0f64);
    for _ in 0..laps {
        let w = opt.ask().unwrap();
        let d: Vec<f64> = w.iter().zip(w0).map(|(a, b)| a - b).collect();
        max_norm = max_norm.max(d.iter().fold(0.0, |m, x| m.max(x.abs())));
        euclid = euclid.max(d.iter().map(|x| x * x).sum::<f64>().sqrt());
        opt.tell(&w, reward(&w)).unwrap();
    }
    (max_norm, euclid)
}

/// Each method's main knob reaches its optimiser and bounds how far it moves from w₀, against
/// the published setting in the same box (r = 1.5, 12 weights): TuRBO's initial design lies in
/// its first region, w₀ ± L_init·r; LineBO's laps lie within the step of the line's origin (w₀,
/// while every lap fails); REMBO's y lie in [−b, b]^d, so |Δwᵢ| ≤ r·b·Σⱼ|Aᵢⱼ| (on a reward
/// rising with Σw, whose EI maximum lies on the box's edge).
#[test]
fn each_methods_knob_reaches_its_optimiser() {
    let w0: Vec<f64> = (0..12).map(|i| 0.1 * i as f64 - 0.4).collect();
    let race = |m| Spec::race(m).seed(3);
    let with = |m, v| race(m).knob(v).unwrap();
    let as_published = |m: Method| race(m).knob(m.knob().published).unwrap();
    let failing = |_: &[f64]| 0.0;
    let rising = |w: &[f64]| 10.0 + w.iter().sum::<f64>();
    // TuRBO: 10 design points (w₀ and 9 in the region) at L_init 0.1: within 0.15 of w₀.
    let (tuned, _) = reach(with(Method::Turbo, 0.1), &w0, 10, failing);
    let (published, _) = reach(as_published(Method::Turbo), &w0, 10, failing);
    assert!(
        tuned <= 0.1 * 1.5 + 1e-12 && tuned > 0.05,
        "TuRBO at L_init 0.1: {tuned}"
    );
    assert!(published > 0.5, "TuRBO at 0.8: {published}");
    // LineBO at step 0.05: every lap within 0.05 of w₀.
    let (_, tuned) = reach(with(Method::Linebo, 0.05), &w0, 12, failing);
    let (_, published) = reach(as_published(Method::Linebo), &w0, 12, failing);
    assert!(
        tuned <= 0.05 + 1e-12 && tuned > 0.01,
        "LineBO at step 0.05: {tuned}"
    );
    assert!(published > 0.5, "LineBO on the whole line: {published}");
    // REMBO-5d at b = 0.002: |Δwᵢ| ≤ 1.5·0.002·Σⱼ|Aᵢⱼ| (5 standard normals: well under 0.1).
    for m in [Method::Rembo5d, Method::Rembo10d] {
        let (tuned, _) = reach(with(m, 0.002), &w0, 15, rising);
        let (published, _) = reach(as_published(m), &w0, 15, rising);
        assert!(tuned < 0.1 && tuned > 0.0, "{m} at b 0.002: {tuned}");
        assert!(published > 0.5, "{m} at √d: {published}");
    }
    // The σ₀ methods: the knob is σ₀.
    assert_eq!(with(Method::Random, 0.2).sigma0_value(), 0.2);
    assert_eq!(
        race(Method::Random).sigma0_value(),
        Method::Random.knob().value
    );
    assert_eq!(
        race(Method::Turbo).knob_value(),
        Some(Method::Turbo.knob().value)
    );
}

/// A value a method cannot take is refused naming the method, its knob and the range.
#[test]
fn bad_knob_values_are_refused_naming_the_knob() {
    for (m, v) in [
        (Method::Turbo, 2.0),
        (Method::Turbo, 0.0),
        (Method::Linebo, -0.1),
        (Method::Rembo5d, f64::NAN),
        (Method::Random, f64::INFINITY),
    ] {
        let e = Spec::race(m).knob(v).unwrap_err().to_string();
        assert!(
            e.contains(m.name()) && e.contains(m.knob().kind.name()),
            "{m} {v}: {e}"
        );
    }
    let e = Spec::race(Method::Turbo).knob(1.7).unwrap_err().to_string();
    assert!(e.contains("(0, 1.6]"), "{e}");
}
