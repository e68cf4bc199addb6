//! The pattern search with failure repair: its repair move, its save/resume with failure
//! places, and a lap with a cliff on which it must beat random search.

use cdbo::learner::pattern_search::{PatternSearch, PatternSearchConfig, push};
use cdbo::method::{Method, Spec, resume};
use cdbo::optimizers::{FailedLap, Optimizer, Saved};
use cdbo::policy::RkhsPolicy;
use cdbo::policy::rkhs::default_lengthscale;

/// `method` as it races, with this seed and β = 2.
fn race_spec(method: Method, seed: u64) -> Spec {
    Spec::told(method, seed, 2.0, None).unwrap()
}

/// A toy lap with a cliff: D segments driven in order at speeds wᵢ; segment i takes at most
/// cᵢ = 0.5 + 0.4·sin²(i). Too fast (wᵢ > cᵢ) or stopped (wᵢ ≤ 0.05), the car fails there, at
/// x = i/(D − 1); otherwise the reward is the mean speed D / Σ 1/wᵢ. The optimum, wᵢ = cᵢ,
/// lies on the cliff's edge.
fn cliff_lap(w: &[f64]) -> (f64, Option<f64>) {
    let last = (w.len() - 1) as f64;
    let mut time = 0.0;
    for (i, &v) in w.iter().enumerate() {
        if v > cap(i) || v <= 0.05 {
            return (0.0, Some(i as f64 / last));
        }
        time += 1.0 / v;
    }
    (w.len() as f64 / time, None)
}

fn cap(i: usize) -> f64 {
    0.5 + 0.4 * (i as f64).sin().powi(2)
}

/// Asks and tells `evals` laps of the cliff, with the failure places; returns the asked weights.
fn drive(opt: &mut dyn Optimizer, evals: usize) -> Vec<Vec<f64>> {
    (0..evals)
        .map(|_| {
            let w = opt.ask().unwrap();
            let (reward, at) = cliff_lap(&w);
            opt.tell_lap(&w, reward, at.map(FailedLap::too_fast))
                .unwrap();
            w
        })
        .collect()
}

/// A search from w = 0 (`n` weights) whose start lap was told a reward of 1.
fn started(n: usize, config: PatternSearchConfig) -> PatternSearch {
    let mut ps = PatternSearch::new(vec![0.0; n], config).unwrap();
    let start = ps.ask().unwrap();
    ps.tell_lap(&start, 1.0, None).unwrap();
    ps
}

/// The best reward of a method on the 20-segment cliff from wᵢ = 0.2, 200 laps.
fn best_on_cliff(method: &str, seed: u64) -> f64 {
    let mut opt = race_spec(method.parse().unwrap(), seed)
        .optimizer(vec![0.2; 20])
        .unwrap();
    drive(opt.as_mut(), 200);
    opt.best().unwrap().1
}

/// Over 10 seeds, the pattern search beats Gaussian random search around the best point (the
/// same start, box and σ₀) on the cliff, and comes within 10 % of the optimum.
#[test]
fn pattern_search_beats_random_search_next_to_a_cliff() {
    let optimum = 20.0 / (0..20).map(|i| 1.0 / cap(i)).sum::<f64>();
    let mean = |method| (0..10).map(|s| best_on_cliff(method, s)).sum::<f64>() / 10.0;
    let (ps, random) = (mean("pattern-search"), mean("random"));
    eprintln!("cliff: optimum {optimum:.4}, pattern-search {ps:.4}, random {random:.4}");
    assert!(ps > random, "pattern search {ps} <= random search {random}");
    assert!(ps > 0.9 * optimum, "pattern search {ps}, optimum {optimum}");
}

/// A lap that fails past the moved weight is repaired: the next lap gives half the step back
/// at the kernel just before the failure; a failure at or before the moved weight is not.
#[test]
fn a_failed_lap_is_repaired_before_where_it_failed() {
    let config = PatternSearchConfig {
        sigma0: 0.1,
        block: 1,
        repairs: 1,
        ..PatternSearchConfig::default()
    };
    for seed in 0..8 {
        let mut ps = started(
            5,
            PatternSearchConfig {
                seed,
                ..config.clone()
            },
        );
        let w = ps.ask().unwrap();
        let moved = w.iter().position(|&v| v != 0.0).unwrap();
        assert_eq!(w[moved], 0.1);
        // A failure at x = 1 lies in kernel 4's span: kernel 3 brakes before it.
        ps.tell_lap(&w, 0.0, Some(FailedLap::too_fast(1.0)))
            .unwrap();
        let next = ps.ask().unwrap();
        if moved < 3 {
            let mut repair = w.clone();
            repair[3] -= 0.05;
            assert_eq!(next, repair, "seed {seed}");
        } else {
            assert_eq!(next.iter().filter(|&&v| v != 0.0).count(), 1, "{next:?}");
            assert!(next[moved] == 0.0, "seed {seed}: {next:?}");
        }
    }
}

