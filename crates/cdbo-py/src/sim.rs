//! Tracks, cars, the simulator, the policy and the limit lap.

use std::path::PathBuf;

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyType};

use cdbo::car::Car;
use cdbo::drive::steering::SteeringLaw;
use cdbo::limit::{Limit, limit_lap};
use cdbo::line::BaseLine;
use cdbo::optimizers::FailedLap;
use cdbo::policy::rkhs::{DEFAULT_RIDGE, default_lengthscale};
use cdbo::policy::{Policy, RkhsPolicy, SpeedTarget};
use cdbo::sim::lap::checked_off_track_margin;
use cdbo::sim::{LapResult, Simulator};
use cdbo::track::Track;

use crate::convert::{Array, Column, IntoPy, array, columns, data_path, vector};

/// A name or a path given as `str` or `os.PathLike`.
fn spec(obj: &Bound<'_, PyAny>) -> PyResult<String> {
    match obj.extract::<String>() {
        Ok(s) => Ok(s),
        Err(_) => Ok(obj.extract::<PathBuf>()?.to_string_lossy().into_owned()),
    }
}

/// A track given as a `Track`, a name or path, or None (the built-in default, Ridgeway).
pub fn track_from(
    py: Python<'_>,
    obj: Option<&Bound<'_, PyAny>>,
    data_dir: Option<&Bound<'_, PyAny>>,
) -> PyResult<Track> {
    let spec = match obj {
        Some(o) if o.is_none() => cdbo::track::builtin::DEFAULT.to_owned(),
        Some(o) => match o.cast::<PyTrack>() {
            Ok(t) => return Ok(t.get().track.clone()),
            Err(_) => spec(o)?,
        },
        None => cdbo::track::builtin::DEFAULT.to_owned(),
    };
    let data = data_path(data_dir)?;
    py.detach(|| cdbo::track::catalog::find(&spec, &data)).py()
}

/// A car given as a `Car`, a name or path, or None (the built-in default, spirit-300).
pub fn car_from(
    obj: Option<&Bound<'_, PyAny>>,
    data_dir: Option<&Bound<'_, PyAny>>,
) -> PyResult<Car> {
    let spec = match obj {
        Some(o) if o.is_none() => cdbo::car::catalog::DEFAULT.to_owned(),
        Some(o) => match o.cast::<PyCar>() {
            Ok(c) => return Ok(c.get().car.clone()),
            Err(_) => spec(o)?,
        },
        None => cdbo::car::catalog::DEFAULT.to_owned(),
    };
    cdbo::car::catalog::find(&spec, &data_path(data_dir)?).py()
}

/// A race track.
///
/// `Track.load(name_or_path, data_dir=None)`: a built-in name (`ridgeway`), a TORCS `.xml` or
/// TUMFTM `.csv` file, or a track name in the data folders (`forza`), as `cdbo race --track`.
#[pyclass(name = "Track", module = "cdbo", frozen)]
#[derive(Clone)]
pub struct PyTrack {
    pub track: Track,
}

#[pymethods]
impl PyTrack {
    #[classmethod]
    #[pyo3(signature = (name_or_path = None, data_dir = None))]
    fn load(
        _cls: &Bound<'_, PyType>,
        py: Python<'_>,
        name_or_path: Option<&Bound<'_, PyAny>>,
        data_dir: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        Ok(PyTrack {
            track: track_from(py, name_or_path, data_dir)?,
        })
    }

    /// The built-in tracks' names.
    #[staticmethod]
    fn builtin() -> Vec<&'static str> {
        cdbo::track::builtin::names().collect()
    }

    /// The track's name.
    #[getter]
    fn name(&self) -> &str {
        &self.track.name
    }

    /// Where it was read from.
    #[getter]
    fn source(&self) -> &str {
        &self.track.source
    }

    /// Centre-line length (m).
    #[getter]
    fn length(&self) -> f64 {
        self.track.length
    }

    /// What was odd about the file (unclosed loop, unknown elements).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.track.warnings.clone()
    }

    /// The centre line at every sample: `s`, `x`, `y`, `z`, `heading`, `curvature`, `width`
    /// (m, rad, 1/m) as NumPy arrays.
    fn centre_line<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let cols: [Column<cdbo::track::Sample>; 7] = [
            ("s", |p| p.s),
            ("x", |p| p.x),
            ("y", |p| p.y),
            ("z", |p| p.z),
            ("heading", |p| p.heading),
            ("curvature", |p| p.curvature),
            ("width", |p| p.width),
        ];
        columns(py, &self.track.samples, &cols)
    }

    fn __repr__(&self) -> String {
        format!(
            "Track({:?}, length={:.1} m, source={:?})",
            self.track.name, self.track.length, self.track.source
        )
    }
}

