//! Pattern search with failure repair: an adaptive coordinate search around the best lap that
//! reads where a failed lap failed, on blocks of weights that narrow sweep by sweep.
//!
//! The weights are a policy's kernels in lap order (weight i acts around x̂ᵢ = i/(M − 1)), and
//! a lap is causal: the pedal at x changes nothing before x. A policy with a line
//! ([`crate::policy::actions`]) has two such blocks, [w_a, w_d]: when the pedal's count M_a is
//! told, blocks, sharpening directions and sweeps stay within one action's weights, and the
//! push and the repairs, which read the pedal, act on w_a only. Sweep k moves blocks of
//! b_k = max(1, ⌊b₀/2ᵏ⁻¹⌋) adjacent weights together (b₀ = 8: first whole stretches of the lap,
//! then single kernels); block B starting at weight i has a signed step sᵢ, first +σ₀ (more
//! pedal), reset to +σ₀ when the width changes. A trial moves one block from the best point
//! w*: w = clamp(w* + sᵢΣ_{k∈B} eₖ) (Rosenbrock's method on the blocks):
//! - a faster lap is accepted and the step grows, sᵢ ← 2sᵢ, on the same block;
//! - a lap that **fails at x_f past the moved block after more pedal** (sᵢ > 0) was too fast
//!   for what follows: the **repair** gives half the step back at the kernel
//!   j = ⌊x_f(M − 1)⌋ − 1 just before the failure, w* + sᵢΣ_{k∈B} eₖ − c·sᵢeⱼ with c = ½
//!   (brake earlier for the corner the car could not take, keeping half the gain); a repaired
//!   lap that fails again at or past j is repaired again there (up to 3 give-backs, the same
//!   kernel twice gives back twice as much); if a repaired lap is faster, it is accepted and
//!   sᵢ doubles;
//! - otherwise (slower, failed before the repair could reach, or failed after less pedal: a
//!   car that brakes more was not too fast) the step reverses and halves, sᵢ ← −sᵢ/2, and the
//!   search moves to the next block.
//!
//! The blocks are visited in a fresh random order each sweep; a step that has shrunk below
//! σ₀/16 starts the next sweep at ±σ₀ again. Only the lap's reward, where it failed and
//! whether the car stalled there are used: what a car's lap timer and driver give.
//!
//! **Sharpening sweeps.** One weight's pedal, wᵢφᵢ(x), is a bump two kernel spacings wide: a
//! braking point sharper than that needs neighbours of opposite signs (the ceiling's fitted
//! policies alternate signs; a sum of single-weight steps seldom gets there). Once the blocks
//! are single weights, every second sweep moves instead along
//! dᵢ = eᵢ − ½(eᵢ₋₁ + eᵢ₊₁) (the ends drop the missing neighbour): pedal at x̂ᵢ taken from
//! either side, the pedal's sum over the lap about unchanged, with its own signed steps and the
//! same rules (grow on a faster lap, repair past eᵢ₊₁ after more pedal at x̂ᵢ, else reverse and
//! halve). Measured on the training panels (docs/results/beyond): the same best laps with
//! 8 % fewer failed laps (165 → 151 a run).
//!
//! **Rests.** A step of more pedal whose lap failed says the car is at its limit there; trying
//! again next sweep mostly fails again. So the direction sits out the next 1, 2, 4, 4, …
//! sweeps of its kind after 1, 2, 3, 4, … such failures with no faster lap between (a faster
//! lap clears the count; a new block width starts afresh), and the laps go to directions that
//! can still gain. Measured on the training panels: the same best laps (32.80 against 32.78 m/s)
//! with 6 % fewer failed laps (151 → 142 a run).
//!
//! **The push** ([`push`]). When the weights are a lap policy's (its length-scale is told), the
//! search begins, after the start lap, by raising the whole pedal by U₀ ≈ 0.35 and repairing
//! the pushed lap corner by corner where it fails, as the ceiling repairs its fit, then by
//! U₀/2, U₀/4, U₀/8 (a push not kept is followed by the next, afresh from the best lap); after
//! a kept push the sweeps begin at single weights (the pushed lap is near the limit
//! everywhere, where blocks of 8 mostly fail).
//! Measured on the training panels: 34.86 against 32.80 m/s (σ₀ 0.12); with the lap's length
//! told, repairs over 275 m of road and later pushes holding what a kept one lowered, 35.62,
//! and 35.68 with σ₀ re-swept to 0.05 (docs/results/beyond).
//!
//! **A warm start** ([`PatternSearchConfig::warm`]): a policy learned elsewhere (in cdbo's
//! simulator, then driven in the game) is not pushed; if its first lap fails, it is repaired
//! as a push is, its weights kept and the repairs' fit added ([`Push::repairing`]), until a lap
//! completes; the sweeps then begin at the widest blocks.

