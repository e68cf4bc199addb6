//! What a race or a study costs each method: the estimate that warns of a legal size
//! ([`crate::sizes`]) that will be slow or large.

use super::Method;

/// Seconds the simulator takes over `laps` laps with `kernels` kernels on one free core,
/// roughly: it grows with M² (every driver step sums the kernels near x, the policy fit solves
/// an M × M system). Calibrated on `cdbo race` timings (docs/results/design.md).
fn simulator_seconds(kernels: usize, laps: usize) -> f64 {
    let (m, n) = (kernels as f64, laps as f64);
    n * (0.008 + 2.5e-7 * m * m)
}

/// Seconds `method`'s optimiser takes over `laps` laps with `kernels` weights, given `cdbo(d)`,
/// CDBO's for the same laps in d dimensions. The multiples are those of the optimiser times
/// of the paper's grid (Table 1 of docs/results/results.md: 300 laps, 10 to 100 kernels): LineBO
/// about 2× CDBO's, TuRBO about 9× at every size; REMBO's does not grow with M, as CDBO's in
/// its embedding's 5 or 10 dimensions; BO-CMA-ES adds to CDBO's its CMA-ES over the
/// acquisition, up to 50,000 samples of O(M²) each, 5e-5 · M² s a lap (measured 1.9, 32 and
/// 139 s a run at 10, 50 and 100 kernels; with CDBO's refits this gives 3.7, 40 and 152). CMA-ES, random search
/// and the pattern search fit no GP: their optimiser's time is nothing beside the laps (0.0 s
/// a run in Table 1).
fn optimizer_seconds(
    method: Method,
    kernels: usize,
    laps: usize,
    cdbo: impl Fn(f64) -> f64,
) -> f64 {
    let (m, n) = (kernels as f64, laps as f64);
    match method {
        Method::Cdbo => cdbo(m),
        Method::Linebo => 2.0 * cdbo(m),
        Method::Turbo => 9.0 * cdbo(m),
        Method::Rembo5d => cdbo(5.0),
        Method::Rembo10d => cdbo(10.0),
        Method::BoCmaes => cdbo(m) + 5e-5 * m * m * n,
        Method::Cmaes | Method::Random | Method::PatternSearch | Method::SafePatternSearch => 0.0,
    }
}

/// Whether `method` models the laps with a GP (whose cost grows as laps³).
fn fits_a_gp(method: Method) -> bool {
    !matches!(
        method,
        Method::Cmaes | Method::Random | Method::PatternSearch | Method::SafePatternSearch
    )
}

/// Seconds a race of `laps` laps with `kernels` kernels by `method` takes on one free core,
/// roughly: the simulator's share, and the optimiser's, for CDBO the GP's refits, n³ summed
/// over the laps: 8e-8 · n³ (2.2 s over 300 laps; 1.2 to 2.1 s in Table 1), other methods in
/// proportion (`optimizer_seconds`).
pub fn race_seconds(method: Method, kernels: usize, laps: usize) -> f64 {
    let n = laps as f64;
    simulator_seconds(kernels, laps)
        + optimizer_seconds(method, kernels, laps, |_| 8e-8 * n * n * n)
}

/// Bytes `method`'s optimiser holds at its peak over `laps` laps with `kernels` weights,
/// roughly: a GP, a few n × n matrices (covariance, its factor, a gradient's work space) and
/// the n × M inputs; CMA-ES, three M × M matrices (the covariance, its eigenvectors, the
/// update); random search and the pattern search, a few weight vectors.
pub fn race_bytes(method: Method, kernels: usize, laps: usize) -> f64 {
    let (m, n) = (kernels as f64, laps as f64);
    match method {
        Method::Cmaes => 8.0 * 3.0 * m * m,
        Method::Random | Method::PatternSearch | Method::SafePatternSearch => 8.0 * 4.0 * m,
        _ => 8.0 * (4.0 * n * n + 2.0 * n * m),
    }
}

/// Seconds `method`'s optimiser takes in a study over `laps` suggestions with `kernels`
/// weights on one free core, besides the laps themselves (an external evaluator's time is not
/// cdbo's to know), roughly: one CDBO suggestion over n observations costs about
/// 0.35 µs · M · n (the acquisition's coordinate scans), summed over the laps
/// 1.75e-7 · M · n², and the GP's refits 8e-8 · n³ as in [`race_seconds`]; other methods in
/// proportion (`optimizer_seconds`). Calibrated on `cdbo bench suggest` (both
/// cores busy): 300 observations in 30, 300 and 1000 dimensions, a median 2.9, 28.7 and 110 ms
/// per CDBO suggestion; this gives 3.7 s for CDBO's optimiser over a 300-lap, 100-kernel
/// race, where Forza-100 races measured 4.1–5.0 s under load (the estimate was
/// 15.7 s with the 3 µs of an older build).
pub fn study_seconds(method: Method, kernels: usize, laps: usize) -> f64 {
    let n = laps as f64;
    optimizer_seconds(method, kernels, laps, |d| {
        1.75e-7 * d * n * n + 8e-8 * n * n * n
    })
}

/// The laps a study's warning assumes when none are given (`study create`): the paper's
/// budget.
pub const STUDY_LAPS_ASSUMED: usize = 300;

/// What grows with the size, for a warning: the GP's cost (if `method` fits one), and `rest`.
fn growth(method: Method, rest: &str) -> String {
    let gp = if fits_a_gp(method) {
        "the GP's cost grows as laps³, "
    } else {
        ""
    };
    format!("{method}: {gp}{rest}")
}

