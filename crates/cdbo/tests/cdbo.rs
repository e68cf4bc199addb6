//! CDBO against random search on standard problems, determinism, resume and bad input.

use cdbo::benchmarks::{ackley, hartmann6, rosenbrock};
use cdbo::optimizers::cdbo::{Cdbo, CdboConfig};
use cdbo::optimizers::{Optimizer, SearchBox, rng_for};
use rand_distr::{Distribution, Normal};

/// Runs `evals` evaluations of `f` and returns the best value.
fn run(opt: &mut dyn Optimizer, f: &dyn Fn(&[f64]) -> f64, evals: usize) -> f64 {
    for _ in 0..evals {
        let w = opt.ask().unwrap();
        opt.tell(&w, f(&w)).unwrap();
    }
    opt.best().unwrap().1
}

/// Gaussian random search around the start, clamped to the box, same budget.
fn random_search(
    w0: &[f64],
    radius: f64,
    f: &dyn Fn(&[f64]) -> f64,
    evals: usize,
    seed: u64,
) -> f64 {
    let bounds = SearchBox::around(w0, radius).unwrap();
    let normal = Normal::new(0.0, radius / 3.0).unwrap();
    let mut best = f(w0);
    for k in 1..evals {
        let mut rng = rng_for(seed ^ 0xABCD, k as u64);
        let mut w: Vec<f64> = w0.iter().map(|v| v + normal.sample(&mut rng)).collect();
        bounds.clamp(&mut w);
        best = best.max(f(&w));
    }
    best
}

fn compare(name: &str, w0: Vec<f64>, radius: f64, f: &dyn Fn(&[f64]) -> f64, evals: usize) {
    let seeds = 10;
    let (mut cdbo_sum, mut random_sum) = (0.0, 0.0);
    for seed in 0..seeds {
        let config = CdboConfig {
            seed,
            box_radius: radius,
            ..CdboConfig::default()
        };
        let mut opt = Cdbo::new(w0.clone(), config).unwrap();
        cdbo_sum += run(&mut opt, f, evals);
        random_sum += random_search(&w0, radius, f, evals, seed);
    }
    let (c, r) = (cdbo_sum / seeds as f64, random_sum / seeds as f64);
    eprintln!(
        "{name}: CDBO {c:.4}, random {r:.4} (mean best of {seeds} seeds, {evals} evaluations)"
    );
    assert!(c > r, "{name}: CDBO {c} did not beat random search {r}");
}

#[test]
fn cdbo_beats_random_search_on_hartmann6_in_100d() {
    let dims = [3, 17, 42, 58, 71, 90];
    let f = move |w: &[f64]| hartmann6(&dims.map(|d| w[d]));
    compare("hartmann6-in-100d", vec![0.5; 100], 0.5, &f, 60);
}

#[test]
fn cdbo_beats_random_search_on_rosenbrock20_and_ackley20() {
    compare("rosenbrock-20", vec![-0.5; 20], 2.0, &rosenbrock, 60);
    compare("ackley-20", vec![1.2; 20], 2.0, &ackley, 60);
}

#[test]
fn same_seed_same_run_and_resume_continues_it() {
    let w0 = vec![0.3; 12];
    let f = |w: &[f64]| ackley(w) + 30.0;
    let config = CdboConfig {
        seed: 42,
        initial_samples: 5,
        ..CdboConfig::default()
    };
    let mut a = Cdbo::new(w0.clone(), config.clone()).unwrap();
    let mut b = Cdbo::new(w0.clone(), config).unwrap();
    let mut asked = Vec::new();
    for i in 0..25 {
        let (wa, wb) = (a.ask().unwrap(), b.ask().unwrap());
        assert_eq!(wa, wb, "step {i}");
        assert_eq!(
            a.ask().unwrap(),
            wa,
            "asking twice returns the pending point"
        );
        a.tell(&wa, f(&wa)).unwrap();
        b.tell(&wb, f(&wb)).unwrap();
        asked.push(wa);
    }
    // Save and resume mid-run: the next suggestion is the same.
    let saved = serde_json::to_string(a.state()).unwrap();
    let state: cdbo::optimizers::cdbo::CdboState = serde_json::from_str(&saved).unwrap();
    assert_eq!(&state, a.state(), "the JSON state round-trips exactly");
    let mut resumed = Cdbo::resume(state).unwrap();
    assert_eq!(resumed.ask().unwrap(), a.ask().unwrap());
    assert_eq!(resumed.best().unwrap().1, a.best().unwrap().1);
}

#[test]
fn bad_tells_are_refused_and_change_nothing() {
    let mut opt = Cdbo::new(vec![0.0; 4], CdboConfig::default()).unwrap();
    let w = opt.ask().unwrap();
    assert!(
        opt.tell(&w[..3], 1.0)
            .unwrap_err()
            .to_string()
            .contains("expected 4 weights")
    );
    assert!(opt.tell(&w, f64::NAN).is_err());
    assert!(opt.tell(&w, f64::INFINITY).is_err());
    assert!(opt.tell(&[0.0, f64::NAN, 0.0, 0.0], 1.0).is_err());
    assert_eq!(opt.evaluations(), 0);
    assert_eq!(opt.ask().unwrap(), w);
    assert!(Cdbo::new(vec![], CdboConfig::default()).is_err());
    assert!(Cdbo::new(vec![f64::NAN], CdboConfig::default()).is_err());
}
