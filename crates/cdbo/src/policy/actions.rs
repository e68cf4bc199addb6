//! A policy with several actions: the pedal a(x) and, optionally, the line d(x), each its own
//! RKHS block ([`RkhsPolicy`]) with its own kernels and length-scale. The paper's pedal-only
//! policy is the one-action case.
//!
//! - the pedal a(x) = clamp(w_aᵀφ_a(x), −1, 1) (throttle > 0, brake < 0);
//! - the line d(x) = w_dᵀφ_d(x), the lateral offset (m, positive left) from the centre line
//!   the steering holds, which the lap clamps to the road: |d| ≤ w(s)/2 − w_car/2, the road's
//!   half-width less half the car's width ([`crate::sim::lap`]). Without a line, d = 0.
//!
//! The optimisers see one flat weight vector, the blocks concatenated: w = [w_a, w_d] ∈
//! R^(M_a + M_d) ([`PolicyShape::policy`] splits it, [`Policy::weights`] joins it). A
//! one-action policy's file is the paper's `{"lengthscale": l, "weights": [...]}`; a line
//! adds `"line": {"lengthscale": l_d, "weights": [...]}`.
//!
//! A policy may carry a [`SpeedTarget`]: its pedal's action then sets the speed to hold,
//! v*(x) = (k₀ + s·a(x))·v_g(x), rather than the pedal ([`super::target`]); its file adds
//! `"target": {"profile": [...], "length": L, "scale": k₀, "span": s}`.

use std::ops::Range;

use serde::{Deserialize, Serialize};

use super::rkhs::{RkhsPedal, RkhsPolicy, check_shape, default_lengthscale};
use super::target::{SpeedTarget, TargetHold};
use crate::drive::{Observation, Pedal};
use crate::error::{Error, Result};

/// One action's block of weights: M kernels of length-scale l at x̂ᵢ = i/(M − 1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Block {
    /// Kernels M ≥ 2.
    pub kernels: usize,
    /// Length-scale l > 0 on the lap fraction x.
    pub lengthscale: f64,
}

impl Block {
    /// M kernels of length-scale l, refused unless M ≥ 2 (and within the size bound) and l is
    /// finite and positive.
    pub fn new(kernels: usize, lengthscale: f64) -> Result<Block> {
        check_shape(kernels, lengthscale)?;
        Ok(Block {
            kernels,
            lengthscale,
        })
    }

    /// M kernels at the paper's length-scale, their spacing 1/(M − 1).
    pub fn paper(kernels: usize) -> Result<Block> {
        Block::new(kernels, default_lengthscale(kernels))
    }
}

/// Which actions a policy has and each one's block: the layout [w_a, w_d] of its weights.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PolicyShape {
    /// The pedal's block.
    pub pedal: Block,
    /// The line's block, if the policy steers a line of its own.
    pub line: Option<Block>,
}

impl PolicyShape {
    /// The paper's pedal-only policy.
    pub fn pedal(pedal: Block) -> PolicyShape {
        PolicyShape { pedal, line: None }
    }

    /// This shape with a line d(x) on its own block.
    pub fn with_line(self, line: Block) -> PolicyShape {
        PolicyShape {
            line: Some(line),
            ..self
        }
    }

    /// The dimension M_a + M_d of the weight vector.
    pub fn dims(&self) -> usize {
        self.pedal.kernels + self.line.map_or(0, |l| l.kernels)
    }

    /// Where the pedal's weights lie in the weight vector: 0..M_a.
    pub fn pedal_range(&self) -> Range<usize> {
        0..self.pedal.kernels
    }

    /// The policy of a weight vector [w_a, w_d] of this shape.
    pub fn policy(&self, weights: &[f64]) -> Result<Policy> {
        if weights.len() != self.dims() {
            let line = self
                .line
                .map_or(String::new(), |l| format!(" + {} line", l.kernels));
            return Err(Error::dimension(
                format!(
                    "policy weights ({} pedal{line} kernels)",
                    self.pedal.kernels
                ),
                self.dims(),
                weights.len(),
            ));
        }
        let (pedal, line) = weights.split_at(self.pedal.kernels);
        Ok(Policy {
            pedal: RkhsPolicy::new(pedal.to_vec(), self.pedal.lengthscale)?,
            line: match self.line {
                Some(block) => Some(RkhsPolicy::new(line.to_vec(), block.lengthscale)?),
                None => None,
            },
            target: None,
        })
    }
}

