//! Helpers shared by the command-line tests: the binary run in a folder, fresh folders, a
//! recorded demonstration, a study's history.
#![allow(dead_code)]

use std::io::{BufRead, BufReader, Lines, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, ExitStatus, Output, Stdio};

/// The `cdbo` binary under test.
pub const CDBO: &str = env!("CARGO_BIN_EXE_cdbo");

/// Runs `cdbo ARGS` in `dir`.
pub fn cdbo(dir: &Path, args: &[&str]) -> Output {
    Command::new(CDBO)
        .args(args)
        .current_dir(dir)
        .output()
        .expect("runs")
}

/// Runs `cdbo ARGS` in `dir`, expects success and returns its standard output.
pub fn ok(dir: &Path, args: &[&str]) -> String {
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
pub fn refused(dir: &Path, args: &[&str], needles: &[&str]) {
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

/// A demonstration recorded on the built-in track, `demo.csv` in `dir`.
pub fn demo(dir: &Path) {
    ok(
        dir,
        &["lap", "--demo", "15", "--trace", "demo.csv", "--json"],
    );
}

/// The told trials of study `s` in `db`, as `cdbo study history --json` lists them.
pub fn history(dir: &Path, db: &str) -> Vec<serde_json::Value> {
    let text = ok(dir, &["study", "history", "s", "--db", db, "--json"]);
    serde_json::from_str(&text).unwrap()
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