/// A car.
///
/// `Car.load(name_or_path="spirit-300", data_dir=None)`: the built-in `spirit-300`, a TORCS /
/// Speed Dreams car `.xml`, or a car name in the data folders, as `cdbo race --car`.
#[pyclass(name = "Car", module = "cdbo", frozen)]
#[derive(Clone)]
pub struct PyCar {
    pub car: Car,
}

#[pymethods]
impl PyCar {
    #[classmethod]
    #[pyo3(signature = (name_or_path = None, data_dir = None))]
    fn load(
        _cls: &Bound<'_, PyType>,
        name_or_path: Option<&Bound<'_, PyAny>>,
        data_dir: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        Ok(PyCar {
            car: car_from(name_or_path, data_dir)?,
        })
    }

    /// The car's name.
    #[getter]
    fn name(&self) -> &str {
        &self.car.name
    }

    /// Mass with driver and fuel (kg).
    #[getter]
    fn mass(&self) -> f64 {
        self.car.mass
    }

    fn __repr__(&self) -> String {
        format!("Car({:?}, mass={:.0} kg)", self.car.name, self.car.mass)
    }
}

/// A policy π(x) = clamp(wᵀφ(x), −1, 1) over Matérn-3/2 kernels at M evenly spaced points
/// of the lap fraction x (the paper's eq. 2–7).
///
/// `Policy(weights, lengthscale=None)` (default length-scale 1/(M − 1)), or
/// `Policy.fit(x, a, kernels)`: the ridge fit of a demonstration's (x, a) pairs (eq. 9).
#[pyclass(name = "Policy", module = "cdbo", frozen)]
#[derive(Clone)]
pub struct PyPolicy {
    pub policy: RkhsPolicy,
}

#[pymethods]
impl PyPolicy {
    #[new]
    #[pyo3(signature = (weights, lengthscale = None))]
    fn new(weights: &Bound<'_, PyAny>, lengthscale: Option<f64>) -> PyResult<Self> {
        let w = vector(weights, "weights")?;
        let l = lengthscale.unwrap_or_else(|| default_lengthscale(w.len()));
        Ok(PyPolicy {
            policy: RkhsPolicy::new(w, l).py()?,
        })
    }

    /// The ridge fit w₀ = (ΦᵀΦ + λI)⁻¹Φᵀa of (x, a) pairs with M = `kernels`.
    #[classmethod]
    #[pyo3(signature = (x, a, kernels, *, lengthscale = None, ridge = DEFAULT_RIDGE))]
    fn fit(
        _cls: &Bound<'_, PyType>,
        py: Python<'_>,
        x: &Bound<'_, PyAny>,
        a: &Bound<'_, PyAny>,
        kernels: usize,
        lengthscale: Option<f64>,
        ridge: f64,
    ) -> PyResult<Self> {
        let (x, a) = (vector(x, "x")?, vector(a, "a")?);
        if x.len() != a.len() {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "x and a must have the same length, got {} and {}",
                x.len(),
                a.len()
            )));
        }
        let pairs: Vec<(f64, f64)> = x.into_iter().zip(a).collect();
        let l = lengthscale.unwrap_or_else(|| default_lengthscale(kernels));
        let policy = py
            .detach(|| RkhsPolicy::fit(&pairs, kernels, l, ridge))
            .py()?;
        Ok(PyPolicy { policy })
    }

    /// The weights w.
    #[getter]
    fn weights<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, self.policy.weights.clone())
    }

    /// The kernels' length-scale l.
    #[getter]
    fn lengthscale(&self) -> f64 {
        self.policy.lengthscale
    }

    /// Number of kernels M.
    #[getter]
    fn kernels(&self) -> usize {
        self.policy.kernels()
    }

    /// π(x) at each lap fraction of `x` (a number or an array).
    fn action<'py>(&self, py: Python<'py>, x: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        if let Ok(v) = x.extract::<f64>() {
            return Ok(self.policy.action(v).into_pyobject(py)?.into_any());
        }
        let xs = vector(x, "x")?;
        let a = xs.iter().map(|&v| self.policy.action(v)).collect();
        Ok(array(py, a).into_any())
    }

    fn __repr__(&self) -> String {
        format!(
            "Policy(kernels={}, lengthscale={})",
            self.policy.kernels(),
            self.policy.lengthscale
        )
    }
}

