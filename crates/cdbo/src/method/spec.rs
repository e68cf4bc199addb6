//! The specification of a run: which method, and everything it is told besides w₀ — seed,
//! UCB β, the search box, the exploration scale σ₀, the method's main knob, and, when the
//! weights are a lap policy's, its kernels' length-scale and the lap's length. Each value is
//! checked once, where it is set ([`Spec`]'s setters); the command line, TOML grids, studies
//! and Python all build a [`Spec`], and [`Spec::optimizer`] is the one place an optimiser is
//! built, [`resume`] the one place a saved one continues.

use super::{KnobKind, Method, PAPER_SIGMA0};
use crate::error::{Error, Result};
use crate::learner::budget::{self, FailureBudget};
use crate::learner::pattern_search::{self, PatternSearch};
use crate::learner::safe_search::{self, SafeSearch};
use crate::optimizers::bo::{self, Bo};
use crate::optimizers::cmaes::{self, Cmaes};
use crate::optimizers::linebo::{self, LineBo};
use crate::optimizers::random::{self, RandomSearch};
use crate::optimizers::rembo::{self, Rembo};
use crate::optimizers::turbo::{self, Turbo};
use crate::optimizers::{DEFAULT_BOX_RADIUS, FailedLap, Optimizer, Saved, SearchBox};

/// A method and everything it is told besides w₀, every value checked when it was set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spec {
    method: Method,
    seed: u64,
    beta: f64,
    box_radius: f64,
    sigma0: f64,
    knob: Option<f64>,
    policy_lengthscale: Option<f64>,
    track_length: Option<f64>,
    pedal_kernels: Option<usize>,
    max_failed_laps: Option<usize>,
    warm: bool,
    start_completes: bool,
}

impl Spec {
    /// `method` as it races (`cdbo race`): seed 0, the default UCB β, the policy box
    /// (r = [`DEFAULT_BOX_RADIUS`]), σ₀ = [`PAPER_SIGMA0`] (CDBO's initial samples; with
    /// σ = 0.1, most perturbations of a cruising demonstration brake the car to a stop on
    /// Forza, and a search whose every lap fails learns nothing) and the method's main knob at
    /// its race value ([`Knob::value`](super::Knob::value): tuned on the training panels where
    /// swept).
    pub fn race(method: Method) -> Spec {
        Spec {
            method,
            seed: 0,
            beta: crate::acquisition::ucb::DEFAULT_BETA,
            box_radius: DEFAULT_BOX_RADIUS,
            sigma0: PAPER_SIGMA0,
            knob: None,
            policy_lengthscale: None,
            track_length: None,
            pedal_kernels: None,
            max_failed_laps: None,
            warm: false,
            start_completes: false,
        }
        .with_checked_knob(method.knob().value)
    }

    /// `method` on a test problem searched in a box of half-width r around its start:
    /// σ₀ = r/15, the method's published knob.
    pub fn problem(method: Method, box_radius: f64) -> Result<Spec> {
        Spec::race(method)
            .with_checked_knob(method.knob().published)
            .box_radius(box_radius)?
            .sigma0(box_radius / 15.0)
    }

    /// `method` as told by a race or a study: its race specification ([`Spec::race`]) with
    /// this seed, UCB β and, if given, main knob.
    pub fn told(method: Method, seed: u64, beta: f64, knob: Option<f64>) -> Result<Spec> {
        let spec = Spec::race(method).seed(seed).beta(beta)?;
        knob.map_or(Ok(spec), |value| spec.knob(value))
    }

    /// This specification with seed `seed` for every random choice.
    pub fn seed(self, seed: u64) -> Spec {
        Spec { seed, ..self }
    }

    /// This specification with UCB β = `beta` (CDBO, BO-CMA-ES, LineBO), refused unless finite
    /// and non-negative.
    pub fn beta(self, beta: f64) -> Result<Spec> {
        if !(beta.is_finite() && beta >= 0.0) {
            return Err(Error::invalid_value("UCB β", beta, "finite and ≥ 0"));
        }
        Ok(Spec { beta, ..self })
    }