/// A policy with a pedal a(x) and, optionally, a line d(x) (see the [module](self)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Policy {
    /// The pedal: a(x) = clamp(w_aᵀφ_a(x), −1, 1).
    #[serde(flatten)]
    pub pedal: RkhsPolicy,
    /// The line: d(x) = w_dᵀφ_d(x) metres left of the centre line; none: the centre line.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line: Option<RkhsPolicy>,
    /// The speed the pedal's action asks for ([`super::target`]); none: the action is the
    /// pedal, open loop.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<SpeedTarget>,
}

impl From<RkhsPolicy> for Policy {
    /// The paper's pedal-only policy.
    fn from(pedal: RkhsPolicy) -> Policy {
        Policy {
            pedal,
            line: None,
            target: None,
        }
    }
}

impl Policy {
    /// A policy from its JSON text (a one-action policy's file is the paper's), every block
    /// checked; `file` names the text in errors.
    pub fn from_json(text: &str, file: &str) -> Result<Policy> {
        let p: Policy = serde_json::from_str(text)
            .map_err(|e| Error::parse(file, "policy", format!("not policy weights: {e}")))?;
        p.checked(file)
    }

    /// The policy with every block checked as [`RkhsPolicy::new`] checks it (finite weights,
    /// a positive length-scale), for one deserialised without those checks; `file` names it
    /// in errors.
    pub fn checked(self, file: &str) -> Result<Policy> {
        let checked = |b: RkhsPolicy, what: &str| {
            RkhsPolicy::new(b.weights, b.lengthscale)
                .map_err(|e| Error::parse(file, what, e.to_string()))
        };
        Ok(Policy {
            pedal: checked(self.pedal, "policy")?,
            line: self.line.map(|l| checked(l, "line")).transpose()?,
            target: self
                .target
                .map(|t| {
                    t.checked()
                        .map_err(|e| Error::parse(file, "target", e.to_string()))
                })
                .transpose()?,
        })
    }

    /// The paper's pedal-only policy this is, if it has no line and its action is the pedal.
    pub fn pedal_only(&self) -> Option<&RkhsPolicy> {
        (self.line.is_none() && self.target.is_none()).then_some(&self.pedal)
    }

    /// This policy with its action asking for `target`'s speeds (none: the pedal, open
    /// loop).
    pub fn targeting(self, target: Option<SpeedTarget>) -> Policy {
        Policy { target, ..self }
    }

    /// The hold of the speeds its target asks for, if it has one.
    pub fn target_hold(&self) -> Option<TargetHold> {
        self.target.as_ref().map(|t| TargetHold {
            speeds: t.speeds(&self.pedal),
            length: t.length,
        })
    }

    /// Its shape: each action's kernels and length-scale.
    pub fn shape(&self) -> PolicyShape {
        let block = |p: &RkhsPolicy| Block {
            kernels: p.kernels(),
            lengthscale: p.lengthscale,
        };
        PolicyShape {
            pedal: block(&self.pedal),
            line: self.line.as_ref().map(block),
        }
    }

    /// The flat weight vector [w_a, w_d] the optimisers see.
    pub fn weights(&self) -> Vec<f64> {
        let line = self.line.iter().flat_map(|l| &l.weights);
        self.pedal.weights.iter().chain(line).copied().collect()
    }

    /// d(x), the line's offset (m, positive left) before the road's bounds; 0 without a line.
    pub fn line_offset(&self, x: f64) -> f64 {
        self.line.as_ref().map_or(0.0, |l| l.raw(x))
    }

    /// The policy prepared for driving: a(x) and d(x) in O(1) per driver step, or with a
    /// target the hold of its speeds.
    pub fn driver(&self) -> PolicyDriver {
        PolicyDriver {
            pedal: self.pedal.pedal(),
            line: self.line.as_ref().map(RkhsPolicy::pedal),
            hold: self.target_hold(),
        }
    }

    /// The (x, a, d) table at `points` evenly spaced x in [0, 1] (d = 0 without a line).
    pub fn table(&self, points: usize) -> Vec<(f64, f64, f64)> {
        self.pedal
            .table(points)
            .into_iter()
            .map(|(x, a)| (x, a, self.line_offset(x)))
            .collect()
    }
}

