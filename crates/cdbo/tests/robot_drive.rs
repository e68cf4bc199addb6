//! The TORCS robot's decisions against cdbo's Rust, without TORCS.
//!
//! The robot's pure functions (`torcs-robot/drive.hpp`, embedded as
//! [`cdbo::torcs::ROBOT_HEADER`]) are compiled with `g++ -std=c++17` and the robot's own
//! flags into the harness `torcs-robot/tests/harness.cpp`, which answers one line per call.
//! The calls replay states recorded from two laps of cdbo's simulator on the default track
//! (the 15 m/s demonstration, and a policy learned by `cdbo race`): at every driver step the
//! policy's action (RKHS and table), the speed hold, the steering's look-ahead, bearing and
//! PI law, the gearbox, the launch clutch, the traction control and the ABS, each given the state the Rust controller had
//! (integrals, gear, time left in a shift), and the answers must equal the Rust definitions
//! bit for bit (within 1e-12 of the simulator's O(1) form of the RKHS policy). Skips with a
//! message where `g++` is missing.
//!
//! A third test replays two laps held on a line (the minimum-curvature line plus a policy's
//! line): the line's table the robot interpolates, the path's points and both steering laws
//! aiming at the path.
//!
//! A new function of the header (a second policy action, a path-tracking steering law) is
//! checked by a line in the harness's table and a `Calls::check` in the file of its topic,
//! `robot_drive/*.rs` (the decisions, the path tracker, the profile hold, the line).

mod common;

#[path = "robot_drive/decisions.rs"]
mod decisions;
#[path = "robot_drive/line.rs"]
mod line;
#[path = "robot_drive/profile_hold.rs"]
mod profile_hold;
#[path = "robot_drive/tracker.rs"]
mod tracker;

use std::fmt::Write;
use std::path::PathBuf;
use std::process::Command;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering};

use cdbo::drive::Pedal;
use cdbo::sim::{Simulator, TracePoint};
use cdbo::torcs::{ROBOT_CXXFLAGS, ROBOT_HEADER, ROBOT_HEADER_NAME};

/// The harness's source, compiled beside the header.
const HARNESS: &str = include_str!("../../../torcs-robot/tests/harness.cpp");

/// A learned policy: the best of `cdbo race --json` (CDBO on the default track, seed 0, 300
/// laps, 24.28 m/s with the rear axle's two wheels), its length-scale 1/29 and its 30 weights.
const LEARNED: (f64, [f64; 30]) = (
    0.034482758620689655,
    [
        0.7337174661007538,
        -0.43694042717594433,
        0.5201826057195019,
        -0.11801068406926697,
        0.09298255826485324,
        -0.06984606353310813,
        0.060475129724434626,
        0.07126463206502902,
        0.0259215183139601,
        0.03310894339182879,
        0.20151611797424623,
        0.02139022189118771,
        -0.032601245046369076,
        0.023931743413441394,
        -0.010326615824044563,
        -0.02276569741592198,
        0.06798864616173275,
        -0.009139452303147715,
        0.0007214249764117531,
        0.1374604199664775,
        0.31369075676239644,
        0.03037078288592783,
        -0.0059686177094644965,
        -0.08026028734180894,
        0.11866791284155351,
        0.5081091629164485,
        0.03954852323972051,
        0.027909705986782656,
        0.10983929994869644,
        -0.0796284654677915,
    ],
);

/// The compiled harness (built once for the tests here), or `None` (with a message) where
/// there is no `g++`.
fn harness() -> Option<PathBuf> {
    static HARNESS_EXE: OnceLock<Option<PathBuf>> = OnceLock::new();
    let exe = HARNESS_EXE.get_or_init(|| {
        if Command::new("g++").arg("--version").output().is_err() {
            return None;
        }
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("robot_drive");
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(ROBOT_HEADER_NAME), ROBOT_HEADER).unwrap();
        std::fs::write(dir.join("harness.cpp"), HARNESS).unwrap();
        let exe = dir.join("harness");
        let out = Command::new("g++")
            .arg("-std=c++17")
            .args(ROBOT_CXXFLAGS)
            .arg("-o")
            .arg(&exe)
            .arg(dir.join("harness.cpp"))
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "the harness did not compile:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        Some(exe)
    });
    if exe.is_none() {
        eprintln!("skipping: g++ is not installed (apt-get install g++)");
    }
    exe.clone()
}

