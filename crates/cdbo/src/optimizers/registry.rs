//! The one registry of methods: each method's name (on the command line, in grids, records,
//! studies and the Python package), its description (the command line's help) and its
//! colour in figures. Everything that names a method reads [`Method`].

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// A method [`Method::optimizer`] builds: the paper's CDBO, its baselines, and later peers.
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
}

impl Method {
    /// Every method, in the order tables and help list them.
    pub const ALL: [Method; 9] = [
        Method::Cdbo,
        Method::Cmaes,
        Method::BoCmaes,
        Method::Rembo5d,
        Method::Rembo10d,
        Method::Turbo,
        Method::Linebo,
        Method::Random,
        Method::PatternSearch,
    ];

    /// The paper's CDBO and the baselines it compares with (Sec. V).
    pub const PAPER: [Method; 5] = [
        Method::Cdbo,
        Method::Cmaes,
        Method::BoCmaes,
        Method::Rembo5d,
        Method::Rembo10d,
    ];

    /// The methods whose main knob, σ₀, was tuned on the training tracks: ridgeway-30,
    /// forza-30, e-track-2-30 and forza-50, 300 laps, seeds 100–105 (not the results' seeds),
    /// session 9's physics, chosen by the mean best reward of the four (docs/results/beyond).
    pub const TUNED: [Method; 3] = [Method::Random, Method::Cmaes, Method::PatternSearch];

    /// The method's exploration scale σ₀ in a race ([`Settings::sigma0`]): for the
    /// [`TUNED`](Method::TUNED) methods their tuned knob — random search's σ 0.01 (of 0.003,
    /// 0.01, 0.03), CMA-ES's σ₀ 0.03 (of 0.003–0.1), the pattern search's first step 0.15 (of
    /// 0.1, 0.15, 0.2) — and the paper's 0.03 for the others (CDBO's initial samples).
    ///
    /// [`Settings::sigma0`]: super::Settings::sigma0
    pub fn sigma0(self) -> f64 {
        match self {
            Method::Random => 0.01,
            Method::PatternSearch => 0.15,
            _ => 0.03,
        }
    }

    /// The method's name: `cdbo`, `cmaes`, `bo-cmaes`, ….
    pub fn name(self) -> &'static str {
        match self {
            Method::Cdbo => "cdbo",
            Method::Cmaes => "cmaes",
            Method::BoCmaes => "bo-cmaes",
            Method::Rembo5d => "rembo-5d",
            Method::Rembo10d => "rembo-10d",
            Method::Turbo => "turbo",
            Method::Linebo => "linebo",
            Method::Random => "random",
            Method::PatternSearch => "pattern-search",
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
                "adaptive coordinate search around the best lap, repairing failed laps"
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
        }
    }
}

/// Methods order by name, as the runs of a grid and its `[sigma0]` table are listed.
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

#[cfg(feature = "clap")]
impl clap::ValueEnum for Method {
    fn value_variants<'a>() -> &'a [Method] {
        &Method::ALL
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.name()).help(self.description()))
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
