//! The repair of a pedal where its lap fails: the targets (x, a) the policy is fitted to move
//! down over the stretch of road before a failure where the car was too fast (off the road,
//! spun, backwards) and up where it was too slow (stalled, past the time limit). The ceiling
//! ([`crate::ceiling`]) repairs its fitted pedal this way, and the pattern search's push
//! ([`crate::learner::pattern_search`]) repairs a pushed pedal.

use serde::{Deserialize, Serialize};

use crate::policy::rkhs::default_lengthscale;

/// The first step δ₀ of a repair of the fitted pedal.
pub const REPAIR_STEP: f64 = 0.1;
/// Kernel spacings 1/(M − 1) before a failure over which a repair moves the fit's targets.
pub const REPAIR_SPACINGS: f64 = 2.0;

/// The repairs of a fitted pedal's targets at the places its laps fail (step 2 of the
/// ceiling): the step δ and the last failure's place and direction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PedalRepair {
    /// The kernel spacing 1/(M − 1).
    pub spacing: f64,
    /// The current step δ.
    pub step: f64,
    /// The last repair's failure place and direction (±1).
    pub last: Option<(f64, f64)>,
    /// The stretch before a failure that a repair moves (lap fraction); `None`:
    /// [`REPAIR_SPACINGS`] kernel spacings (the ceiling's, and repairs saved before it was set).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub window: Option<f64>,
    /// The first step δ₀ at each new place (the default [`REPAIR_STEP`] is not written).
    #[serde(default = "default_step", skip_serializing_if = "is_default_step")]
    pub first: f64,
    /// Whether a corner that fails too fast again after its repair is braked for earlier
    /// ([`Self::braking_earlier`]).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub earlier: bool,
    /// Too-fast failures in a row at the same corner, the first not counted.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub repeats: usize,
}

/// Whether no failure has repeated.
fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// The most repeated failures a repair braking earlier counts ([`PedalRepair::braking_earlier`]):
/// its stretch reaches back at most 1 + this many windows, and a failure up to this many
/// spacings before the last one is still the same corner.
pub const MOST_REPEATS: usize = 6;

/// δ₀ of repairs saved before it was set.
fn default_step() -> f64 {
    REPAIR_STEP
}

/// Whether δ₀ is the default, left out of a saved repair.
fn is_default_step(step: &f64) -> bool {
    *step == REPAIR_STEP
}

impl PedalRepair {
    /// Repairs of an M-kernel fit, at δ₀ = [`REPAIR_STEP`], over [`REPAIR_SPACINGS`] spacings.
    pub fn new(kernels: usize) -> PedalRepair {
        PedalRepair {
            spacing: default_lengthscale(kernels),
            step: REPAIR_STEP,
            last: None,
            window: None,
            first: REPAIR_STEP,
            earlier: false,
            repeats: 0,
        }
    }

    /// These repairs, braking earlier for a corner that fails again: a too-fast failure at or
    /// before one spacing past the last one, and no more than [`MOST_REPEATS`] spacings
    /// before it, is that corner again, and the n-th such failure in a row moves the targets
    /// over (1 + n) windows before it rather than one (at most 1 + [`MOST_REPEATS`]). A repair
    /// that only lowers the pedal in the corner brakes the car while it turns; at the limit
    /// that spins it or stops it there, and the next repair, too slow, raises the pedal again.
    /// Braking earlier, on the straight before the corner, is what the tracked lap did.
    pub fn braking_earlier(self) -> PedalRepair {
        PedalRepair {
            earlier: true,
            ..self
        }
    }

    /// These repairs with first step δ₀ = `first` at each new place.
    pub fn starting_at(self, first: f64) -> PedalRepair {
        PedalRepair {
            first,
            step: first,
            ..self
        }
    }

    /// These repairs over a stretch of `window` (lap fraction) before each failure.
    pub fn over(self, window: f64) -> PedalRepair {
        PedalRepair {
            window: Some(window),
            ..self
        }
    }

    /// The stretch before a failure that a repair moves (lap fraction).
    pub fn window(&self) -> f64 {
        self.window.unwrap_or(REPAIR_SPACINGS * self.spacing)
    }

    /// Moves the targets (x, a) with x ∈ [x_f − [`window`](Self::window), x_f] by ±δ for a lap
    /// that failed at x_f: down where the car was too fast (off the road, spun, backwards), up
    /// where it was `too_slow` (stalled, time limit); halving δ first if the last failure lay
    /// within one spacing and asked for the other direction, or restoring δ₀ if it lay more
    /// than one spacing before x_f.
    pub fn repair(&mut self, targets: &mut [(f64, f64)], x_fail: f64, too_slow: bool) {
        self.repair_over(targets, x_fail, too_slow, self.window());
    }

