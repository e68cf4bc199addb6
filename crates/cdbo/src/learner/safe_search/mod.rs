//! The safe pattern search: the pattern search ([`crate::learner::pattern_search`]) within a
//! budget of failed laps, proposing only laps its memory of failures does not predict to fail.
//!
//! On a real car a failed lap is a car off the road. The pattern search learns fast because it
//! steps up to the limit and repairs where laps fail, but most of its failures repeat what an
//! earlier lap already said: a push failing at the same corner again, a step of more pedal
//! before a corner that left the road at less. This learner keeps every failed lap as a bracket
//! on the road before where it failed ([`memory`]) and, before a lap is driven, asks whether a
//! bracket predicts it to fail. If one does, the lap is not driven: the search is told the
//! predicted failure instead, as if the lap had failed there (it repairs before that place or
//! moves on, exactly as after a real failure), and proposes again. Only laps no bracket
//! predicts to fail reach the car.
//!
//! **The budget.** A budget of B failed laps is spent over a horizon of H laps: after t laps,
//! B·min(1, t/H)^p may have failed (the pace p). While fewer have, a lap is predicted to fail
//! when it keeps κ = [`REACH`] of a failed lap's excess (a move of more pedal that gives back
//! less than half of what failed is not driven); once the failed laps are ahead of the pace,
//! κ = [`STRICT_REACH`]: no lap that adds pedal before a place any lap failed at is driven,
//! only moves where nothing has failed yet. Once B laps have failed, only the best completed
//! lap is driven again (in a deterministic simulator, a hard cap of B; until a lap completes
//! the search goes on, as [`FailureBudget`] does).
//!
//! **The push, gentler.** The push raises the pedal by U₀ = [`PUSH`] rather than 0.35, and a
//! corner's first repair lowers it by δ₀ = [`REPAIR_STEP`] rather than 0.1: fewer corners are
//! over the limit per push, and fewer laps fail at each. Where the start lap itself fails, it
//! is first repaired where it fails until it completes (a push of size 0), then pushed.
//!
//! **The laps before its start.** A race drives its w₀ until it completes
//! ([`crate::experiment::start`]); those failed laps count in the budget, and the search
//! remembers those too fast as brackets against w₀ ([`SafeSearch::after_failures`]): without
//! them its first push failed again where the start had (measured at 4174b20 on TUMFTM's 13
//! circuits, seeds 0–2: Austin 69.0 → 79.8 % of the centre-line limit, all 86.3 → 86.2 %;
//! docs/results/any-track.md).
//!
//! **A lifted budget.** A budget of at least H failed laps cannot bind within the horizon: the
//! learner is then the pattern search itself, its push, repairs and laps exactly
//! ([`SafeSearchConfig::within`]).
//!
//! Measured on four panels (6 seeds × 300 laps each): docs/budgets.md.
//!
//! [`FailureBudget`]: crate::learner::budget::FailureBudget

pub mod memory;

use std::borrow::Cow;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::learner::pattern_search::{
    PatternSearchConfig, PatternSearchProgress, PatternSearchProposer, Trial,
};
use crate::optimizers::FailedLap;
use crate::optimizers::ask_tell::{AskTell, Lap, Proposal, Proposer, Recorded, SavedAs, Told};
use memory::{FailureMemory, Pedals};

/// The method's name, and the kind of its saved state.
pub const NAME: &str = "safe-pattern-search";
/// Failed laps allowed by default, B: 10 % of the paper's 300-lap race (docs/budgets.md).
pub const BUDGET: usize = 30;
/// The laps the budget is spent over, H (the paper's race).
pub const HORIZON: usize = 300;
/// The pace p: B·(t/H)^p laps may have failed after t laps (measured: 0, ¼, ½ on 3 seeds of
/// the four benchmark panels, ½ best; docs/budgets.md).
pub const PACE: f64 = 0.5;
/// The reach κ of a bracket while the failed laps keep to the pace (measured: ¼ and ½).
pub const REACH: f64 = 0.25;
/// The reach κ once they are ahead of it (measured: 0, 0.1, ¼, ½).
pub const STRICT_REACH: f64 = 0.1;
/// The first push's size U₀, gentler than the pattern search's 0.35: fewer corners left the
/// road per push (measured: 0.2, 0.25, 0.35).
pub const PUSH: f64 = 0.25;
/// The push's first repair step δ₀ at a new corner, larger than the pattern search's 0.1:
/// fewer failed laps per corner (measured: 0.1, 0.15, 0.2, 0.35).
pub const REPAIR_STEP: f64 = 0.15;

