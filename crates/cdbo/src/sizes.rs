//! Upper bounds on every size a user gives — kernels, laps, points, jobs, dimensions,
//! evaluations, observations, repeats — checked before anything is allocated. What a legal
//! size costs each method is [`crate::method::cost`]'s.
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
}
