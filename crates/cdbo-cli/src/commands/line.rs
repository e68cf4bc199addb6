//! `--line`, `--line-kernels` and `--line-start`: the line the car holds, one definition for
//! every command that races (`race`, `optimize`, `study create`, `serve-sim`), read into the
//! library's [`LineSetting`].

use clap::Args;

use cdbo::line::{BaseLine, LineKind, LineSetting};
use cdbo::method::Preset;

/// The line flags.
#[derive(Debug, Args, Clone, Copy, Default)]
pub struct LineArgs {
    /// The line the car holds, the demonstration's included: the centre line, the
    /// minimum-curvature racing line (fixed, as `cdbo limit` computes it), or a line d(x)
    /// learned with the pedal (a second action on its own kernels, starting at --line-start).
    #[arg(long, value_enum)]
    line: Option<Line>,
    /// Where a learned line starts, and what its offsets d(x) are measured from: the centre
    /// line, or the minimum-curvature line d₀(s) (the car holds d₀(s) + d(x)). Only with
    /// `--line learn`.
    #[arg(long, value_enum)]
    line_start: Option<FixedLine>,
    /// Kernels of a learned line (default: the pedal's). Only with `--line learn`.
    #[arg(long, value_parser = super::value::kernels)]
    line_kernels: Option<usize>,
}

impl LineArgs {
    /// The flags with `preset`'s line as `--line` (clap refuses a line flag beside
    /// `--preset`).
    pub fn with_preset(self, preset: Option<Preset>) -> LineArgs {
        match preset {
            Some(p) => LineArgs {
                line: Some(Line::of(p.line())),
                ..self
            },
            None => self,
        }
    }

    /// Whether any line flag was given (a resumed study checks only those given).
    pub fn given(&self) -> bool {
        self.line.is_some() || self.line_start.is_some() || self.line_kernels.is_some()
    }

    /// The setting the flags ask for: the centre line unless `--line` is given.
    pub fn setting(&self) -> LineSetting {
        LineSetting {
            line: self.line.map_or(LineKind::Centre, Line::kind),
            kernels: self.line_kernels,
            start: self.line_start.map(FixedLine::base_line),
        }
    }

    /// The race's base line and learned line's kernels for `pedal_kernels` pedal kernels; a
    /// start or kernels without `--line learn` refused naming the flag.
    pub fn resolve(&self, pedal_kernels: usize) -> Result<(BaseLine, Option<usize>), String> {
        let setting = self.setting();
        if setting.line != LineKind::Learn {
            let given = match (setting.start, setting.kernels) {
                (Some(start), _) => Some(format!("--line-start {}", start.name())),
                (None, Some(k)) => Some(format!("--line-kernels {k}")),
                (None, None) => None,
            };
            if let Some(given) = given {
                return Err(format!(
                    "{given}: only a learned line starts somewhere and has kernels of its own: add --line learn (not --line {})",
                    setting.line.name()
                ));
            }
        }
        setting
            .resolve(pedal_kernels)
            .map_err(|e| format!("--line-kernels: {e}"))
    }
}

/// The flags that ask for `setting`: `--line learn --line-kernels 8 --line-start
/// min-curvature`, `--line centre`.
pub fn flags(setting: &LineSetting) -> String {
    let mut flags = format!("--line {}", setting.line.name());
    if let Some(k) = setting.kernels {
        flags += &format!(" --line-kernels {k}");
    }
    if let Some(start) = setting.start {
        flags += &format!(" --line-start {}", start.name());
    }
    flags
}

/// The line the car holds (`--line`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Line {
    /// The centre line (the paper; the default).
    Centre,
    /// The minimum-curvature racing line, fixed.
    MinCurvature,
    /// A line d(x) learned with the pedal.
    Learn,
}

impl Line {
    fn of(kind: LineKind) -> Line {
        match kind {
            LineKind::Centre => Line::Centre,
            LineKind::MinCurvature => Line::MinCurvature,
            LineKind::Learn => Line::Learn,
        }
    }

    fn kind(self) -> LineKind {
        match self {
            Line::Centre => LineKind::Centre,
            Line::MinCurvature => LineKind::MinCurvature,
            Line::Learn => LineKind::Learn,
        }
    }
}

/// A fixed line: where a learned line starts (`--line-start`), the line of `ceiling --line`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum FixedLine {
    /// The centre line: d₀ = 0.
    #[default]
    Centre,
    /// The minimum-curvature racing line.
    MinCurvature,
}

impl FixedLine {
    /// The line as a race's base line.
    pub fn base_line(self) -> BaseLine {
        match self {
            FixedLine::Centre => BaseLine::Centre,
            FixedLine::MinCurvature => BaseLine::MinCurvature,
        }
    }
}
