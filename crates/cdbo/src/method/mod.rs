//! The one registry of methods: each method's name (on the command line, in grids, records,
//! studies and the Python package), its description (the command line's help), its colour in
//! figures, its main knob ([`knob`]), the specification every run is built from ([`spec`]),
//! what it costs ([`cost`]) and the recommended stack by one name ([`preset`]). Everything
//! that names a method reads [`Method`]; the generic optimisers ([`crate::optimizers`]) and
//! the learners ([`crate::learner`]) know nothing of it.

pub mod cost;
pub mod knob;
pub mod preset;
pub mod spec;

pub use knob::{Knob, KnobKind, PAPER_SIGMA0};
pub use preset::Preset;
pub use spec::{Spec, resume};

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::learner::{pattern_search, safe_search};
use crate::optimizers::{bo, cmaes, linebo, random, rembo, turbo};

/// A method [`Spec::optimizer`] builds: the paper's CDBO, its baselines, and later peers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(into = "&'static str", try_from = "String")]
pub enum Method {
    /// The paper's CDBO.
    Cdbo,
    /// Active CMA-ES with IPOP restarts.
    Cmaes,
    /// The GP and UCB of CDBO, the acquisition maximised by CMA-ES.
    BoCmaes,
    /// REMBO in a 5-dimensional embedding.
    Rembo5d,
    /// REMBO in a 10-dimensional embedding.
    Rembo10d,
    /// TuRBO-1.
    Turbo,
    /// LineBO.
    Linebo,
    /// Gaussian random search.
    Random,
    /// The adaptive coordinate pattern search with failure repair.
    PatternSearch,
    /// The pattern search within a budget of failed laps, skipping laps its failures predict
    /// to fail.
    SafePatternSearch,
}

impl Method {
    /// Every method, in the order tables and help list them.
    pub const ALL: [Method; 10] = [
        Method::Cdbo,
        Method::Cmaes,
        Method::BoCmaes,
        Method::Rembo5d,
        Method::Rembo10d,
        Method::Turbo,
        Method::Linebo,
        Method::Random,
        Method::PatternSearch,
        Method::SafePatternSearch,
    ];

    /// The paper's CDBO and the baselines it compares with (Sec. V).
    pub const PAPER: [Method; 5] = [
        Method::Cdbo,
        Method::Cmaes,
        Method::BoCmaes,
        Method::Rembo5d,
        Method::Rembo10d,
    ];

    /// The method's name: `cdbo`, `cmaes`, `bo-cmaes`, ….
    pub fn name(self) -> &'static str {
        match self {
            Method::Cdbo => bo::CDBO,
            Method::Cmaes => cmaes::NAME,
            Method::BoCmaes => bo::BO_CMAES,
            Method::Rembo5d => rembo::NAME_5D,
            Method::Rembo10d => rembo::NAME_10D,
            Method::Turbo => turbo::NAME,
            Method::Linebo => linebo::NAME,
            Method::Random => random::NAME,
            Method::PatternSearch => pattern_search::NAME,
            Method::SafePatternSearch => safe_search::NAME,
        }
    }

    /// One line saying what the method is.
    pub fn description(self) -> &'static str {
        match self {
            Method::Cdbo => "the paper's CDBO: GP + UCB maximised by randomised coordinate ascent",
            Method::Cmaes => "active CMA-ES (negative weights), IPOP restarts",
            Method::BoCmaes => "the same GP and UCB, the acquisition maximised by CMA-ES",
            Method::Rembo5d => "REMBO: GP + EI in a random 5-dimensional embedding",
            Method::Rembo10d => "REMBO: GP + EI in a random 10-dimensional embedding",
            Method::Turbo => "TuRBO-1: trust region, Matérn-5/2 ARD GP, Thompson sampling",
            Method::Linebo => {
                "LineBO: UCB along coordinate and random lines through the best point"
            }
            Method::Random => "Gaussian random search around the best point",
            Method::PatternSearch => {
                "the whole pedal pushed and repaired where laps fail, then coordinate search around the best lap"
            }
            Method::SafePatternSearch => {
                "the pattern search within a budget of failed laps (--max-failed-laps, default 30), never driving a lap its failures predict to fail"
            }
        }
    }

    /// The method's colour in figures (RGB), the same in every figure.
    pub fn colour(self) -> (u8, u8, u8) {
        match self {
            Method::Cdbo => (0, 0, 255),
            Method::Cmaes => (255, 0, 0),
            Method::BoCmaes => (0, 255, 0),
            Method::Rembo5d => (255, 0, 255),
            Method::Rembo10d => (150, 80, 0),
            Method::Turbo => (0, 255, 255),
            Method::Linebo => (120, 120, 120),
            Method::Random => (230, 150, 0),
            Method::PatternSearch => (110, 40, 160),
            Method::SafePatternSearch => (40, 150, 60),
        }
    }
}

/// Methods order by name, as the runs of a grid and its `[knob]` table are listed.
impl Ord for Method {
    fn cmp(&self, other: &Method) -> std::cmp::Ordering {
        self.name().cmp(other.name())
    }
}

impl PartialOrd for Method {
    fn partial_cmp(&self, other: &Method) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Method {
    type Err = Error;

    fn from_str(name: &str) -> Result<Method> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| Error::NotFound {
                what: "method",
                name: format!("{name:?}"),
                detail: format!("available: {}", Method::ALL.map(Method::name).join(", ")),
            })
    }
}

impl From<Method> for &'static str {
    fn from(m: Method) -> &'static str {
        m.name()
    }
}

impl TryFrom<String> for Method {
    type Error = Error;

    fn try_from(name: String) -> Result<Method> {
        name.parse()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every method's name parses back to it, in serde as on the command line; others are
    /// refused naming the choices.
    #[test]
    fn names_round_trip() {
        for m in Method::ALL {
            assert_eq!(m.name().parse::<Method>().unwrap(), m);
            let json = serde_json::to_string(&m).unwrap();
            assert_eq!(json, format!("\"{}\"", m.name()));
            assert_eq!(serde_json::from_str::<Method>(&json).unwrap(), m);
        }
        let e = "simplex".parse::<Method>().unwrap_err().to_string();
        assert!(e.contains("simplex") && e.contains("pattern-search"), "{e}");
        assert!(serde_json::from_str::<Method>("\"CDBO\"").is_err());
    }
}
