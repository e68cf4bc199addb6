//! Upper bounds on every size a user gives — kernels, laps, points, jobs, dimensions,
//! evaluations, observations, repeats — checked before anything is allocated, and the cost
//! estimate that warns of a legal size that will be slow.
//!
//! A bound is where a size stops making sense or stops fitting a workstation: the paper's
//! policies have 10 to 100 kernels (1000 is already one kernel per 50 Hz driver step on a
//! one-minute lap), and a GP over n laps holds an n × n covariance (10,000 laps: 800 MB, and
//! every hyperparameter fit costs O(n³)).

use crate::error::{Error, Result};

/// One kind of size and its legal range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Size {
    /// What it counts, as a command-line flag would name it (`kernels`).
    pub name: &'static str,
    /// Smallest legal value.
    pub min: usize,
    /// Largest legal value.
    pub max: usize,
    /// Why the bound is where it is.
    pub why: &'static str,
}

/// Policy kernels M (and the dimension of every optimiser's search).
pub const KERNELS: Size = Size::new(
    "kernels",
    2,
    1000,
    "one kernel per 50 Hz driver step of a one-minute lap; the paper uses 10 to 100",
);

/// Laps of a race or a study (GP observations).
pub const LAPS: Size = Size::new(
    "laps",
    1,
    10_000,
    "a GP over 10,000 laps holds an 800 MB covariance and refits in O(n³)",
);

/// Points of a policy table.
pub const POINTS: Size = Size::new(
    "points",
    2,
    1_000_000,
    "a table finer than a millionth of the lap adds nothing",
);

/// Parallel jobs.
pub const JOBS: Size = Size::new(
    "jobs",
    1,
    1024,
    "one thread per run; more threads than that only share the same cores",
);

/// Dimensions of a benchmark problem: the bounds of [`KERNELS`].
pub const DIMS: Size = KERNELS.alias("dims", "the same bound as --kernels");

/// Evaluations of a benchmark run: the bounds of [`LAPS`].
pub const EVALUATIONS: Size = LAPS.alias("evals", "the same bound as --laps");

/// Observations of a GP benchmark: the bounds of [`LAPS`].
pub const OBSERVATIONS: Size = LAPS.alias("observations", "the same bound as --laps");

/// Repeats (runs per cell, seeds, timed suggestions, scan points).
pub const REPEATS: Size = Size::new(
    "repeats",
    1,
    10_000,
    "beyond that a repeat adds no precision worth its time",
);

impl Size {
    /// A size counting `name`, legal from `min` to `max` because of `why`.
    pub const fn new(name: &'static str, min: usize, max: usize, why: &'static str) -> Size {
        Size {
            name,
            min,
            max,
            why,
        }
    }

    /// Another size with the same bounds, counting `name`.
    const fn alias(self, name: &'static str, why: &'static str) -> Size {
        Size { name, why, ..self }
    }

    /// `value` if it is within the bounds, else the bound it breaks (the caller names the
    /// flag and the value: clap does, and so does [`Size::checked`]).
    pub fn check(&self, value: usize) -> std::result::Result<usize, String> {
        if value < self.min {
            return Err(format!("must be at least {}", self.min));
        }
        if value > self.max {
            return Err(format!("must be at most {} ({})", self.max, self.why));
        }
        Ok(value)
    }

    /// [`Size::check`] as a library error ([`Error::TooSmall`], [`Error::TooLarge`]) naming the
    /// size and the value:
    /// `kernels 100000: must be at most 1000 (…)`.
    pub fn checked(&self, value: usize) -> Result<usize> {
        if value < self.min {
            return Err(Error::too_small(self.name, value, self.min));
        }
        if value > self.max {
            return Err(Error::TooLarge {
                what: self.name.into(),
                value: value as u64,
                max: self.max as u64,
                why: self.why.into(),
            });
        }
        Ok(value)
    }
}

/// Seconds a race of `laps` laps with `kernels` kernels takes on one free core, roughly: the
/// simulator's share grows with M² (every driver step sums the kernels near x, the policy fit
/// solves an M × M system), the GP's with n³ summed over the laps (refits over n observations).
/// The coefficients are calibrated on `cdbo race` timings (docs/results/design.md).
pub fn race_seconds(kernels: usize, laps: usize) -> f64 {
    let (m, n) = (kernels as f64, laps as f64);
    n * (0.008 + 2.5e-7 * m * m) + 8e-8 * n * n * n
}