pub mod push;

use std::borrow::Cow;

use rand::seq::SliceRandom;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::optimizers::ask_tell::{AskTell, Lap, Proposal, Proposer, Recorded, SavedAs, Told};
use crate::optimizers::{DEFAULT_BOX_RADIUS, FailedLap, SearchBox, rng_for};
use push::Push;

/// The method's name, and the kind of its saved state.
pub const NAME: &str = "pattern-search";

/// Settings of a pattern search.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PatternSearchConfig {
    /// Seed of every random choice (the sweeps' orders).
    pub seed: u64,
    /// The first step σ₀ of every weight.
    pub sigma0: f64,
    /// Half-width of the search box around the start.
    pub box_radius: f64,
    /// Repair failed laps where they failed.
    pub repair: bool,
    /// Width b₀ of the first sweep's blocks of adjacent weights, halved each sweep down to 1.
    #[serde(default = "single_weight")]
    pub block: usize,
    /// Give-backs at most on one step (a repaired lap that fails again is repaired again).
    #[serde(default = "single_weight")]
    pub repairs: usize,
    /// The fraction c of the step a repair gives back at the kernel before the failure.
    #[serde(default = "whole_step")]
    pub give_back: f64,
    /// Every second sweep of single weights moves along dᵢ = eᵢ − ½(eᵢ₋₁ + eᵢ₊₁) instead.
    #[serde(default)]
    pub sharpen: bool,
    /// A direction whose step of more pedal failed sits out the next 1, 2, 4, 4, … sweeps,
    /// after 1, 2, 3, … such failures with no faster lap between.
    #[serde(default)]
    pub rest: bool,
    /// The first push's size U₀ (0: no push).
    #[serde(default)]
    pub push: f64,
    /// The policy's kernel length-scale, when the weights are a lap policy's: the push needs
    /// it (without it, no push).
    #[serde(default)]
    pub lengthscale: Option<f64>,
    /// The lap's length (m), when told: the push repairs over [`push::REPAIR_DISTANCE`] m of
    /// road before a failure (without it, over two kernel spacings).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub track_length: Option<f64>,
    /// The pedal's kernels M_a when the weights after them are another action's (a line);
    /// none: every weight is the pedal's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pedal_kernels: Option<usize>,
    /// The push's first repair step δ₀ at each new place (the default
    /// [`REPAIR_STEP`](crate::policy::repair::REPAIR_STEP) is not written).
    #[serde(default = "repair_step", skip_serializing_if = "is_repair_step")]
    pub repair_step: f64,
    /// Repair the start where its lap fails, as a push is repaired (push 0, of size 0;
    /// [`Push::repairing`]), before any push: a policy learned elsewhere may leave the road
    /// here, and a demonstration's fit may fail (the safe search); its repair keeps the rest.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub repair_start: bool,
    /// A push's repair stops half-way back to the nearest other place the pushes failed, not
    /// less than two kernel spacings back ([`push`], "Not through the corner before"); off in
    /// searches saved before it existed and in the safe search, whose budget of failed laps
    /// pays for the extra repairs (measured there: Forza-50 41.42 → 38.91 m/s).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub stop_half_way: bool,
    /// A push gives up once this many of its laps in a row fail short of the furthest place
    /// its laps reached ([`push`]; 0: never, as in searches saved before it existed).
    #[serde(default)]
    pub push_patience: usize,
    /// A push that is not kept (its first complete lap slower than the best, or given up) is
    /// followed by the next, half its size, begun afresh from the best lap ([`push`], "After
    /// a push not kept"); off, the pushes end there, as in searches saved before it existed
    /// and in the safe search, whose budget of failed laps would pay for the extra pushes.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub push_after_unkept: bool,
}

/// The push's default repair step.
fn repair_step() -> f64 {
    crate::policy::repair::REPAIR_STEP
}

/// Whether a push's repair step is the default, left out of a saved search.
fn is_repair_step(step: &f64) -> bool {
    *step == repair_step()
}