/// A repaired lap that fails again at or past its give-back is given back there too, the same
/// kernel twice braking twice as hard, up to `repairs` give-backs; then the step is dropped.
#[test]
fn a_repair_that_fails_again_is_repaired_again() {
    let config = PatternSearchConfig {
        sigma0: 0.1,
        block: 1,
        repairs: 3,
        ..PatternSearchConfig::default()
    };
    let mut checked = 0;
    for seed in 0..8 {
        let mut ps = started(
            10,
            PatternSearchConfig {
                seed,
                ..config.clone()
            },
        );
        let w = ps.ask().unwrap();
        let moved = w.iter().position(|&v| v != 0.0).unwrap();
        if moved >= 6 {
            continue;
        }
        checked += 1;
        // Kernel 7's span (x = 7/9): kernel 6 gives half the step back.
        ps.tell_lap(&w, 0.0, Some(FailedLap::too_fast(7.0 / 9.0)))
            .unwrap();
        let mut expected = w.clone();
        expected[6] -= 0.05;
        assert_eq!(ps.ask().unwrap(), expected, "seed {seed}");
        // Failed again further on (x = 1): kernel 8 gives it back too.
        ps.tell_lap(&expected, 0.0, Some(FailedLap::too_fast(1.0)))
            .unwrap();
        expected[8] -= 0.05;
        assert_eq!(ps.ask().unwrap(), expected, "seed {seed}");
        // And again at the same place: kernel 8 brakes twice as hard.
        ps.tell_lap(&expected, 0.0, Some(FailedLap::too_fast(1.0)))
            .unwrap();
        expected[8] -= 0.05;
        assert_eq!(ps.ask().unwrap(), expected, "seed {seed}");
        // A fourth failure drops the step: the next trial leaves the moved weight alone.
        ps.tell_lap(&expected, 0.0, Some(FailedLap::too_fast(1.0)))
            .unwrap();
        let next = ps.ask().unwrap();
        assert_eq!(next[moved], 0.0, "seed {seed}: {next:?}");
        assert_eq!(next.iter().filter(|&&v| v != 0.0).count(), 1, "{next:?}");
    }
    assert!(checked > 0, "no seed moved a weight before kernel 6 first");
}

/// The first sweep moves blocks of `block` adjacent weights together, the next ones half as
/// wide, down to single weights.
#[test]
fn sweeps_narrow_their_blocks() {
    let mut ps = started(
        16,
        PatternSearchConfig {
            sigma0: 0.1,
            block: 4,
            ..PatternSearchConfig::default()
        },
    );
    // Every trial slower: each block is tried once per sweep, 4 + 8 + 16 trials.
    let mut widths = Vec::new();
    for _ in 0..28 {
        let w = ps.ask().unwrap();
        let moved: Vec<usize> = (0..16).filter(|&k| w[k] != 0.0).collect();
        assert!(moved.windows(2).all(|p| p[1] == p[0] + 1), "{moved:?}");
        widths.push(moved.len());
        ps.tell_lap(&w, 0.5, None).unwrap();
    }
    assert_eq!(widths, [[4; 4].as_slice(), &[2; 8], &[1; 16]].concat());
}

/// Same seed, same laps; a search saved mid-run (failure places told) resumes bit for bit.
#[test]
fn pattern_search_is_deterministic_and_resumes_exactly() {
    let new = || {
        race_spec(Method::PatternSearch, 3)
            .optimizer(vec![0.2; 12])
            .unwrap()
    };
    let (mut a, mut b) = (new(), new());
    assert_eq!(drive(a.as_mut(), 40), drive(b.as_mut(), 40));
    let pending = a.ask().unwrap();
    let saved: Saved = serde_json::from_str(&serde_json::to_string(&a.save()).unwrap()).unwrap();
    let mut resumed = resume(saved).unwrap();
    assert_eq!(resumed.ask().unwrap(), pending);
    assert_eq!(drive(a.as_mut(), 30), drive(resumed.as_mut(), 30));
    assert_eq!(a.best(), resumed.best());
}

/// A failure place outside [0, 1] is refused and changes nothing.
#[test]
fn a_bad_failure_place_is_refused() {
    let mut ps = race_spec(Method::PatternSearch, 0)
        .optimizer(vec![0.2; 4])
        .unwrap();
    let w = ps.ask().unwrap();
    let before = ps.save();
    for at in [-0.1, 1.5, f64::NAN] {
        assert!(ps.tell_lap(&w, 0.0, Some(FailedLap::too_fast(at))).is_err());
    }
    assert_eq!(ps.save(), before);
}