/// What a lap produced: `completed`, `time` (s, None if it failed), `reward` = L/T (m/s, 0 on
/// failure), `failure` (`off_track`, `hit_wall`, `spun`, `backwards`, `stalled`, `time_limit` or None) and
/// where (`x_fail`, lap fraction), and the `trace` when asked for: a dict of NumPy arrays, one
/// entry per driver step (t, distance_m, x, speed, pedal, steer, lateral, heading_error,
/// slip_angle, gear, rpm, pos_x, pos_y). `Optimizer.tell(w, lap)` takes it whole, failure
/// and all; `float(lap)` is its reward.
#[pyclass(name = "LapResult", module = "cdbo", frozen)]
pub struct PyLapResult {
    lap: LapResult,
    trace: Option<Py<PyDict>>,
}

impl PyLapResult {
    /// The reward and, for a failed lap, where it failed and whether it was too slow there:
    /// everything an optimiser is told of a lap.
    pub fn told(&self) -> (f64, Option<FailedLap>) {
        let failure = self.lap.failure.map(|f| FailedLap {
            at: f.x,
            too_slow: f.reason.too_slow(),
        });
        (self.lap.reward_mps, failure)
    }

    pub fn new(py: Python<'_>, lap: LapResult, with_trace: bool) -> PyResult<Self> {
        let trace = if with_trace {
            let cols: [Column<cdbo::sim::TracePoint>; 13] = [
                ("t", |p| p.t),
                ("distance_m", |p| p.distance_m),
                ("x", |p| p.x),
                ("speed", |p| p.speed),
                ("pedal", |p| p.pedal),
                ("steer", |p| p.steer),
                ("lateral", |p| p.lateral),
                ("heading_error", |p| p.heading_error),
                ("slip_angle", |p| p.slip_angle),
                ("gear", |p| p.gear as f64),
                ("rpm", |p| p.rpm),
                ("pos_x", |p| p.pos_x),
                ("pos_y", |p| p.pos_y),
            ];
            Some(columns(py, &lap.trace, &cols)?.unbind())
        } else {
            None
        };
        Ok(PyLapResult { lap, trace })
    }
}

#[pymethods]
impl PyLapResult {
    #[getter]
    fn completed(&self) -> bool {
        self.lap.completed
    }

    #[getter]
    fn time(&self) -> Option<f64> {
        self.lap.lap_time_s
    }

    #[getter]
    fn reward(&self) -> f64 {
        self.lap.reward_mps
    }

    #[getter]
    fn failure(&self) -> Option<&'static str> {
        self.lap.failure.map(|f| f.reason.name())
    }

    #[getter]
    fn x_fail(&self) -> Option<f64> {
        self.lap.failure.map(|f| f.x)
    }

    /// Whether the lap failed for being too slow (it stalled or ran out of time) rather than
    /// too fast (it left the road, spun or turned round); False for a completed lap.
    #[getter]
    fn too_slow(&self) -> bool {
        self.lap.failure.is_some_and(|f| f.reason.too_slow())
    }

    /// The reward, so that a lap reads as its number: `float(lap)`.
    fn __float__(&self) -> f64 {
        self.lap.reward_mps
    }

    /// Simulated time (s).
    #[getter]
    fn simulated_s(&self) -> f64 {
        self.lap.simulated_s
    }

    #[getter]
    fn trace(&self, py: Python<'_>) -> Option<Py<PyDict>> {
        self.trace.as_ref().map(|t| t.clone_ref(py))
    }

    fn __repr__(&self) -> String {
        match (self.lap.lap_time_s, self.lap.failure) {
            (Some(t), _) => format!(
                "LapResult(time={t:.3} s, reward={:.3} m/s)",
                self.lap.reward_mps
            ),
            (_, Some(f)) => format!(
                "LapResult(failure={:?}, x_fail={:.3})",
                f.reason.name(),
                f.x
            ),
            _ => "LapResult(failed)".into(),
        }
    }
}

