//! The ask/tell shell every method runs in: a method is a [`Proposer`] (it proposes the next
//! weights and observes the laps told), and [`AskTell`] keeps what every method keeps alike —
//! the pending proposal (asking twice returns the same weights), the checks of a told lap, the
//! best lap and the number of laps told, and the saved state.

use std::borrow::Cow;
use std::ops::{Deref, DerefMut};

use serde::{Deserialize, Serialize};

use super::{Best, FailedLap, Optimizer, Saved, check_tell_lap};
use crate::error::Result;

/// A method's half of an ask/tell optimiser: its update rule, without the bookkeeping the
/// [`AskTell`] shell keeps for it.
pub trait Proposer {
    /// What a proposal carries besides its weights, handed back when a lap is told after it
    /// (`()` for most methods).
    type Note: Clone + std::fmt::Debug;
    /// The method's own saved state.
    type State: Clone + Serialize;
    /// The kind of the saved state and where the shell's record goes.
    const SAVED_AS: SavedAs;

    /// The method's name on the command line: the kind of its saved state unless it says.
    fn name(&self) -> &'static str {
        Self::SAVED_AS.kind()
    }

    /// Number of weights.
    fn dim(&self) -> usize;

    /// The next weights to drive, given what was told so far.
    fn propose(&mut self, told: &Told) -> Result<Proposal<Self::Note>>;

    /// Learns from a lap, already checked and recorded in `told`; `asked` is the pending
    /// proposal when there was one (its weights may differ from the lap's). A lap it refuses
    /// must leave it unchanged: the shell then undoes its record.
    fn observe(
        &mut self,
        lap: &Lap<'_>,
        asked: Option<&Proposal<Self::Note>>,
        told: &Told,
    ) -> Result<()>;

    /// Whether it learns from laps of any weights, not only those of its last proposal
    /// ([`Optimizer::tells_any_weights`]).
    fn takes_any_weights(&self) -> bool {
        true
    }

    /// The method's state, to save.
    fn state(&self) -> Cow<'_, Self::State>;
}

/// How a method's state is saved: under which kind ([`Saved::kind`]), and where the shell's
/// record of the told laps goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SavedAs {
    /// The method's state holds its told laps, and its resume rebuilds the record from them.
    Laps(&'static str),
    /// The record (`evaluations` and `best`) is flattened beside the method's fields
    /// ([`Recorded`]).
    WithRecord(&'static str),
}

impl SavedAs {
    /// The kind of the saved state.
    pub fn kind(self) -> &'static str {
        match self {
            SavedAs::Laps(kind) | SavedAs::WithRecord(kind) => kind,
        }
    }
}

/// Weights proposed for the next lap, with the proposer's note on them.
#[derive(Debug, Clone, PartialEq)]
pub struct Proposal<N> {
    /// The weights to drive.
    pub weights: Vec<f64>,
    /// What the proposer keeps with them until the lap is told.
    pub note: N,
}

impl Proposal<()> {
    /// Weights with nothing noted.
    pub fn plain(weights: Vec<f64>) -> Proposal<()> {
        Proposal { weights, note: () }
    }
}

/// A told lap, checked, as the shell hands it to its proposer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lap<'a> {
    /// The weights driven.
    pub weights: &'a [f64],
    /// The reward (0 for a failed lap).
    pub reward: f64,
    /// Where and how it failed, when told.
    pub failure: Option<FailedLap>,
    /// Whether it beat every lap told before it (it is now the best).
    pub improved: bool,
}

/// The shell's record of the laps told: how many, and the best.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Told {
    /// Rewards told.
    evaluations: usize,
    /// The best (weights, reward) told.
    best: Best,
}

impl Told {
    /// The record of `laps` (weights, reward) told in order.
    pub fn of<W: AsRef<[f64]>>(laps: impl IntoIterator<Item = (W, f64)>) -> Told {
        let mut told = Told::default();
        for (weights, reward) in laps {
            told.record(weights.as_ref(), reward);
        }
        told
    }

    /// Number of rewards told.
    pub fn evaluations(&self) -> usize {
        self.evaluations
    }

    /// The best weights told and their reward.
    pub fn best(&self) -> Option<(&[f64], f64)> {
        self.best.get()
    }

    /// The best weights told, or `start` before any lap.
    pub fn best_or<'a>(&'a self, start: &'a [f64]) -> &'a [f64] {
        self.best().map_or(start, |b| b.0)
    }