/// A lap that fails past a step of less pedal is not repaired (braking more did not make the
/// car too fast for what follows): the step reverses and halves, and the next block is tried.
#[test]
fn a_failure_after_less_pedal_is_not_repaired() {
    let mut checked = 0;
    for seed in 0..8 {
        let mut ps = started(
            5,
            PatternSearchConfig {
                seed,
                sigma0: 0.1,
                block: 1,
                sharpen: false,
                ..PatternSearchConfig::default()
            },
        );
        // A slower lap on every weight: each step reverses to −σ₀/2 for the next sweep.
        for _ in 0..5 {
            let w = ps.ask().unwrap();
            ps.tell_lap(&w, 0.5, None).unwrap();
        }
        let w = ps.ask().unwrap();
        let moved = w.iter().position(|&v| v != 0.0).unwrap();
        assert_eq!(w[moved], -0.05);
        if moved >= 3 {
            continue;
        }
        checked += 1;
        // It fails at x = 1, in kernel 4's span and past the moved weight, where a step of
        // more pedal would be given back at kernel 3: no give-back, the next weight moves.
        ps.tell_lap(&w, 0.0, Some(FailedLap::too_fast(1.0)))
            .unwrap();
        let next = ps.ask().unwrap();
        assert_eq!(
            next.iter().filter(|&&v| v != 0.0).count(),
            1,
            "seed {seed}: {next:?}"
        );
        assert_eq!(next[moved], 0.0, "seed {seed}: {next:?}");
        assert!(
            next.iter().all(|&v| v == 0.0 || v == -0.05),
            "seed {seed}: {next:?}"
        );
    }
    assert!(checked > 0, "no seed moved a weight before kernel 3 first");
}

/// A saved search whose settings are out of range (a corrupt or hand-edited study) is refused
/// when it resumes, naming the setting, as a new one would be.
#[test]
fn a_saved_search_with_a_bad_setting_is_refused() {
    let ps = started(4, PatternSearchConfig::default());
    let saved = ps.save();
    assert_eq!(saved.kind(), "pattern-search");
    let state: cdbo::learner::pattern_search::PatternSearchState =
        saved.state("pattern search").unwrap();
    assert!(PatternSearch::resume(state.clone()).is_ok());
    for (sigma0, give_back) in [
        (f64::NAN, 0.5),
        (-0.1, 0.5),
        (0.1, f64::INFINITY),
        (0.1, 0.0),
    ] {
        let mut bad = state.clone();
        bad.config.sigma0 = sigma0;
        bad.config.give_back = give_back;
        let e = PatternSearch::resume(bad).unwrap_err().to_string();
        assert!(e.contains("σ₀") || e.contains("give-back"), "{e}");
    }
}

/// Once the blocks are single weights, every second sweep moves along
/// dᵢ = eᵢ − ½(eᵢ₋₁ + eᵢ₊₁), each direction once, with its own first step +σ₀.
#[test]
fn every_second_sweep_of_single_weights_sharpens() {
    let n = 6;
    let mut ps = started(
        n,
        PatternSearchConfig {
            sigma0: 0.1,
            block: 2,
            ..PatternSearchConfig::default()
        },
    );
    // Every trial slower: blocks of 2 (3 trials), single weights (6), sharpening (6), single (6).
    let mut sweeps: Vec<Vec<Vec<f64>>> = Vec::new();
    for trials in [3, 6, 6, 6] {
        let sweep = (0..trials)
            .map(|_| {
                let w = ps.ask().unwrap();
                ps.tell_lap(&w, 0.5, None).unwrap();
                w
            })
            .collect();
        sweeps.push(sweep);
    }
    let mut centres: Vec<usize> = sweeps[2]
        .iter()
        .map(|w| {
            let i = w.iter().position(|&v| v == 0.1).unwrap();
            let mut d = vec![0.0; n];
            d[i] = 0.1;
            for k in [i.wrapping_sub(1), i + 1] {
                if k < n {
                    d[k] = -0.05;
                }
            }
            assert_eq!(*w, d, "sharpening along d_{i}");
            i
        })
        .collect();
    centres.sort();
    assert_eq!(centres, (0..n).collect::<Vec<_>>());
    // The single weights' steps reversed and halved in their own sweep.
    for w in &sweeps[3] {
        assert_eq!(w.iter().filter(|&&v| v != 0.0).count(), 1, "{w:?}");
        assert!(w.iter().all(|&v| v == 0.0 || v == -0.05), "{w:?}");
    }
}

