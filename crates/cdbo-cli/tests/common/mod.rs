//! Helpers shared by the command-line tests: the binary run in a folder or where the tests run
//! (with ../shared on its data path), fresh folders and scratch files, a recorded
//! demonstration and its fit, the study and optimize commands of the tests, a study's history,
//! workers started and waited for.
#![allow(dead_code)]

use std::ffi::OsStr;
use std::fmt::Debug;
use std::io::{BufRead, BufReader, Lines, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, ExitStatus, Output, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// A hand-written TORCS track: an oval of two 100 m straights and two 180° turns of radius
/// 50 m, 10 m wide, of asphalt of friction 1 (514 m a lap, a seventh of Ridgeway: a grid of
/// races on it is quick).
pub const OVAL: &str = r#"<?xml version="1.0"?>
<params name="t">
  <section name="Main Track">
    <attnum name="width" unit="m" val="10"/>
    <section name="Track Segments">
      <section name="s1"><attstr name="type" val="str"/><attnum name="lg" unit="m" val="100"/></section>
      <section name="c1"><attstr name="type" val="lft"/><attnum name="radius" unit="m" val="50"/><attnum name="arc" unit="deg" val="180"/></section>
      <section name="s2"><attstr name="type" val="str"/><attnum name="lg" unit="m" val="100"/></section>
      <section name="c2"><attstr name="type" val="lft"/><attnum name="radius" unit="m" val="50"/><attnum name="arc" unit="deg" val="180"/></section>
    </section>
  </section>
  <section name="Surfaces">
    <section name="asphalt"><attnum name="friction" val="1.0"/></section>
  </section>
</params>
"#;

/// The `cdbo` binary under test.
pub const CDBO: &str = env!("CARGO_BIN_EXE_cdbo");

/// The test data beside the repository, through the one helper of the library's tests.
#[path = "../../../cdbo/tests/common/shared.rs"]
mod shared_data;

/// `../shared` beside the repository: the TORCS and Speed Dreams data the tests read.
pub fn shared() -> PathBuf {
    shared_data::shared("")
}

/// Runs `cdbo ARGS` where the tests run, with `../shared` on its data path.
pub fn run(args: &[&str]) -> Output {
    Command::new(CDBO)
        .args(args)
        .env("CDBO_DATA_PATH", shared())
        .output()
        .expect("runs")
}

/// Runs `cdbo ARGS` ([`run`]) and expects success.
pub fn succeed(args: &[&str]) -> Output {
    let out = run(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Runs `cdbo ARGS` ([`succeed`]) and reads its standard output as JSON.
pub fn json(args: &[&str]) -> serde_json::Value {
    serde_json::from_slice(&succeed(args).stdout).expect("JSON")
}

/// A scratch file with `content`, in a folder of this test binary's own.
pub fn scratch(name: &str, content: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-cli-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, content).unwrap();
    p
}

/// The oval ([`OVAL`]) as a file, written once for this test binary: a race on it is quick.
pub fn oval_file() -> &'static str {
    static FILE: OnceLock<String> = OnceLock::new();
    FILE.get_or_init(|| {
        let file = scratch("oval-track.xml", OVAL);
        file.to_str().unwrap().to_owned()
    })
}

/// Runs `cdbo ARGS` ([`run`]), expects failure with exactly one `error:` line containing every
/// `needle`, and no panic.
pub fn fails_with(args: &[&str], needles: &[&str]) {
    let out = run(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded");
    let errors: Vec<&str> = err.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "{err}");
    for n in needles {
        assert!(errors[0].contains(n), "{:?} lacks {n:?}", errors[0]);
    }
    assert!(!err.contains("panicked"), "{err}");
}

/// Runs `cdbo ARGS` in `dir`.
pub fn cdbo<S: AsRef<OsStr>>(dir: &Path, args: &[S]) -> Output {
    Command::new(CDBO)
        .args(args)
        .current_dir(dir)
        .output()
        .expect("runs")
}

/// Runs `cdbo ARGS` in `dir`, expects success and returns its standard output.
pub fn ok<S: AsRef<OsStr> + Debug>(dir: &Path, args: &[S]) -> String {
    let out = cdbo(dir, args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// An empty scratch folder of its own for test `name` of this test file, under cargo's
/// `target/tmp` (nothing is left in the system's temporary folder).
pub fn fresh_dir(name: &str) -> PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!(
        "cdbo-{}-{}-{name}",
        env!("CARGO_CRATE_NAME"),
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Expects exit status 2 and exactly one line on stderr, `error: …` containing every needle.
pub fn refused<S: AsRef<OsStr> + Debug>(dir: &Path, args: &[S], needles: &[&str]) {
    let out = cdbo(dir, args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 1, "{args:?}: not one line: {err}");
    assert!(lines[0].starts_with("error: "), "{args:?}: {err}");
    for n in needles {
        assert!(lines[0].contains(n), "{args:?}: {:?} lacks {n:?}", lines[0]);
    }
}

/// A demonstration recorded on the oval ([`OVAL`], `oval.xml` in `dir`), `demo.csv` in `dir`:
/// the laps of a study fitted to it are driven there ([`OVAL_LAP`]), a seventh of Ridgeway.
pub fn demo(dir: &Path) {
    std::fs::write(dir.join("oval.xml"), OVAL).unwrap();
    ok(
        dir,
        &[
            "lap", "--track", "oval.xml", "--demo", "15", "--trace", "demo.csv", "--json",
        ],
    );
}

/// An evaluator's lap on the oval of [`demo`]: `cdbo lap` of the trial's policy file, with
/// `{cdbo}` for the binary.
pub const OVAL_LAP: &str = "{cdbo} lap --track oval.xml --policy {policy} --json";

/// Ridgeway's 15 m/s demonstration traced (`cdbo lap --trace`, `TAG-demo.csv`) and w0 of 20
/// kernels fitted to it (`cdbo policy fit`, `TAG-w0.json`).
pub fn fitted_to_the_demonstration(tag: &str) -> (PathBuf, PathBuf) {
    let trace = scratch(&format!("{tag}-demo.csv"), "");
    succeed(&["lap", "--trace", trace.to_str().unwrap()]);
    let w0 = scratch(&format!("{tag}-w0.json"), "");
    let (demo, out) = (trace.to_str().unwrap(), w0.to_str().unwrap());
    succeed(&[
        "policy",
        "fit",
        "--demo",
        demo,
        "--kernels",
        "20",
        "-o",
        out,
    ]);
    (trace, w0)
}

/// A fresh scratch folder ([`fresh_dir`]) holding a demonstration, `demo.csv` ([`demo`]).
pub fn fresh_dir_with_demo(name: &str) -> PathBuf {
    let dir = fresh_dir(name);
    demo(&dir);
    dir
}

/// `cdbo study create NAME` of 6 kernels fitted to `demo.csv` ([`demo`]), then `more` (such
/// as `--storage URL`).
pub fn create_study<'a>(name: &'a str, more: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "study",
        "create",
        name,
        "--kernels",
        "6",
        "--demo",
        "demo.csv",
    ];
    args.extend(more);
    args
}

/// `cdbo optimize` of 6 kernels fitted to `demo.csv` ([`demo`]) on `storage`, to `laps` told
/// trials, each lap driven by `evaluator`.
pub fn optimize_args(evaluator: &str, storage: &str, laps: usize) -> Vec<String> {
    let laps = laps.to_string();
    [
        "optimize",
        "--evaluator",
        evaluator,
        "--kernels",
        "6",
        "--laps",
        &laps,
        "--storage",
        storage,
        "--demo",
        "demo.csv",
    ]
    .map(String::from)
    .to_vec()
}

/// A worker: [`optimize_args`] with 2 s leases, each lap a `cdbo lap` on the oval ([`OVAL_LAP`]) that first appends its
/// policy to `driven.log` ([`driven`]) and, `pause_s` > 0, sleeps that long.
pub fn optimize(storage: &str, laps: usize, pause_s: f64) -> Command {
    let pause = if pause_s > 0.0 {
        format!("sleep {pause_s}; ")
    } else {
        String::new()
    };
    let evaluator = format!(
        "echo {{policy}} >> driven.log; {pause}{}",
        OVAL_LAP.replace("{cdbo}", CDBO)
    );
    let mut c = Command::new(CDBO);
    c.args(optimize_args(&evaluator, storage, laps))
        .args(["--lease", "2"]);
    c
}

/// Laps driven so far by the workers of [`optimize`] in `dir`.
pub fn driven(dir: &Path) -> usize {
    std::fs::read_to_string(dir.join("driven.log")).map_or(0, |t| t.lines().count())
}

/// The trials of study `study` at `storage`, as `cdbo study history --json` lists them.
pub fn history(dir: &Path, study: &str, storage: &str) -> Vec<serde_json::Value> {
    let text = ok(
        dir,
        &["study", "history", study, "--storage", storage, "--json"],
    );
    serde_json::from_str(&text).unwrap()
}

/// Every trial of history `h` told, `trials` of them, each with weights of its own.
pub fn every_trial_told_once_and_distinct(h: &[serde_json::Value], trials: usize) {
    assert_eq!(h.len(), trials, "{h:?}");
    assert!(h.iter().all(|t| t["reward"].is_number()), "{h:?}");
    for (i, a) in h.iter().enumerate() {
        for b in &h[..i] {
            assert_ne!(
                a["weights"], b["weights"],
                "trials {} and {}",
                a["id"], b["id"]
            );
        }
    }
}

/// `command` started in `dir`, its output piped (kept for [`kill_first_and_reap`]).
pub fn spawn(mut command: Command, dir: &Path) -> Child {
    command
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// Waits until `done()`, checking every 20 ms; fails naming `what` after `timeout`.
pub fn wait_until(what: &str, timeout: Duration, mut done: impl FnMut() -> bool) {
    let start = Instant::now();
    while !done() {
        assert!(start.elapsed() < timeout, "{what}: not within {timeout:?}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Kills the first of `workers` (SIGKILL, mid-lap) and waits for them all: none panicked, and
/// every survivor ended successfully.
pub fn kill_first_and_reap(mut workers: Vec<std::process::Child>) {
    workers[0].kill().unwrap();
    for (k, w) in workers.into_iter().enumerate() {
        let out = w.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "{err}");
        if k > 0 {
            assert!(out.status.success(), "worker {k}: {err}");
        }
    }
}

/// The "Final best reward" table of a report's results.md: the rewards, not the timings.
pub fn rewards_table(report: &Path) -> String {
    let text = std::fs::read_to_string(report.join("results.md")).unwrap();
    let start = text.find("## Final best reward").expect("a rewards table");
    let end = text[start..]
        .find("## Run times")
        .expect("run times after it")
        + start;
    text[start..end].to_owned()
}

/// A running `cdbo serve-sim`, asked one JSON line at a time.
pub struct Service {
    child: Child,
    stdin: ChildStdin,
    lines: Lines<BufReader<ChildStdout>>,
}

impl Service {
    /// Starts `command` (a `cdbo ... serve-sim ...`) with piped standard input and output.
    pub fn start(mut command: Command) -> Service {
        let mut child = command
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        let stdin = child.stdin.take().unwrap();
        let lines = BufReader::new(child.stdout.take().unwrap()).lines();
        Service {
            child,
            stdin,
            lines,
        }
    }

    /// Sends one line and reads the reply line as JSON.
    pub fn ask(&mut self, line: &str) -> serde_json::Value {
        writeln!(self.stdin, "{line}").unwrap();
        serde_json::from_str(&self.lines.next().unwrap().unwrap()).unwrap()
    }

    /// Closes its input and waits for it to end.
    pub fn finish(self) -> ExitStatus {
        let Service {
            mut child, stdin, ..
        } = self;
        drop(stdin);
        child.wait().unwrap()
    }
}

/// The long form of `--preset fast-safe`.
pub const FAST_SAFE_FLAGS: [&str; 6] = [
    "--method",
    "safe-pattern-search",
    "--steering",
    "tracker",
    "--line",
    "min-curvature",
];
