//! Each method's one main knob: what it sets, its published value, its value in a race (tuned
//! on the training panels where swept) and the values it may take.

use super::Method;
use crate::error::{Error, Result};
use crate::optimizers::turbo;

/// The paper's σ₀ of CDBO's initial samples: the exploration scale every method shares unless
/// its main knob is σ₀ and tuned.
pub const PAPER_SIGMA0: f64 = 0.03;

/// What a method's main knob sets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KnobKind {
    /// The exploration scale σ₀ around w₀ ([`Spec::sigma0`](crate::method::Spec::sigma0)).
    Sigma0,
    /// TuRBO's initial trust-region side L_init.
    TrustRegionLength,
    /// LineBO's line half-length.
    LineStep,
    /// REMBO's embedding box half-width.
    EmbeddingBox,
}

impl KnobKind {
    /// The knob's short name, as results and errors show it.
    pub fn name(self) -> &'static str {
        match self {
            KnobKind::Sigma0 => "sigma0",
            KnobKind::TrustRegionLength => "length",
            KnobKind::LineStep => "step",
            KnobKind::EmbeddingBox => "box",
        }
    }
}

/// A method's one main knob: what it sets, its published value, its value in a race (tuned on
/// the training panels where [`swept`](Knob::swept) lists values) and the values swept.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Knob {
    /// What the knob sets.
    pub kind: KnobKind,
    /// One line saying what it is.
    pub meaning: &'static str,
    /// Its value in the method's paper (or the paper's σ₀ for the methods that use it).
    pub published: f64,
    /// Its value in a race (`cdbo race`, the `paper-plus` grid): the sweep's choice, or the
    /// published value if not swept.
    pub value: f64,
    /// The values swept on the training panels; empty: not tuned.
    pub swept: &'static [f64],
    /// The largest value the method takes.
    pub max: f64,
}

impl Knob {
    /// Whether the knob was tuned by a sweep.
    pub fn tuned(&self) -> bool {
        !self.swept.is_empty()
    }

    /// `value` if the method can take it: positive, at most [`max`](Knob::max), and finite
    /// unless the published value is infinite (LineBO's whole line: `--knob inf`).
    pub(super) fn check(&self, method: Method, value: f64) -> Result<f64> {
        let finite = value.is_finite() || value == self.published;
        if finite && value > 0.0 && value <= self.max {
            Ok(value)
        } else {
            Err(Error::invalid_value(
                format!("{method}'s knob {} ({})", self.kind.name(), self.meaning),
                value,
                if self.max.is_finite() {
                    format!("in (0, {}]", self.max)
                } else if self.published.is_infinite() {
                    "a positive number (inf: the published whole line)".into()
                } else {
                    "a finite positive number".into()
                },
            ))
        }
    }
}

impl Method {
    /// The method's one main knob (every peer's is chosen by the same small sweep on
    /// the training panels ridgeway-30, forza-30, e-track-2-30 and forza-50, 300 laps, seeds
    /// from 100, by the mean best reward of the four; docs/results/beyond): random search's σ
    /// 0.01, CMA-ES's σ₀ 0.03, the pattern search's first step 0.05 (seeds 100–105); TuRBO's
    /// L_init 0.03 (TuRBO: 0.8), LineBO's step 0.3 (LineBO: the whole line), REMBO-5d's box
    /// 0.1 and REMBO-10d's 0.03 (REMBO: √d) (seeds 100–102). CDBO and BO-CMA-ES keep the
    /// paper's σ₀.
    pub fn knob(self) -> Knob {
        let sigma0 = |meaning, value, swept| Knob {
            kind: KnobKind::Sigma0,
            meaning,
            published: PAPER_SIGMA0,
            value,
            swept,
            max: f64::INFINITY,
        };
        let rembo_box = |d: f64, value, swept| Knob {
            kind: KnobKind::EmbeddingBox,
            meaning: "half-width b of the embedding's box [-b, b]^d",
            published: d.sqrt(),
            value,
            swept,
            max: f64::INFINITY,
        };
        match self {
            Method::Cdbo | Method::BoCmaes => {
                sigma0("σ₀ of the initial samples", PAPER_SIGMA0, &[])
            }
            Method::Cmaes => sigma0("initial step size σ₀", 0.03, &[0.003, 0.01, 0.03, 0.1]),
            Method::Random => sigma0(
                "σ of the samples around the best point",
                0.01,
                &[0.003, 0.01, 0.03],
            ),
            Method::PatternSearch => {
                sigma0("first step σ₀", 0.05, &[0.03, 0.05, 0.08, 0.1, 0.12, 0.15])
            }
            Method::SafePatternSearch => sigma0("first step σ₀ (the pattern search's)", 0.05, &[]),
            Method::Rembo5d => rembo_box(5.0, 0.1, &[0.01, 0.03, 0.1, 2.236]),
            Method::Rembo10d => rembo_box(10.0, 0.03, &[0.01, 0.03, 0.1, 3.162]),
            Method::Turbo => Knob {
                kind: KnobKind::TrustRegionLength,
                meaning: "initial trust-region side L_init, a fraction of the box's side",
                published: turbo::LENGTH_INIT,
                value: 0.03,
                swept: &[0.01, 0.03, 0.1, 0.8],
                max: turbo::LENGTH_MAX,
            },
            Method::Linebo => Knob {
                kind: KnobKind::LineStep,
                meaning: "half-length of each line: the farthest a lap moves from its origin (inf: the box)",
                published: f64::INFINITY,
                value: 0.3,
                swept: &[0.03, 0.1, 0.3, f64::INFINITY],
                max: f64::INFINITY,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A knob takes positive values up to its maximum; infinity only where it is the published
    /// setting (LineBO's whole line), which then leaves the method as published.
    #[test]
    fn knobs_take_their_range_and_linebo_its_whole_line() {
        let linebo = Method::Linebo.knob();
        assert_eq!(
            linebo.check(Method::Linebo, f64::INFINITY).unwrap(),
            f64::INFINITY
        );
        let spec = crate::method::Spec::race(Method::Linebo);
        assert_eq!(spec.knob_value(), Some(0.3));
        let whole = spec.knob(f64::INFINITY).unwrap();
        assert_eq!(whole.knob_value(), None);
        for m in [Method::Turbo, Method::Rembo5d, Method::Random] {
            let e = m.knob().check(m, f64::INFINITY).unwrap_err().to_string();
            assert!(e.contains(m.name()), "{e}");
        }
        for bad in [0.0, -0.1, f64::NAN] {
            assert!(linebo.check(Method::Linebo, bad).is_err(), "{bad}");
        }
        let turbo = Method::Turbo.knob();
        assert!(turbo.check(Method::Turbo, turbo.max).is_ok());
        assert!(turbo.check(Method::Turbo, 1.01 * turbo.max).is_err());
    }
}
