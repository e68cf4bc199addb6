//! `cdbo.Optimizer`: every method of `cdbo race --method` behind one ask/tell object.

use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyType};

use cdbo::method::{Method, Spec};
use cdbo::optimizers::{DEFAULT_BOX_RADIUS, FailedLap, Optimizer, Saved};

use crate::convert::{IntoPy, array, lock, vector};
use crate::sim::PyLapResult;

/// An ask/tell optimiser of rewards over weights, started from w0.
///
/// `Optimizer(method, w0, seed=0, beta=1.0, bounds=1.5, sigma0=None, knob=None,
/// lengthscale=None, track_length=None, max_failed=None)`: `method` is
/// one of `cdbo.METHODS`; the weights are searched in the box [w0 - bounds, w0 + bounds];
/// `sigma0` is the exploration scale around w0 (CDBO's initial samples, the evolution
/// strategies' step); `knob` is the method's main knob (`cdbo race --knob`: σ₀ for CMA-ES,
/// random and pattern search, TuRBO's initial trust-region side, LineBO's step, REMBO's box),
/// checked against its range; `lengthscale`, when w0 are a lap policy's weights, is its
/// kernels' length-scale (`RaceEnv.lengthscale`; pattern search then pushes the policy's
/// pedal) and `track_length` the lap's length in metres (`RaceEnv.track_length`; the push then
/// repairs over road); `max_failed` caps the failed laps (once they have failed, only the best
/// completed weights are asked again); `pedal_kernels`, when w0 are [w_a, w_d] of a policy
/// with a learned line (`RaceEnv(line="learn")`), is how many of them are the pedal's (the
/// pattern search pushes and repairs those). With the defaults, the policy's length-scale and the lap's length, it
/// is `cdbo race`'s optimiser (each knob at its tuned value), so the same seed asks the same
/// weights.
#[pyclass(name = "Optimizer", module = "cdbo")]
pub struct PyOptimizer {
    inner: Mutex<Box<dyn Optimizer + Send>>,
    /// Seconds the library spent in the last `ask` (f64 bits), for the binding's overhead.
    last_ask_s: AtomicU64,
}

impl PyOptimizer {
    fn wrap(inner: Box<dyn Optimizer + Send>) -> Self {
        PyOptimizer {
            inner: Mutex::new(inner),
            last_ask_s: AtomicU64::new(0),
        }
    }
}

