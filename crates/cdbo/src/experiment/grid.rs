//! An experiment grid (paper Sec. V): tracks × policy sizes × methods × repeats, every run a
//! [`race`](super::race) of the same number of laps. Written as TOML or named by a preset:
//!
//! ```toml
//! laps = 300
//! repeats = 4
//! demo_speed = 15.0
//! beta = 1.0
//! methods = ["cdbo", "cmaes", "bo-cmaes", "rembo-5d", "rembo-10d"]
//!
//! [[tracks]]
//! track = "forza"
//! kernels = [10, 50, 100]
//! ```
//!
//! `line = "learn"` (with `line_kernels = 20`, `line_start = "min-curvature"`) or `line =
//! "min-curvature"` races every run on that line, as `cdbo race --line`; a grid without it
//! races the centre line, the paper's.
//! `steering = "tracker"` drives every run with the path tracker (default `"pi"`);
//! `preset = "fast-safe"` stands for the stack it names ([`Preset`]), `methods =
//! ["safe-pattern-search"]`, `steering = "tracker"` and `line = "min-curvature"`, which the
//! grid then does not give;
//! `off_track_margin = 1.0` fails its laps 1 m past the road's edge, the game's rule (default:
//! the learning reserve in cdbo's simulator, as `cdbo race`; the game's rule in the game).
//!
//! Run r of every cell has seed r, so that the methods meet the same random numbers where
//! they draw alike. The runs are listed in a fixed order; shard I of N takes every N-th run
//! from the I-th, so shards partition the grid whatever machine runs them.

use serde::{Deserialize, Serialize};

use crate::drive::steering::SteeringLaw;
use crate::line::{BaseLine, LineKind, LineSetting};
use crate::method::{Method, Preset, Spec};
use crate::sim::lap::{GAME_OFF_TRACK_MARGIN, checked_off_track_margin};

use crate::error::{Error, Result};

/// The policy sizes to race on one track.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackGrid {
    /// A built-in track, a file, or a name found in the data folders.
    pub track: String,
    /// Policy kernels M, one panel each.
    pub kernels: Vec<usize>,
}

/// An experiment grid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExperimentConfig {
    /// Laps per run (the paper: 300).
    pub laps: usize,
    /// Runs per cell (the paper: 4).
    pub repeats: usize,
    /// Demonstration speed in m/s (the paper: 15).
    #[serde(default = "default_demo_speed")]
    pub demo_speed: f64,
    /// UCB β (the paper: within [0.5, 2]).
    #[serde(default = "default_beta")]
    pub beta: f64,
    /// A stack by name ([`Preset`]) in place of `methods`, `steering` and `line`, which a grid
    /// with it does not give: [`ExperimentConfig::from_toml`] reads it into them, so that the
    /// grid holds no preset once read and writes the settings it stood for.
    #[serde(default, skip_serializing)]
    preset: Option<Preset>,
    /// Optimisers, by their names.
    #[serde(default)]
    pub methods: Vec<Method>,
    /// Tracks and their policy sizes.
    pub tracks: Vec<TrackGrid>,
    /// A method's main knob ([`Method::knob`]: σ₀, TuRBO's L_init, LineBO's step, REMBO's
    /// box), by method name; a method not listed gets the published setting (σ₀ 0.03).
    /// `[knob]` table: `random = 0.01`; `[sigma0]`, its name in older grids, reads the same.
    #[serde(
        default,
        alias = "sigma0",
        skip_serializing_if = "std::collections::BTreeMap::is_empty"
    )]
    pub knob: std::collections::BTreeMap<Method, f64>,
    /// The line every run's car holds, as `cdbo race --line`: `centre` (the paper; the
    /// default), `min-curvature` or `learn`.
    #[serde(default, skip_serializing_if = "LineKind::is_centre")]
    pub line: LineKind,
    /// Kernels of a learned line (default: each panel's pedal kernels), as `--line-kernels`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line_kernels: Option<usize>,
    /// Where a learned line starts, as `--line-start`: `centre` or `min-curvature`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line_start: Option<BaseLine>,
    /// How every run's car steers, the ceiling's lap included: `"pi"` (the paper's, the
    /// default) or `"tracker"` (the path tracker, as `cdbo race --steering tracker`).
    #[serde(default, skip_serializing_if = "SteeringLaw::is_pi")]
    pub steering: SteeringLaw,
    /// Where every run's laps leave the road, as `cdbo race --off-track-margin`: the car's
    /// centre this far past the road's edge (m; negative: inside the road). Default, as `cdbo
    /// race`'s: the learning reserve in cdbo's simulator
    /// ([`Reserve::LEARNING`](crate::sim::lap::Reserve::LEARNING)), the game's rule in the
    /// game ([`crate::venue::Venue::for_learning`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub off_track_margin: Option<f64>,
}