    /// Counts a lap and offers it to the best; returns the best it displaced, if it beat it.
    fn record(&mut self, weights: &[f64], reward: f64) -> Option<Best> {
        self.evaluations += 1;
        let beaten = self.best.get().is_none_or(|b| reward > b.1);
        let displaced = beaten.then(|| std::mem::take(&mut self.best));
        self.best.offer(weights, reward);
        displaced
    }

    /// Undoes [`record`](Told::record).
    fn undo(&mut self, displaced: Option<Best>) {
        self.evaluations -= 1;
        if let Some(best) = displaced {
            self.best = best;
        }
    }
}

/// A method's saved state with the shell's record flattened beside its fields (`evaluations`,
/// `best`): the saved form of the methods whose state kept them ([`SavedAs::WithRecord`]).
/// It reads as the method's state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Recorded<S, T = Told> {
    #[serde(flatten)]
    state: S,
    #[serde(flatten)]
    told: T,
}

impl<S> Recorded<S> {
    /// The method's state and the shell's record, apart.
    pub fn into_parts(self) -> (S, Told) {
        (self.state, self.told)
    }
}

impl<S> Deref for Recorded<S> {
    type Target = S;

    fn deref(&self) -> &S {
        &self.state
    }
}

impl<S> DerefMut for Recorded<S> {
    fn deref_mut(&mut self) -> &mut S {
        &mut self.state
    }
}

/// An [`Optimizer`] made of a method's [`Proposer`] and the bookkeeping every method shares.
/// It reads as its proposer (for a method's own accessors).
#[derive(Debug, Clone)]
pub struct AskTell<P: Proposer> {
    proposer: P,
    told: Told,
    pending: Option<Proposal<P::Note>>,
}

impl<P: Proposer> AskTell<P> {
    /// A run of `proposer` with the record `told` (nothing told yet for a new run).
    pub fn resumed(proposer: P, told: Told) -> AskTell<P> {
        AskTell {
            proposer,
            told,
            pending: None,
        }
    }

    /// A new run of `proposer`, told again the `laps` (weights, reward) in order: how a method
    /// whose state is its told laps resumes.
    pub fn replayed(proposer: P, laps: &[(Vec<f64>, f64)]) -> Result<AskTell<P>> {
        let mut run = AskTell::resumed(proposer, Told::default());
        for (weights, reward) in laps {
            run.tell(weights, *reward)?;
        }
        Ok(run)
    }

    /// The record of the laps told.
    pub fn told(&self) -> &Told {
        &self.told
    }

    /// The proposer, to change what the shell does not keep (a method's own settings).
    pub(crate) fn proposer_mut(&mut self) -> &mut P {
        &mut self.proposer
    }
}

impl<P: Proposer> Deref for AskTell<P> {
    type Target = P;

    fn deref(&self) -> &P {
        &self.proposer
    }
}

impl<P: Proposer> Optimizer for AskTell<P> {
    fn name(&self) -> &'static str {
        self.proposer.name()
    }

    fn dim(&self) -> usize {
        self.proposer.dim()
    }

    fn ask(&mut self) -> Result<Vec<f64>> {
        if let Some(p) = &self.pending {
            return Ok(p.weights.clone());
        }
        let proposal = self.proposer.propose(&self.told)?;
        let weights = proposal.weights.clone();
        self.pending = Some(proposal);
        Ok(weights)
    }

    fn tell(&mut self, weights: &[f64], reward: f64) -> Result<()> {
        self.tell_lap(weights, reward, None)
    }

    fn tell_lap(&mut self, weights: &[f64], reward: f64, failure: Option<FailedLap>) -> Result<()> {
        check_tell_lap(self.dim(), weights, reward, failure)?;
        let displaced = self.told.record(weights, reward);
        let lap = Lap {
            weights,
            reward,
            failure,
            improved: displaced.is_some(),
        };
        match self
            .proposer
            .observe(&lap, self.pending.as_ref(), &self.told)
        {
            Ok(()) => {
                self.pending = None;
                Ok(())
            }
            Err(e) => {
                self.told.undo(displaced);
                Err(e)
            }
        }
    }

    fn tells_any_weights(&self) -> bool {
        self.proposer.takes_any_weights()
    }

    fn best(&self) -> Option<(&[f64], f64)> {
        self.told.best()
    }

    fn evaluations(&self) -> usize {
        self.told.evaluations()
    }

    fn save(&self) -> Saved {
        let state = self.proposer.state();
        match P::SAVED_AS {
            SavedAs::Laps(kind) => Saved::new(kind, &state),
            SavedAs::WithRecord(kind) => Saved::new(
                kind,
                &Recorded {
                    state,
                    told: Cow::Borrowed(&self.told),
                },
            ),
        }
    }
}