/// A [`Policy`] prepared for driving: each block's wᵀφ(x) from two exponentials
/// ([`RkhsPedal`]), and with a target the hold of its speeds.
#[derive(Debug, Clone, PartialEq)]
pub struct PolicyDriver {
    pedal: RkhsPedal,
    line: Option<RkhsPedal>,
    hold: Option<TargetHold>,
}

impl Pedal for PolicyDriver {
    fn pedal(&mut self, obs: &Observation) -> f64 {
        match &mut self.hold {
            Some(hold) => hold.pedal(obs),
            None => self.pedal.action(obs.x),
        }
    }

    fn line(&self, x: f64) -> f64 {
        self.line.as_ref().map_or(0.0, |l| l.raw(x))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_actions() -> Policy {
        let pedal = RkhsPolicy::new(vec![0.2, -0.4, 0.9, 0.1], 1.0 / 3.0).unwrap();
        let line = RkhsPolicy::new(vec![1.5, -2.0, 0.5], 0.25).unwrap();
        Policy {
            pedal,
            line: Some(line),
            target: None,
        }
    }

    /// The flat weights split back into the same blocks, and each action is its block's:
    /// a(x) the pedal's clamped sum, d(x) the line's sum, the driver's O(1) forms agreeing.
    #[test]
    fn the_weights_are_the_blocks_concatenated() {
        let p = two_actions();
        let shape = p.shape();
        assert_eq!(shape.dims(), 7);
        assert_eq!(shape.pedal_range(), 0..4);
        assert_eq!(p.weights(), [0.2, -0.4, 0.9, 0.1, 1.5, -2.0, 0.5]);
        assert_eq!(shape.policy(&p.weights()).unwrap(), p);
        let mut driver = p.driver();
        for x in [0.0, 0.17, 0.5, 0.93, 1.0] {
            let obs = Observation {
                x,
                speed: 10.0,
                time: 0.0,
            };
            assert_eq!(driver.pedal(&obs), p.pedal.pedal().action(x));
            assert!((driver.line(x) - p.line_offset(x)).abs() < 1e-13);
            let line = p.line.as_ref().unwrap();
            assert_eq!(p.line_offset(x), line.raw(x));
        }
        assert!(shape.policy(&[0.0; 6]).is_err());
        assert!(
            shape
                .policy(&[0.0, 0.0, 0.0, 0.0, 0.0, f64::NAN, 0.0])
                .is_err()
        );
    }

    /// A one-action policy is the paper's: its file reads and writes in the paper's form, its
    /// driver gives the paper's pedal and the centre line.
    #[test]
    fn the_pedal_only_policy_is_the_papers() {
        let text = r#"{"lengthscale": 0.5, "weights": [0.25, -1.5, 0.75]}"#;
        let p = Policy::from_json(text, "w.json").unwrap();
        let paper = RkhsPolicy::new(vec![0.25, -1.5, 0.75], 0.5).unwrap();
        assert_eq!(p, Policy::from(paper.clone()));
        assert_eq!(
            serde_json::to_string(&p).unwrap(),
            serde_json::to_string(&paper).unwrap()
        );
        let mut driver = p.driver();
        let obs = Observation {
            x: 0.3,
            speed: 1.0,
            time: 0.0,
        };
        assert_eq!(driver.pedal(&obs), paper.pedal().action(0.3));
        assert_eq!(driver.line(0.3), 0.0);
        let two = two_actions();
        let again = Policy::from_json(&serde_json::to_string(&two).unwrap(), "w.json").unwrap();
        assert_eq!(again, two);
    }

    #[test]
    fn bad_files_are_refused_naming_the_file() {
        for bad in [
            r#"{"lengthscale": 0.5}"#,
            r#"{"lengthscale": -0.5, "weights": [0.0, 1.0]}"#,
            r#"{"lengthscale": 0.5, "weights": [0.0, 1.0], "line": {"lengthscale": 0.5, "weights": [1.0]}}"#,
        ] {
            let e = Policy::from_json(bad, "w.json").unwrap_err().to_string();
            assert!(e.contains("w.json"), "{e}");
        }
    }
}