    /// This specification searching the box [w₀ − r, w₀ + r], refused unless
    /// 0 < r ≤ [`MAX_BOX_RADIUS`](crate::optimizers::MAX_BOX_RADIUS).
    pub fn box_radius(self, box_radius: f64) -> Result<Spec> {
        crate::optimizers::SearchBox::around(&[], box_radius)?;
        Ok(Spec { box_radius, ..self })
    }

    /// This specification with exploration scale σ₀ around w₀ (CDBO's and REMBO's initial
    /// samples, and the knob of the methods whose knob is σ₀), refused unless finite and
    /// positive.
    pub fn sigma0(self, sigma0: f64) -> Result<Spec> {
        let sigma0 = positive("σ₀", sigma0)?;
        Ok(Spec { sigma0, ..self })
    }

    /// This specification with the method's main knob at `value` (σ₀, TuRBO's L_init, LineBO's
    /// step, REMBO's box), refused with the knob's name and range if the method cannot take it
    /// (`Knob::check`: the one check of a knob).
    pub fn knob(self, value: f64) -> Result<Spec> {
        let value = self.method.knob().check(self.method, value)?;
        Ok(self.with_checked_knob(value))
    }

    fn with_checked_knob(self, value: f64) -> Spec {
        let knob = self.method.knob();
        match knob.kind {
            KnobKind::Sigma0 => Spec {
                sigma0: value,
                ..self
            },
            _ => Spec {
                knob: (value != knob.published).then_some(value),
                ..self
            },
        }
    }

    /// This specification for the weights of a lap policy whose kernels have length-scale ℓ
    /// (the pattern search then pushes that policy's pedal), refused unless ℓ is finite and
    /// positive.
    pub fn policy(self, lengthscale: f64) -> Result<Spec> {
        Ok(Spec {
            policy_lengthscale: Some(positive("the policy's length-scale", lengthscale)?),
            ..self
        })
    }

    /// This specification for a lap of `length` metres (the pattern search's push then repairs
    /// over road rather than kernels), refused unless finite and positive.
    pub fn track_length(self, length: f64) -> Result<Spec> {
        Ok(Spec {
            track_length: Some(positive("the lap's length (m)", length)?),
            ..self
        })
    }

    /// This specification for the weights of a policy with a line ([`crate::policy::actions`]):
    /// the first `kernels` are the pedal's (the pattern search pushes and repairs those), the
    /// rest another action's.
    pub fn pedal_kernels(self, kernels: usize) -> Spec {
        Spec {
            pedal_kernels: Some(kernels),
            ..self
        }
    }

    /// This specification within a budget of `max` failed laps ([`FailureBudget`]): once they
    /// have failed, only the best completed lap is driven again.
    pub fn max_failed_laps(self, max: usize) -> Spec {
        Spec {
            max_failed_laps: Some(max),
            ..self
        }
    }

    /// This specification starting from a learned policy rather than a demonstration's fit
    /// (a warm start): the pattern search does not push it (a learned policy is pushed
    /// already) but repairs it where its first lap fails, as a push is repaired
    /// ([`PatternSearchConfig::warm`](pattern_search::PatternSearchConfig::warm)); the other
    /// methods are unchanged (their search box is centred on the start, as always).
    pub fn warm_started(self) -> Spec {
        Spec { warm: true, ..self }
    }

    /// This specification for a start w₀ whose lap is known to complete (a race drives it until
    /// it does, [`crate::experiment::start`]): a budget of failed laps spent before any lap of
    /// the method has completed drives the start again ([`FailureBudget::falling_back_to`]), so
    /// that the budget is a cap from the first lap.
    pub fn start_completed(self) -> Spec {
        Spec {
            start_completes: true,
            ..self
        }
    }

    /// The method.
    pub fn method(&self) -> Method {
        self.method
    }

    /// The seed of every random choice.
    pub fn seed_value(&self) -> u64 {
        self.seed
    }