/// Blocks of one weight and one repair: the settings of a search saved before they existed.
fn single_weight() -> usize {
    1
}

/// A repair that gives the whole step back: the settings of a search saved before `give_back`.
fn whole_step() -> f64 {
    1.0
}

impl Default for PatternSearchConfig {
    fn default() -> Self {
        PatternSearchConfig {
            seed: 0,
            sigma0: 0.03,
            box_radius: DEFAULT_BOX_RADIUS,
            repair: true,
            block: 8,
            repairs: 3,
            give_back: 0.5,
            sharpen: true,
            rest: true,
            push: push::SIZE,
            lengthscale: None,
            track_length: None,
            pedal_kernels: None,
            repair_step: repair_step(),
            repair_start: false,
            stop_half_way: true,
            push_patience: push::PATIENCE,
            push_after_unkept: true,
        }
    }
}

impl PatternSearchConfig {
    /// The settings of a search that starts from a learned policy (a warm start): no push,
    /// and the start repaired where its lap fails ([`PatternSearchConfig::repair_start`]).
    /// Measured in the game from policies learned in cdbo's simulator (Forza, 50 kernels,
    /// seeds 0-2, docs/results/torcs.md): the first completed lap after 3-4 laps against
    /// 25-32 with the push, the best after 30 laps 115.76 / 113.41 / 116.47 s against
    /// 115.05 s / none / 114.88 s, after 100 laps 109.40 s against 107.78 s on average.
    pub fn warm() -> Self {
        PatternSearchConfig {
            push: 0.0,
            repair_start: true,
            ..PatternSearchConfig::default()
        }
    }
}

/// What the pending trial is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Trial {
    /// The start point.
    Start,
    /// w* + sᵢ·Σ_{k∈B(i)} eₖ, B(i) the block of weights starting at i.
    Step {
        /// The first moved weight i.
        weight: usize,
    },
    /// The step with c·sᵢ given back at the weights before the failures,
    /// w* + sᵢΣeₖ − c·sᵢΣⱼeⱼ.
    Repair {
        /// The first moved weight i.
        weight: usize,
        /// The weights j before the failures.
        before: Vec<usize>,
    },
    /// The push under way ([`push`]).
    Push,
}

/// How long a direction sits out after its steps of more pedal failed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Rest {
    /// Steps of more pedal given up after a failed lap, with no faster lap since.
    pub failures: u32,
    /// Sweeps still to sit out.
    pub sweeps: u32,
}

impl Rest {
    /// The longest rest, in sweeps.
    const LONGEST: u32 = 4;

    /// One more failure: sit out 2^(failures − 1) sweeps, at most [`Rest::LONGEST`].
    fn failed(&mut self) {
        self.failures = self.failures.saturating_add(1);
        self.sweeps = 1u32
            .checked_shl(self.failures - 1)
            .map_or(Self::LONGEST, |s| s.min(Self::LONGEST));
    }
}

/// The search's steps, sweeps and pushes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PatternSearchProgress {
    /// Settings.
    pub config: PatternSearchConfig,
    /// The start point.
    pub start: Vec<f64>,
    /// The signed step of every weight.
    pub steps: Vec<f64>,
    /// This sweep's order of the blocks (their first weights).
    pub order: Vec<usize>,
    /// Position in `order`.
    pub cursor: usize,
    /// Sweeps begun.
    pub sweeps: u64,
    /// Whether this sweep moves along the sharpening directions dᵢ rather than blocks.
    #[serde(default)]
    pub sharpening: bool,
    /// The signed step of every sharpening direction dᵢ.
    #[serde(default)]
    pub sharp_steps: Vec<f64>,
    /// The rest of every block (by its first weight), emptied when the width changes.
    #[serde(default)]
    pub rests: Vec<Rest>,
    /// The rest of every sharpening direction dᵢ.
    #[serde(default)]
    pub sharp_rests: Vec<Rest>,
    /// The push under way.
    #[serde(default)]
    pub push: Option<Push>,
    /// Whether a push was kept (the sweeps then begin at single weights).
    #[serde(default)]
    pub pushed: bool,
    /// The next trial.
    pub next: Trial,
}

/// Everything needed to resume a search: its steps and the laps' record.
pub type PatternSearchState = Recorded<PatternSearchProgress>;