/// A search saved before sharpening sweeps existed (no `sharpen`, `sharpening`, `sharp_steps`)
/// resumes as it was: with single-weight sweeps only, lap for lap as a search without them.
#[test]
fn a_search_saved_before_sharpening_resumes_without_it() {
    let config = PatternSearchConfig {
        sigma0: 0.1,
        block: 1,
        sharpen: false,
        ..PatternSearchConfig::default()
    };
    resumes_as_saved_without(config, &["sharpening", "sharp_steps"], "sharpen", 60);
}

/// A search with `config` (whose newer feature is off), saved as an older version wrote it —
/// without the `state_keys` and the `config_key` — resumes lap for lap as it was.
fn resumes_as_saved_without(
    config: PatternSearchConfig,
    state_keys: &[&str],
    config_key: &str,
    laps: usize,
) {
    let mut old = started(10, config);
    let mut json = serde_json::to_value(old.save()).unwrap();
    let state = json["state"].as_object_mut().unwrap();
    for key in state_keys {
        assert!(state.remove(*key).is_some(), "no {key} in {state:?}");
    }
    let config_json = state["config"].as_object_mut().unwrap();
    assert!(config_json.remove(config_key).is_some(), "no {config_key}");
    let saved: Saved = serde_json::from_value(json).unwrap();
    let mut resumed = resume(saved).unwrap();
    assert_eq!(drive(&mut old, laps), drive(resumed.as_mut(), laps));
}

/// A direction whose step of more pedal failed sits out the next sweep, after a second such
/// failure (no faster lap between) the next two; a slower lap or less pedal rests nothing.
#[test]
fn a_failed_step_of_more_pedal_rests_its_direction() {
    let n = 6;
    let mut ps = started(
        n,
        PatternSearchConfig {
            sigma0: 0.1,
            block: 1,
            sharpen: false,
            ..PatternSearchConfig::default()
        },
    );
    // One sweep; weight 2's lap fails before it (no repair), every other lap is slower.
    let mut sweep = |trials: usize| -> Vec<f64> {
        (0..trials)
            .filter_map(|_| {
                let w = ps.ask().unwrap();
                let moved = w.iter().position(|&v| v != 0.0).unwrap();
                let fails = moved == 2 && w[2] > 0.0;
                let (reward, at) = if fails { (0.0, Some(0.0)) } else { (0.5, None) };
                ps.tell_lap(&w, reward, at.map(FailedLap::too_fast))
                    .unwrap();
                (moved == 2).then_some(w[2])
            })
            .collect()
    };
    assert_eq!(sweep(n), [0.1]); // fails: rests one sweep
    assert_eq!(sweep(n - 1), [0.0; 0]);
    assert_eq!(sweep(n), [-0.05]); // less pedal, slower: no rest
    assert_eq!(sweep(n), [0.025]); // fails again: rests two sweeps
    assert_eq!(sweep(n - 1), [0.0; 0]);
    assert_eq!(sweep(n - 1), [0.0; 0]);
    assert_eq!(sweep(n), [-0.0125]);
}

/// A search saved before rests existed (no `rest`, `rests`, `sharp_rests`) resumes as it was:
/// without rests, lap for lap as a search without them.
#[test]
fn a_search_saved_before_rests_resumes_without_them() {
    let config = PatternSearchConfig {
        sigma0: 0.1,
        block: 2,
        rest: false,
        ..PatternSearchConfig::default()
    };
    resumes_as_saved_without(config, &["rests", "sharp_rests"], "rest", 120);
}

/// A toy lap over a policy's pedal: the speed integrates the pedal, v ← v + 0.01·π(x) over
/// 400 steps from v = 1, and the car fails at the first x where v > c(x) = 1.6 + 0.5·sin(6πx)
/// (too fast for the corner there) or v < 0.1 (stalled: too slow); a completed lap's reward is
/// its mean speed, 400 / Σ 1/v. The best pedal brakes just enough before each corner.
fn pedal_lap(w: &[f64], lengthscale: f64) -> (f64, Option<FailedLap>) {
    let policy = RkhsPolicy::new(w.to_vec(), lengthscale).unwrap();
    let n = 400;
    let (mut v, mut time) = (1.0, 0.0);
    for k in 0..n {
        let x = k as f64 / (n - 1) as f64;
        v += 0.01 * policy.action(x);
        if v > 1.6 + 0.5 * (6.0 * std::f64::consts::PI * x).sin() {
            return (0.0, Some(FailedLap::too_fast(x)));
        }
        if v < 0.1 {
            return (
                0.0,
                Some(FailedLap {
                    at: x,
                    too_slow: true,
                }),
            );
        }
        time += 1.0 / v;
    }
    (n as f64 / time, None)
}

