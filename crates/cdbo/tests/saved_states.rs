//! States saved before the methods ran in one ask/tell shell resume as they were: each
//! fixture is a run of 12 laps on Ackley-4 (every fourth lap told failed, with its place),
//! saved by the code of that time with the weights it asked next.

use cdbo::benchmarks::Problem;
use cdbo::method::{Method, Spec, resume};
use cdbo::optimizers::{FailedLap, Optimizer, Saved};

/// (method, saved state as JSON, the weights asked next as JSON), one per method.
const FIXTURES: &str = include_str!("fixtures/saved_before_the_shell.txt");

/// The fixtures' run: 12 laps of `method` from Ackley-4's start with seed 5.
fn driven(method: &str, problem: &Problem) -> Box<dyn Optimizer + Send> {
    let method: Method = method.parse().unwrap();
    let spec = Spec::problem(method, problem.radius).unwrap().seed(5);
    let mut opt = spec.optimizer(problem.start.clone()).unwrap();
    for k in 0..12 {
        let w = opt.ask().unwrap();
        if k % 4 == 3 {
            let failure = FailedLap::too_fast(0.25 + 0.05 * k as f64);
            opt.tell_lap(&w, 0.0, Some(failure)).unwrap();
        } else {
            opt.tell(&w, problem.reward(&w)).unwrap();
        }
    }
    opt
}

#[test]
fn states_saved_before_the_shell_resume_and_ask_as_the_uninterrupted_run() {
    let problem = Problem::by_name("ackley", 4).unwrap();
    let lines: Vec<&str> = FIXTURES.lines().collect();
    assert_eq!(lines.len(), 27, "three lines for each of the nine methods");
    for fixture in lines.chunks(3) {
        let [method, json, next] = fixture else {
            unreachable!("chunks of three")
        };
        let saved: Saved = serde_json::from_str(json).unwrap();
        let mut resumed = resume(saved).unwrap();
        let mut uninterrupted = driven(method, &problem);
        assert_eq!(resumed.name(), *method);
        assert_eq!(resumed.evaluations(), 12, "{method}");
        assert_eq!(resumed.best(), uninterrupted.best(), "{method}");
        let next: Vec<f64> = serde_json::from_str(next).unwrap();
        assert_eq!(resumed.ask().unwrap(), next, "{method}: as saved");
        assert_eq!(
            uninterrupted.ask().unwrap(),
            next,
            "{method}: uninterrupted"
        );
        for _ in 0..6 {
            let (a, b) = (resumed.ask().unwrap(), uninterrupted.ask().unwrap());
            assert_eq!(a, b, "{method}: the resumed run diverged");
            resumed.tell(&a, problem.reward(&a)).unwrap();
            uninterrupted.tell(&b, problem.reward(&b)).unwrap();
        }
    }
}
