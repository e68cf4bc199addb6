//! A recommended stack by one name: the learner, the steering and the line a race takes from
//! `--preset` (on `race`, `study create`, `optimize`, `torcs transfer`), a grid's `preset` key
//! and Python's `preset=`. Every interface reads the stack here, so that the name means the
//! same everywhere; anything a preset does not set keeps its own default (the kernels, the
//! method's failure budget).

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use super::Method;
use crate::drive::steering::SteeringLaw;
use crate::error::{Error, Result};
use crate::line::LineKind;

/// A named stack of a learner, a steering law and a line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(into = "&'static str", try_from = "String")]
pub enum Preset {
    /// `fast-safe`, the stack we recommend for a car: `--method safe-pattern-search
    /// --steering tracker --line min-curvature`. The safe pattern search learns within a
    /// budget of failed laps (its own, 30, unless `--max-failed-laps` gives another), never
    /// driving a lap its failures predict to fail; the path tracker steers from the path's
    /// curvature and the car's understeer gradient, and so holds its line at speed where the
    /// paper's PI steering, steering at a look-ahead point, cuts corners and fishtails; the
    /// minimum-curvature racing line has a faster limit lap than the centre line (`cdbo
    /// limit` gives both). Its demonstration holds a share of the limit's speed profile on
    /// that line ([`crate::experiment::profile_start`]), not the paper's 15 m/s. The paper's
    /// CDBO, PI steering and centre line stay the defaults.
    FastSafe,
    /// `fast`, the same drive with the pattern search and no budget: `--method pattern-search
    /// --steering tracker --line min-curvature`. Where a failed lap costs nothing (in a
    /// simulator) it learns the fastest laps, failing several times as many laps as
    /// `fast-safe`; it starts from the paper's demonstration, as every method but the safe
    /// pattern search does.
    Fast,
}

impl Preset {
    /// Every preset, in the order help lists them.
    pub const ALL: [Preset; 2] = [Preset::FastSafe, Preset::Fast];

    /// Its name, as `--preset`, a grid and Python take it.
    pub fn name(self) -> &'static str {
        match self {
            Preset::FastSafe => "fast-safe",
            Preset::Fast => "fast",
        }
    }

    /// The learner it sets.
    pub fn method(self) -> Method {
        match self {
            Preset::FastSafe => Method::SafePatternSearch,
            Preset::Fast => Method::PatternSearch,
        }
    }

    /// The steering it sets.
    pub fn steering(self) -> SteeringLaw {
        match self {
            Preset::FastSafe | Preset::Fast => SteeringLaw::Tracker,
        }
    }

    /// The line it sets.
    pub fn line(self) -> LineKind {
        match self {
            Preset::FastSafe | Preset::Fast => LineKind::MinCurvature,
        }
    }

    /// The long form it stands for, e.g. `--method safe-pattern-search --steering tracker
    /// --line min-curvature`.
    pub fn flags(self) -> String {
        format!(
            "--method {} --steering {} --line {}",
            self.method(),
            self.steering(),
            self.line().name()
        )
    }

    /// One line saying what it sets and why, as `--preset`'s help lists it.
    pub fn description(self) -> &'static str {
        match self {
            Preset::FastSafe => {
                "the safe pattern search (learning within a budget of failed laps, 30 unless \
                 --max-failed-laps gives another) on the path tracker and the minimum-curvature \
                 line: --method safe-pattern-search --steering tracker --line min-curvature"
            }
            Preset::Fast => {
                "the pattern search with no budget on the same drive, for a simulator, where a \
                 failed lap costs nothing: --method pattern-search --steering tracker --line \
                 min-curvature"
            }
        }
    }
}

impl fmt::Display for Preset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Preset {
    type Err = Error;

    fn from_str(name: &str) -> Result<Preset> {
        Preset::ALL
            .into_iter()
            .find(|p| p.name() == name)
            .ok_or_else(|| Error::NotFound {
                what: "preset",
                name: format!("{name:?}"),
                detail: format!("available: {}", Preset::ALL.map(Preset::name).join(", ")),
            })
    }
}

impl From<Preset> for &'static str {
    fn from(p: Preset) -> &'static str {
        p.name()
    }
}

impl TryFrom<String> for Preset {
    type Error = Error;

    fn try_from(name: String) -> Result<Preset> {
        name.parse()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `fast-safe` is the long form the README recommends, and its name parses back to it in
    /// serde as on the command line; another name is refused naming the choices.
    #[test]
    fn fast_safe_is_the_recommended_long_form() {
        let p: Preset = "fast-safe".parse().unwrap();
        assert_eq!(p.method(), Method::SafePatternSearch);
        assert_eq!(p.steering(), SteeringLaw::Tracker);
        assert_eq!(p.line(), LineKind::MinCurvature);
        assert_eq!(
            p.flags(),
            "--method safe-pattern-search --steering tracker --line min-curvature"
        );
        assert!(p.description().ends_with(&p.flags()));
        assert_eq!(serde_json::to_string(&p).unwrap(), "\"fast-safe\"");
        assert_eq!(serde_json::from_str::<Preset>("\"fast-safe\"").unwrap(), p);
        let e = "fastest".parse::<Preset>().unwrap_err().to_string();
        assert!(e.contains("fastest") && e.contains("fast-safe"), "{e}");
    }

    /// `fast` is the pattern search on the same drive, by its name and its long form.
    #[test]
    fn fast_is_the_pattern_search_on_the_same_drive() {
        let p: Preset = "fast".parse().unwrap();
        assert_eq!(p, Preset::Fast);
        assert_eq!(
            p.flags(),
            "--method pattern-search --steering tracker --line min-curvature"
        );
        assert!(p.description().ends_with(&p.flags()));
        assert_eq!(serde_json::to_string(&p).unwrap(), "\"fast\"");
    }
}
