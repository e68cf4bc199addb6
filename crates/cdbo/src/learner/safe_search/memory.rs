//! The failure memory: what the failed laps say about laps not yet driven.
//!
//! A lap that left the road at x_f was too fast for the corner at x_f: its pedal over the
//! stretch of road S before x_f (the [`window`](Pedals::window), the push's repair distance)
//! brought the car there too fast. Each failed lap is remembered as a **bracket** on that
//! stretch, its pedal sampled at places xₖ ∈ S: the failed lap's pedal fₖ and a reference rₖ,
//! the best lap when it failed (the lap the failed one was a move from; a completed lap
//! whenever one has completed). The speed a car brings to x_f grows with the pedal it was given
//! over S, so a proposal of pedal aₖ is **predicted to fail** at x_f when its mean excess over
//! the reference reaches κ of the failed lap's,
//!
//! mean_S(aₖ − rₖ) ≥ κ · g,  g = mean_S(fₖ − rₖ) > 0  (κ the reach, 0 ≤ κ ≤ 1).
//!
//! With κ = 1 a lap is not driven again when it pushes over S at least as hard as a lap that
//! left the road there; with κ = ½ a move must give back half of a failed move's pedal before
//! it is driven, so the next lap tried at that corner bisects the gap between a completed lap
//! and a failed one. A stall (too slow) is the mirror image, signs reversed: a lap that is as
//! timid over S as κ of a stalled lap's shortfall is predicted to stall.
//!
//! A completed lap that reaches κ = 1 of a bracket shows it wrong (the car came through, for
//! instance entering S slower): the bracket is dropped. A completed lap with more pedal over S
//! than the reference becomes the reference there, narrowing the bracket from the safe side.
//! A failed lap no more aggressive over S than its reference (g ≈ 0: the start lap's own
//! failure) brackets nothing and is not remembered.
//!
//! Only what a car's timer gives is used: where a lap failed, whether it was too slow, and the
//! pedal the learner itself asked for.

use serde::{Deserialize, Serialize};

use crate::error::Result;
use crate::learner::pattern_search::push::REPAIR_DISTANCE;
use crate::optimizers::FailedLap;
use crate::policy::RkhsPolicy;
use crate::policy::repair::REPAIR_SPACINGS;

/// Pedal samples per kernel spacing, when the weights are a lap policy's.
const SAMPLES_PER_SPACING: usize = 4;
/// A failed lap no more aggressive than its reference than this (mean pedal over the
/// stretch) says nothing about other laps: it is not remembered.
const MIN_GAP: f64 = 1e-3;
/// Pedal differences below this are equal (rounding of the policy's sum).
const TOLERANCE: f64 = 1e-9;

/// How a lap's pedal is read along the lap: the policy's action π(xₖ) at evenly spaced xₖ
/// when its kernels' length-scale is told, else the weights themselves at x̂ᵢ = i/(M − 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pedals {
    /// Kernels M.
    kernels: usize,
    /// The policy's length-scale (none: the weights are read as the pedal).
    lengthscale: Option<f64>,
    /// The stretch before a failure its pedal is remembered over (lap fraction).
    window: f64,
}

impl Pedals {
    /// The pedal of M weights, a policy's of length-scale ℓ if told, remembered over
    /// [`REPAIR_DISTANCE`] metres before a failure when the lap's length is told (else
    /// [`REPAIR_SPACINGS`] kernel spacings).
    pub fn new(kernels: usize, lengthscale: Option<f64>, track_length: Option<f64>) -> Pedals {
        let spacing = 1.0 / kernels.saturating_sub(1).max(1) as f64;
        Pedals {
            kernels,
            lengthscale: lengthscale.filter(|_| kernels >= 2),
            window: track_length.map_or(REPAIR_SPACINGS * spacing, |l| REPAIR_DISTANCE / l),
        }
    }

    /// The number of places the pedal is read at.
    pub fn points(&self) -> usize {
        match self.lengthscale {
            Some(_) => SAMPLES_PER_SPACING * (self.kernels - 1) + 1,
            None => self.kernels,
        }
    }

    /// The stretch before a failure its pedal is remembered over (lap fraction).
    pub fn window(&self) -> f64 {
        self.window
    }

    /// The pedal of `weights` at every place (its first M weights: those after them are
    /// another action's, a line).
    pub fn sample(&self, weights: &[f64]) -> Result<Vec<f64>> {
        let weights = &weights[..self.kernels.min(weights.len())];
        let Some(l) = self.lengthscale else {
            return Ok(weights.to_vec());
        };
        let pedal = RkhsPolicy::new(weights.to_vec(), l)?.pedal();
        let last = (self.points() - 1) as f64;
        Ok((0..self.points())
            .map(|k| pedal.action(k as f64 / last))
            .collect())
    }