    /// [`repair`](Self::repair) over the `stretch` (lap fraction) before x_f instead of the
    /// window.
    pub fn repair_over(
        &mut self,
        targets: &mut [(f64, f64)],
        x_fail: f64,
        too_slow: bool,
        stretch: f64,
    ) {
        let direction = if too_slow { 1.0 } else { -1.0 };
        let stretch = if self.earlier && !too_slow {
            let again = matches!(self.last, Some((x, d)) if d == direction
                && x_fail <= x + self.spacing
                && x_fail >= x - MOST_REPEATS as f64 * self.spacing);
            self.repeats = if again {
                (self.repeats + 1).min(MOST_REPEATS)
            } else {
                0
            };
            stretch * (1 + self.repeats) as f64
        } else {
            stretch
        };
        match self.last {
            Some((x, d)) if (x_fail - x).abs() < self.spacing && d != direction => {
                self.step *= 0.5;
            }
            Some((x, _)) if x_fail <= x + self.spacing => {}
            _ => self.step = self.first,
        }
        self.last = Some((x_fail, direction));
        let from = x_fail - stretch;
        for (x, a) in targets.iter_mut() {
            if (from..=x_fail).contains(x) {
                *a += direction * self.step;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A repair moves the targets over two spacings before the failure only, down for a spin
    /// and up for a stall; a reversal within one spacing halves δ, a failure further on
    /// restores δ₀.
    #[test]
    fn a_repair_moves_the_targets_before_the_failure() {
        let mut repair = PedalRepair::new(11);
        let mut targets: Vec<(f64, f64)> = (0..=100).map(|i| (i as f64 / 100.0, 0.5)).collect();
        repair.repair(&mut targets, 0.5, false /* spun: too fast */);
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        for (i, &(x, a)) in targets.iter().enumerate() {
            let moved = (30..=50).contains(&i);
            assert!(close(a, if moved { 0.4 } else { 0.5 }), "x {x}: {a}");
        }
        repair.repair(&mut targets, 0.52, true /* stalled: too slow */);
        assert_eq!(repair.step, REPAIR_STEP / 2.0);
        assert!(close(targets[51].1, 0.55) && close(targets[50].1, 0.45));
        assert!(close(targets[31].1, 0.4) && close(targets[32].1, 0.45));
        repair.repair(&mut targets, 0.53, true /* stalled: too slow */);
        assert_eq!(repair.step, REPAIR_STEP / 2.0);
        repair.repair(&mut targets, 0.8, false /* off the road: too fast */);
        assert_eq!(repair.step, REPAIR_STEP);
        assert!(close(targets[80].1, 0.4) && close(targets[57].1, 0.5));
        // The plain repair moves the window again where the car fails again.
        let mut plain = PedalRepair::new(11);
        let mut targets: Vec<(f64, f64)> = (0..=100).map(|i| (i as f64 / 100.0, 0.5)).collect();
        plain.repair(&mut targets, 0.5, false);
        plain.repair(&mut targets, 0.5, false);
        assert!(close(targets[30].1, 0.3) && close(targets[29].1, 0.5));
        // Over a window of its own: 0.055 of the lap before the failure, not two spacings.
        let mut narrow = PedalRepair::new(11).over(0.055);
        let mut targets: Vec<(f64, f64)> = (0..=100).map(|i| (i as f64 / 100.0, 0.5)).collect();
        narrow.repair(&mut targets, 0.5, false /* spun: too fast */);
        for (i, &(x, a)) in targets.iter().enumerate() {
            let moved = (45..=50).contains(&i);
            assert!(close(a, if moved { 0.4 } else { 0.5 }), "x {x}: {a}");
        }
    }

    /// Braking earlier: the corner failing too fast again moves the targets over two windows,
    /// then three; a stall between, or a failure elsewhere, starts again at one.
    #[test]
    fn a_corner_that_fails_again_is_braked_for_earlier() {
        let mut repair = PedalRepair::new(11).braking_earlier();
        let mut targets: Vec<(f64, f64)> = (0..=100).map(|i| (i as f64 / 100.0, 0.0)).collect();
        // The targets moved by the last repair, as (first, last) indices.
        let mut moved = |repair: &mut PedalRepair, x: f64, too_slow: bool| {
            let before: Vec<f64> = targets.iter().map(|t| t.1).collect();
            repair.repair(&mut targets, x, too_slow);
            let changed: Vec<usize> = (0..=100).filter(|&i| targets[i].1 != before[i]).collect();
            (changed[0], changed[changed.len() - 1])
        };
        assert_eq!(moved(&mut repair, 0.7, false), (50, 70));
        assert_eq!(moved(&mut repair, 0.69, false), (29, 69));
        assert_eq!(moved(&mut repair, 0.68, false), (8, 68));
        assert_eq!(repair.repeats, 2);
        // A stall is repaired over one window, and the next too-fast failure is new.
        assert_eq!(moved(&mut repair, 0.7, true), (50, 70));
        assert_eq!(moved(&mut repair, 0.7, false), (50, 70));
        assert_eq!(moved(&mut repair, 0.7, false), (30, 70));
        // Further on than a spacing past the last: another corner.
        assert_eq!(moved(&mut repair, 0.95, false), (75, 95));
        assert_eq!(repair.repeats, 0);
    }
}
