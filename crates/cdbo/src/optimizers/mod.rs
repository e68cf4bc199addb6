//! Optimisers behind one ask/tell face: ask for the weights of the next lap, tell its reward.
//!
//! Every method starts from the demonstration's weights w₀ (the paper: "all methods are
//! informed with this initial solution"), counts one lap per evaluation, takes every random
//! choice from its seed, and treats a failed lap (reward 0) as an ordinary observation.

pub mod bo;
pub mod cmaes;
pub mod cmaes_ascent;
pub mod coordinate_ascent;
pub mod linebo;
pub mod pattern_search;
pub mod random;
pub mod registry;
pub mod rembo;
pub mod turbo;

pub use registry::{Knob, KnobKind, Method};

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// An ask/tell optimiser of lap rewards over policy weights.
pub trait Optimizer {
    /// The method's name on the command line.
    fn name(&self) -> &'static str;

    /// Number of weights.
    fn dim(&self) -> usize;

    /// The weights of the next lap to drive. Asking again before telling returns the same.
    fn ask(&mut self) -> Result<Vec<f64>>;

    /// The reward of a lap driven with `weights` (0 for a failed lap). Bad input — wrong
    /// dimension, non-finite weights or reward — is refused and changes nothing.
    fn tell(&mut self, weights: &[f64], reward: f64) -> Result<()>;

    /// [`tell`](Optimizer::tell) with where and how a failed lap failed (for a failed lap whose
    /// place is known): all a car's lap timer and driver give besides the time. Methods that
    /// read it override this; the others are told the reward.
    fn tell_lap(&mut self, weights: &[f64], reward: f64, failure: Option<FailedLap>) -> Result<()> {
        let _ = failure;
        self.tell(weights, reward)
    }

    /// Whether [`tell`](Optimizer::tell) takes any weights, not only those of the last ask:
    /// what a study needs to hand several workers distinct laps at once (it tells a copy of
    /// the optimiser each lap in flight with a made-up reward, then asks the copy).
    fn tells_any_weights(&self) -> bool {
        true
    }

    /// The best weights told so far and their reward.
    fn best(&self) -> Option<(&[f64], f64)>;

    /// Number of rewards told.
    fn evaluations(&self) -> usize;

    /// The whole state, to resume the run later with [`Saved::resume`] exactly where it is.
    fn save(&self) -> Saved;
}

/// What a car's timer and driver tell of a failed lap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FailedLap {
    /// Where it failed, a lap fraction in [0, 1].
    pub at: f64,
    /// Whether the car was too slow there (it stalled or ran out of time) rather than too fast
    /// (it left the road, spun or turned round).
    pub too_slow: bool,
}

impl FailedLap {
    /// A lap that failed at `at` for being too fast, the usual failure of a faster policy.
    pub fn too_fast(at: f64) -> FailedLap {
        FailedLap {
            at,
            too_slow: false,
        }
    }
}

/// The saved state of an optimiser of any method, tagged with its kind.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", tag = "kind", content = "state")]
pub enum Saved {
    /// CDBO or BO-CMA-ES.
    Bo(Box<bo::BoState>),
    /// Active CMA-ES.
    Cmaes(Box<cmaes::CmaesState>),
    /// Random search.
    Random(Box<random::RandomState>),
    /// REMBO.
    Rembo(Box<rembo::RemboState>),
    /// TuRBO-1.
    Turbo(Box<turbo::TurboState>),
    /// LineBO.
    Linebo(Box<linebo::LineBoState>),
    /// Pattern search with failure repair.
    PatternSearch(Box<pattern_search::PatternSearchState>),
}

