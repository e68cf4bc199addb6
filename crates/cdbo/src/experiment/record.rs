//! One finished run of a grid, as saved to `DIR/runs/ID.json`: what was run, the learning
//! curve, the best policy and the time spent. A file exists only for a finished run (it is
//! written to a temporary name and renamed), so an interrupted grid resumes by redoing the
//! runs without one.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::grid::{ExperimentConfig, RunSpec};
use super::race::{LapRecord, RaceConfig, race};
use crate::bounded;
use crate::car::Car;
use crate::drive::steering::SteeringLaw;
use crate::error::{Error, Result};
use crate::line::{BaseLine, LineSetting};
use crate::policy::RacedPolicy;
use crate::policy::{Block, PolicyShape, SpeedTarget};
use crate::track::Track;
use crate::venue::Venue;

/// A finished run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    /// Which run.
    pub spec: RunSpec,
    /// Laps of the run.
    pub laps_planned: usize,
    /// The track's own name and length.
    pub track_name: String,
    /// Track length (m).
    pub length_m: f64,
    /// Speed of the demonstrator (m/s).
    pub demo_speed: f64,
    /// Reward of the demonstration lap.
    pub demo_reward_mps: f64,
    /// Reward of the limit lap.
    pub limit_reward_mps: f64,
    /// Reward of the ceiling: the tracked limit profile's lap
    /// ([`tracked_profile`](crate::ceiling::tracked_profile)), the crest-aware profile's
    /// ([`profile`](crate::ceiling::profile)) in records that store it; absent in records
    /// written before it was stored.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ceiling_reward_mps: Option<f64>,
    /// Reward of the initial policy π(w₀).
    pub initial_reward_mps: f64,
    /// Best reward.
    pub best_reward_mps: f64,
    /// Best weights.
    pub best_weights: Vec<f64>,
    /// The policy's kernel length-scale (the pedal's).
    pub lengthscale: f64,
    /// Kernels of the learned line, whose weights follow the pedal's in `best_weights` (at the
    /// paper's length-scale); absent: the pedal only (and in records written before it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line_kernels: Option<usize>,
    /// The line the run's car held ([`BaseLine`]); absent: the centre line.
    #[serde(default, skip_serializing_if = "BaseLine::is_centre")]
    pub base_line: BaseLine,
    /// The steering the run's car drove with; absent: the paper's PI.
    #[serde(default, skip_serializing_if = "SteeringLaw::is_pi")]
    pub steering: SteeringLaw,
    /// The speed the best policy's action asks for ([`crate::policy::target`]); absent: its
    /// action is the pedal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<SpeedTarget>,
    /// Every lap.
    pub laps: Vec<LapRecord>,
    /// Wall-clock seconds of the run.
    pub wall_s: f64,
}

impl RunRecord {
    /// The run's line, as the grid asked for it.
    pub fn line(&self) -> LineSetting {
        LineSetting::of(self.base_line, self.line_kernels)
    }

    /// The best policy, with the line it was raced on.
    pub fn best_policy(&self) -> Result<RacedPolicy> {
        let pedal = PolicyShape::pedal(Block::new(self.spec.kernels, self.lengthscale)?);
        let shape = match self.line_kernels {
            Some(m) => pedal.with_line(Block::paper(m)?),
            None => pedal,
        };
        Ok(RacedPolicy {
            policy: shape
                .policy(&self.best_weights)?
                .targeting(self.target.clone()),
            base_line: self.base_line,
            steering: self.steering,
        })
    }

    /// Seconds the optimiser spent in total.
    pub fn optimizer_s(&self) -> f64 {
        self.laps.iter().map(|l| l.optimizer_s).sum()
    }

    /// Seconds the simulator spent in total.
    pub fn simulator_s(&self) -> f64 {
        self.laps.iter().map(|l| l.simulator_s).sum()
    }

    /// Where run `spec` is saved under an experiment folder.
    pub fn path(dir: &Path, spec: &RunSpec) -> PathBuf {
        dir.join("runs").join(format!("{}.json", spec.id()))
    }

    /// Saves atomically: written to `ID.json.tmp`, then renamed.
    pub fn save(&self, dir: &Path) -> Result<()> {
        let path = RunRecord::path(dir, &self.spec);
        let tmp = path.with_extension("json.tmp");
        let io = |source: std::io::Error, p: &Path| Error::Io {
            path: p.to_owned(),
            source,
        };
        std::fs::create_dir_all(dir.join("runs")).map_err(|e| io(e, dir))?;
        let text =
            serde_json::to_string(self).map_err(|e| Error::json(path.display().to_string(), e))?;
        std::fs::write(&tmp, text).map_err(|e| io(e, &tmp))?;
        std::fs::rename(&tmp, &path).map_err(|e| io(e, &path))
    }