fn default_demo_speed() -> f64 {
    crate::drive::demo::DEFAULT_TARGET_SPEED
}

fn default_beta() -> f64 {
    crate::acquisition::ucb::DEFAULT_BETA
}

/// The presets [`ExperimentConfig::preset`] knows.
pub const PRESETS: &[&str] = &["paper", "paper-plus", "quick"];

impl ExperimentConfig {
    /// The grid's line.
    pub fn line(&self) -> LineSetting {
        LineSetting {
            line: self.line,
            kernels: self.line_kernels,
            start: self.line_start,
        }
    }

    /// The main knob `method` runs at in this grid: its entry in the `[knob]` table, else its
    /// published setting ([`Knob::published`](crate::method::Knob::published): σ₀ 0.03,
    /// TuRBO's 0.8, LineBO's whole line, REMBO's √d), so that a grid names every tuned value
    /// it uses and reads the same whatever the race defaults become.
    pub fn knob_of(&self, method: Method) -> f64 {
        self.knob
            .get(&method)
            .copied()
            .unwrap_or(method.knob().published)
    }

    /// `paper`: Forza with 10/50/100 kernels and Allondaz with 10/30/50; CDBO, CMA-ES,
    /// BO-CMA-ES, REMBO-5d and -10d; 4 repeats of 300 laps. `paper-plus`: the same with
    /// TuRBO, LineBO, random search and the pattern search, every method's main knob at its
    /// race value where it was tuned on the training tracks ([`Method::knob`]); `paper` keeps
    /// every method at the paper's σ₀ 0.03 and the published settings.
    /// Both judge their laps at the game's rule ([`GAME_OFF_TRACK_MARGIN`]), as docs/results
    /// reports them, not with the simulator's reserve a grid learns with by default.
    /// `quick`: the built-in track, 10 and 20 kernels, four
    /// methods, 2 repeats of 25 laps (for CI).
    pub fn preset(name: &str) -> Option<ExperimentConfig> {
        let paper_tracks = vec![
            TrackGrid {
                track: "forza".into(),
                kernels: vec![10, 50, 100],
            },
            TrackGrid {
                track: "allondaz".into(),
                kernels: vec![10, 30, 50],
            },
        ];
        let methods = |extra: &[Method]| -> Vec<Method> {
            Method::PAPER.iter().chain(extra).copied().collect()
        };
        Some(match name {
            "paper" => ExperimentConfig {
                preset: None,
                laps: 300,
                repeats: 4,
                demo_speed: default_demo_speed(),
                beta: default_beta(),
                methods: methods(&[]),
                tracks: paper_tracks,
                knob: Default::default(),
                line: LineKind::Centre,
                line_kernels: None,
                line_start: None,
                steering: Default::default(),
                off_track_margin: Some(GAME_OFF_TRACK_MARGIN),
            },
            "paper-plus" => ExperimentConfig {
                methods: methods(&[
                    Method::Turbo,
                    Method::Linebo,
                    Method::Random,
                    Method::PatternSearch,
                ]),
                knob: Method::ALL
                    .into_iter()
                    .filter(|m| m.knob().tuned())
                    .map(|m| (m, m.knob().value))
                    .collect(),
                ..ExperimentConfig::preset("paper")?
            },
            "quick" => ExperimentConfig {
                preset: None,
                laps: 25,
                repeats: 2,
                demo_speed: default_demo_speed(),
                beta: default_beta(),
                methods: vec![Method::Cdbo, Method::Cmaes, Method::BoCmaes, Method::Random],
                tracks: vec![TrackGrid {
                    track: crate::track::builtin::DEFAULT.into(),
                    kernels: vec![10, 20],
                }],
                knob: Default::default(),
                line: LineKind::Centre,
                line_kernels: None,
                line_start: None,
                steering: Default::default(),
                off_track_margin: None,
            },
            _ => return None,
        })
    }

    /// Reads a grid from TOML text, its `preset` read into the settings it stands for;
    /// `origin` names the file in errors.
    pub fn from_toml(text: &str, origin: &str) -> Result<ExperimentConfig> {
        let mut config: ExperimentConfig = toml::from_str(text).map_err(|e| {
            // The line of the offending span, and its key (the text before `=`).
            let start = e.span().map_or(0, |s| s.start.min(text.len()));
            let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
            let line_text = text[line_start..].lines().next().unwrap_or("");
            let key = line_text.split_once('=').map_or("grid", |(k, _)| k.trim());
            Error::Parse {
                file: origin.to_owned(),
                line: e
                    .span()
                    .map(|_| 1 + text[..start].matches('\n').count() as u32),
                element: key.to_owned(),
                message: e.message().trim().to_owned(),
            }
        })?;
        if let Some(preset) = config.preset.take() {
            config.set(preset, text, origin)?;
        }
        config.check().map_err(|e| Error::Parse {
            file: origin.to_owned(),
            line: None,
            element: "grid".into(),
            message: e.to_string(),
        })?;
        Ok(config)
    }