/// A race's pattern search on a 12-kernel policy (told its length-scale) from π = 0.
fn pushing(seed: u64) -> (Box<dyn Optimizer + Send>, f64) {
    let l = default_lengthscale(12);
    (
        race_spec(Method::PatternSearch, seed)
            .policy(l)
            .unwrap()
            .optimizer(vec![0.0; 12])
            .unwrap(),
        l,
    )
}

fn drive_pedal(opt: &mut dyn Optimizer, l: f64, laps: usize) -> Vec<(Vec<f64>, f64)> {
    (0..laps)
        .map(|_| {
            let w = opt.ask().unwrap();
            let (reward, failure) = pedal_lap(&w, l);
            opt.tell_lap(&w, reward, failure).unwrap();
            (w, reward)
        })
        .collect()
}

/// Told the policy's length-scale, the search pushes the whole pedal after the start lap and
/// repairs the pushed lap where it fails until it completes: on the pedal cliff, a lap faster
/// than the start within the push's laps, whose pedal is raised nearly everywhere; without the
/// length-scale its second lap moves one block only.
#[test]
fn the_push_raises_the_pedal_and_repairs_it_until_the_lap_completes() {
    let (mut opt, l) = pushing(4);
    let laps = drive_pedal(opt.as_mut(), l, 1 + push::LAPS);
    let first = RkhsPolicy::new(laps[1].0.clone(), l).unwrap();
    assert!(
        (0..=20).all(|k| first.action(k as f64 / 20.0) > 0.25),
        "the first push is not raised everywhere"
    );
    assert_eq!(laps[1].1, 0.0, "π = U₀ takes the first corner too fast");
    let completed = laps
        .iter()
        .skip(1)
        .position(|l| l.1 > 0.0)
        .expect("no pushed lap completed");
    assert!(
        laps[1 + completed].1 > laps[0].1 + 0.1,
        "{} against {}",
        laps[1 + completed].1,
        laps[0].1
    );

    let mut plain = race_spec(Method::PatternSearch, 4)
        .optimizer(vec![0.0; 12])
        .unwrap();
    let laps = drive_pedal(plain.as_mut(), l, 2);
    assert_eq!(
        laps[1].0.iter().filter(|&&v| v != 0.0).count(),
        8,
        "blocks of 8 first"
    );
}

/// After a kept push the sweeps begin at single weights: once the pushes are done, each step
/// moves one weight of the best by σ₀.
#[test]
fn after_a_kept_push_the_sweeps_move_single_weights() {
    let (mut opt, l) = pushing(2);
    let laps = drive_pedal(opt.as_mut(), l, 200);
    let sigma0 = Method::PatternSearch.knob().value;
    // The first lap after the pushes that differs from the best lap before it in one weight
    // by σ₀.
    let mut best = laps[0].clone();
    let single = laps.iter().skip(1).any(|(w, r)| {
        let moved: Vec<f64> = w
            .iter()
            .zip(&best.0)
            .map(|(a, b)| a - b)
            .filter(|d| *d != 0.0)
            .collect();
        let is_single = moved.len() == 1 && (moved[0] - sigma0).abs() < 1e-12;
        if *r > best.1 {
            best = (w.clone(), *r);
        }
        is_single
    });
    assert!(single, "no single-weight step of σ₀ in 200 laps");
    assert!(
        best.1 > laps[0].1 + 0.08,
        "{} against {}",
        best.1,
        laps[0].1
    );
}

/// A push whose lap completes slower than the best is not kept; the next lap is then the next
/// push, the best lap's pedal raised by about U₀/4 everywhere (push 3 after kept push 1 and
/// unkept push 2), not a step of one weight. A search saved before that rule (no
/// `push_after_unkept`) ends its pushes there and steps one weight by σ₀.
#[test]
fn a_push_not_kept_is_followed_by_the_next() {
    let l = default_lengthscale(12);
    let config = PatternSearchConfig {
        sigma0: 0.1,
        lengthscale: Some(l),
        ..PatternSearchConfig::default()
    };
    assert!(config.push_after_unkept);
    let third_lap = |config: PatternSearchConfig| {
        let mut ps = started(12, config);
        let first = ps.ask().unwrap();
        ps.tell_lap(&first, 2.0, None).unwrap();
        let second = ps.ask().unwrap();
        ps.tell_lap(&second, 1.5, None).unwrap();
        (first, ps.ask().unwrap())
    };
    let (kept, next) = third_lap(config.clone());
    let (kept, next) = (
        RkhsPolicy::new(kept, l).unwrap(),
        RkhsPolicy::new(next, l).unwrap(),
    );
    let quarter = push::SIZE / 4.0;
    for k in 1..20 {
        let x = k as f64 / 20.0;
        let raised = next.action(x) - kept.action(x);
        assert!(
            (raised - quarter).abs() < push::JITTER * quarter + 0.01,
            "at x = {x}: raised {raised}, U₀/4 = {quarter}"
        );
    }
    let (kept, next) = third_lap(PatternSearchConfig {
        push_after_unkept: false,
        ..config
    });
    let moved: Vec<f64> = next
        .iter()
        .zip(&kept)
        .map(|(a, b)| a - b)
        .filter(|d| *d != 0.0)
        .collect();
    assert_eq!(moved.len(), 1, "{moved:?}");
    assert!((moved[0].abs() - 0.1).abs() < 1e-12, "{moved:?}");
}