    /// The exploration scale σ₀.
    pub fn sigma0_value(&self) -> f64 {
        self.sigma0
    }

    /// The main knob of a method whose knob is not σ₀, when it differs from the published
    /// setting.
    pub fn knob_value(&self) -> Option<f64> {
        self.knob
    }

    /// The method's optimiser, from w₀ (within its failed-lap budget, if it has one; the safe
    /// pattern search spends its budget itself, [`safe_search::BUDGET`] unless told).
    pub fn optimizer(&self, w0: Vec<f64>) -> Result<Box<dyn Optimizer + Send>> {
        self.optimizer_after(w0, &[])
    }

    /// The method's optimiser, from a w₀ whose lap completed after the laps `failed` (their
    /// weights, and where and how each failed; a race's start, [`crate::experiment::start`]):
    /// the safe pattern search remembers them ([`SafeSearch::after_failures`]), the other
    /// methods keep no memory of failed laps and start as [`optimizer`](Self::optimizer).
    pub fn optimizer_after(
        &self,
        w0: Vec<f64>,
        failed: &[(Vec<f64>, FailedLap)],
    ) -> Result<Box<dyn Optimizer + Send>> {
        let method = self.method_optimizer(w0.clone(), failed)?;
        Ok(match self.max_failed_laps {
            Some(max) if self.method != Method::SafePatternSearch => {
                let budget = FailureBudget::new(method, max);
                Box::new(if self.start_completes {
                    budget.falling_back_to(w0)
                } else {
                    budget
                })
            }
            _ => method,
        })
    }

    fn method_optimizer(
        &self,
        w0: Vec<f64>,
        failed: &[(Vec<f64>, FailedLap)],
    ) -> Result<Box<dyn Optimizer + Send>> {
        let Spec {
            method,
            seed,
            beta,
            box_radius,
            sigma0,
            knob,
            policy_lengthscale,
            track_length,
            pedal_kernels,
            max_failed_laps,
            warm,
            start_completes: _,
        } = *self;
        let pattern_search = pattern_search::PatternSearchConfig {
            seed,
            sigma0,
            box_radius,
            repair: true,
            lengthscale: policy_lengthscale,
            track_length,
            pedal_kernels,
            ..if warm {
                pattern_search::PatternSearchConfig::warm()
            } else {
                pattern_search::PatternSearchConfig::default()
            }
        };
        let bo = |maximiser| bo::BoConfig {
            seed,
            acquisition: crate::acquisition::Acquisition::Ucb { beta },
            box_radius,
            maximiser,
            initial_sigma: sigma0,
            ..bo::BoConfig::default()
        };
        let rembo = |embedding_dim| rembo::RemboConfig {
            seed,
            embedding_dim,
            box_radius,
            sigma0,
            embedding_box: knob,
        };
        Ok(match method {
            Method::Cdbo => Box::new(Bo::new(
                w0,
                bo(bo::Maximiser::CoordinateAscent(Default::default())),
            )?),
            Method::BoCmaes => Box::new(Bo::new(w0, bo(bo::Maximiser::Cmaes(Default::default())))?),
            Method::Cmaes => {
                let config = cmaes::CmaesConfig {
                    seed,
                    sigma0,
                    bounds: Some(SearchBox::around(&w0, box_radius)?),
                    ..cmaes::CmaesConfig::default()
                };
                Box::new(Cmaes::new(w0, config)?)
            }
            Method::Rembo5d => Box::new(Rembo::new(w0, rembo(5))?),
            Method::Rembo10d => Box::new(Rembo::new(w0, rembo(10))?),
            Method::Turbo => Box::new(Turbo::new(
                w0,
                turbo::TurboConfig {
                    seed,
                    box_radius,
                    length_init: knob.unwrap_or(turbo::LENGTH_INIT),
                    ..turbo::TurboConfig::default()
                },
            )?),
            Method::Linebo => Box::new(LineBo::new(
                w0,
                linebo::LineBoConfig {
                    seed,
                    box_radius,
                    beta,
                    step: knob,
                    ..linebo::LineBoConfig::default()
                },
            )?),
            Method::Random => Box::new(RandomSearch::new(
                w0,
                random::RandomConfig {
                    seed,
                    sigma: sigma0,
                    box_radius,
                },
            )?),
            Method::PatternSearch => Box::new(PatternSearch::new(w0, pattern_search)?),
            Method::SafePatternSearch => {
                let budget = max_failed_laps.unwrap_or(safe_search::BUDGET);
                let config = safe_search::SafeSearchConfig::within(pattern_search, budget);
                Box::new(SafeSearch::after_failures(w0, config, failed)?)
            }
        })
    }
}

