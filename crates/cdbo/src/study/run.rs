//! The lap loop, the one every command drives laps through: take the next trial from a
//! [`TrialSource`], drive it with an [`Evaluator`], tell the source its [`Outcome`], and
//! report each step as an [`Event`] (the caller prints or records them; the loop prints
//! nothing).
//!
//! Two sources exist: a [`Study`] claimed by one of several workers ([`Study::run`]: leases
//! renewed by a heartbeat while the lap is driven, a trial another worker told first skipped,
//! waiting while the last trials are out with other workers), and [`InMemory`], an optimiser
//! asked and told directly, which is what a race is ([`crate::experiment::race`]).

use std::path::PathBuf;
use std::time::{Duration, Instant};

use super::claim::{Missed, Worker, while_renewing};
use super::{Location, Next, Outcome, Study, Trial};
use crate::error::{Error, Result};
use crate::evaluator::Evaluator;
use crate::optimizers::Optimizer;

/// Where the loop's trials come from and where their outcomes go.
pub trait TrialSource {
    /// The next trial to drive, or whether to wait or stop.
    fn next(&mut self) -> Result<Next>;

    /// Records the outcome of `trial`; returns its reward. An [`Error::Conflict`] (another
    /// worker told the trial first) is reported by the loop, which goes on.
    fn tell(&mut self, trial: &Trial, outcome: &Outcome) -> Result<f64>;

    /// Drives `lap` for `trial` while keeping the trial this worker's; returns its outcome and
    /// what happened to the claim meanwhile. Without claims: just drives.
    fn keep_claimed(
        &self,
        trial: i64,
        lap: &mut dyn FnMut() -> Result<Outcome>,
    ) -> (Result<Outcome>, Vec<Event<'static>>) {
        let _ = trial;
        (lap(), Vec::new())
    }

    /// Waits before asking again after [`Next::Wait`].
    fn wait(&self) {
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// Seconds spent on each step of one trial.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Timing {
    /// Getting the trial (the optimiser's ask, with the study's storage if any).
    pub ask_s: f64,
    /// Driving the lap.
    pub evaluate_s: f64,
    /// Telling the outcome (the optimiser's tell, with the study's storage if any).
    pub tell_s: f64,
}

/// What the loop reports.
#[derive(Debug)]
pub enum Event<'a> {
    /// A trial's outcome was told (for a study: committed, durable).
    Told {
        /// The trial driven.
        trial: &'a Trial,
        /// Its outcome.
        outcome: &'a Outcome,
        /// Its reward.
        reward: f64,
        /// Where the time went.
        timing: Timing,
    },
    /// Every remaining trial is out with other workers: the loop waits (reported once per
    /// wait).
    Waiting,
    /// Another worker told this trial first (ours had lost its claim); the loop goes on.
    Conflict {
        /// The trial.
        trial: i64,
        /// The study's refusal.
        error: Error,
    },
    /// While the lap was driven its claim ran out and another worker took the trial over.
    ClaimLost {
        /// The trial.
        trial: i64,
    },
    /// A heartbeat could not renew the claim (the lap goes on; the next beat retries).
    HeartbeatFailed {
        /// The trial.
        trial: i64,
        /// Why.
        error: Error,
    },
    /// A file an evaluator left behind when its process was killed mid-lap was removed.
    LeftoverRemoved {
        /// The file.
        path: PathBuf,
        /// The process that wrote it.
        pid: u32,
    },
}

/// Drives every trial `source` hands out with `evaluator` until it says done.
pub fn run(
    source: &mut dyn TrialSource,
    evaluator: &mut dyn Evaluator,
    on_event: &mut dyn FnMut(Event<'_>),
) -> Result<()> {
    let mut waiting = false;
    loop {
        let t0 = Instant::now();
        let trial = match source.next()? {
            Next::Done => return Ok(()),
            Next::Wait => {
                if !waiting {
                    on_event(Event::Waiting);
                    waiting = true;
                }
                source.wait();
                continue;
            }
            Next::Drive(t) => t,
        };
        waiting = false;
        let ask_s = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        let (outcome, notes) = source.keep_claimed(trial.id, &mut || {
            evaluator.evaluate(trial.id, &trial.weights)
        });
        let evaluate_s = t1.elapsed().as_secs_f64();
        notes.into_iter().for_each(&mut *on_event);
        let outcome = outcome?;
        let t2 = Instant::now();
        let reward = match source.tell(&trial, &outcome) {
            Ok(r) => r,
            Err(error @ Error::Conflict { .. }) => {
                on_event(Event::Conflict {
                    trial: trial.id,
                    error,
                });
                continue;
            }
            Err(e) => return Err(e),
        };
        let timing = Timing {
            ask_s,
            evaluate_s,
            tell_s: t2.elapsed().as_secs_f64(),
        };
        on_event(Event::Told {
            trial: &trial,
            outcome: &outcome,
            reward,
            timing,
        });
    }
}

/// An optimiser asked and told directly for a number of laps, nothing stored: a race.
pub struct InMemory {
    optimizer: Box<dyn Optimizer + Send>,
    laps: usize,
    told: usize,
}

impl InMemory {
    /// `laps` trials of `optimizer`, numbered 1, 2, 3, ….
    pub fn new(optimizer: Box<dyn Optimizer + Send>, laps: usize) -> InMemory {
        InMemory {
            optimizer,
            laps,
            told: 0,
        }
    }
}

impl TrialSource for InMemory {
    fn next(&mut self) -> Result<Next> {
        if self.told >= self.laps {
            return Ok(Next::Done);
        }
        Ok(Next::Drive(Trial {
            id: self.told as i64 + 1,
            weights: self.optimizer.ask()?,
            reward: None,
            lap_time_s: None,
            failure: None,
            x_fail: None,
        }))
    }

    fn tell(&mut self, trial: &Trial, outcome: &Outcome) -> Result<f64> {
        let reward = outcome.reward()?;
        self.optimizer
            .tell_lap(&trial.weights, reward, outcome.failed_lap())?;
        self.told += 1;
        Ok(reward)
    }
}

/// A study as one worker's trial source, driving to `total` told trials.
struct Claims<'a> {
    study: &'a mut Study,
    worker: &'a Worker,
    total: usize,
}