/// Bytes a GP over `laps` observations of `kernels` dimensions holds at its peak, roughly: a
/// few n × n matrices (covariance, its factor, a gradient's work space) and the n × M inputs.
pub fn race_bytes(kernels: usize, laps: usize) -> f64 {
    let (m, n) = (kernels as f64, laps as f64);
    8.0 * (4.0 * n * n + 2.0 * n * m)
}

/// Seconds the optimiser of a study takes over `laps` suggestions with `kernels` weights on one
/// free core, besides the laps themselves (an external evaluator's time is not cdbo's to
/// know), roughly: one CDBO suggestion over n observations costs about 3 µs · M · n (the
/// acquisition's coordinate scans), summed over the laps 1.5e-6 · M · n², and the GP's refits
/// 8e-8 · n³ as in [`race_seconds`]. Calibrated on `cdbo bench suggest`: 300 observations in
/// 30, 300 and 1000 dimensions ≈ 0.04, 0.3 and 0.9 s per suggestion.
pub fn study_seconds(kernels: usize, laps: usize) -> f64 {
    let (m, n) = (kernels as f64, laps as f64);
    1.5e-6 * m * n * n + 8e-8 * n * n * n
}

/// The laps a study's warning assumes when none are given (`study create`): the paper's
/// budget.
pub const STUDY_LAPS_ASSUMED: usize = 300;

/// A warning for a legal race that will be slow (over a minute) or large (over 1 GiB), with
/// the estimate; `None` for an ordinary one.
pub fn slow_race_warning(kernels: usize, laps: usize) -> Option<String> {
    slow_warning(
        race_seconds(kernels, laps),
        race_bytes(kernels, laps),
        |time, mb| {
            format!(
                "{kernels} kernels and {laps} laps: expect about {time} on one free core and {mb} of memory (the GP's cost grows as laps³, the simulator's as kernels²)"
            )
        },
    )
}

/// A warning for a legal study whose optimiser will be slow (over a minute, besides the laps)
/// or large (over 1 GiB) over `laps` laps, with the estimate; `None` for an ordinary one.
pub fn slow_study_warning(kernels: usize, laps: usize) -> Option<String> {
    slow_warning(
        study_seconds(kernels, laps),
        race_bytes(kernels, laps),
        |time, mb| {
            format!(
                "{kernels} kernels and {laps} laps: expect the optimiser to take about {time} on one free core besides the laps themselves, and {mb} of memory (the GP's cost grows as laps³, each suggestion's as kernels × laps)"
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
    fn sizes_outside_their_bounds_are_named() {
        assert_eq!(KERNELS.check(30), Ok(30));
        let e = KERNELS.checked(100_000).unwrap_err().to_string();
        assert!(e.starts_with("kernels 100000: must be at most 1000"), "{e}");
        assert!(KERNELS.check(1).unwrap_err().contains("at least 2"));
        assert!(LAPS.check(0).is_err() && LAPS.check(10_000).is_ok());
    }

    #[test]
    fn the_default_race_is_not_slow_and_a_large_one_is() {
        assert_eq!(slow_race_warning(30, 300), None);
        assert_eq!(slow_race_warning(100, 300), None);
        let w = slow_race_warning(100, 5000).unwrap();
        assert!(w.contains("5000 laps") && w.contains(" h "), "{w}");
        assert!(slow_race_warning(1000, 300).is_some());
    }

    /// A study's estimate counts only the optimiser: 30 kernels over the paper's 300 laps is
    /// about 6 s, 1000 kernels about 2.3 min, 100 kernels over 4000 laps two hours.
    #[test]
    fn a_large_study_is_slow_in_the_optimiser_alone() {
        assert!((study_seconds(30, 300) - 6.21).abs() < 1e-9);
        assert_eq!(slow_study_warning(30, STUDY_LAPS_ASSUMED), None);
        assert_eq!(slow_study_warning(300, STUDY_LAPS_ASSUMED), None);
        let w = slow_study_warning(1000, STUDY_LAPS_ASSUMED).unwrap();
        assert!(
            w.starts_with("1000 kernels and 300 laps: expect the optimiser to take about 3 min"),
            "{w}"
        );
        let w = slow_study_warning(100, 4000).unwrap();
        assert!(w.contains("about 2.1 h") && w.contains("518 MB"), "{w}");
    }
}