/// The pattern search's proposer: the next trial moves one block (or sharpening direction)
/// from the best point, repairs it or pushes, and each told lap grows, repairs, or reverses
/// and halves the step, as the module says.
#[derive(Debug, Clone)]
pub struct PatternSearchProposer {
    state: PatternSearchProgress,
    bounds: SearchBox,
}

/// Pattern search with failure repair.
pub type PatternSearch = AskTell<PatternSearchProposer>;

impl PatternSearch {
    /// A search from `start` (driven first, unmoved).
    pub fn new(start: Vec<f64>, config: PatternSearchConfig) -> Result<PatternSearch> {
        let proposer = PatternSearchProposer::new(start, config)?;
        Ok(AskTell::resumed(proposer, Told::default()))
    }

    /// Rebuilds a search from its state.
    pub fn resume(state: PatternSearchState) -> Result<PatternSearch> {
        let (state, told) = state.into_parts();
        Ok(AskTell::resumed(
            PatternSearchProposer::resume(state)?,
            told,
        ))
    }
}

impl PatternSearchProposer {
    /// A search from `start` (driven first, unmoved).
    pub(crate) fn new(
        start: Vec<f64>,
        config: PatternSearchConfig,
    ) -> Result<PatternSearchProposer> {
        if start.is_empty() || start.iter().any(|v| !v.is_finite()) {
            return Err(Error::invalid_value(
                "pattern search's start point",
                format!("{start:?}"),
                "finite, of at least one weight",
            ));
        }
        let n = start.len();
        PatternSearchProposer::resume(PatternSearchProgress {
            steps: vec![config.sigma0; n],
            sharp_steps: vec![config.sigma0; n],
            rests: vec![Rest::default(); n],
            sharp_rests: vec![Rest::default(); n],
            sharpening: false,
            order: Vec::new(),
            cursor: 0,
            sweeps: 0,
            push: None,
            pushed: false,
            next: Trial::Start,
            config,
            start,
        })
    }

    /// The search's state.
    pub(crate) fn progress(&self) -> &PatternSearchProgress {
        &self.state
    }

    /// A search continuing from `state`.
    pub(crate) fn resume(mut state: PatternSearchProgress) -> Result<PatternSearchProposer> {
        if !(state.config.sigma0.is_finite() && state.config.sigma0 > 0.0) {
            return Err(Error::invalid_value("σ₀", state.config.sigma0, "positive"));
        }
        if !(state.config.push.is_finite() && state.config.push >= 0.0) {
            return Err(Error::invalid_value(
                "the push's size",
                state.config.push,
                "0 or more",
            ));
        }
        for (what, value) in [
            ("the policy's length-scale", state.config.lengthscale),
            ("the lap's length (m)", state.config.track_length),
        ] {
            if let Some(v) = value.filter(|v| !(v.is_finite() && *v > 0.0)) {
                return Err(Error::invalid_value(what, v, "positive"));
            }
        }
        if !(state.config.repair_step.is_finite() && state.config.repair_step > 0.0) {
            return Err(Error::invalid_value(
                "the push's repair step",
                state.config.repair_step,
                "positive",
            ));
        }
        if !(state.config.give_back.is_finite() && state.config.give_back > 0.0) {
            return Err(Error::invalid_value(
                "the repair's give-back",
                state.config.give_back,
                "a positive fraction of the step",
            ));
        }
        let n = state.start.len();
        if let Some(m) = state.config.pedal_kernels.filter(|&m| m == 0 || m > n) {
            return Err(Error::invalid_value(
                "the pedal's kernels",
                m,
                format!("1 to the {n} weights"),
            ));
        }
        if state.sharp_steps.is_empty() {
            // Saved before sharpening sweeps existed.
            state.sharp_steps = vec![state.config.sigma0; n];
        }
        for rests in [&mut state.rests, &mut state.sharp_rests] {
            if rests.is_empty() {
                // Saved before rests existed.
                *rests = vec![Rest::default(); n];
            }
        }
        if let Some(push) = state.push.as_mut().filter(|p| p.repaired.is_empty()) {
            // Saved before pushes held their lowered targets.
            push.repaired = vec![0.0; push.targets.len()];
        }
        if state.steps.len() != n
            || state.sharp_steps.len() != n
            || state.rests.len() != n
            || state.sharp_rests.len() != n
            || state.order.iter().any(|&i| i >= n)
            || (state.next == Trial::Push) != state.push.is_some()
            || state.push.as_ref().is_some_and(|p| {
                let pedal = state.config.pedal_kernels.unwrap_or(n);
                state.config.lengthscale.is_none() || !p.is_sound(pedal)
            })
        {
            return Err(Error::CorruptState {
                method: "pattern search",
                reason: format!(
                    "{n} weights but {} steps, {} sharpening steps, {} and {} rests, order {:?}, \
                     next trial {:?} and {} push targets",
                    state.steps.len(),
                    state.sharp_steps.len(),
                    state.rests.len(),
                    state.sharp_rests.len(),
                    state.order,
                    state.next,
                    state.push.as_ref().map_or(0, |p| p.targets.len()),
                ),
            });
        }
        Ok(PatternSearchProposer {
            bounds: SearchBox::around(&state.start, state.config.box_radius)?,
            state,
        })
    }