/// How far back before a failure place a failed step's bracket reaches, in windows of the
/// push's repair distance: from the first place where the failed lap had more pedal than its
/// reference (at least a tenth of its largest excess), at most this far back. A step of more
/// pedal on the straight before a corner fails there as surely as one in the braking zone
/// (profiled on Forza-50: steps at x ≈ 0.08–0.18 failing at 0.24, outside its 275 m). Measured
/// (6 seeds, the four panels, m/s): 1 window 33.43 / 23.35 / 22.12 / 29.93, 3 windows 34.12 /
/// 23.96 / 22.46 / 30.63, 6 windows 34.36 / 23.62 / 22.64 / 32.49, 10 windows 34.53 / 23.74 /
/// 22.64 / 31.26. A push's failures keep one window (a push raises the whole lap, and its
/// repairs act over one window).
pub const REACH_BACK: f64 = 6.0;

/// A failed step's bracket over one window: the state of searches saved before
/// [`REACH_BACK`].
fn one_window() -> f64 {
    1.0
}

/// Settings of a safe pattern search.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SafeSearchConfig {
    /// The pattern search proposing the laps.
    pub search: PatternSearchConfig,
    /// Failed laps allowed, B.
    pub budget: usize,
    /// The laps the budget is spent over, H.
    pub horizon: usize,
    /// The pace p.
    pub pace: f64,
    /// The reach κ while the failed laps keep to the pace.
    pub reach: f64,
    /// The reach κ once they are ahead of it.
    pub strict_reach: f64,
    /// How far back a failed step's bracket reaches, in windows ([`REACH_BACK`]).
    #[serde(default = "one_window")]
    pub reach_back: f64,
}

impl SafeSearchConfig {
    /// The default budget, pace and reaches around `search`, whose push is made gentler
    /// ([`PUSH`], [`REPAIR_STEP`]) and repairs a failed start lap first.
    pub fn around(search: PatternSearchConfig) -> SafeSearchConfig {
        SafeSearchConfig::within(search, BUDGET)
    }

    /// The settings around `search` within a budget of `budget` failed laps: those of
    /// [`around`](Self::around) while the budget can bind within the [`HORIZON`]. A budget of
    /// at least [`HORIZON`] failed laps is lifted: the search is then the pattern search
    /// itself (its own push and repairs, no lap held back), so lifting the budget gives the
    /// pattern search's laps exactly (measured with the gentler push and the brackets kept:
    /// 37.45 / 25.79 / 23.70 / 35.10 m/s on the four panels against its 40.21 / 27.17 /
    /// 25.48 / 37.50).
    pub fn within(search: PatternSearchConfig, budget: usize) -> SafeSearchConfig {
        let search = if budget >= HORIZON {
            search
        } else {
            PatternSearchConfig {
                push: PUSH,
                repair_step: REPAIR_STEP,
                repair_start: true,
                stop_half_way: false,
                push_after_unkept: false,
                ..search
            }
        };
        SafeSearchConfig {
            search,
            budget,
            horizon: HORIZON,
            pace: PACE,
            reach: REACH,
            strict_reach: STRICT_REACH,
            reach_back: REACH_BACK,
        }
    }
}

/// The search's state besides the pattern search's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SafeSearchProgress {
    /// Settings.
    pub config: SafeSearchConfig,
    /// The pattern search's own state.
    pub search: PatternSearchProgress,
    /// The brackets of the failed laps.
    pub memory: FailureMemory,
    /// Laps told.
    pub laps: usize,
    /// Failed laps told.
    pub failed: usize,
    /// Laps predicted to fail and not driven.
    pub skipped: usize,
}

/// The lap asked and not yet told: its weights, whether it is the best lap driven again (not
/// the search's), and the search as it stands after the laps skipped to reach it. Asking
/// changes nothing saved: a run saved between ask and tell asks the same lap again.
#[derive(Debug, Clone)]
struct Asked {
    weights: Vec<f64>,
    again: bool,
    search: PatternSearchProposer,
    skipped: usize,
}

/// A safe search's saved state: its progress and the shell's record.
pub type SafeSearchState = Recorded<SafeSearchProgress>;

