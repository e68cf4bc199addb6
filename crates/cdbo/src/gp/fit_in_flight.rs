//! A hyperparameter fit ([`super::likelihood::fit`]) running on a thread of its own while
//! laps are driven, so that a run's main thread never waits for the O(n³) likelihood steps.
//!
//! The fit starts from a copy of the GP (its data, hyperparameters and bounds at one lap) and
//! its result is taken later by [`FitInFlight::finish`]; it is a function of that copy alone,
//! so the result is the same bit for bit whether the thread has finished, is still running,
//! or (in a clone) is redone on the caller's thread.

use std::sync::Arc;
use std::thread::JoinHandle;

use super::likelihood::{Bounds, fit};
use super::{GaussianProcess, Hyper};
use crate::error::{Error, Result};

/// A fit started on its own thread.
#[derive(Debug)]
pub struct FitInFlight {
    /// The GP the fit started from, shared with the thread and kept to redo the fit where
    /// the thread is not ours.
    start: Arc<GaussianProcess>,
    bounds: Bounds,
    iterations: usize,
    thread: Option<JoinHandle<Result<Hyper>>>,
}

impl FitInFlight {
    /// Starts fitting a copy of `gp` within `bounds` for `iterations` steps.
    pub fn start(gp: &GaussianProcess, bounds: Bounds, iterations: usize) -> FitInFlight {
        let start = Arc::new(gp.clone());
        let (shared, b) = (Arc::clone(&start), bounds.clone());
        let thread = std::thread::Builder::new()
            .name("cdbo-fit".into())
            .spawn(move || fit_copy(&shared, &b, iterations))
            .ok();
        FitInFlight {
            start,
            bounds,
            iterations,
            thread,
        }
    }

    /// The fitted hyperparameters, waiting for the thread if it is still running (or fitting
    /// here if no thread could be started).
    pub fn finish(self) -> Result<Hyper> {
        match self.thread {
            Some(thread) => thread
                .join()
                .map_err(|_| Error::Panicked("hyperparameter fit"))?,
            None => fit_copy(&self.start, &self.bounds, self.iterations),
        }
    }
}

/// A clone redoes the fit on the caller's thread when finished: same start, same result.
impl Clone for FitInFlight {
    fn clone(&self) -> FitInFlight {
        FitInFlight {
            start: Arc::clone(&self.start),
            bounds: self.bounds.clone(),
            iterations: self.iterations,
            thread: None,
        }
    }
}

/// Fits a copy of `start`, which stays as it is.
fn fit_copy(start: &GaussianProcess, bounds: &Bounds, iterations: usize) -> Result<Hyper> {
    let mut gp = start.clone();
    fit(&mut gp, bounds, iterations)?;
    Ok(gp.hyper().clone())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gp::{Kernel, Mean};

    fn gp() -> GaussianProcess {
        let h = Hyper {
            kernel: Kernel::Exponential,
            lengthscales: vec![1.0, 1.0],
            signal_var: 1.0,
            noise_var: 0.0,
            mean: Mean::Constant,
        };
        let mut gp = GaussianProcess::new(2, h).unwrap();
        for i in 0..30 {
            let w = [(i as f64 * 0.37).sin(), (i as f64 * 0.91).cos()];
            gp.add(&w, (3.0 * w[0]).sin() + w[1] * w[1]).unwrap();
        }
        gp
    }

    /// On its thread, in a clone redone here, and fitted directly: the same hyperparameters.
    #[test]
    fn the_thread_a_clone_and_a_direct_fit_agree_bit_for_bit() {
        let bounds = Bounds {
            lengthscale: (0.05, 20.0),
            signal_var: (1e-3, 1e2),
            noise_var: None,
        };
        let gp = gp();
        let in_flight = FitInFlight::start(&gp, bounds.clone(), 25);
        let redone = in_flight.clone();
        let mut direct = gp.clone();
        fit(&mut direct, &bounds, 25).unwrap();
        let threaded = in_flight.finish().unwrap();
        assert_ne!(&threaded, gp.hyper(), "the fit moved nothing");
        assert_eq!(&threaded, direct.hyper());
        assert_eq!(redone.finish().unwrap(), threaded);
    }
}