/// Saved in the middle of a push, the search resumes bit for bit.
#[test]
fn a_search_saved_mid_push_resumes_exactly() {
    let (mut a, l) = pushing(9);
    drive_pedal(a.as_mut(), l, 5);
    let json = serde_json::to_string(&a.save()).unwrap();
    assert!(
        json.contains("\"next\":\"Push\""),
        "not in a push after 5 laps"
    );
    let mut resumed = resume(serde_json::from_str::<Saved>(&json).unwrap()).unwrap();
    assert_eq!(
        drive_pedal(a.as_mut(), l, 80),
        drive_pedal(resumed.as_mut(), l, 80)
    );
    assert_eq!(a.best(), resumed.best());
}

/// A search saved before pushes existed (no `push` in its settings, no `push` or `pushed` in
/// its state) resumes as it was.
#[test]
fn a_search_saved_before_pushes_resumes_without_them() {
    let config = PatternSearchConfig {
        sigma0: 0.1,
        push: 0.0,
        lengthscale: Some(default_lengthscale(10)),
        ..PatternSearchConfig::default()
    };
    resumes_as_saved_without(config, &["push", "pushed"], "push", 80);
}

/// A saved push that this code could not have made — a push number of 0 or past the last, a
/// non-finite target, a step of 0, too few targets, no length-scale — is refused with the
/// state's shape, not driven.
#[test]
fn a_saved_push_that_cannot_be_is_refused() {
    let (mut opt, l) = pushing(9);
    drive_pedal(opt.as_mut(), l, 3);
    let saved = opt.save();
    assert_eq!(saved.kind(), "pattern-search");
    let state: cdbo::learner::pattern_search::PatternSearchState =
        saved.state("pattern search").unwrap();
    assert!(PatternSearch::resume(state.clone()).is_ok());
    let corrupt: [fn(&mut cdbo::learner::pattern_search::PatternSearchState); 6] = [
        |s| s.push.as_mut().unwrap().number = 0,
        |s| s.push.as_mut().unwrap().number = u32::MAX,
        |s| s.push.as_mut().unwrap().targets[7] = f64::NAN,
        |s| s.push.as_mut().unwrap().repair.step = 0.0,
        |s| {
            s.push.as_mut().unwrap().targets.pop();
        },
        |s| s.config.lengthscale = None,
    ];
    for (k, spoil) in corrupt.iter().enumerate() {
        let mut bad = state.clone();
        spoil(&mut bad);
        let e = PatternSearch::resume(bad).unwrap_err().to_string();
        assert!(e.contains("push targets"), "case {k}: {e}");
    }
}

/// On the pedal cliff (a lap policy, its length-scale told), over 10 seeds and 150 laps, the
/// pattern search with its push beats Gaussian random search around the best point from the
/// same start in the same box, each at its race knob, on every seed.
#[test]
fn with_the_push_it_beats_random_search_on_the_pedal_cliff() {
    let l = default_lengthscale(12);
    let best = |method: Method, seed: u64| {
        let spec = race_spec(method, seed).policy(l).unwrap();
        let mut opt = spec.optimizer(vec![0.0; 12]).unwrap();
        drive_pedal(opt.as_mut(), l, 150);
        opt.best().unwrap().1
    };
    for seed in 0..10 {
        let (ps, random) = (
            best(Method::PatternSearch, seed),
            best(Method::Random, seed),
        );
        assert!(
            ps > random,
            "seed {seed}: pattern search {ps} against random search {random}"
        );
    }
}