    /// The places (first and one past the last) over the window before lap fraction `at`.
    fn stretch(&self, at: f64) -> (usize, usize) {
        self.stretch_over(at, self.window)
    }

    /// The places (first and one past the last) over `window` before lap fraction `at`.
    fn stretch_over(&self, at: f64, window: f64) -> (usize, usize) {
        let last = self.points().saturating_sub(1) as f64;
        let to = (at.clamp(0.0, 1.0) * last).floor() as usize;
        let from = ((at - window).max(0.0) * last).ceil() as usize;
        (from.min(to), to + 1)
    }
}

/// One failed lap's bracket on the stretch before where it failed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bracket {
    /// Where the lap failed (lap fraction).
    pub at: f64,
    /// Whether it was too slow there (a stall) rather than too fast.
    pub too_slow: bool,
    /// The first place of the stretch.
    pub from: usize,
    /// The failed lap's pedal fₖ over the stretch.
    pub failed: Vec<f64>,
    /// The reference rₖ: the best lap when it failed, raised by later completed laps.
    pub reference: Vec<f64>,
}

impl Bracket {
    /// +1 for a lap too fast, −1 for one too slow: the direction of "more aggressive".
    fn sign(&self) -> f64 {
        if self.too_slow { -1.0 } else { 1.0 }
    }

    /// The pedal `pedal` over the stretch, with the bracket's values.
    fn over<'a>(&'a self, pedal: &'a [f64]) -> impl Iterator<Item = (f64, f64, f64)> + 'a {
        self.failed
            .iter()
            .zip(&self.reference)
            .zip(&pedal[self.from..])
            .map(|((&f, &r), &a)| (f, r, a))
    }

    /// The mean of s·(aₖ − rₖ) over the stretch: how much more aggressive than the reference
    /// `pedal` is there, s = ±1 the bracket's sign.
    fn excess(&self, pedal: &[f64]) -> f64 {
        let s = self.sign();
        self.over(pedal).map(|(_, r, a)| s * (a - r)).sum::<f64>() / self.failed.len() as f64
    }

    /// The failed lap's own excess over the reference, g.
    fn gap(&self) -> f64 {
        let s = self.sign();
        self.failed
            .iter()
            .zip(&self.reference)
            .map(|(f, r)| s * (f - r))
            .sum::<f64>()
            / self.failed.len() as f64
    }

    /// Whether `pedal` has at least κ = `reach` of the failed lap's excess over the stretch.
    pub fn predicts(&self, pedal: &[f64], reach: f64) -> bool {
        self.excess(pedal) >= reach * self.gap() - TOLERANCE
    }
}

/// The brackets of every failed lap told.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct FailureMemory {
    /// One bracket per failed lap still believed.
    pub brackets: Vec<Bracket>,
}

impl FailureMemory {
    /// The failure predicted for a lap of pedal `pedal` with reach κ: the earliest place a
    /// bracket predicts it fails at, if any.
    pub fn predict(&self, pedal: &[f64], reach: f64) -> Option<FailedLap> {
        self.brackets
            .iter()
            .filter(|b| b.predicts(pedal, reach))
            .min_by(|a, b| a.at.total_cmp(&b.at))
            .map(|b| FailedLap {
                at: b.at,
                too_slow: b.too_slow,
            })
    }

    /// Remembers a lap of pedal `failed` that failed as `failure` says, a move from the lap of
    /// pedal `reference`: over the window before the failure, or from where the failed lap
    /// first had more pedal than the reference (over a tenth of its largest excess) if that
    /// lies further back, at most `reach_back` windows before the failure.
    pub fn failed(
        &mut self,
        pedals: &Pedals,
        failed: &[f64],
        reference: &[f64],
        failure: FailedLap,
        reach_back: f64,
    ) {
        let (mut from, to) = pedals.stretch(failure.at);
        if reach_back > 1.0 {
            let (far, _) = pedals.stretch_over(failure.at, reach_back * pedals.window());
            let s = if failure.too_slow { -1.0 } else { 1.0 };
            let most = (far..to)
                .map(|k| s * (failed[k] - reference[k]))
                .fold(0.0, f64::max);
            if let Some(k) = (far..to).find(|&k| s * (failed[k] - reference[k]) > 0.1 * most) {
                from = from.min(k);
            }
        }
        let bracket = Bracket {
            at: failure.at,
            too_slow: failure.too_slow,
            from,
            failed: failed[from..to].to_vec(),
            reference: reference[from..to].to_vec(),
        };
        if bracket.gap() > MIN_GAP {
            self.brackets.push(bracket);
        }
    }

    /// Learns from a completed lap of pedal `pedal`: drops the brackets it shows wrong and
    /// raises the references it pushed past all along their stretch.
    pub fn completed(&mut self, pedal: &[f64]) {
        self.brackets.retain(|b| !b.predicts(pedal, 1.0));
        for b in &mut self.brackets {
            if b.excess(pedal) > 0.0 {
                let to = b.from + b.reference.len();
                b.reference.copy_from_slice(&pedal[b.from..to]);
            }
        }
    }