    /// This sweep's block width: the first sweep's halved each sweep, down to 1.
    fn width(&self) -> usize {
        let shift = self.state.sweeps.saturating_sub(1).min(63);
        (self.state.config.block >> shift).max(1)
    }

    /// Push `number` from the best lap after the kept push `previous`, if this search pushes
    /// and has not pushed that often.
    fn begin_push(
        &self,
        number: u32,
        previous: Option<&Push>,
        told: &Told,
    ) -> Result<Option<Push>> {
        let c = &self.state.config;
        let n = self.pedal_kernels();
        match (c.lengthscale, told.best()) {
            (Some(l), Some((best, _)))
                if c.push > 0.0
                    && number <= push::PUSHES
                    && (2..=push::MAX_KERNELS).contains(&n) =>
            {
                Push::begin(number, &best[..n], l, c, previous).map(Some)
            }
            _ => Ok(None),
        }
    }

    /// The next push (number `number`, after the kept push `previous`), or the sweeps once the
    /// pushes are done: from single weights after a kept push, from the widest blocks
    /// otherwise.
    fn push_or_sweep(&mut self, number: u32, previous: Option<&Push>, told: &Told) -> Result<()> {
        self.state.push = self.begin_push(number, previous, told)?;
        if self.state.push.is_some() {
            self.state.next = Trial::Push;
        } else {
            if self.state.pushed {
                // The first sweep of single weights is number 1 + ⌊log₂ b₀⌋.
                self.state.sweeps = u64::from(self.state.config.block.max(1).ilog2());
            }
            self.begin_sweep();
        }
        Ok(())
    }

    /// Repairs the start, whose lap failed as `failure` says, as a push of size 0 is repaired;
    /// the sweeps or the pushes begin once a repaired lap completes or the repair gives up.
    fn repair_start(&mut self, failure: FailedLap, told: &Told) -> Result<()> {
        if self.state.config.lengthscale.is_none() {
            return self.push_or_sweep(1, None, told);
        }
        let pedal = self.pedal_kernels();
        let mut push = Push::repairing(&self.state.start[..pedal], &self.state.config);
        if push.repair(failure, &self.state.config) {
            self.state.push = Some(push);
            self.state.next = Trial::Push;
            Ok(())
        } else {
            self.push_or_sweep(1, None, told)
        }
    }

    /// Begins a new sweep: a fresh order of the blocks, less those resting, steps shrunk below
    /// σ₀/16 back at σ₀; once the blocks are single weights, every second sweep sharpens.
    fn begin_sweep(&mut self) {
        let old_width = self.width();
        self.state.sweeps += 1;
        let width = self.width();
        let n = self.state.start.len();
        let sigma0 = self.state.config.sigma0;
        // The first sweep of single weights: b₀ >> (k − 1) ≤ 1 from k = 1 + ⌊log₂ b₀⌋.
        let singles_from = 1 + u64::from(self.state.config.block.max(1).ilog2());
        let s = &mut self.state;
        s.sharpening =
            s.config.sharpen && width == 1 && (s.sweeps.saturating_sub(singles_from)) % 2 == 1;
        let pedal = s.config.pedal_kernels.unwrap_or(n);
        s.order = (0..pedal)
            .step_by(width)
            .chain((pedal..n).step_by(width))
            .collect();
        s.order.shuffle(&mut rng_for(s.config.seed, s.sweeps - 1));
        s.cursor = 0;
        if width != old_width {
            s.steps.iter_mut().for_each(|v| *v = sigma0);
            s.rests.iter_mut().for_each(|r| *r = Rest::default());
        }
        for step in s.steps.iter_mut().chain(&mut s.sharp_steps) {
            if step.abs() < sigma0 / 16.0 {
                *step = sigma0.copysign(*step);
            }
        }
        if s.config.rest {
            self.sit_out_resting();
        }
        self.state.next = Trial::Step {
            weight: self.state.order[0],
        };
    }

