//! The line a race's car holds, as every interface names it (`--line`, `--line-kernels`,
//! `--line-start` on the command line, `line = …` in a grid, `line=…` in Python): one
//! [`LineSetting`], resolved into the race's [`BaseLine`] and learned line's kernels.

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::{LineOptions, RacingLine};
use crate::car::Car;
use crate::error::{Error, Result};
use crate::track::Track;
/// The line a race's car holds where its policy has none, part of the track as the driver's
/// reference ([`crate::sim::LapConfig::line`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BaseLine {
    /// The centre line, d₀ = 0.
    #[default]
    Centre,
    /// The minimum-curvature racing line ([`RacingLine::minimum_curvature`]) at half the car's
    /// width plus [`SAFETY_MARGIN`](crate::line::SAFETY_MARGIN) inside the edge laps are
    /// learned by ([`LineOptions::for_race`]): |d₀(s)| ≤ w(s)/2 − w_car/2 − 0.5 m, a metre less
    /// where the track gives no verges.
    MinCurvature,
}

impl BaseLine {
    /// Whether this is the centre line.
    pub fn is_centre(&self) -> bool {
        *self == BaseLine::Centre
    }

    /// Its name: `centre` or `min-curvature`.
    pub fn name(&self) -> &'static str {
        match self {
            BaseLine::Centre => "centre",
            BaseLine::MinCurvature => "min-curvature",
        }
    }

    /// The line on `track` for `car`; `None` for the centre line.
    pub fn line(&self, track: &Track, car: &Car) -> Result<Option<Arc<RacingLine>>> {
        Ok(match self {
            BaseLine::Centre => None,
            BaseLine::MinCurvature => Some(Arc::new(RacingLine::minimum_curvature(
                track,
                &LineOptions::for_race(car, track),
            )?)),
        })
    }
}

impl std::str::FromStr for BaseLine {
    type Err = Error;
    fn from_str(s: &str) -> Result<BaseLine> {
        match s {
            "centre" => Ok(BaseLine::Centre),
            "min-curvature" => Ok(BaseLine::MinCurvature),
            _ => Err(Error::invalid_value(
                "the line start",
                format!("{s:?}"),
                "centre or min-curvature",
            )),
        }
    }
}

/// The line a race's car holds (`--line`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LineKind {
    /// The centre line: the paper.
    #[default]
    Centre,
    /// The minimum-curvature racing line, fixed.
    MinCurvature,
    /// A line d(x) learned with the pedal, a second action on its own kernels.
    Learn,
}

impl LineKind {
    /// Every kind, in `--help` order.
    pub const ALL: [LineKind; 3] = [LineKind::Centre, LineKind::MinCurvature, LineKind::Learn];

    /// Its name, as the flag and the grid write it.
    pub fn name(&self) -> &'static str {
        match self {
            LineKind::Centre => "centre",
            LineKind::MinCurvature => "min-curvature",
            LineKind::Learn => "learn",
        }
    }

    /// Whether this is the centre line.
    pub fn is_centre(&self) -> bool {
        *self == LineKind::Centre
    }
}

impl std::str::FromStr for LineKind {
    type Err = Error;
    fn from_str(s: &str) -> Result<LineKind> {
        LineKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                Error::invalid_value(
                    "the line",
                    format!("{s:?}"),
                    "centre, min-curvature or learn",
                )
            })
    }
}

/// The line of a race as it is asked for: the kind, and for a learned line its kernels
/// (default: the pedal's) and its start (default: the centre line).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct LineSetting {
    /// The line.
    pub line: LineKind,
    /// Kernels of a learned line; `None`: the pedal's.
    pub kernels: Option<usize>,
    /// Where a learned line starts, and what its offsets are measured from; `None`: the centre.
    pub start: Option<BaseLine>,
}

impl LineSetting {
    /// The paper's centre line.
    pub fn centre() -> LineSetting {
        LineSetting::default()
    }