/// A study told the lap's length drives the laps `cdbo race` drives, lap for lap (its push
/// repairs over the same road); one created without it repairs over two kernel spacings and
/// parts ways with the race once a pushed lap fails.
#[test]
fn a_study_told_the_laps_length_drives_the_races_laps() {
    use cdbo::evaluator::Outcome;
    use cdbo::experiment::race::{RaceConfig, race};
    use cdbo::study::{Study, StudyConfig};

    let track = || cdbo::track::builtin::load("ridgeway").unwrap().unwrap();
    let car = cdbo::car::Car::spirit_300();
    let config = RaceConfig {
        method: Method::PatternSearch,
        kernels: 12,
        laps: 25,
        seed: 3,
        ..RaceConfig::default()
    };
    let venue = cdbo::venue::Venue::simulator(track(), &car);
    let raced = race(&venue, &track(), &car, &config, |_| {}).unwrap();
    let race_rewards: Vec<f64> = raced.laps.iter().map(|l| l.reward_mps).collect();
    assert!(race_rewards[1..].contains(&0.0), "no pushed lap failed");
    let sim = cdbo::sim::Simulator::new(track(), &car);
    let length = sim.track.length;
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("study_like_race");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (name, track_length) in [("told", Some(length)), ("untold", None)] {
        let mut study = Study::create(
            &dir.join(format!("{name}.cdbo.db")),
            StudyConfig {
                method: config.method,
                kernels: config.kernels,
                lengthscale: raced.initial.pedal.lengthscale,
                seed: config.seed,
                beta: config.beta,
                w0: raced.initial.weights(),
                track: None,
                track_length,
                knob: None,
                max_failed_laps: None,
                box_radius: None,
                warm_start: None,
                line_kernels: None,
                base_line: Default::default(),
                steering: Default::default(),
            },
        )
        .unwrap();
        let rewards: Vec<f64> = (0..config.laps)
            .map(|_| {
                let trial = study.ask().unwrap();
                let policy =
                    RkhsPolicy::new(trial.weights, raced.initial.pedal.lengthscale).unwrap();
                let lap = sim.lap(&mut policy.pedal());
                study
                    .tell(trial.id, &Outcome::of_lap(&lap, length))
                    .unwrap()
            })
            .collect();
        assert_eq!(
            rewards == race_rewards,
            track_length.is_some(),
            "{name}: {rewards:?} against the race's {race_rewards:?}"
        );
    }
}

/// With a line ([`cdbo::policy::actions`]) the weights are two blocks [w_a, w_d]: every trial
/// (the push, the blocks of a sweep, the sharpening directions, the repairs) moves the
/// weights of one action only, and the push moves the pedal's.
#[test]
fn a_search_with_a_line_moves_one_action_at_a_time() {
    let (pedal, line) = (12, 6);
    let config = PatternSearchConfig {
        lengthscale: Some(default_lengthscale(pedal)),
        pedal_kernels: Some(pedal),
        ..PatternSearchConfig::default()
    };
    let mut ps = PatternSearch::new(vec![0.1; pedal + line], config).unwrap();
    // A lap whose pedal above 0.6 anywhere fails there; else faster the nearer the line to 1 m.
    let lap = |w: &[f64]| {
        let policy = RkhsPolicy::new(w[..pedal].to_vec(), default_lengthscale(pedal)).unwrap();
        let fail = (0..=200)
            .map(|i| i as f64 / 200.0)
            .find(|&x| policy.action(x) > 0.6);
        let line: f64 = w[pedal..].iter().map(|d| (d - 1.0).powi(2)).sum();
        let pedal_sum: f64 = w[..pedal].iter().sum();
        (fail.map_or(10.0 + pedal_sum - line, |_| 0.0), fail)
    };
    let mut moved_line = false;
    for _ in 0..300 {
        let best = ps
            .best()
            .map_or(vec![0.1; pedal + line], |(w, _)| w.to_vec());
        let w = ps.ask().unwrap();
        let changed: Vec<usize> = (0..w.len()).filter(|&k| w[k] != best[k]).collect();
        assert!(
            changed.iter().all(|&k| k < pedal) || changed.iter().all(|&k| k >= pedal),
            "a trial moved both actions: {changed:?}"
        );
        moved_line |= changed.iter().any(|&k| k >= pedal);
        let (reward, at) = lap(&w);
        ps.tell_lap(&w, reward, at.map(FailedLap::too_fast))
            .unwrap();
    }
    let (best, reward) = ps.best().unwrap();
    assert!(moved_line && reward > 10.0, "{reward}");
    assert!(
        best[pedal..].iter().all(|d| (d - 1.0).abs() < 0.5),
        "{best:?}"
    );
}