    /// The next block of the sweep, or a new sweep when it is done.
    fn advance(&mut self) {
        self.state.cursor += 1;
        match self.state.order.get(self.state.cursor) {
            Some(&weight) => self.state.next = Trial::Step { weight },
            None => self.begin_sweep(),
        }
    }

    /// The direction of the trial at `weight`, as (weight, coefficient) pairs in lap order:
    /// the block starting there, or the sharpening direction dᵢ.
    fn direction(&self, weight: usize) -> Vec<(usize, f64)> {
        let pedal = self.pedal_kernels();
        let (first, n) = if weight < pedal {
            (0, pedal)
        } else {
            (pedal, self.state.start.len())
        };
        if self.state.sharpening {
            let before = (weight > first).then(|| (weight - 1, -0.5));
            let after = (weight + 1 < n).then_some((weight + 1, -0.5));
            before
                .into_iter()
                .chain([(weight, 1.0)])
                .chain(after)
                .collect()
        } else {
            (weight..(weight + self.width()).min(n))
                .map(|k| (k, 1.0))
                .collect()
        }
    }

    /// The first weight past the trial's direction at `weight`.
    fn past(&self, weight: usize) -> usize {
        self.direction(weight).last().map_or(weight, |&(k, _)| k) + 1
    }

    /// The signed steps of this sweep's kind of direction.
    fn steps(&self) -> &[f64] {
        let s = &self.state;
        if s.sharpening {
            &s.sharp_steps
        } else {
            &s.steps
        }
    }

    /// The signed step of the trial at `weight`, in this sweep's kind of direction.
    fn step(&mut self, weight: usize) -> &mut f64 {
        let s = &mut self.state;
        let steps = if s.sharpening {
            &mut s.sharp_steps
        } else {
            &mut s.steps
        };
        &mut steps[weight]
    }

    /// The pedal's kernels M_a: the first M_a weights.
    fn pedal_kernels(&self) -> usize {
        let n = self.state.start.len();
        self.state.config.pedal_kernels.unwrap_or(n)
    }

    /// The pedal's kernel just before a failure at lap fraction `at`, if it lies at or past
    /// `after`.
    fn before_failure(&self, after: usize, at: f64) -> Option<usize> {
        let last = self.pedal_kernels() - 1;
        let at_kernel = (at.clamp(0.0, 1.0) * last as f64).floor() as usize;
        let j = at_kernel.checked_sub(1)?;
        (j >= after).then_some(j)
    }

    /// The rests of this sweep's kind of direction.
    fn rests(&mut self) -> &mut [Rest] {
        let s = &mut self.state;
        if s.sharpening {
            &mut s.sharp_rests
        } else {
            &mut s.rests
        }
    }

    /// The rest of the direction at `weight`, in this sweep's kind of direction.
    fn rest(&mut self, weight: usize) -> &mut Rest {
        &mut self.rests()[weight]
    }

    /// Drops the resting directions from this sweep's order, each one sweep nearer waking
    /// (all stay if all rest).
    fn sit_out_resting(&mut self) {
        let order = std::mem::take(&mut self.state.order);
        let rests = self.rests();
        let awake: Vec<usize> = order
            .iter()
            .copied()
            .filter(|&i| {
                let resting = rests[i].sweeps > 0;
                rests[i].sweeps = rests[i].sweeps.saturating_sub(1);
                !resting
            })
            .collect();
        self.state.order = if awake.is_empty() { order } else { awake };
    }

    /// The step on `weight` gave no faster lap: reverse and halve it, move to the next block;
    /// a step of more pedal whose lap `failed` rests its direction.
    fn give_up(&mut self, weight: usize, failed: bool) {
        if failed && self.state.config.rest && *self.step(weight) > 0.0 {
            self.rest(weight).failed();
        }
        *self.step(weight) *= -0.5;
        self.advance();
    }
}

impl Proposer for PatternSearchProposer {
    type Note = ();
    type State = PatternSearchProgress;
    const SAVED_AS: SavedAs = SavedAs::WithRecord(NAME);