#[pymethods]
impl PyOptimizer {
    #[new]
    #[pyo3(signature = (method, w0, *, seed = 0, beta = cdbo::acquisition::ucb::DEFAULT_BETA, bounds = DEFAULT_BOX_RADIUS, sigma0 = None, knob = None, lengthscale = None, track_length = None, max_failed = None, pedal_kernels = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        method: &str,
        w0: &Bound<'_, PyAny>,
        seed: u64,
        beta: f64,
        bounds: f64,
        sigma0: Option<f64>,
        knob: Option<f64>,
        lengthscale: Option<f64>,
        track_length: Option<f64>,
        max_failed: Option<usize>,
        pedal_kernels: Option<usize>,
    ) -> PyResult<Self> {
        let w0 = vector(w0, "w0")?;
        let method: Method = method.parse().py()?;
        let spec = || -> cdbo::Result<Spec> {
            let mut spec = Spec::race(method)
                .seed(seed)
                .beta(beta)?
                .box_radius(bounds)?;
            if let Some(sigma0) = sigma0 {
                spec = spec.sigma0(sigma0)?;
            }
            if let Some(value) = knob {
                spec = spec.knob(value)?;
            }
            if let Some(lengthscale) = lengthscale {
                spec = spec.policy(lengthscale)?;
            }
            if let Some(max) = max_failed {
                spec = spec.max_failed_laps(max);
            }
            if let Some(kernels) = pedal_kernels {
                spec = spec.pedal_kernels(kernels);
            }
            track_length.map_or(Ok(spec), |length| spec.track_length(length))
        };
        let spec = spec().py()?;
        let inner = py.detach(|| spec.optimizer(w0)).py()?;
        Ok(PyOptimizer::wrap(inner))
    }

    /// The weights of the next evaluation (the same until they are told).
    fn ask<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let w = py.detach(|| {
            let mut inner = lock(&self.inner)?;
            let t0 = Instant::now();
            let w = inner.ask();
            let seconds = t0.elapsed().as_secs_f64();
            self.last_ask_s.store(seconds.to_bits(), Ordering::Relaxed);
            w.py()
        })?;
        Ok(array(py, w))
    }

    /// Seconds the library itself spent choosing the weights in the last `ask` (the rest of
    /// the call's time is the binding's: `bench/ask_overhead.py` measures it).
    #[getter]
    fn last_ask_s(&self) -> f64 {
        f64::from_bits(self.last_ask_s.load(Ordering::Relaxed))
    }

    /// Tells what the lap driven with `w` gave: a `LapResult` (`env.lap(w)`,
    /// `Simulator.lap(...)`), which carries its failure's place and reason, or its reward as a
    /// number (0 for a failed lap) with, for a failed lap whose place is known, where it failed
    /// (`failed_at`, a lap fraction) and whether the car was too slow there (`too_slow`: it
    /// stalled or ran out of time, rather than leaving the road or spinning). Methods that use
    /// the failure, such as pattern-search, repair the policy there.
    #[pyo3(signature = (w, lap, failed_at = None, too_slow = false))]
    fn tell(
        &self,
        py: Python<'_>,
        w: &Bound<'_, PyAny>,
        lap: &Bound<'_, PyAny>,
        failed_at: Option<f64>,
        too_slow: bool,
    ) -> PyResult<()> {
        let w = vector(w, "w")?;
        let (reward, failure) = match lap.cast::<PyLapResult>() {
            Ok(_) if failed_at.is_some() || too_slow => {
                return Err(pyo3::exceptions::PyValueError::new_err(
                    "tell: the LapResult already says where and why it failed; \
                     failed_at= and too_slow= go with a reward given as a number",
                ));
            }
            Ok(result) => result.borrow().told(),
            Err(_) => {
                let reward: f64 = lap.extract().map_err(|_| {
                    pyo3::exceptions::PyTypeError::new_err(format!(
                        "tell: the lap is a LapResult or a reward (a number), not {}",
                        lap.get_type()
                    ))
                })?;
                (reward, failed_at.map(|at| FailedLap { at, too_slow }))
            }
        };
        py.detach(|| lock(&self.inner)?.tell_lap(&w, reward, failure).py())
    }

    /// The best (weights, reward) told so far, or None.
    #[getter]
    fn best<'py>(&self, py: Python<'py>) -> PyResult<Option<(Bound<'py, PyArray1<f64>>, f64)>> {
        let inner = lock(&self.inner)?;
        Ok(inner.best().map(|(w, r)| (array(py, w.to_vec()), r)))
    }

    /// The method's name.
    #[getter]
    fn method(&self) -> PyResult<&'static str> {
        Ok(lock(&self.inner)?.name())
    }

    /// Number of weights.
    #[getter]
    fn dim(&self) -> PyResult<usize> {
        Ok(lock(&self.inner)?.dim())
    }

    /// Number of rewards told.
    #[getter]
    fn evaluations(&self) -> PyResult<usize> {
        Ok(lock(&self.inner)?.evaluations())
    }

    /// The whole state as bytes (JSON); `Optimizer.load` continues exactly from it.
    fn save<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let saved = lock(&self.inner)?.save();
        let json = py
            .detach(|| serde_json::to_vec(&saved))
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
        Ok(PyBytes::new(py, &json))
    }

    /// The optimiser saved by `save()`.
    #[classmethod]
    fn load(_cls: &Bound<'_, PyType>, py: Python<'_>, state: &[u8]) -> PyResult<Self> {
        let saved: Saved = serde_json::from_slice(state).map_err(|e| {
            pyo3::exceptions::PyValueError::new_err(format!("not a saved cdbo optimiser: {e}"))
        })?;
        let inner = py.detach(|| cdbo::method::resume(saved)).py()?;
        Ok(PyOptimizer::wrap(inner))
    }

    fn __repr__(&self) -> PyResult<String> {
        let inner = lock(&self.inner)?;
        Ok(format!(
            "Optimizer({:?}, dim={}, evaluations={})",
            inner.name(),
            inner.dim(),
            inner.evaluations()
        ))
    }
}