/// A track and a car, ready to run laps: `Simulator(track, car)`; `line="min-curvature"` holds
/// the minimum-curvature racing line (as `cdbo race --line min-curvature`), the demonstration's
/// included; `steering="tracker"` steers with the path tracker (as `--steering tracker`);
/// `off_track_margin` is where a lap leaves the road (m past its edge, as
/// `--off-track-margin`; 1, the game's rule); None keeps the reserve `cdbo race` learns with,
/// as `race` and `RaceEnv` do by default (the wheels 0.25 m off slippery ground, the body 1 m
/// off the walls, the car's centre on the road; `LEARNING_OFF_TRACK_MARGIN` where the road's
/// verges are not known).
#[pyclass(name = "Simulator", module = "cdbo", frozen)]
pub struct PySimulator {
    pub sim: Simulator,
    /// The car the simulator drives.
    pub car: cdbo::car::Car,
    /// The base line the simulator's laps hold (`line=`).
    pub base: BaseLine,
}

#[pymethods]
impl PySimulator {
    #[new]
    #[pyo3(signature = (track = None, car = None, *, data_dir = None, line = "centre", steering = "pi", off_track_margin = Some(1.0)))]
    fn new(
        py: Python<'_>,
        track: Option<&Bound<'_, PyAny>>,
        car: Option<&Bound<'_, PyAny>>,
        data_dir: Option<&Bound<'_, PyAny>>,
        line: &str,
        steering: &str,
        off_track_margin: Option<f64>,
    ) -> PyResult<Self> {
        let track = track_from(py, track, data_dir)?;
        let car = car_from(car, data_dir)?;
        let base: BaseLine = line.parse().py()?;
        let steering: SteeringLaw = steering.parse().py()?;
        let off_track_margin = off_track_margin
            .map(checked_off_track_margin)
            .transpose()
            .py()?;
        let held = py.detach(|| base.line(&track, &car)).py()?;
        let mut sim = Simulator::new(track, &car);
        sim.config.steering = steering.steering();
        sim.config.learn_with(off_track_margin);
        sim.config.line = held;
        Ok(PySimulator { sim, base, car })
    }

    /// One lap with `policy`; `line`, a second `Policy`, is a learned line d(x): its raw sum
    /// wᵀφ(x) (m, positive left) is the offset from the simulator's base line, clamped to the
    /// road less half the car's width; `target`, a dict as `RaceResult.best_target`, makes the
    /// policy's action ask for the speed (k₀ + s·a(x))·v_g(x) rather than be the pedal;
    /// `trace=True` records every driver step.
    #[pyo3(signature = (policy, *, line = None, target = None, trace = false))]
    fn lap(
        &self,
        py: Python<'_>,
        policy: PyRef<'_, PyPolicy>,
        line: Option<PyRef<'_, PyPolicy>>,
        target: Option<&Bound<'_, PyDict>>,
        trace: bool,
    ) -> PyResult<PyLapResult> {
        let policy = Policy {
            pedal: policy.policy.clone(),
            line: line.map(|l| l.policy.clone()),
            target: target.map(target_from).transpose()?,
        };
        let lap = py.detach(|| {
            if trace {
                let mut sim = self.sim.clone();
                sim.config.trace = true;
                sim.lap(&mut policy.driver())
            } else {
                self.sim.lap(&mut policy.driver())
            }
        });
        PyLapResult::new(py, lap, trace)
    }