    fn propose(&mut self, told: &Told) -> Result<Proposal<()>> {
        let (weight, before) = match &self.state.next {
            Trial::Start => return Ok(Proposal::plain(self.state.start.clone())),
            Trial::Push => {
                return match (&self.state.push, self.state.config.lengthscale) {
                    (Some(push), Some(l)) => {
                        // The pushed pedal, the other actions' weights those of the best lap.
                        let pedal = self.pedal_kernels();
                        let mut w = told.best_or(&self.state.start).to_vec();
                        let bounds = SearchBox {
                            lower: self.bounds.lower[..pedal].to_vec(),
                            upper: self.bounds.upper[..pedal].to_vec(),
                        };
                        w[..pedal].copy_from_slice(&push.weights(l, &bounds)?);
                        Ok(Proposal::plain(w))
                    }
                    _ => Err(Error::CorruptState {
                        method: "pattern search",
                        reason: "a push trial without its push".into(),
                    }),
                };
            }
            Trial::Step { weight } => (*weight, &[][..]),
            Trial::Repair { weight, before } => (*weight, &before[..]),
        };
        let step = self.steps()[weight];
        let mut w = told.best_or(&self.state.start).to_vec();
        for (k, coefficient) in self.direction(weight) {
            w[k] += coefficient * step;
        }
        for &j in before {
            w[j] -= self.state.config.give_back * step;
        }
        self.bounds.clamp(&mut w);
        Ok(Proposal::plain(w))
    }

    /// Its tell reads the reward as the outcome of its last step.
    fn takes_any_weights(&self) -> bool {
        false
    }

    fn observe(&mut self, lap: &Lap<'_>, _: Option<&Proposal<()>>, told: &Told) -> Result<()> {
        let (reward, failure, better) = (lap.reward, lap.failure, lap.improved);
        // A failed lap: where it failed is told, or its reward is a failure's 0.
        let failed = failure.is_some() || reward == 0.0;
        let failed_at = failure.map(|f| f.at);
        let repair = self.state.config.repair;
        match self.state.next.clone() {
            Trial::Start => match failure.filter(|_| self.state.config.repair_start) {
                Some(f) => self.repair_start(f, told)?,
                None => self.push_or_sweep(1, None, told)?,
            },
            Trial::Push => {
                let Some(mut push) = self.state.push.take() else {
                    return Err(Error::CorruptState {
                        method: "pattern search",
                        reason: "a push trial without its push".into(),
                    });
                };
                push.laps += 1;
                if better {
                    // A repaired start is not a kept push: the sweeps begin at the widest
                    // blocks (measured: 109.40 against 109.51 s after 100 laps).
                    self.state.pushed |= push.base.is_none();
                    self.push_or_sweep(push.number + 1, Some(&push), told)?;
                } else if failure.is_some_and(|f| push.repair(f, &self.state.config)) {
                    self.state.push = Some(push);
                } else if push.base.is_none() && self.state.config.push_after_unkept {
                    self.push_or_sweep(push.number + 1, None, told)?;
                } else {
                    self.push_or_sweep(push::PUSHES + 1, None, told)?;
                }
            }
            Trial::Step { weight } | Trial::Repair { weight, .. } if better => {
                *self.step(weight) *= 2.0;
                self.rest(weight).failures = 0;
                self.state.next = Trial::Step { weight };
            }
            Trial::Step { weight } => {
                let past = self.past(weight);
                let more_pedal = *self.step(weight) > 0.0;
                match failed_at
                    .filter(|_| repair && more_pedal)
                    .and_then(|at| self.before_failure(past, at))
                {
                    Some(j) => {
                        self.state.next = Trial::Repair {
                            weight,
                            before: vec![j],
                        }
                    }
                    None => self.give_up(weight, failed),
                }
            }
            Trial::Repair { weight, mut before } => {
                let last = before.last().copied().unwrap_or(weight);
                match failed_at
                    .filter(|_| before.len() < self.state.config.repairs)
                    .and_then(|at| self.before_failure(last, at))
                {
                    Some(j) => {
                        before.push(j);
                        self.state.next = Trial::Repair { weight, before };
                    }
                    None => self.give_up(weight, failed),
                }
            }
        }
        Ok(())
    }

    fn dim(&self) -> usize {
        self.state.start.len()
    }

    fn state(&self) -> Cow<'_, PatternSearchProgress> {
        Cow::Borrowed(&self.state)
    }
}
