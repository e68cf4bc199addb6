//! `cdbo.Study`: a persistent ask/tell study in the same SQLite file as `cdbo study`.

use std::path::PathBuf;
use std::sync::Mutex;

use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyType};

use cdbo::line::LineKind;
use cdbo::policy::rkhs::default_lengthscale;
use cdbo::study::{Outcome, Study, StudyConfig, Trial};

use crate::convert::{IntoPy, array, lock, vector};
use crate::preset::Stack;
use crate::race::line_setting;

/// One trial of a study: `id`, the `weights` to drive, and once told its `reward`,
/// `lap_time` (s), `failure` and `x_fail`.
#[pyclass(name = "Trial", module = "cdbo", frozen)]
pub struct PyTrial {
    trial: Trial,
}

#[pymethods]
impl PyTrial {
    #[getter]
    fn id(&self) -> i64 {
        self.trial.id
    }

    #[getter]
    fn weights<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, self.trial.weights.clone())
    }

    #[getter]
    fn reward(&self) -> Option<f64> {
        self.trial.reward
    }

    #[getter]
    fn lap_time(&self) -> Option<f64> {
        self.trial.lap_time_s
    }

    #[getter]
    fn failure(&self) -> Option<&str> {
        self.trial.failure.as_deref()
    }

    #[getter]
    fn x_fail(&self) -> Option<f64> {
        self.trial.x_fail
    }

    fn __repr__(&self) -> String {
        match self.trial.reward {
            Some(r) => format!("Trial(id={}, reward={r})", self.trial.id),
            None => format!("Trial(id={}, pending)", self.trial.id),
        }
    }
}

/// A persistent ask/tell study: one SQLite file, the same as `cdbo study` reads and writes,
/// so a study created here can be driven by the command line and back.
///
/// `Study.create(path, w0, method="cdbo", lengthscale=None, seed=0, beta=1.0,
/// track_length=None, knob=None, max_failed=None, line="centre", line_kernels=None,
/// line_start=None, steering="pi", bounds=None, preset=None)` (M = len(w0) kernels,
/// length-scale 1/(M − 1) by default; the lap's length in metres, if known, lets pattern
/// search repair over road; `max_failed` is `cdbo study create --max-failed-laps`; `method`,
/// `line`, `line_kernels`, `line_start`, `steering` and `preset` as `cdbo.race`'s, stored with
/// the study: `preset="fast-safe"` stores the safe pattern search, the path tracker and the
/// minimum-curvature line; with `line="learn"` w0 is [w_a, w_d]
/// as `RaceEnv(line="learn").w0`, the line's M_d = `line_kernels` weights last, half of w0 by
/// default; `bounds` the search box's half-width, as `--box-radius`), `Study.open(path)`;
/// then `ask()` → `Trial`,
/// `tell(trial, reward)`, `tell(trial, lap_time=T, length=L)` or `tell(trial, failed=True,
/// at=x, reason=...)`; every told result is on disk when `tell` returns.
#[pyclass(name = "Study", module = "cdbo")]
pub struct PyStudy {
    study: Mutex<Study>,
}

#[pymethods]
impl PyStudy {
    #[classmethod]
    #[pyo3(signature = (path, w0, *, method = None, lengthscale = None, seed = 0, beta = cdbo::acquisition::ucb::DEFAULT_BETA, track_length = None, knob = None, max_failed = None, line = None, line_kernels = None, line_start = None, steering = None, bounds = None, preset = None))]
    #[allow(clippy::too_many_arguments)]
    fn create(
        _cls: &Bound<'_, PyType>,
        py: Python<'_>,
        path: PathBuf,
        w0: &Bound<'_, PyAny>,
        method: Option<&str>,
        lengthscale: Option<f64>,
        seed: u64,
        beta: f64,
        track_length: Option<f64>,
        knob: Option<f64>,
        max_failed: Option<usize>,
        line: Option<&str>,
        line_kernels: Option<usize>,
        line_start: Option<&str>,
        steering: Option<&str>,
        bounds: Option<f64>,
        preset: Option<&str>,
    ) -> PyResult<Self> {
        let stack = Stack::of(preset, method, steering, line, line_kernels, line_start)?;
        let w0 = vector(w0, "w0")?;
        let learned = stack.line == LineKind::Learn;
        // A learned line's weights follow the pedal's in w0, half of them by default (as
        // `RaceEnv(line="learn").w0`).
        let line_kernels = match learned {
            true => Some(line_kernels.unwrap_or(w0.len() / 2)),
            false => line_kernels,
        };
        let kernels = match line_kernels.filter(|_| learned) {
            Some(m) if m < w0.len() => w0.len() - m,
            Some(m) => {
                return Err(PyValueError::new_err(format!(
                    "w0 has {} weights: too few for a line of {m} kernels after the pedal's",
                    w0.len()
                )));
            }
            None => w0.len(),
        };
        let (base_line, line_kernels) = line_setting(stack.line, line_kernels, line_start)?
            .resolve(kernels)
            .py()?;
        let config = StudyConfig {
            method: stack.method,
            kernels,
            lengthscale: lengthscale.unwrap_or_else(|| default_lengthscale(kernels)),
            seed,
            beta,
            w0,
            track: None,
            track_length,
            knob,
            max_failed_laps: max_failed,
            box_radius: bounds,
            warm_start: None,
            line_kernels,
            base_line,
            steering: stack.steering,
        };
        let study = py.detach(|| Study::create(&path, config)).py()?;
        Ok(PyStudy {
            study: Mutex::new(study),
        })
    }