    /// Sets `preset`'s method, steering and line, refusing a grid `text` that gives any of them
    /// as well: one name never mixes with a key of its own stack.
    fn set(&mut self, preset: Preset, text: &str, origin: &str) -> Result<()> {
        const SETS: [&str; 5] = ["methods", "steering", "line", "line_kernels", "line_start"];
        let keys: toml::Table = toml::from_str(text)
            .map_err(|e| Error::parse(origin, "grid", e.message().trim().to_owned()))?;
        if let Some(key) = SETS.into_iter().find(|k| keys.contains_key(*k)) {
            return Err(Error::parse(
                origin,
                key,
                format!(
                    "preset = \"{preset}\" sets methods = [\"{}\"], steering = \"{}\" and line = \"{}\": give the preset or these keys, not both",
                    preset.method(),
                    preset.steering(),
                    preset.line().name()
                ),
            ));
        }
        self.methods = vec![preset.method()];
        self.steering = preset.steering();
        self.line = preset.line();
        Ok(())
    }

    /// Checks the grid is non-empty, its methods known and its numbers sensible.
    pub fn check(&self) -> Result<()> {
        crate::sizes::LAPS.checked(self.laps)?;
        crate::sizes::REPEATS.checked(self.repeats)?;
        if let Some(margin) = self.off_track_margin {
            checked_off_track_margin(margin)?;
        }
        if self.methods.is_empty() {
            return Err(Error::invalid_value(
                "the grid's methods",
                "none",
                "at least one, as methods = [\"cdbo\"] or preset = \"fast-safe\"",
            ));
        }
        if self.tracks.is_empty() {
            return Err(Error::too_small("the grid's tracks", 0, 1));
        }
        for t in &self.tracks {
            if t.kernels.is_empty() {
                return Err(Error::too_small(
                    format!("track {:?}'s kernels", t.track),
                    0,
                    1,
                ));
            }
            for &k in &t.kernels {
                crate::sizes::KERNELS.checked(k).map_err(|e| match e {
                    Error::TooSmall { what, value, min } => Error::TooSmall {
                        what: format!("track {:?}'s {what}", t.track),
                        value,
                        min,
                    },
                    Error::TooLarge {
                        what,
                        value,
                        max,
                        why,
                    } => Error::TooLarge {
                        what: format!("track {:?}'s {what}", t.track),
                        value,
                        max,
                        why,
                    },
                    e => e,
                })?;
            }
        }
        for (&m, &v) in &self.knob {
            if !self.methods.contains(&m) {
                return Err(Error::invalid_value(
                    "the knob table's method",
                    m,
                    "a method of the grid",
                ));
            }
            Spec::race(m).knob(v)?;
        }
        self.line().resolve(2)?;
        if !(self.demo_speed.is_finite() && self.demo_speed > 0.0) {
            return Err(Error::invalid_value(
                "demo_speed",
                self.demo_speed,
                "positive",
            ));
        }
        if !(self.beta.is_finite() && self.beta >= 0.0) {
            return Err(Error::invalid_value("beta", self.beta, "non-negative"));
        }
        Ok(())
    }

    /// Every run of the grid, in a fixed order: track, size, repeat, method.
    pub fn runs(&self) -> Vec<RunSpec> {
        let mut runs = Vec::new();
        for t in &self.tracks {
            for &kernels in &t.kernels {
                for repeat in 0..self.repeats {
                    for method in &self.methods {
                        runs.push(RunSpec {
                            track: t.track.clone(),
                            kernels,
                            method: method.to_string(),
                            repeat,
                        });
                    }
                }
            }
        }
        runs
    }
}

/// One run of a grid.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct RunSpec {
    /// Track name as the grid gives it.
    pub track: String,
    /// Policy kernels M.
    pub kernels: usize,
    /// Optimiser.
    pub method: String,
    /// Repeat index r, also the seed.
    pub repeat: usize,
}

impl RunSpec {
    /// A name unique in the grid, safe as a file name: `forza-m50-cdbo-r0`.
    pub fn id(&self) -> String {
        let track: String = self
            .track
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        format!("{track}-m{}-{}-r{}", self.kernels, self.method, self.repeat)
    }