/// The proposer: the pattern search's, its laps filtered by the memory and the budget. The
/// pattern search's state is kept in the progress too, as of the last ask or tell, to save.
#[derive(Debug, Clone)]
pub struct SafeSearchProposer {
    state: SafeSearchProgress,
    search: PatternSearchProposer,
    pedals: Pedals,
    asked: Option<Asked>,
}

/// The safe pattern search.
pub type SafeSearch = AskTell<SafeSearchProposer>;

impl SafeSearch {
    /// A search from `start` (driven first, unmoved).
    pub fn new(start: Vec<f64>, config: SafeSearchConfig) -> Result<SafeSearch> {
        SafeSearch::after_failures(start, config, &[])
    }

    /// A search from `start`, a lap that completed after the laps `failed` (their weights,
    /// and where and how each failed), driven before the search and not counted in its
    /// budget: each is remembered as a bracket against `start` over one window before where
    /// it failed, as a push's failure is, so that the search's first laps do not drive again
    /// what they already said. A race's start is such a lap: w₀ repaired where its laps left
    /// the road ([`crate::experiment::start`]).
    pub fn after_failures(
        start: Vec<f64>,
        config: SafeSearchConfig,
        failed: &[(Vec<f64>, FailedLap)],
    ) -> Result<SafeSearch> {
        let pedals = pedals_of(&config, start.len());
        let reference = pedals.sample(&start)?;
        let mut memory = FailureMemory::default();
        for (weights, failure) in failed {
            if weights.len() != start.len() {
                return Err(Error::invalid_value(
                    "a failed lap before the safe search's start",
                    format!("{} weights", weights.len()),
                    format!("{} weights, as the start has", start.len()),
                ));
            }
            memory.failed(&pedals, &pedals.sample(weights)?, &reference, *failure, 1.0);
        }
        let search = PatternSearchProposer::new(start, config.search.clone())?;
        let progress = SafeSearchProgress {
            config,
            search: search.progress().clone(),
            memory,
            laps: 0,
            failed: 0,
            skipped: 0,
        };
        Ok(AskTell::resumed(
            SafeSearchProposer::resume(progress)?,
            Told::default(),
        ))
    }

    /// Rebuilds a search from its state.
    pub fn resume(state: SafeSearchState) -> Result<SafeSearch> {
        let (state, told) = state.into_parts();
        Ok(AskTell::resumed(SafeSearchProposer::resume(state)?, told))
    }
}

/// How a search of `config` reads the pedal of its `dim` weights.
fn pedals_of(config: &SafeSearchConfig, dim: usize) -> Pedals {
    let c = &config.search;
    Pedals::new(
        c.pedal_kernels.unwrap_or(dim),
        c.lengthscale,
        c.track_length,
    )
}

impl SafeSearchProposer {
    fn resume(state: SafeSearchProgress) -> Result<SafeSearchProposer> {
        let c = &state.config;
        for (what, value) in [
            ("the safe search's reach", c.reach),
            ("the safe search's strict reach", c.strict_reach),
        ] {
            if !(0.0..=1.0).contains(&value) {
                return Err(Error::invalid_value(what, value, "in [0, 1]"));
            }
        }
        if !(c.reach_back.is_finite() && c.reach_back >= 1.0) {
            return Err(Error::invalid_value(
                "the safe search's reach back",
                c.reach_back,
                "at least 1 window",
            ));
        }
        if !(c.pace.is_finite() && c.pace >= 0.0) || c.horizon == 0 {
            return Err(Error::invalid_value(
                "the safe search's pace and horizon",
                format!("{} and {}", c.pace, c.horizon),
                "a pace ≥ 0 over at least one lap",
            ));
        }
        let search = PatternSearchProposer::resume(state.search.clone())?;
        let pedals = pedals_of(c, state.search.start.len());
        let n = c.search.pedal_kernels.unwrap_or(state.search.start.len());
        if !state.memory.is_sound(pedals.points()) {
            return Err(Error::CorruptState {
                method: "safe pattern search",
                reason: format!(
                    "brackets that do not fit {n} weights read at {} places",
                    pedals.points()
                ),
            });
        }
        Ok(SafeSearchProposer {
            state,
            search,
            pedals,
            asked: None,
        })
    }

    /// Whether the budget is lifted, at least one failed lap per lap of the horizon: no lap
    /// is held back.
    fn lifted(&self) -> bool {
        self.state.config.budget >= self.state.config.horizon
    }