impl Saved {
    /// The optimiser, continuing exactly as the saved one would have.
    pub fn resume(self) -> Result<Box<dyn Optimizer + Send>> {
        Ok(match self {
            Saved::Bo(s) => Box::new(bo::Bo::resume(*s)?),
            Saved::Cmaes(s) => Box::new(cmaes::Cmaes::resume(*s)?),
            Saved::Random(s) => Box::new(random::RandomSearch::resume(*s)?),
            Saved::Rembo(s) => Box::new(rembo::Rembo::resume(*s)?),
            Saved::Turbo(s) => Box::new(turbo::Turbo::resume(*s)?),
            Saved::Linebo(s) => Box::new(linebo::LineBo::resume(*s)?),
            Saved::PatternSearch(s) => Box::new(pattern_search::PatternSearch::resume(*s)?),
        })
    }
}

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
            sigma0: registry::PAPER_SIGMA0,
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
            Method::Cdbo => Box::new(bo::Bo::new(
                w0,
                bo(bo::Maximiser::CoordinateAscent(Default::default())),
            )?),
            Method::BoCmaes => Box::new(bo::Bo::new(
                w0,
                bo(bo::Maximiser::Cmaes(Default::default())),
            )?),
            Method::Cmaes => {
                let config = cmaes::CmaesConfig {
                    seed,
                    sigma0,
                    bounds: Some(SearchBox::around(&w0, box_radius)?),
                    ..cmaes::CmaesConfig::default()
                };
                Box::new(cmaes::Cmaes::new(w0, config)?)
            }
            Method::Rembo5d => Box::new(rembo::Rembo::new(w0, rembo(5))?),
            Method::Rembo10d => Box::new(rembo::Rembo::new(w0, rembo(10))?),
            Method::Turbo => Box::new(turbo::Turbo::new(
                w0,
                turbo::TurboConfig {
                    seed,
                    box_radius,
                    length_init: knob.unwrap_or(turbo::LENGTH_INIT),
                    ..turbo::TurboConfig::default()
                },
            )?),
            Method::Linebo => Box::new(linebo::LineBo::new(
                w0,
                linebo::LineBoConfig {
                    seed,
                    box_radius,
                    beta,
                    step: knob,
                    ..linebo::LineBoConfig::default()
                },
            )?),
            Method::Random => Box::new(random::RandomSearch::new(
                w0,
                random::RandomConfig {
                    seed,
                    sigma: sigma0,
                    box_radius,
                },
            )?),
            Method::PatternSearch => Box::new(pattern_search::PatternSearch::new(
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

/// The box the weights are searched in: [w₀ − r, w₀ + r] in every coordinate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SearchBox {
    /// Lower corner.
    pub lower: Vec<f64>,
    /// Upper corner.
    pub upper: Vec<f64>,
}

/// The default half-width r of the search box around w₀.
pub const DEFAULT_BOX_RADIUS: f64 = 1.5;

impl SearchBox {
    /// [w₀ − r, w₀ + r].
    pub fn around(w0: &[f64], radius: f64) -> Result<SearchBox> {
        if !(radius.is_finite() && radius > 0.0) {
            return Err(Error::invalid_value(
                "the search-box radius",
                radius,
                "positive",
            ));
        }
        Ok(SearchBox {
            lower: w0.iter().map(|w| w - radius).collect(),
            upper: w0.iter().map(|w| w + radius).collect(),
        })
    }

    /// The point clamped into the box.
    pub fn clamp(&self, w: &mut [f64]) {
        for ((v, lo), hi) in w.iter_mut().zip(&self.lower).zip(&self.upper) {
            *v = v.clamp(*lo, *hi);
        }
    }
}

/// The best (weights, reward) told so far.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct Best(Option<(Vec<f64>, f64)>);

impl Best {
    /// Records (weights, reward) if it beats the best; returns whether it did.
    pub fn offer(&mut self, weights: &[f64], reward: f64) -> bool {
        let better = self.0.as_ref().is_none_or(|b| reward > b.1);
        if better {
            self.0 = Some((weights.to_vec(), reward));
        }
        better
    }

    /// The best weights and reward.
    pub fn get(&self) -> Option<(&[f64], f64)> {
        self.0.as_ref().map(|(w, r)| (w.as_slice(), *r))
    }
}

/// Checks a told (weights, reward) pair against the dimension.
pub(crate) fn check_tell(dim: usize, weights: &[f64], reward: f64) -> Result<()> {
    if weights.len() != dim {
        return Err(Error::dimension("weights", dim, weights.len()));
    }
    if let Some(i) = weights.iter().position(|w| !w.is_finite()) {
        return Err(Error::invalid_value(
            format!("weight {i}"),
            weights[i],
            "finite",
        ));
    }
    if !reward.is_finite() {
        return Err(Error::invalid_value(
            "the reward",
            reward,
            "finite (0 for a failed lap)",
        ));
    }
    Ok(())
}

/// [`check_tell`] with the place a failed lap failed at, a lap fraction in [0, 1] when known.
pub(crate) fn check_tell_lap(
    dim: usize,
    weights: &[f64],
    reward: f64,
    failure: Option<FailedLap>,
) -> Result<()> {
    check_tell(dim, weights, reward)?;
    match failure.map(|f| f.at) {
        Some(x) if !(x.is_finite() && (0.0..=1.0).contains(&x)) => Err(Error::invalid_value(
            "the failure place",
            x,
            "a lap fraction in [0, 1]",
        )),
        _ => Ok(()),
    }
}

/// A generator for draw number `stream` of a run seeded with `seed`: every random choice is a
/// pure function of (seed, stream), so a resumed run makes the same choices.
pub fn rng_for(seed: u64, stream: u64) -> rand_chacha::ChaCha8Rng {
    use rand::SeedableRng;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(stream);
    rng
}