    /// The run's seed.
    pub fn seed(&self) -> u64 {
        self.repeat as u64
    }
}

/// Shard I of N (`I/N`, 0 ≤ I < N): the runs whose position in the grid is I modulo N.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// I.
    pub index: usize,
    /// N.
    pub count: usize,
}

impl Shard {
    /// Parses `I/N`.
    pub fn parse(text: &str) -> Result<Shard> {
        let bad = || {
            Error::invalid_value(
                "the shard",
                format!("{text:?}"),
                "I/N with 0 ≤ I < N, e.g. 0/4",
            )
        };
        let (i, n) = text.split_once('/').ok_or_else(bad)?;
        let (index, count): (usize, usize) = (
            i.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// The shard's runs.
    pub fn select(&self, runs: Vec<RunSpec>) -> Vec<RunSpec> {
        runs.into_iter()
            .enumerate()
            .filter(|(k, _)| k % self.count == self.index)
            .map(|(_, r)| r)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_paper_grid_has_the_papers_cells() {
        let paper = ExperimentConfig::preset("paper").unwrap();
        assert_eq!(paper.runs().len(), 6 * 5 * 4);
        let plus = ExperimentConfig::preset("paper-plus").unwrap();
        assert_eq!(plus.runs().len(), 6 * 9 * 4);
        assert_eq!(plus.knob.get(&Method::Random), Some(&0.01));
        assert_eq!(plus.knob.get(&Method::Cmaes), Some(&0.03));
        assert_eq!(plus.knob.get(&Method::PatternSearch), Some(&0.05));
        assert_eq!(plus.knob.get(&Method::Turbo), Some(&0.03));
        assert_eq!(plus.knob.get(&Method::Linebo), Some(&0.3));
        assert_eq!(plus.knob.get(&Method::Rembo5d), Some(&0.1));
        assert_eq!(plus.knob.get(&Method::Rembo10d), Some(&0.03));
        assert_eq!(plus.knob.get(&Method::Cdbo), None);
        let paper = ExperimentConfig::preset("paper").unwrap();
        assert_eq!(paper.knob_of(Method::Rembo5d), 5f64.sqrt());
        assert_eq!(paper.knob_of(Method::Cmaes), 0.03);
        assert_eq!(plus.knob_of(Method::Rembo5d), 0.1);
        assert_eq!(plus.knob_of(Method::Cdbo), 0.03);
        assert_eq!(plus.knob_of(Method::Linebo), 0.3);
        assert_eq!(paper.knob_of(Method::Linebo), f64::INFINITY);
        for p in PRESETS {
            ExperimentConfig::preset(p).unwrap().check().unwrap();
        }
    }

    /// A grid's `[knob]` table reaches each method's knob; `[sigma0]`, its name in older grids
    /// (docs/results/experiment.toml), reads the same; a bad value or a method not in the grid
    /// is refused naming the file, the method and its knob.
    #[test]
    fn the_knob_table_and_its_older_name() {
        let head = "laps = 3\nrepeats = 1\nmethods = [\"turbo\", \"random\"]\ntracks = [{track = \"x\", kernels = [5]}]\n";
        let new = ExperimentConfig::from_toml(
            &format!("{head}[knob]\nturbo = 0.1\nrandom = 0.01\n"),
            "g",
        )
        .unwrap();
        assert_eq!(new.knob.get(&Method::Turbo), Some(&0.1));
        let old = ExperimentConfig::from_toml(
            &format!("{head}[sigma0]\nrandom = 0.01\nturbo = 0.1\n"),
            "g",
        )
        .unwrap();
        assert_eq!(old, new);
        let saved = toml::to_string(&new).unwrap();
        assert!(saved.contains("[knob]"), "{saved}");
        assert_eq!(ExperimentConfig::from_toml(&saved, "g").unwrap(), new);
        for (table, what) in [("turbo = 1.7", "turbo"), ("cdbo = 0.03", "cdbo")] {
            let e = ExperimentConfig::from_toml(&format!("{head}[knob]\n{table}\n"), "g.toml")
                .unwrap_err()
                .to_string();
            assert!(e.contains("g.toml") && e.contains(what), "{e}");
        }
        let e = ExperimentConfig::from_toml(&format!("{head}[knob]\nturbo = 1.7\n"), "g.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("length"), "{e}");
    }

    /// A grid's line reads and writes as the flags name it; a grid without one is the centre
    /// line's (every grid written before it), and a start without a learned line is refused.
    #[test]
    fn the_line_of_a_grid() {
        let head = "laps = 3\nrepeats = 1\nmethods = [\"random\"]\ntracks = [{track = \"x\", kernels = [5]}]\n";
        let old = ExperimentConfig::from_toml(head, "g").unwrap();
        assert_eq!(old.line(), LineSetting::centre());
        assert!(!toml::to_string(&old).unwrap().contains("line"));
        let text =
            format!("line = \"learn\"\nline_kernels = 4\nline_start = \"min-curvature\"\n{head}");
        let grid = ExperimentConfig::from_toml(&text, "g").unwrap();
        assert_eq!(
            grid.line().resolve(5).unwrap(),
            (BaseLine::MinCurvature, Some(4))
        );
        let saved = toml::to_string(&grid).unwrap();
        assert_eq!(ExperimentConfig::from_toml(&saved, "g").unwrap(), grid);
        let e = ExperimentConfig::from_toml(
            &format!("line_start = \"min-curvature\"\n{head}"),
            "g.toml",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("g.toml") && e.contains("line start"), "{e}");
    }

    /// `preset = "fast-safe"` reads as the stack it names: its runs are the safe pattern
    /// search's, on the path tracker and the minimum-curvature line; the grid saved holds those
    /// settings, not the preset, and reads back the same. A key of the stack beside the preset
    /// is refused naming the file and the key; a grid with neither methods nor a preset is
    /// refused naming both.
    #[test]
    fn a_grid_preset_sets_the_method_the_steering_and_the_line() {
        let head = "laps = 3\nrepeats = 1\ntracks = [{track = \"x\", kernels = [5]}]\n";
        let grid = ExperimentConfig::from_toml(
            &format!("preset = \"fast-safe\"\n{head}[knob]\nsafe-pattern-search = 0.05\n"),
            "g",
        )
        .unwrap();
        assert_eq!(grid.methods, [Method::SafePatternSearch]);
        assert_eq!(grid.steering, SteeringLaw::Tracker);
        assert_eq!(
            grid.line(),
            LineSetting {
                line: LineKind::MinCurvature,
                ..LineSetting::centre()
            }
        );
        assert_eq!(grid.runs()[0].method, "safe-pattern-search");
        let saved = toml::to_string(&grid).unwrap();
        assert!(!saved.contains("preset"), "{saved}");
        assert_eq!(ExperimentConfig::from_toml(&saved, "g").unwrap(), grid);
        let long = "methods = [\"safe-pattern-search\"]\nsteering = \"tracker\"\nline = \"min-curvature\"\n";
        let long = ExperimentConfig::from_toml(
            &format!("{long}{head}[knob]\nsafe-pattern-search = 0.05\n"),
            "g",
        )
        .unwrap();
        assert_eq!(long, grid);
        for key in [
            "methods = [\"cdbo\"]",
            "steering = \"pi\"",
            "line = \"min-curvature\"",
            "line_kernels = 4",
        ] {
            let e = ExperimentConfig::from_toml(
                &format!("preset = \"fast-safe\"\n{key}\n{head}"),
                "g.toml",
            )
            .unwrap_err()
            .to_string();
            let name = key.split(' ').next().unwrap();
            assert!(
                e.contains("g.toml") && e.contains(name) && e.contains("not both"),
                "{e}"
            );
        }
        let e = ExperimentConfig::from_toml(&format!("preset = \"fastest\"\n{head}"), "g.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("fastest") && e.contains("fast-safe"), "{e}");
        let e = ExperimentConfig::from_toml(head, "g.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("g.toml") && e.contains("methods = [") && e.contains("preset = "),
            "{e}"
        );
    }

    #[test]
    fn shards_partition_the_grid() {
        let runs = ExperimentConfig::preset("paper").unwrap().runs();
        let mut all: Vec<RunSpec> = (0..7)
            .flat_map(|i| Shard { index: i, count: 7 }.select(runs.clone()))
            .collect();
        all.sort();
        let mut expected = runs.clone();
        expected.sort();
        assert_eq!(all, expected);
        assert!(Shard::parse("3/3").is_err() && Shard::parse("a/2").is_err());
        assert_eq!(Shard::parse("2/5").unwrap(), Shard { index: 2, count: 5 });
    }

    #[test]
    fn toml_errors_name_the_file_and_the_problem() {
        let e = ExperimentConfig::from_toml("laps = 3\nrepeats = 1\nmethods = [\"simplex\"]\ntracks = [{track = \"x\", kernels = [5]}]", "grid.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("grid.toml") && e.contains("simplex"), "{e}");
        let e = ExperimentConfig::from_toml("laps = \"many\"", "g.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("g.toml") && e.contains("laps"), "{e}");
    }
}