    /// Loads one saved run.
    pub fn load(path: &Path) -> Result<RunRecord> {
        let text = bounded::read_text(path, &bounded::RUN_RECORD)?;
        RunRecord::parse(&text, &path.display().to_string())
    }

    /// A run record from its JSON text; `file` names it in the error.
    pub fn parse(text: &str, file: &str) -> Result<RunRecord> {
        serde_json::from_str(text).map_err(|e| Error::Parse {
            file: file.to_string(),
            line: u32::try_from(e.line()).ok().filter(|&l| l > 0),
            element: "run record".into(),
            message: format!("not a cdbo run record: {e}"),
        })
    }

    /// Every run saved under the experiment folders, the first copy of each run kept.
    pub fn load_all(dirs: &[PathBuf]) -> Result<Vec<RunRecord>> {
        let mut records: Vec<RunRecord> = Vec::new();
        for dir in dirs {
            let runs = dir.join("runs");
            let entries = std::fs::read_dir(&runs).map_err(|source| Error::Io {
                path: runs.clone(),
                source,
            })?;
            let mut paths: Vec<PathBuf> = entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "json"))
                .collect();
            paths.sort();
            for p in paths {
                let r = RunRecord::load(&p)?;
                if !records.iter().any(|o| o.spec == r.spec) {
                    records.push(r);
                }
            }
        }
        records.sort_by(|a, b| a.spec.cmp(&b.spec));
        Ok(records)
    }
}

/// Where a grid's laps are driven.
#[derive(Debug, Clone, Default)]
pub enum Grounds {
    /// cdbo's simulator.
    #[default]
    Simulator,
    /// The game TORCS: every lap (the demonstration's too) a fresh game process driven by
    /// cdbo's robot ([`Venue::Game`]); the car by its TORCS name, the track by the run's. The
    /// record's limit is cdbo's reading of the game's track; it has no ceiling (that is a lap
    /// in cdbo's simulator).
    Torcs {
        /// The set-up game.
        game: crate::torcs::Game,
        /// The game's car.
        car: String,
    },
}

/// Races one run of the grid in cdbo's simulator; `progress` is called after every lap.
pub fn run(
    spec: &RunSpec,
    grid: &ExperimentConfig,
    track: Track,
    car: &Car,
    progress: impl FnMut(&LapRecord),
) -> Result<RunRecord> {
    run_at(spec, grid, track, car, &Grounds::Simulator, progress)
}

/// Races one run of the grid on `grounds` (`track` and `car` are cdbo's reading of them, for
/// the limit); `progress` is called after every lap.
pub fn run_at(
    spec: &RunSpec,
    grid: &ExperimentConfig,
    track: Track,
    car: &Car,
    grounds: &Grounds,
    progress: impl FnMut(&LapRecord),
) -> Result<RunRecord> {
    let start = std::time::Instant::now();
    let method: crate::method::Method = spec.method.parse()?;
    let (base_line, line_kernels) = grid.line().resolve(spec.kernels)?;
    let config = RaceConfig {
        method,
        kernels: spec.kernels,
        laps: grid.laps,
        seed: spec.seed(),
        beta: grid.beta,
        demo_speed: grid.demo_speed,
        fixed_demo_speed: false,
        knob: Some(grid.knob_of(method)),
        max_failed_laps: None,
        line_kernels,
        warm_start: None,
        base_line,
        box_radius: None,
        flying: false,
    };
    let (track_name, length_m) = (track.name.clone(), track.length);
    let venue = match grounds {
        Grounds::Simulator => Venue::simulator(track.clone(), car),
        Grounds::Torcs { game, car } => Venue::game(game, &spec.track, car, track.clone())?,
    }
    .steered(grid.steering.steering())
    .for_learning(grid.off_track_margin);
    let outcome = race(&venue, &track, car, &config, progress)?;
    let ceiling_reward_mps = match venue {
        Venue::Simulator(sim) => {
            let profile = crate::ceiling::profile(&track, car, None);
            Some(crate::ceiling::tracked_profile(&sim, &profile)?.1)
        }
        Venue::Game { .. } => None,
    };
    Ok(RunRecord {
        spec: spec.clone(),
        laps_planned: grid.laps,
        track_name,
        length_m,
        demo_speed: grid.demo_speed,
        demo_reward_mps: outcome.demo.reward_mps,
        limit_reward_mps: outcome.limit.reward_mps,
        ceiling_reward_mps,
        initial_reward_mps: outcome.laps.first().map_or(0.0, |l| l.reward_mps),
        best_reward_mps: outcome.best_reward_mps,
        best_weights: outcome.best.weights(),
        lengthscale: outcome.best.pedal.lengthscale,
        line_kernels,
        base_line,
        steering: grid.steering,
        target: outcome.best.target.clone(),
        laps: outcome.laps,
        wall_s: start.elapsed().as_secs_f64(),
    })
}