/// How closely the C++ must agree.
#[derive(Debug, Clone, Copy)]
enum Agree {
    /// The same bits.
    Exactly,
    /// Within this absolute difference.
    Within(f64),
}

/// Calls to the harness and the answers the Rust definitions give. A call's line is written
/// once, as the harness reads it; the message naming it is made only where an answer differs.
#[derive(Default)]
struct Calls {
    input: String,
    expected: Vec<(String, Vec<f64>, Agree)>,
}

/// Numbers written once for many calls that begin with them (a table, a policy's weights),
/// each with a space before it, as [`Calls::check_after`] takes them.
fn written(args: &[f64]) -> String {
    let mut text = String::new();
    for a in args {
        write!(text, " {a:?}").unwrap();
    }
    text
}

impl Calls {
    /// Calls `name` with `args`; the answer must be `expected`.
    fn check(&mut self, what: &str, name: &str, args: &[f64], expected: &[f64], agree: Agree) {
        self.check_after(what, name, "", args, expected, agree);
    }

    /// Calls `name` with the numbers `first` ([`written`]) and then `args`; the answer must be
    /// `expected`.
    fn check_after(
        &mut self,
        what: &str,
        name: &str,
        first: &str,
        args: &[f64],
        expected: &[f64],
        agree: Agree,
    ) {
        self.input.push_str(name);
        self.input.push_str(first);
        for a in args {
            write!(self.input, " {a:?}").unwrap();
        }
        self.input.push('\n');
        self.expected
            .push((what.to_owned(), expected.to_vec(), agree));
    }

    /// Runs the harness on every call and compares; returns the number of calls. Each run
    /// has an input file of its own (the tests run in parallel).
    fn run(&self, exe: &PathBuf) -> usize {
        static RUNS: AtomicUsize = AtomicUsize::new(0);
        let input = exe.with_extension(format!("in{}", RUNS.fetch_add(1, Ordering::Relaxed)));
        std::fs::write(&input, &self.input).unwrap();
        let out = Command::new(exe)
            .stdin(std::fs::File::open(&input).unwrap())
            .output()
            .unwrap();
        let text = String::from_utf8(out.stdout).unwrap();
        assert!(out.status.success(), "the harness failed: {text}");
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), self.expected.len());
        let calls = self.input.lines();
        for ((line, (what, expected, agree)), call) in lines.iter().zip(&self.expected).zip(calls) {
            let got: Vec<f64> = line.split(' ').map(|v| v.parse().unwrap()).collect();
            assert_eq!(got.len(), expected.len(), "{what}: {call}: {line}");
            for (g, e) in got.iter().zip(expected) {
                let ok = match agree {
                    Agree::Exactly => g.to_bits() == e.to_bits(),
                    Agree::Within(tol) => (g - e).abs() <= *tol,
                };
                assert!(ok, "{what}: {call}: C++ {got:?}, Rust {expected:?}");
            }
        }
        let _ = std::fs::remove_file(&input);
        self.expected.len()
    }
}

/// A lap of the simulator with its trace.
fn lap(sim: &Simulator, pedal: &mut dyn Pedal) -> Vec<TracePoint> {
    let r = sim.lap(pedal);
    assert!(r.completed, "{:?}", r.failure);
    r.trace
}

/// The harness refuses what it does not know: a misspelt call or a short line fails the
/// run instead of answering something.
#[test]
fn the_harness_refuses_unknown_and_short_calls() {
    let Some(exe) = harness() else { return };
    for (i, input) in [
        "no_such_function 1 2\n",
        "bearing 1 2 3\n",
        "lookahead 1 2 3 4\n",
    ]
    .iter()
    .enumerate()
    {
        let path = exe.with_extension(format!("bad{i}"));
        std::fs::write(&path, input).unwrap();
        let out = Command::new(&exe)
            .stdin(std::fs::File::open(&path).unwrap())
            .output()
            .unwrap();
        assert!(!out.status.success(), "{input:?} was answered");
        assert!(String::from_utf8_lossy(&out.stdout).starts_with("error"));
    }
}