    /// The failed laps allowed after the laps told so far: B·min(1, t/H)^p.
    fn allowance(&self) -> f64 {
        let c = &self.state.config;
        let t = (self.state.laps as f64 / c.horizon as f64).min(1.0);
        c.budget as f64 * t.powf(c.pace)
    }

    /// The search's next lap that no bracket predicts to fail with reach `reach`, telling
    /// `search` the predicted failure of each one skipped, and how many were; after as many
    /// skips as four per weight (and 16 more), no lap.
    fn unpredicted(
        &self,
        search: &mut PatternSearchProposer,
        reach: f64,
        told: &Told,
    ) -> Result<(Option<Vec<f64>>, usize)> {
        let limit = 4 * search.dim() + 16;
        for skipped in 0..limit {
            let w = search.propose(told)?.weights;
            let Some(failure) = self.state.memory.predict(&self.pedals.sample(&w)?, reach) else {
                return Ok((Some(w), skipped));
            };
            let predicted = Lap {
                weights: &w,
                reward: 0.0,
                failure: Some(failure),
                improved: false,
            };
            search.observe(&predicted, None, told)?;
        }
        Ok((None, limit))
    }

    /// The next lap: the best completed lap again once the budget is spent, the search's next
    /// lap where the budget is lifted, else the search's next lap no bracket predicts to fail (with the strict reach once the failed laps are
    /// ahead of the pace; if none is found then, the best lap again).
    fn ask(&self, told: &Told) -> Result<Asked> {
        let best = told
            .best()
            .filter(|(_, reward)| *reward > 0.0)
            .map(|(w, _)| w.to_vec());
        let c = &self.state.config;
        let spent = self.state.failed >= c.budget;
        let ahead = best.is_some() && self.state.failed as f64 >= self.allowance();
        let reach = if ahead { c.strict_reach } else { c.reach };
        let mut search = self.search.clone();
        let (weights, again, skipped) = match best {
            Some(best) if spent => (best, true, 0),
            _ if self.lifted() => (search.propose(told)?.weights, false, 0),
            best => match (self.unpredicted(&mut search, reach, told)?, best) {
                ((Some(w), skipped), _) => (w, false, skipped),
                ((None, skipped), Some(best)) if ahead => (best, true, skipped),
                ((None, skipped), _) => (search.propose(told)?.weights, false, skipped),
            },
        };
        Ok(Asked {
            weights,
            again,
            search,
            skipped,
        })
    }
}

impl Proposer for SafeSearchProposer {
    type Note = ();
    type State = SafeSearchProgress;
    const SAVED_AS: SavedAs = SavedAs::WithRecord(NAME);

    fn propose(&mut self, told: &Told) -> Result<Proposal<()>> {
        let asked = match self.asked.take() {
            Some(asked) => asked,
            None => self.ask(told)?,
        };
        let weights = asked.weights.clone();
        self.asked = Some(asked);
        Ok(Proposal::plain(weights))
    }

    /// Its tell reads the reward as the outcome of its last proposal.
    fn takes_any_weights(&self) -> bool {
        false
    }

    fn observe(&mut self, lap: &Lap<'_>, asked: Option<&Proposal<()>>, told: &Told) -> Result<()> {
        let Asked {
            again,
            mut search,
            skipped,
            ..
        } = match self.asked.take() {
            Some(asked) => asked,
            None => self.ask(told)?,
        };
        let pushed = search.progress().next == Trial::Push;
        let c_back = self.state.config.reach_back;
        if !again {
            search.observe(lap, asked, told)?;
        }
        self.search = search;
        self.state.skipped += skipped;
        let pedal = self.pedals.sample(lap.weights)?;
        let failed = lap.failure.is_some() || lap.reward == 0.0;
        match lap.failure {
            Some(failure) => {
                let reference = self.pedals.sample(told.best_or(lap.weights))?;
                self.state.memory.failed(
                    &self.pedals,
                    &pedal,
                    &reference,
                    failure,
                    if pushed { 1.0 } else { c_back },
                );
            }
            None if !failed => self.state.memory.completed(&pedal),
            None => {}
        }
        self.state.laps += 1;
        self.state.failed += usize::from(failed);
        self.state.search = self.search.progress().clone();
        Ok(())
    }

    fn dim(&self) -> usize {
        self.search.dim()
    }

    fn state(&self) -> Cow<'_, SafeSearchProgress> {
        Cow::Borrowed(&self.state)
    }
}
