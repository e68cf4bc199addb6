//! The settings every method is built from besides w₀, and the one place a method's
//! optimiser is built ([`Method::optimizer`]) or resumed ([`resume`]).

use super::{KnobKind, Method, PAPER_SIGMA0};
use crate::error::{Error, Result};
use crate::learner::pattern_search::{self, PatternSearch};
use crate::optimizers::bo::{self, Bo};
use crate::optimizers::cmaes::{self, Cmaes};
use crate::optimizers::linebo::{self, LineBo};
use crate::optimizers::random::{self, RandomSearch};
use crate::optimizers::rembo::{self, Rembo};
use crate::optimizers::turbo::{self, Turbo};
use crate::optimizers::{DEFAULT_BOX_RADIUS, Optimizer, Saved, SearchBox};

/// What every method is told besides w₀.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Seed of every random choice.
    pub seed: u64,
    /// UCB β of the UCB methods (CDBO, BO-CMA-ES, LineBO).
    pub beta: f64,
    /// Half-width r of the search box around w₀.
    pub box_radius: f64,
    /// The exploration scale around w₀: CDBO's and REMBO's initial σ₀, and the main knob of the
    /// methods whose knob is σ₀ ([`KnobKind::Sigma0`]: CMA-ES, random and pattern search).
    pub sigma0: f64,
    /// The main knob of the other methods ([`Method::knob`]: TuRBO's L_init, LineBO's line
    /// half-length, REMBO's box half-width); `None`: the method's published setting.
    pub knob: Option<f64>,
    /// The length-scale ℓ of the policy's kernels when the weights are a lap policy's (races
    /// and studies; the pattern search pushes that policy's pedal); `None` for any other
    /// problem.
    pub policy_lengthscale: Option<f64>,
    /// The lap's length (m) when the weights are a lap policy's and it is known (races, and
    /// studies that record it): the pattern search's push repairs over road rather than kernels.
    pub track_length: Option<f64>,
}

impl Settings {
    /// For a race of `method`: the policy box (r = 1.5), σ₀ = 0.03 (CDBO's initial samples;
    /// with σ = 0.1, most perturbations of a cruising demonstration brake the car to a stop on
    /// Forza, and a search whose every lap fails learns nothing) and the method's main knob at
    /// its race value ([`Knob::value`]: tuned on the training panels where swept).
    pub fn race(method: Method, seed: u64, beta: f64) -> Settings {
        let knob = method.knob();
        Settings {
            seed,
            beta,
            box_radius: DEFAULT_BOX_RADIUS,
            sigma0: PAPER_SIGMA0,
            knob: None,
            policy_lengthscale: None,
            track_length: None,
        }
        .with_knob_unchecked(method, knob.value)
    }

    /// These settings with `method`'s main knob at `value`, refused with the knob's name and
    /// range if the method cannot take it ([`Knob::check`]).
    pub fn with_knob(self, method: Method, value: f64) -> Result<Settings> {
        let value = method.knob().check(method, value)?;
        Ok(self.with_knob_unchecked(method, value))
    }

    fn with_knob_unchecked(self, method: Method, value: f64) -> Settings {
        let knob = method.knob();
        match knob.kind {
            KnobKind::Sigma0 => Settings {
                sigma0: value,
                ..self
            },
            _ => Settings {
                knob: (value != knob.published).then_some(value),
                ..self
            },
        }
    }

    /// These settings for the weights of a lap policy whose kernels have length-scale ℓ.
    pub fn for_policy(self, lengthscale: f64) -> Settings {
        Settings {
            policy_lengthscale: Some(lengthscale),
            ..self
        }
    }

    /// These settings for a lap of `length` metres.
    pub fn on_track(self, length: f64) -> Settings {
        Settings {
            track_length: Some(length),
            ..self
        }
    }

    /// For a test problem on a box of half-width r: σ₀ = r/15.
    pub fn problem(seed: u64, box_radius: f64) -> Settings {
        Settings {
            seed,
            beta: crate::acquisition::ucb::DEFAULT_BETA,
            box_radius,
            sigma0: box_radius / 15.0,
            knob: None,
            policy_lengthscale: None,
            track_length: None,
        }
    }
}

/// An optimiser by its name ([`Method`]), from w₀ and the settings shared by every method.
pub fn by_name(name: &str, w0: Vec<f64>, settings: &Settings) -> Result<Box<dyn Optimizer + Send>> {
    name.parse::<Method>()?.optimizer(w0, settings)
}

impl Method {
    /// The method's optimiser, from w₀ and the settings shared by every method.
    pub fn optimizer(self, w0: Vec<f64>, settings: &Settings) -> Result<Box<dyn Optimizer + Send>> {
        let Settings {
            seed,
            beta,
            box_radius,
            sigma0,
            knob,
            policy_lengthscale,
            track_length,
        } = *settings;
        if let Some(length) = track_length.filter(|l| !(l.is_finite() && *l > 0.0)) {
            return Err(Error::invalid_value(
                "the lap's length (m)",
                length,
                "a positive number of metres",
            ));
        }
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
        Ok(match self {
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
            Method::PatternSearch => Box::new(PatternSearch::new(
                w0,
                pattern_search::PatternSearchConfig {
                    seed,
                    sigma0,
                    box_radius,
                    repair: true,
                    lengthscale: policy_lengthscale,
                    track_length,
                    ..pattern_search::PatternSearchConfig::default()
                },
            )?),
        })
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
        kind => {
            return Err(Error::NotFound {
                what: "kind of saved optimiser",
                name: format!("{kind:?}"),
                detail: "available: bo, cmaes, random, rembo, turbo, linebo, pattern-search".into(),
            });
        }
    })
}
