//! Every method behind the `Optimizer` trait: determinism, save/resume, and the qualitative
//! results of the papers that introduced the peers (TuRBO, LineBO, REMBO).

use cdbo::benchmarks::Problem;
use cdbo::optimizers::{METHODS, Optimizer, Saved, Settings, by_name};

fn optimiser(method: &str, problem: &Problem, seed: u64) -> Box<dyn Optimizer + Send> {
    by_name(
        method,
        problem.start.clone(),
        &Settings::problem(seed, problem.radius),
    )
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
    for &method in METHODS {
        let mut a = optimiser(method, &problem, 11);
        let mut b = optimiser(method, &problem, 11);
        let first = drive(a.as_mut(), &problem, 23);
        assert_eq!(first, drive(b.as_mut(), &problem, 23), "{method}");
        // Save mid-run with a pending suggestion, resume from JSON, continue both.
        let pending = a.ask().unwrap();
        let json = serde_json::to_string(&a.save()).unwrap();
        let saved: Saved = serde_json::from_str(&json).unwrap();
        let mut resumed = saved.resume().unwrap();
        assert_eq!(resumed.name(), method);
        assert_eq!(resumed.evaluations(), 23, "{method}");
        assert_eq!(resumed.best(), a.best(), "{method}");
        assert_eq!(resumed.ask().unwrap(), pending, "{method}");
        let rest_a = drive(a.as_mut(), &problem, 12);
        let rest_b = drive(resumed.as_mut(), &problem, 12);
        assert_eq!(rest_a, rest_b, "{method}: resumed run diverged");
    }
}

#[test]
fn every_method_refuses_bad_tells_and_keeps_its_state() {
    let problem = Problem::by_name("ackley", 4).unwrap();
    for &method in METHODS {
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
    assert!(by_name("simplex", vec![0.0], &Settings::problem(0, 1.0)).is_err());
}

/// TuRBO (Eriksson et al. 2019, Fig. 3) and LineBO (Kirschner et al. 2019, Fig. 2) beat
/// random search on Ackley in 20 dimensions; here over 10 seeds of 150 evaluations, against
/// Gaussian random search around the best point.
#[test]
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
