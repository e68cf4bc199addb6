//! `cdbo.race`: the library's own race loop (`cdbo race`), from Python.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use cdbo::experiment::race::{LapRecord, RaceConfig, RaceOutcome};
use cdbo::line::{BaseLine, LineKind, LineSetting};
use cdbo::sim::lap::checked_off_track_margin;

use crate::convert::IntoPy;
use crate::preset::Stack;
use crate::sim::{PyLapResult, PyLimit, PyPolicy, car_from, track_from};

/// The line a race asks for, from its Python arguments: `line`, and `line_start` `centre` or
/// `min-curvature`.
pub fn line_setting(
    line: LineKind,
    kernels: Option<usize>,
    start: Option<&str>,
) -> PyResult<LineSetting> {
    Ok(LineSetting {
        line,
        kernels,
        start: start.map(str::parse::<BaseLine>).transpose().py()?,
    })
}

/// `(base_line, line_kernels)`: the line `cdbo.race(line=…)` races for `kernels` pedal kernels
/// (`RaceEnv` holds the same): the base line's name, and a learned line's kernels or None.
#[pyfunction]
#[pyo3(signature = (kernels, line = "centre", line_kernels = None, line_start = None))]
pub fn resolve_line(
    kernels: usize,
    line: &str,
    line_kernels: Option<usize>,
    line_start: Option<&str>,
) -> PyResult<(&'static str, Option<usize>)> {
    let (base, m) = line_setting(line.parse().py()?, line_kernels, line_start)?
        .resolve(kernels)
        .py()?;
    Ok((base.name(), m))
}

/// A lap record as a dict: lap, reward, best, lap_time, failure, x_fail, optimizer_s,
/// simulator_s.
fn record<'py>(py: Python<'py>, r: &LapRecord) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("lap", r.lap)?;
    d.set_item("reward", r.reward_mps)?;
    d.set_item("best", r.best_mps)?;
    d.set_item("lap_time", r.lap_time_s)?;
    d.set_item("failure", r.failure.map(|f| f.name()))?;
    d.set_item("x_fail", r.x_fail)?;
    d.set_item("optimizer_s", r.optimizer_s)?;
    d.set_item("simulator_s", r.simulator_s)?;
    Ok(d)
}

/// What a race produced: `best_reward` (m/s) and the `best` policy, the `initial` policy
/// fitted to the `demo` lap, every lap's record in `laps` (a list of dicts), and the `limit`.
#[pyclass(name = "RaceResult", module = "cdbo", frozen)]
pub struct PyRaceResult {
    outcome: RaceOutcome,
    base_line: BaseLine,
    demo: Py<PyLapResult>,
    limit: Py<PyLimit>,
}

#[pymethods]
impl PyRaceResult {
    #[getter]
    fn best_reward(&self) -> f64 {
        self.outcome.best_reward_mps
    }

    #[getter]
    fn best(&self) -> PyPolicy {
        PyPolicy {
            policy: self.outcome.best.pedal.clone(),
        }
    }

    /// The speed the best policy's action asks for, v*(x) = (scale + span·a(x))·profile(x),
    /// as a dict (`profile` in m/s at stations spaced evenly over the lap, `length` in m,
    /// `scale`, `span`): the safe pattern search's profile start learns it
    /// (`cdbo::policy::target`); `Simulator.lap(best, target=...)` drives it again. None: the
    /// action is the pedal.
    #[getter]
    fn best_target<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.outcome
            .best
            .target
            .as_ref()
            .map(|t| crate::sim::target_dict(py, t))
            .transpose()
    }

    /// The best policy's learned line d(x) (a `Policy` whose raw sum wᵀφ(x) is the offset in
    /// metres from `base_line`, before the road's bounds), or None without one.
    #[getter]
    fn best_line(&self) -> Option<PyPolicy> {
        self.outcome
            .best
            .line
            .clone()
            .map(|policy| PyPolicy { policy })
    }

    /// The best policy's weights as the optimisers see them: [w_a, w_d] with a learned line
    /// (`RaceEnv.step`'s action), the pedal's alone without.
    #[getter]
    fn best_weights<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray1<f64>> {
        crate::convert::array(py, self.outcome.best.weights())
    }

    /// The line the laps held where the policy has none: `centre` or `min-curvature`.
    #[getter]
    fn base_line(&self) -> &'static str {
        self.base_line.name()
    }

    #[getter]
    fn initial(&self) -> PyPolicy {
        PyPolicy {
            policy: self.outcome.initial.pedal.clone(),
        }
    }

    #[getter]
    fn demo(&self, py: Python<'_>) -> Py<PyLapResult> {
        self.demo.clone_ref(py)
    }

    #[getter]
    fn limit(&self, py: Python<'_>) -> Py<PyLimit> {
        self.limit.clone_ref(py)
    }

    #[getter]
    fn laps<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let list = PyList::empty(py);
        for r in &self.outcome.laps {
            list.append(record(py, r)?)?;
        }
        Ok(list)
    }

    fn __repr__(&self) -> String {
        format!(
            "RaceResult(best_reward={:.4} m/s, laps={}, limit={:.4} m/s)",
            self.outcome.best_reward_mps,
            self.outcome.laps.len(),
            self.outcome.limit.reward_mps
        )
    }
}