    /// Opens an existing study file.
    #[classmethod]
    fn open(_cls: &Bound<'_, PyType>, py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let study = py.detach(|| Study::open(&path)).py()?;
        Ok(PyStudy {
            study: Mutex::new(study),
        })
    }

    /// The trial to drive next: the pending one if any, else a new suggestion.
    fn ask(&self, py: Python<'_>) -> PyResult<PyTrial> {
        let trial = py.detach(|| lock(&self.study)?.ask().py())?;
        Ok(PyTrial { trial })
    }

    /// Records trial `trial` (a `Trial` or its id): a `reward`, or a completed lap's
    /// `lap_time` (s) and `length` (m), or `failed=True` (reward 0) with where (`at`, lap
    /// fraction) and why (`reason`). Returns the reward; durable on return.
    #[pyo3(signature = (trial, reward = None, *, lap_time = None, length = None, failed = false, at = None, reason = None))]
    #[allow(clippy::too_many_arguments)]
    fn tell(
        &self,
        py: Python<'_>,
        trial: &Bound<'_, PyAny>,
        reward: Option<f64>,
        lap_time: Option<f64>,
        length: Option<f64>,
        failed: bool,
        at: Option<f64>,
        reason: Option<String>,
    ) -> PyResult<f64> {
        let id = match trial.cast::<PyTrial>() {
            Ok(t) => t.get().trial.id,
            Err(_) => trial
                .extract::<i64>()
                .map_err(|_| PyValueError::new_err("trial must be a Trial or a trial id"))?,
        };
        if !failed && (at.is_some() || reason.is_some()) {
            return Err(PyValueError::new_err(
                "at= and reason= describe a failed lap: give them with failed=True",
            ));
        }
        let outcome = match (reward, lap_time, length, failed) {
            (Some(r), None, None, false) => Outcome::Reward(r),
            (None, Some(time_s), Some(length_m), false) => Outcome::Lap { time_s, length_m },
            (None, None, None, true) => Outcome::Failed { at, reason },
            _ => {
                return Err(PyValueError::new_err(
                    "tell one of: a reward, lap_time= and length=, or failed=True",
                ));
            }
        };
        py.detach(|| lock(&self.study)?.tell(id, &outcome).py())
    }

    /// The told trial with the highest reward, or None.
    #[getter]
    fn best(&self, py: Python<'_>) -> PyResult<Option<PyTrial>> {
        let best = py.detach(|| lock(&self.study)?.best().py())?;
        Ok(best.map(|trial| PyTrial { trial }))
    }

    /// Number of told trials.
    #[getter]
    fn told(&self) -> PyResult<usize> {
        lock(&self.study)?.told().py()
    }

    /// The study's settings as a dict (method, kernels, lengthscale, seed, beta, w0, track,
    /// track_length, knob, max_failed_laps, box_radius, warm_start, line_kernels, base_line,
    /// steering;
    /// None where unset).
    #[getter]
    fn config<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = lock(&self.study)?.config().clone();
        let d = PyDict::new(py);
        d.set_item("method", c.method.name())?;
        d.set_item("kernels", c.kernels)?;
        d.set_item("lengthscale", c.lengthscale)?;
        d.set_item("seed", c.seed)?;
        d.set_item("beta", c.beta)?;
        d.set_item("w0", array(py, c.w0))?;
        d.set_item("track", c.track)?;
        d.set_item("track_length", c.track_length)?;
        d.set_item("knob", c.knob)?;
        d.set_item("max_failed_laps", c.max_failed_laps)?;
        d.set_item("box_radius", c.box_radius)?;
        d.set_item("warm_start", c.warm_start)?;
        d.set_item("line_kernels", c.line_kernels)?;
        d.set_item("base_line", c.base_line.name())?;
        d.set_item("steering", c.steering.name())?;
        Ok(d)
    }

    /// The study file.
    #[getter]
    fn path(&self) -> PyResult<PathBuf> {
        Ok(lock(&self.study)?.path().to_owned())
    }

    /// Every trial in asking order: a pandas DataFrame when pandas is installed (and
    /// `as_frame` is not False), else a list of dicts; columns id, weights, reward,
    /// lap_time, failure, x_fail.
    #[pyo3(signature = (*, as_frame = None))]
    fn history<'py>(&self, py: Python<'py>, as_frame: Option<bool>) -> PyResult<Bound<'py, PyAny>> {
        let trials = py.detach(|| lock(&self.study)?.history().py())?;
        let list = PyList::empty(py);
        for t in trials {
            let d = PyDict::new(py);
            d.set_item("id", t.id)?;
            d.set_item("weights", array(py, t.weights))?;
            d.set_item("reward", t.reward)?;
            d.set_item("lap_time", t.lap_time_s)?;
            d.set_item("failure", t.failure)?;
            d.set_item("x_fail", t.x_fail)?;
            list.append(d)?;
        }
        if as_frame == Some(false) {
            return Ok(list.into_any());
        }
        match py.import("pandas") {
            Ok(pandas) => pandas.getattr("DataFrame")?.call1((list,)),
            Err(e) if as_frame == Some(true) => Err(e),
            Err(_) => Ok(list.into_any()),
        }
    }

    fn __repr__(&self) -> PyResult<String> {
        let s = lock(&self.study)?;
        Ok(format!(
            "Study({:?}, method={:?}, kernels={})",
            s.path().display().to_string(),
            s.config().method,
            s.config().kernels
        ))
    }
}
