//! CDBO against random search on standard problems, determinism, resume and bad input.

use cdbo::benchmarks::{ackley, hartmann6, rosenbrock};
use cdbo::optimizers::bo::{Bo, BoConfig};
use cdbo::optimizers::{Optimizer, SearchBox, rng_for};
use rand_distr::{Distribution, Normal};

mod common;

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
        let config = BoConfig {
            seed,
            box_radius: radius,
            ..BoConfig::default()
        };
        let mut opt = Bo::new(w0.clone(), config).unwrap();
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
    let config = BoConfig {
        seed: 42,
        initial_samples: 5,
        ..BoConfig::default()
    };
    let mut a = Bo::new(w0.clone(), config.clone()).unwrap();
    let mut b = Bo::new(w0.clone(), config).unwrap();
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
    let state: cdbo::optimizers::bo::BoState = serde_json::from_str(&saved).unwrap();
    assert_eq!(&state, a.state(), "the JSON state round-trips exactly");
    let mut resumed = Bo::resume(state).unwrap();
    assert_eq!(resumed.ask().unwrap(), a.ask().unwrap());
    assert_eq!(resumed.best().unwrap().1, a.best().unwrap().1);
}

#[test]
fn bad_tells_are_refused_and_change_nothing() {
    let mut opt = Bo::new(vec![0.0; 4], BoConfig::default()).unwrap();
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
    assert!(Bo::new(vec![], BoConfig::default()).is_err());
    assert!(Bo::new(vec![f64::NAN], BoConfig::default()).is_err());
}

mod cmaes {
    use cdbo::optimizers::Optimizer;
    use cdbo::optimizers::cmaes::{Cmaes, CmaesConfig};

    fn sphere(x: &[f64]) -> f64 {
        x.iter().map(|v| v * v).sum()
    }

    fn ellipsoid(x: &[f64]) -> f64 {
        let n = x.len() as f64;
        x.iter()
            .enumerate()
            .map(|(i, v)| 1e6f64.powf(i as f64 / (n - 1.0)) * v * v)
            .sum()
    }

    fn rosen(x: &[f64]) -> f64 {
        -cdbo::benchmarks::rosenbrock(x)
    }

    /// Evaluations until f ≤ 1e-8 (minimising f; the optimiser maximises −f).
    fn evals_to_target(
        f: fn(&[f64]) -> f64,
        n: usize,
        x0: f64,
        sigma0: f64,
        seed: u64,
        cap: usize,
    ) -> Option<usize> {
        let mut es = Cmaes::new(
            vec![x0; n],
            CmaesConfig {
                seed,
                sigma0,
                ..CmaesConfig::default()
            },
        )
        .unwrap();
        for k in 1..=cap {
            let x = es.ask().unwrap();
            let v = f(&x);
            es.tell(&x, -v).unwrap();
            if v <= 1e-8 {
                return Some(k);
            }
        }
        None
    }

    fn median_evals(
        f: fn(&[f64]) -> f64,
        n: usize,
        x0: f64,
        sigma0: f64,
        seeds: u64,
        cap: usize,
    ) -> usize {
        let mut v: Vec<usize> = (1..=seeds)
            .map(|s| evals_to_target(f, n, x0, sigma0, s, cap).unwrap_or(usize::MAX))
            .collect();
        v.sort();
        v[v.len() / 2]
    }

    /// Reference: pycma 4.5.0 with CMA_active, x0 = 1 (Rosenbrock 0), σ0 = 1 (0.5), f ≤ 1e-8,
    /// median of seeds 1–5: sphere-10 1350, sphere-50 5955, ellipsoid-10 4000, ellipsoid-50
    /// 74565, Rosenbrock-10 4850 evaluations.
    #[test]
    fn evaluation_counts_are_within_20_percent_of_pycma() {
        for (name, f, n, x0, s0, reference) in [
            (
                "sphere-10",
                sphere as fn(&[f64]) -> f64,
                10,
                1.0,
                1.0,
                1350.0,
            ),
            ("sphere-50", sphere, 50, 1.0, 1.0, 5955.0),
            ("ellipsoid-10", ellipsoid, 10, 1.0, 1.0, 4000.0),
            ("rosenbrock-10", rosen, 10, 0.0, 0.5, 4850.0),
        ] {
            let m = median_evals(f, n, x0, s0, 5, 100_000) as f64;
            eprintln!("{name}: median {m} evaluations (pycma {reference})");
            assert!(
                m <= 1.2 * reference,
                "{name}: {m} evaluations vs pycma's {reference}"
            );
        }
    }

    #[test]
    #[ignore = "slow (3 CMA-ES runs of ~75,000 evaluations in 50-D): .ci/run runs it with --ignored"]
    fn ellipsoid_50_is_within_20_percent_of_pycma() {
        let m = median_evals(ellipsoid, 50, 1.0, 1.0, 3, 200_000) as f64;
        eprintln!("ellipsoid-50: median {m} evaluations (pycma 74565)");
        assert!(m <= 1.2 * 74565.0);
    }

    #[test]
    fn resume_mid_generation_continues_identically() {
        let f = |x: &[f64]| -sphere(x);
        let mut a = Cmaes::new(
            vec![0.7; 6],
            CmaesConfig {
                seed: 5,
                ..CmaesConfig::default()
            },
        )
        .unwrap();
        for _ in 0..23 {
            let x = a.ask().unwrap();
            a.tell(&x, f(&x)).unwrap();
        }
        let saved = serde_json::to_string(&a.save()).unwrap();
        let saved: cdbo::optimizers::Saved = serde_json::from_str(&saved).unwrap();
        let mut b = Cmaes::resume(saved.state("CMA-ES").unwrap()).unwrap();
        for _ in 0..30 {
            let (xa, xb) = (a.ask().unwrap(), b.ask().unwrap());
            assert_eq!(xa, xb);
            a.tell(&xa, f(&xa)).unwrap();
            b.tell(&xb, f(&xb)).unwrap();
        }
    }
}

/// A repeated lap of the deterministic simulator teaches the GP nothing (noise 0), and the
/// next ascent would end on the same weights again: CDBO must never re-drive a lap. Forza with
/// 10 kernels, seed 1 reached that state at lap 12 (every lap after it re-drove π(w₀)) before
/// ascents that end on an observation were rerun with the observations excluded. Over 30 laps
/// (since the road's crests load the car, its first lap faster than the start comes at 24).
#[test]
fn cdbo_never_re_drives_a_lap() {
    let path = common::shared("torcs/tracks/road/forza/forza.xml");
    let track = cdbo::track::torcs::read(&path, cdbo::track::Ends::MustMeet)
        .unwrap_or_else(|e| panic!("{e}"));
    let config = cdbo::experiment::race::RaceConfig {
        kernels: 10,
        laps: 30,
        seed: 1,
        ..Default::default()
    };
    let car = cdbo::car::Car::spirit_300();
    let venue = cdbo::venue::Venue::simulator(track.clone(), &car);
    let outcome = cdbo::experiment::race::race(&venue, &track, &car, &config, |_| {}).unwrap();
    let times: Vec<f64> = outcome.laps.iter().filter_map(|l| l.lap_time_s).collect();
    for (k, t) in times.iter().enumerate() {
        assert!(
            !times[..k].contains(t),
            "lap time {t} s driven twice: {times:?}"
        );
    }
    assert!(outcome.best_reward_mps > outcome.laps[0].reward_mps);
}