    /// The line the laps hold where a policy has none: `centre` or `min-curvature`.
    #[getter]
    fn line(&self) -> &'static str {
        self.base.name()
    }

    /// The demonstrator's lap at `speed` (m/s) and its (x, a) pairs as two arrays: what
    /// `Policy.fit` turns into w0.
    #[pyo3(signature = (speed = 15.0))]
    fn demonstrate<'py>(
        &self,
        py: Python<'py>,
        speed: f64,
    ) -> PyResult<(PyLapResult, Array<'py>, Array<'py>)> {
        let (lap, pairs) = py.detach(|| self.sim.demonstrate(speed));
        let (x, a) = pairs.into_iter().unzip();
        Ok((
            PyLapResult::new(py, lap, false)?,
            array(py, x),
            array(py, a),
        ))
    }

    /// The recommended learner's demonstration, as `cdbo race --method safe-pattern-search`
    /// drives it: a hold of a share of the limit's speed profile on the laps' line (the profile
    /// start). Returns its lap, its (x, a) pairs as two arrays, a in the units of the policy
    /// that learns from it (the action asking for the demonstrated speed, 0), the speed it
    /// holds (m/s) and the target the policy's action asks for (a dict as
    /// `RaceResult.best_target`, for `lap(policy, target=...)`); None where no share of the
    /// profile completes.
    #[allow(clippy::type_complexity)]
    fn demonstrate_profile<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<Option<(PyLapResult, Array<'py>, Array<'py>, f64, Bound<'py, PyDict>)>> {
        let venue = cdbo::venue::Venue::Simulator(Box::new(self.sim.clone()));
        let demonstrator = cdbo::experiment::profile_start::ProfileDemonstrator::new(
            &self.sim.track,
            &self.car,
            self.sim.config.line.as_deref(),
        );
        let chosen = py.detach(|| demonstrator.choose(&venue)).py()?;
        let Some(((lap, pairs), choice)) = chosen else {
            return Ok(None);
        };
        let target = demonstrator.target(&self.sim.track, choice.k).py()?;
        let a = target.action_holding(choice.k);
        let (x, a) = pairs.into_iter().map(|(x, _)| (x, a)).unzip();
        Ok(Some((
            PyLapResult::new(py, lap, false)?,
            array(py, x),
            array(py, a),
            choice.speed_mps,
            target_dict(py, &target)?,
        )))
    }

    /// The track.
    #[getter]
    fn track(&self) -> PyTrack {
        PyTrack {
            track: self.sim.track.clone(),
        }
    }

    /// The car.
    #[getter]
    fn car(&self) -> PyCar {
        PyCar {
            car: self.sim.vehicle.car.clone(),
        }
    }

    /// A lap's time limit (s).
    #[getter]
    fn time_limit(&self) -> f64 {
        self.sim.time_limit()
    }
}

/// The quasi-steady-state limit lap: `time` (s), `reward` = L/T (m/s) and the limit `speed`
/// at every track sample (m/s).
#[pyclass(name = "Limit", module = "cdbo", frozen)]
pub struct PyLimit {
    pub limit: Limit,
}

#[pymethods]
impl PyLimit {
    #[getter]
    fn time(&self) -> f64 {
        self.limit.lap_time_s
    }

    #[getter]
    fn reward(&self) -> f64 {
        self.limit.reward_mps
    }

    #[getter]
    fn speed<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array(py, self.limit.speed.clone())
    }

    fn __repr__(&self) -> String {
        format!(
            "Limit(time={:.3} s, reward={:.3} m/s)",
            self.limit.lap_time_s, self.limit.reward_mps
        )
    }
}

/// The physical limit of `car` on `track` (objects or names): no lap of the simulator beats
/// it.
#[pyfunction]
#[pyo3(signature = (track = None, car = None, *, data_dir = None))]
pub fn limit(
    py: Python<'_>,
    track: Option<&Bound<'_, PyAny>>,
    car: Option<&Bound<'_, PyAny>>,
    data_dir: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyLimit> {
    let track = track_from(py, track, data_dir)?;
    let car = car_from(car, data_dir)?;
    Ok(PyLimit {
        limit: py.detach(|| limit_lap(&track, &car)),
    })
}

/// A speed target as a dict: `profile` (m/s at stations spaced evenly over the lap), `length`
/// (m), `scale` k₀ and `span` s.
pub fn target_dict<'py>(py: Python<'py>, t: &SpeedTarget) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("profile", t.profile.clone())?;
    d.set_item("length", t.length)?;
    d.set_item("scale", t.scale)?;
    d.set_item("span", t.span)?;
    Ok(d)
}

/// The speed target of a dict as [`target_dict`] writes it; a missing or mistyped key raises
/// `ValueError` naming it.
pub fn target_from(d: &Bound<'_, PyDict>) -> PyResult<SpeedTarget> {
    use pyo3::exceptions::PyValueError;
    let item = |key: &str| {
        d.get_item(key)?
            .ok_or_else(|| PyValueError::new_err(format!("target: no \"{key}\"")))
    };
    fn bad(key: &'static str) -> impl Fn(PyErr) -> PyErr {
        move |e| PyValueError::new_err(format!("target[\"{key}\"]: {e}"))
    }
    let number = |key: &'static str| item(key)?.extract::<f64>().map_err(bad(key));
    SpeedTarget::new(
        item("profile")?
            .extract::<Vec<f64>>()
            .map_err(bad("profile"))?,
        number("length")?,
        number("scale")?,
        number("span")?,
    )
    .py()
}