/// A race with a learned line: w₀'s line is the centre (d = 0), all methods see the joint
/// weights, and the best policy has the pedal's and the line's kernels.
#[test]
fn a_race_learns_a_line_from_the_centre() {
    use cdbo::experiment::race::{RaceConfig, race};
    let track = cdbo::track::builtin::load("ridgeway").unwrap().unwrap();
    let car = cdbo::car::Car::spirit_300();
    let venue = cdbo::venue::Venue::simulator(track.clone(), &car);
    for method in [Method::PatternSearch, Method::Cdbo] {
        let config = RaceConfig {
            method,
            kernels: 12,
            laps: 30,
            line_kernels: Some(8),
            ..RaceConfig::default()
        };
        let raced = race(&venue, &track, &car, &config, |_| {}).unwrap();
        let line = raced.initial.line.as_ref().expect("no line");
        assert_eq!(line.weights, vec![0.0; 8]);
        assert_eq!(raced.best.shape(), config.shape().unwrap());
        assert_eq!(raced.best.weights().len(), 20);
        assert!(raced.best_reward_mps > raced.demo.reward_mps, "{method}");
    }
}

/// A warm-started race starts from the policy it is given: its start is that policy, its first
/// lap that policy's lap in the simulator, bit for bit; a policy of another shape is refused
/// with both shapes named. The pattern search, warm-started, does not push: its second trial
/// moves one weight, where a cold start raises the whole pedal.
#[test]
fn a_warm_started_race_starts_from_its_policy() {
    use cdbo::experiment::race::{RaceConfig, race};

    let track = || cdbo::track::builtin::load("ridgeway").unwrap().unwrap();
    let car = cdbo::car::Car::spirit_300();
    let venue = cdbo::venue::Venue::simulator(track(), &car);
    let learn = RaceConfig {
        method: Method::PatternSearch,
        kernels: 12,
        laps: 20,
        seed: 3,
        ..RaceConfig::default()
    };
    let learned = race(&venue, &track(), &car, &learn, |_| {}).unwrap().best;
    let lap = cdbo::sim::Simulator::new(track(), &car).lap(&mut learned.driver());
    assert!(lap.completed);
    let warm = RaceConfig {
        laps: 3,
        warm_start: Some(learned.clone()),
        ..learn.clone()
    };
    let raced = race(&venue, &track(), &car, &warm, |_| {}).unwrap();
    assert_eq!(raced.initial, learned);
    assert_eq!(
        raced.laps[0].reward_mps.to_bits(),
        lap.reward_mps.to_bits(),
        "{} against {}",
        raced.laps[0].reward_mps,
        lap.reward_mps
    );
    let other = RaceConfig {
        kernels: 10,
        ..warm
    };
    let e = race(&venue, &track(), &car, &other, |_| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("12 kernels") && e.contains("10 kernels"), "{e}");

    // Warm, a completed start is followed by a block of at most 8 weights, where a cold
    // start is pushed (every weight moves); a failed start is repaired before the failure,
    // the start's pedal kept well before it, and saved mid-repair it resumes.
    let w0 = learned.weights();
    let spec = race_spec(Method::PatternSearch, 3)
        .policy(learned.pedal.lengthscale)
        .unwrap();
    let second = |spec: Spec, failure: Option<FailedLap>| {
        let mut search = spec.optimizer(w0.clone()).unwrap();
        let start = search.ask().unwrap();
        assert_eq!(start, w0);
        let reward = if failure.is_some() { 0.0 } else { 30.0 };
        search.tell_lap(&start, reward, failure).unwrap();
        search.ask().unwrap()
    };
    let moved = |w: &[f64]| w.iter().zip(&w0).filter(|(a, b)| a != b).count();
    assert!((1..=8).contains(&moved(&second(spec.warm_started(), None))));
    assert_eq!(moved(&second(spec, None)), w0.len());
    let repaired = second(spec.warm_started(), Some(FailedLap::too_fast(0.8)));
    let pedal = |w: &[f64], x: f64| {
        RkhsPolicy::new(w.to_vec(), learned.pedal.lengthscale)
            .unwrap()
            .raw(x)
    };
    assert!(pedal(&repaired, 0.75) < pedal(&w0, 0.75) - 0.05);
    assert!((pedal(&repaired, 0.1) - pedal(&w0, 0.1)).abs() < 1e-3);
    // A search saved mid-repair resumes to the same trial.
    let mut search = spec.warm_started().optimizer(w0.clone()).unwrap();
    let start = search.ask().unwrap();
    search
        .tell_lap(&start, 0.0, Some(FailedLap::too_fast(0.8)))
        .unwrap();
    let mut again = resume(search.save()).unwrap();
    assert_eq!(again.ask().unwrap(), search.ask().unwrap());
}