    /// The race's base line and, for a learned line, its kernels (the pedal's `pedal_kernels`
    /// unless given). A start or kernels without `learn` are refused: only a learned line
    /// starts somewhere or has kernels.
    pub fn resolve(&self, pedal_kernels: usize) -> Result<(BaseLine, Option<usize>)> {
        let refused = |what: &str, value: String| {
            Err(Error::invalid_value(
                format!("{what} of line {}", self.line.name()),
                value,
                "none: only a learned line (learn) starts somewhere and has kernels of its own",
            ))
        };
        match (self.line, self.start, self.kernels) {
            (LineKind::Learn, start, kernels) => {
                let kernels = kernels.unwrap_or(pedal_kernels);
                crate::sizes::KERNELS.checked(kernels)?;
                Ok((start.unwrap_or_default(), Some(kernels)))
            }
            (_, Some(start), _) => refused("the line start", start.name().into()),
            (_, None, Some(k)) => refused("the line kernels", k.to_string()),
            (LineKind::MinCurvature, None, None) => Ok((BaseLine::MinCurvature, None)),
            (LineKind::Centre, None, None) => Ok((BaseLine::Centre, None)),
        }
    }

    /// The setting a race resolved to ([`LineSetting::resolve`]'s inverse, the kernels kept
    /// explicit): what records and studies store.
    pub fn of(base_line: BaseLine, line_kernels: Option<usize>) -> LineSetting {
        match line_kernels {
            Some(k) => LineSetting {
                line: LineKind::Learn,
                kernels: Some(k),
                start: (!base_line.is_centre()).then_some(base_line),
            },
            None if base_line.is_centre() => LineSetting::centre(),
            None => LineSetting {
                line: LineKind::MinCurvature,
                ..LineSetting::default()
            },
        }
    }

    /// A short label for reports and file names: `centre`, `min-curvature`, `learn-m20`,
    /// `learn-m20-from-min-curvature`.
    pub fn label(&self) -> String {
        match (self.line, self.kernels, self.start) {
            (LineKind::Learn, k, start) => format!(
                "learn{}{}",
                k.map_or(String::new(), |k| format!("-m{k}")),
                start
                    .filter(|s| !s.is_centre())
                    .map_or(String::new(), |s| format!("-from-{}", s.name()))
            ),
            (kind, _, _) => kind.name().into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every setting resolves as `cdbo race` always did, and back: a start or kernels
    /// without a learned line are refused naming them.
    #[test]
    fn settings_resolve_and_round_trip() {
        let learn = |kernels, start| LineSetting {
            line: LineKind::Learn,
            kernels,
            start,
        };
        let cases = [
            (LineSetting::centre(), (BaseLine::Centre, None)),
            (
                LineSetting {
                    line: LineKind::MinCurvature,
                    ..LineSetting::default()
                },
                (BaseLine::MinCurvature, None),
            ),
            (learn(None, None), (BaseLine::Centre, Some(12))),
            (
                learn(Some(6), Some(BaseLine::MinCurvature)),
                (BaseLine::MinCurvature, Some(6)),
            ),
        ];
        for (setting, resolved) in cases {
            assert_eq!(setting.resolve(12).unwrap(), resolved, "{setting:?}");
            let again = LineSetting::of(resolved.0, resolved.1);
            assert_eq!(again.resolve(99).unwrap(), resolved, "{setting:?}");
        }
        let e = LineSetting {
            start: Some(BaseLine::MinCurvature),
            ..LineSetting::centre()
        }
        .resolve(12)
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("line start") && e.contains("min-curvature"),
            "{e}"
        );
        let e = LineSetting {
            kernels: Some(5),
            ..LineSetting::centre()
        }
        .resolve(12)
        .unwrap_err()
        .to_string();
        assert!(e.contains("line kernels") && e.contains('5'), "{e}");
        assert_eq!("learn".parse::<LineKind>().unwrap(), LineKind::Learn);
        assert!("racing".parse::<LineKind>().is_err());
        assert_eq!(
            learn(Some(8), Some(BaseLine::MinCurvature)).label(),
            "learn-m8-from-min-curvature"
        );
    }
}