/// Learns a policy for a track exactly as `cdbo race` does (the same laps, bit for bit, for
/// the same settings): drive the demonstration, fit w0, then `laps` laps of `method` (None:
/// `cdbo`), on the line `line` (`centre`, the default, `min-curvature` or `learn`, with
/// `line_kernels` and `line_start` as `cdbo race --line-kernels` and `--line-start`), steered
/// by `steering` (`pi`, the default, or `tracker`); or with `preset="fast-safe"` (as `cdbo
/// race --preset fast-safe`) in place of those five, the recommended stack: the safe pattern
/// search (within its budget of 30 failed laps, or `max_failed`) on the path tracker and the
/// minimum-curvature line, method="safe-pattern-search", steering="tracker",
/// line="min-curvature" (one of those beside it raises `ValueError`);
/// its laps failing `off_track_margin` m past the road's edge (as `--off-track-margin`; by
/// default, None, keeping the reserve `cdbo race` learns with: the wheels 0.25 m off slippery
/// ground, the body 1 m off the walls, the car's centre on the road, `LEARNING_OFF_TRACK_MARGIN`
/// where the road's verges are not known),
/// searching w₀ ± `bounds` (as `--box-radius`; None: 1.5), on the flying lap if `flying` (as
/// `--flying`: the second of two laps from the standing start, timed line to line).
/// `demo_speed` (m/s) is held exactly, as `--demo-speed`; None: the paper's 15 m/s, or where its
/// lap fails the fastest constant speed that completes (the race says which); the safe pattern
/// search's: a hold of a share of the limit's speed profile (`cdbo::experiment::profile_start`).
/// `track` and `car` are objects or names; `knob` is the method's main knob (`cdbo race
/// --knob`; None: its tuned value); `progress(record)` is called after every lap with the
/// lap's record (a dict).
#[pyfunction]
#[pyo3(signature = (track = None, car = None, *, method = None, kernels = 30, laps = 300, seed = 0, beta = cdbo::acquisition::ucb::DEFAULT_BETA, demo_speed = None, knob = None, max_failed = None, data_dir = None, progress = None, line = None, line_kernels = None, line_start = None, steering = None, off_track_margin = None, bounds = None, preset = None, flying = false))]
#[allow(clippy::too_many_arguments)]
pub fn race(
    py: Python<'_>,
    track: Option<&Bound<'_, PyAny>>,
    car: Option<&Bound<'_, PyAny>>,
    method: Option<&str>,
    kernels: usize,
    laps: usize,
    seed: u64,
    beta: f64,
    demo_speed: Option<f64>,
    knob: Option<f64>,
    max_failed: Option<usize>,
    data_dir: Option<&Bound<'_, PyAny>>,
    progress: Option<Py<PyAny>>,
    line: Option<&str>,
    line_kernels: Option<usize>,
    line_start: Option<&str>,
    steering: Option<&str>,
    off_track_margin: Option<f64>,
    bounds: Option<f64>,
    preset: Option<&str>,
    flying: bool,
) -> PyResult<PyRaceResult> {
    let stack = Stack::of(preset, method, steering, line, line_kernels, line_start)?;
    let track = track_from(py, track, data_dir)?;
    let car = car_from(car, data_dir)?;
    let off_track_margin = off_track_margin
        .map(checked_off_track_margin)
        .transpose()
        .py()?;
    let (base_line, line_kernels) = line_setting(stack.line, line_kernels, line_start)?
        .resolve(kernels)
        .py()?;
    let config = RaceConfig {
        method: stack.method,
        kernels,
        laps,
        seed,
        beta,
        demo_speed: demo_speed.unwrap_or(RaceConfig::default().demo_speed),
        fixed_demo_speed: demo_speed.is_some(),
        knob,
        max_failed_laps: max_failed,
        line_kernels,
        warm_start: None,
        base_line,
        box_radius: bounds,
        flying,
    };
    config.spec().py()?;
    let mut callback_error: Option<PyErr> = None;
    let outcome = py
        .detach(|| {
            let venue = cdbo::venue::Venue::simulator(track.clone(), &car)
                .steered(stack.steering.steering())
                .for_learning(off_track_margin);
            cdbo::experiment::race::race(&venue, &track, &car, &config, |r| {
                if let (Some(cb), None) = (&progress, &callback_error) {
                    Python::attach(|py| {
                        if let Err(e) = record(py, r).and_then(|d| cb.call1(py, (d,))) {
                            callback_error = Some(e);
                        }
                    });
                }
            })
        })
        .py()?;
    if let Some(e) = callback_error {
        return Err(e);
    }
    let demo = Py::new(py, PyLapResult::new(py, outcome.demo.clone(), false)?)?;
    let limit = Py::new(
        py,
        PyLimit {
            limit: outcome.limit.clone(),
        },
    )?;
    Ok(PyRaceResult {
        outcome,
        base_line,
        demo,
        limit,
    })
}