impl TrialSource for Claims<'_> {
    fn next(&mut self) -> Result<Next> {
        self.study.claim(self.worker, Some(self.total))
    }

    fn tell(&mut self, trial: &Trial, outcome: &Outcome) -> Result<f64> {
        self.study.tell(trial.id, outcome)
    }

    fn keep_claimed(
        &self,
        trial: i64,
        lap: &mut dyn FnMut() -> Result<Outcome>,
    ) -> (Result<Outcome>, Vec<Event<'static>>) {
        with_heartbeat(self.study.location(), self.worker, trial, lap)
    }

    fn wait(&self) {
        std::thread::sleep(
            self.worker
                .heartbeat_interval()
                .clamp(Duration::from_millis(100), Duration::from_secs(1)),
        );
    }
}

impl Study {
    /// Drives this study's trials as `worker` with `evaluator` until it has `total` told
    /// trials (counting those told before), as [`run`] does; first removes what the
    /// evaluator's killed processes left behind ([`Evaluator::remove_leftovers`]).
    pub fn run(
        &mut self,
        evaluator: &mut dyn Evaluator,
        worker: &Worker,
        total: usize,
        on_event: &mut dyn FnMut(Event<'_>),
    ) -> Result<()> {
        for (path, pid) in evaluator.remove_leftovers() {
            on_event(Event::LeftoverRemoved { path, pid });
        }
        let mut claims = Claims {
            study: self,
            worker,
            total,
        };
        run(&mut claims, evaluator, on_event)
    }
}

/// Runs `lap` while a thread renews `worker`'s claim on trial `id` every heartbeat interval,
/// through its own connection to the study at `location`; returns the lap's result and what
/// the heartbeat met.
fn with_heartbeat(
    location: &Location,
    worker: &Worker,
    id: i64,
    lap: &mut dyn FnMut() -> Result<Outcome>,
) -> (Result<Outcome>, Vec<Event<'static>>) {
    let renewer = move || -> Result<Box<dyn FnMut() -> Result<bool> + '_>> {
        let study = Study::open_at(location)?;
        Ok(Box::new(move || study.heartbeat(id, worker)))
    };
    let (result, missed) = while_renewing(worker.heartbeat_interval(), renewer, lap);
    let notes = missed
        .into_iter()
        .map(|m| match m {
            Missed::Lost => Event::ClaimLost { trial: id },
            Missed::Failed(error) => Event::HeartbeatFailed { trial: id, error },
        })
        .collect();
    (result, notes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::method::{Method, Spec};

    /// Rewards from a closed form: −‖w − w*‖², a failed lap where w₀ > 1.
    struct Bowl;

    impl Evaluator for Bowl {
        fn evaluate(&mut self, _trial: i64, w: &[f64]) -> Result<Outcome> {
            if w[0] > 1.0 {
                return Ok(Outcome::Failed {
                    at: Some(0.5),
                    reason: None,
                });
            }
            Ok(Outcome::Reward(
                -w.iter().map(|x| (x - 0.3).powi(2)).sum::<f64>(),
            ))
        }
    }

    /// The in-memory loop asks, drives and tells exactly as a hand-written ask/tell loop does.
    #[test]
    fn in_memory_runs_are_the_hand_written_loop() {
        let optimizer = || {
            Spec::told(Method::Cdbo, 4, 2.0, None)
                .and_then(|spec| spec.optimizer(vec![0.0; 3]))
                .unwrap()
        };
        let mut told = Vec::new();
        let mut source = InMemory::new(optimizer(), 12);
        run(&mut source, &mut Bowl, &mut |e| {
            if let Event::Told { trial, reward, .. } = e {
                told.push((trial.id, trial.weights.clone(), reward));
            }
        })
        .unwrap();
        let mut by_hand = optimizer();
        for (k, (id, weights, reward)) in told.iter().enumerate() {
            assert_eq!(*id, k as i64 + 1);
            let w = by_hand.ask().unwrap();
            assert_eq!(&w, weights);
            let outcome = Bowl.evaluate(*id, &w).unwrap();
            assert_eq!(outcome.reward().unwrap(), *reward);
            by_hand.tell_lap(&w, *reward, outcome.failed_lap()).unwrap();
        }
        assert_eq!(told.len(), 12);
    }
}