/// A warning for a legal race by `method` that will be slow (over a minute) or large (over
/// 1 GiB), with the estimate; `None` for an ordinary one.
pub fn slow_race_warning(method: Method, kernels: usize, laps: usize) -> Option<String> {
    slow_warning(
        race_seconds(method, kernels, laps),
        race_bytes(method, kernels, laps),
        |time, mb| {
            format!(
                "{kernels} kernels and {laps} laps: expect about {time} on one free core and {mb} of memory ({})",
                growth(method, "the simulator's as kernels²")
            )
        },
    )
}

/// A warning for a legal study whose optimiser (`method`) will be slow (over a minute,
/// besides the laps) or large (over 1 GiB) over `laps` laps, with the estimate; `None` for an
/// ordinary one.
pub fn slow_study_warning(method: Method, kernels: usize, laps: usize) -> Option<String> {
    slow_warning(
        study_seconds(method, kernels, laps),
        race_bytes(method, kernels, laps),
        |time, mb| {
            format!(
                "{kernels} kernels and {laps} laps: expect the optimiser to take about {time} on one free core besides the laps themselves, and {mb} of memory ({})",
                growth(method, "each suggestion's as kernels × laps")
            )
        },
    )
}

/// The warning `say(time, memory)` when `seconds` is over a minute or `bytes` over 1 GiB.
fn slow_warning(seconds: f64, bytes: f64, say: impl Fn(&str, &str) -> String) -> Option<String> {
    if seconds < 60.0 && bytes < (1u64 << 30) as f64 {
        return None;
    }
    let time = if seconds < 3600.0 {
        format!("{:.0} min", (seconds / 60.0).ceil())
    } else {
        format!("{:.1} h", seconds / 3600.0)
    };
    Some(say(&time, &format!("{:.0} MB", bytes / 1e6)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_race_is_not_slow_and_a_large_one_is() {
        assert_eq!(slow_race_warning(Method::Cdbo, 30, 300), None);
        assert_eq!(slow_race_warning(Method::Cdbo, 100, 300), None);
        let w = slow_race_warning(Method::Cdbo, 100, 5000).unwrap();
        assert!(w.contains("5000 laps") && w.contains(" h "), "{w}");
        assert!(w.contains("(cdbo: the GP's cost grows as laps³"), "{w}");
        assert!(slow_race_warning(Method::Cdbo, 1000, 300).is_some());
    }

    /// The race's optimiser share against the optimiser times of the paper's grid (Table 1 of
    /// docs/results/results.md, 300 laps, seconds a run): CDBO 1.2–2.1, LineBO 2.0–4.3, TuRBO
    /// 11.4–19.3, REMBO 2.0–4.1 at every size, BO-CMA-ES 1.5–1.9 at 10 kernels and 139 at 100,
    /// CMA-ES and random search 0.0.
    #[test]
    fn the_optimisers_cost_follows_the_measured_run_times() {
        let optimiser = |method, m| race_seconds(method, m, 300) - simulator_seconds(m, 300);
        assert!((optimiser(Method::Cdbo, 100) - 2.16).abs() < 1e-9);
        assert!((optimiser(Method::Linebo, 100) - 4.32).abs() < 1e-9);
        assert!((optimiser(Method::Turbo, 10) - 19.44).abs() < 1e-9);
        assert!((optimiser(Method::Rembo5d, 100) - optimiser(Method::Cdbo, 10)).abs() < 1e-9);
        assert!((optimiser(Method::BoCmaes, 100) - 152.16).abs() < 1e-9);
        assert!((optimiser(Method::BoCmaes, 10) - 3.66).abs() < 1e-9);
        for cheap in [Method::Cmaes, Method::Random, Method::PatternSearch] {
            assert_eq!(optimiser(cheap, 1000), 0.0);
        }
    }

    /// A study's estimate counts only the optimiser: 30 kernels over the paper's 300 laps is
    /// about 3 s, 1000 kernels 18 s (no warning), 1000 kernels over 1000 laps 4.3 min, 100
    /// kernels over 4000 laps 1.5 hours, for CDBO; for random search and the pattern search
    /// nothing at any legal size, and BO-CMA-ES is slow already at the paper's 100 kernels.
    #[test]
    fn a_large_study_is_slow_in_the_optimiser_alone() {
        assert!((study_seconds(Method::Cdbo, 30, 300) - 2.6325).abs() < 1e-9);
        assert_eq!(
            slow_study_warning(Method::Cdbo, 30, STUDY_LAPS_ASSUMED),
            None
        );
        assert_eq!(
            slow_study_warning(Method::Cdbo, 1000, STUDY_LAPS_ASSUMED),
            None
        );
        let w = slow_study_warning(Method::Cdbo, 1000, 1000).unwrap();
        assert!(
            w.starts_with("1000 kernels and 1000 laps: expect the optimiser to take about 5 min"),
            "{w}"
        );
        let w = slow_study_warning(Method::Cdbo, 100, 4000).unwrap();
        assert!(w.contains("about 1.5 h") && w.contains("518 MB"), "{w}");
        for cheap in [Method::Random, Method::PatternSearch, Method::Cmaes] {
            assert_eq!(slow_study_warning(cheap, 1000, 10_000), None, "{cheap}");
        }
        let w = slow_study_warning(Method::BoCmaes, 100, STUDY_LAPS_ASSUMED).unwrap();
        assert!(
            w.contains("about 3 min") && w.contains("(bo-cmaes: "),
            "{w}"
        );
    }
}