/// `value` if it is finite and positive, else an error naming `what`.
fn positive(what: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::invalid_value(what, value, "finite and positive"))
    }
}

/// The optimiser a [`Saved`] state was saved from, continuing exactly as it would have.
pub fn resume(saved: Saved) -> Result<Box<dyn Optimizer + Send>> {
    Ok(match saved.kind() {
        "bo" => Box::new(Bo::resume(saved.state("BO")?)?),
        cmaes::NAME => Box::new(Cmaes::resume(saved.state("CMA-ES")?)?),
        random::NAME => Box::new(RandomSearch::resume(saved.state("random search")?)?),
        "rembo" => Box::new(Rembo::resume(saved.state("REMBO")?)?),
        turbo::NAME => Box::new(Turbo::resume(saved.state("TuRBO")?)?),
        linebo::NAME => Box::new(LineBo::resume(saved.state("LineBO")?)?),
        pattern_search::NAME => Box::new(PatternSearch::resume(saved.state("pattern search")?)?),
        safe_search::NAME => Box::new(SafeSearch::resume(saved.state("safe pattern search")?)?),
        budget::SAVED_KIND => Box::new(FailureBudget::resume(
            saved.state("failure budget")?,
            resume,
        )?),
        kind => {
            return Err(Error::NotFound {
                what: "kind of saved optimiser",
                name: format!("{kind:?}"),
                detail: "available: bo, cmaes, random, rembo, turbo, linebo, pattern-search, safe-pattern-search, failure-budget".into(),
            });
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every value is refused where it is set, naming what it is and the value; nothing
    /// reaches an optimiser unchecked.
    #[test]
    fn bad_values_are_refused_where_they_are_set() {
        let spec = Spec::race(Method::PatternSearch);
        for bad in [f64::NAN, -1.0, f64::INFINITY] {
            let errors = [
                spec.beta(bad).unwrap_err(),
                spec.box_radius(bad).unwrap_err(),
                spec.sigma0(bad).unwrap_err(),
                spec.policy(bad).unwrap_err(),
                spec.track_length(bad).unwrap_err(),
                spec.knob(bad).unwrap_err(),
            ];
            for e in errors.map(|e| e.to_string()) {
                let shown = if bad.is_nan() {
                    "NaN".into()
                } else {
                    bad.to_string()
                };
                assert!(e.contains(&shown), "{e}");
            }
        }
        assert!(spec.box_radius(0.0).is_err() && spec.sigma0(0.0).is_err());
        assert_eq!(spec.beta(0.0).unwrap().beta, 0.0);
    }

    /// A race's specification is the method's race value of its knob, and a knob told is the
    /// method's own: σ₀ for the σ₀ methods, the knob otherwise, and the published value leaves
    /// the method as published.
    #[test]
    fn a_told_knob_sets_what_the_method_reads() {
        let told = Spec::told(Method::Random, 5, 1.0, Some(0.2)).unwrap();
        assert_eq!((told.seed_value(), told.sigma0_value()), (5, 0.2));
        let cdbo = Spec::told(Method::Cdbo, 0, 1.0, None).unwrap();
        assert_eq!(cdbo.sigma0_value(), PAPER_SIGMA0);
        let turbo = Spec::told(Method::Turbo, 0, 1.0, Some(0.1)).unwrap();
        assert_eq!(
            (turbo.knob_value(), turbo.sigma0_value()),
            (Some(0.1), PAPER_SIGMA0)
        );
        let published = Spec::told(Method::Turbo, 0, 1.0, Some(turbo::LENGTH_INIT)).unwrap();
        assert_eq!(published.knob_value(), None);
        let problem = Spec::problem(Method::Cmaes, 3.0).unwrap();
        assert_eq!(problem.sigma0_value(), 0.2);
    }

    /// A cliff: laps fail wherever Σw > 0.5, else the reward rises towards the cliff.
    fn lap(w: &[f64]) -> (f64, Option<crate::optimizers::FailedLap>) {
        let s: f64 = w.iter().sum();
        if s > 0.5 {
            (0.0, Some(crate::optimizers::FailedLap::too_fast(0.5)))
        } else {
            (10.0 + s, None)
        }
    }

    /// Within a budget of 3, at most 3 laps fail over 80, for each of 10 seeds; saved halfway
    /// and resumed, the run asks the same weights as the uninterrupted one.
    #[test]
    fn a_budget_caps_failures_and_resumes_bit_for_bit() {
        for seed in 0..10 {
            let spec = Spec::race(Method::Random).seed(seed).max_failed_laps(3);
            let mut a = spec.optimizer(vec![0.0; 4]).unwrap();
            let mut failed = 0;
            let mut resumed = None;
            for k in 0..80 {
                if k == 40 {
                    resumed = Some(resume(a.save()).unwrap());
                }
                let w = a.ask().unwrap();
                if let Some(b) = resumed.as_mut() {
                    assert_eq!(b.ask().unwrap(), w, "seed {seed} lap {k}");
                }
                let (reward, failure) = lap(&w);
                failed += usize::from(failure.is_some());
                a.tell_lap(&w, reward, failure).unwrap();
                if let Some(b) = resumed.as_mut() {
                    b.tell_lap(&w, reward, failure).unwrap();
                }
            }
            assert!(failed <= 3, "seed {seed}: {failed} failed laps");
            assert_eq!(a.evaluations(), 80);
            assert!(a.best().unwrap().1 > 10.0, "seed {seed}: no gain");
        }
    }

    /// A search box is refused where it is not positive, not finite, or past the bound the
    /// weights saturate within; the bound itself is taken.
    #[test]
    fn a_box_radius_past_its_bound_is_refused() {
        let spec = Spec::race(Method::Cdbo);
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e308, 1000.5] {
            let e = spec.box_radius(bad).unwrap_err().to_string();
            assert!(e.contains("search-box radius"), "{bad}: {e}");
        }
        assert!(spec.box_radius(crate::optimizers::MAX_BOX_RADIUS).is_ok());
    }

    /// Every method's first lap is its start w₀ (CMA-ES's excepted: it samples around it), as
    /// a race relies on: the race drives the start until it completes and hands the completed
    /// lap to the method as its first. Told that the start completes, a budget spent before any
    /// lap of the method's completed drives the start again, CMA-ES's included.
    #[test]
    fn every_methods_first_lap_is_its_start() {
        let w0: Vec<f64> = (0..12).map(|i| 0.1 * i as f64 - 0.3).collect();
        for method in Method::ALL {
            let spec = Spec::race(method)
                .policy(1.0 / 11.0)
                .unwrap()
                .track_length(3000.0)
                .unwrap();
            let first = spec.optimizer(w0.clone()).unwrap().ask().unwrap();
            assert_eq!(first == w0, method != Method::Cmaes, "{method}");
            if method == Method::SafePatternSearch {
                continue;
            }
            let mut spent = spec
                .max_failed_laps(0)
                .start_completed()
                .optimizer(w0.clone())
                .unwrap();
            for _ in 0..3 {
                let w = spent.ask().unwrap();
                assert_eq!(w, w0, "{method}");
                spent.tell(&w, 0.0).unwrap();
            }
        }
    }
}