    /// Whether every bracket fits a pedal read at `points` places.
    pub fn is_sound(&self, points: usize) -> bool {
        self.brackets.iter().all(|b| {
            b.failed.len() == b.reference.len()
                && b.from + b.failed.len() <= points
                && b.at.is_finite()
                && b.failed.iter().chain(&b.reference).all(|v| v.is_finite())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eleven weights read as the pedal (no length-scale), remembered over two spacings.
    fn pedals() -> Pedals {
        Pedals::new(11, None, None)
    }

    /// A move of 0.2 more pedal at weights 4–6 that left the road at x = 0.6 brackets
    /// weights 4–6: a lap keeping half its excess there is predicted to fail with κ = ½, a
    /// lap giving more than half back is not, nor is a move elsewhere; a stall is the mirror.
    #[test]
    fn a_bracket_predicts_laps_as_aggressive_as_a_failed_one() {
        let mut memory = FailureMemory::default();
        let best = vec![0.5; 11];
        let mut failed = best.clone();
        (4..=6).for_each(|i| failed[i] += 0.2);
        memory.failed(&pedals(), &failed, &best, FailedLap::too_fast(0.6), 1.0);
        assert_eq!(memory.brackets[0].from, 4);
        let moved = |d: f64| {
            let mut w = best.clone();
            (4..=6).for_each(|i| w[i] += d);
            w
        };
        assert_eq!(
            memory.predict(&moved(0.1), 0.5),
            Some(FailedLap::too_fast(0.6))
        );
        assert_eq!(memory.predict(&moved(0.09), 0.5), None);
        assert_eq!(
            memory.predict(&moved(0.2), 1.0),
            Some(FailedLap::too_fast(0.6))
        );
        assert_eq!(memory.predict(&moved(0.19), 1.0), None);
        let mut elsewhere = best.clone();
        elsewhere[8] += 0.3;
        assert_eq!(memory.predict(&elsewhere, 0.5), None);
        // A stall after less pedal: as timid is predicted to stall, bolder is not.
        let stall = FailedLap {
            at: 0.6,
            too_slow: true,
        };
        let mut memory = FailureMemory::default();
        memory.failed(&pedals(), &moved(-0.2), &best, stall, 1.0);
        assert_eq!(memory.predict(&moved(-0.1), 0.5), Some(stall));
        assert_eq!(memory.predict(&moved(-0.05), 0.5), None);
        // The start lap's own failure (no excess over itself) brackets nothing.
        memory.failed(&pedals(), &best, &best, FailedLap::too_fast(0.3), 1.0);
        assert_eq!(memory.brackets.len(), 1);
    }

    /// A failed step of more pedal far before where it failed (weights 1–2, failing at 0.6)
    /// brackets from where it added pedal when it may reach back that far: the same move is
    /// predicted to fail there, a move after the failure is not; over one window it is not.
    #[test]
    fn a_bracket_reaches_back_to_where_the_failed_lap_added_pedal() {
        let best = vec![0.5; 11];
        let mut failed = best.clone();
        (1..=2).for_each(|i| failed[i] += 0.2);
        let mut memory = FailureMemory::default();
        memory.failed(&pedals(), &failed, &best, FailedLap::too_fast(0.6), 3.0);
        assert_eq!(memory.brackets[0].from, 1);
        assert_eq!(memory.predict(&failed, 0.5), Some(FailedLap::too_fast(0.6)));
        let mut later = best.clone();
        later[8] += 0.2;
        assert_eq!(memory.predict(&later, 0.5), None);
        let mut near = FailureMemory::default();
        near.failed(&pedals(), &failed, &best, FailedLap::too_fast(0.6), 1.0);
        assert!(
            near.brackets.is_empty(),
            "no excess over one window: no bracket"
        );
    }

    /// A completed lap with more pedal than the reference narrows the bracket from below; one
    /// as aggressive as the failed lap shows it wrong and drops it.
    #[test]
    fn completed_laps_narrow_or_drop_brackets() {
        let mut memory = FailureMemory::default();
        let best = vec![0.5; 11];
        let with = |d: f64| {
            let mut w = best.clone();
            (4..=6).for_each(|i| w[i] += d);
            w
        };
        memory.failed(&pedals(), &with(0.2), &best, FailedLap::too_fast(0.6), 1.0);
        memory.completed(&with(0.1));
        assert_eq!(memory.brackets[0].reference, vec![0.6; 3]);
        // Now half-way between 0.6 and 0.7 is predicted with κ = ½.
        assert!(memory.predict(&with(0.15), 0.5).is_some());
        assert!(memory.predict(&with(0.14), 0.5).is_none());
        memory.completed(&with(0.2));
        assert!(memory.brackets.is_empty());
    }
}
