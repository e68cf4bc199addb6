//! An external command as the evaluator: a real car's lap timer, another simulator, a script.
//!
//! For each lap the policy is written as JSON — `{"weights": […], "lengthscale": l,
//! "table": [[x, a], …]}` — to a file, and the command runs through `sh -c` with `{policy}`
//! replaced by that file's (quoted) path. Its standard output gives the reward: a number, or a
//! JSON object with `reward` (or `reward_mps`), or a failure with its place and reason —
//! `{"failed": true, "at": x, "reason": …}`, or as `cdbo lap --json` reports one,
//! `{"completed": false, "failure": {"reason": …, "x": x}}` — which learners that repair
//! where a lap failed (the pattern search) are told.
//! A non-zero exit, a timeout, output that parses as neither or an output past its bound
//! ([`bounded::LAP_COMMAND_OUTPUT`], the command then stopped) is a failed lap with the reason.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::{Arc, OnceLock};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::{Evaluator, Outcome};
use crate::bounded;
use crate::drive::steering::SteeringLaw;
use crate::error::{Error, Result};
use crate::line::BaseLine;
use crate::policy::PolicyShape;
use crate::policy::RacedPolicy;
use crate::store::claim::process_exists;

/// Points of the (x, a) table written with each policy.
pub const TABLE_POINTS: usize = 1001;

/// An external command evaluating policies.
#[derive(Debug, Clone)]
pub struct CommandEvaluator {
    /// The command line, with `{policy}` where the policy file's path goes.
    pub template: String,
    /// Longest a lap may take.
    pub timeout: Duration,
    /// Where the policy files go: trial `id`'s is `FILES.trial-ID.pid-PID.json`
    /// ([`policy_file`]), written before the lap and removed after it.
    pub files: PathBuf,
    /// The policies' shape: the pedal's kernels and length-scale, and a learned line's.
    pub shape: PolicyShape,
    /// The line the car holds, written into each policy file ([`RacedPolicy`]) so that a lap
    /// command such as `cdbo lap --policy {policy}` drives it.
    pub base_line: BaseLine,
    /// The steering, written into each policy file likewise.
    pub steering: SteeringLaw,
}

/// Where process `pid` writes trial `id`'s policy for the command: one file per trial and
/// process, so that no worker reads another's half-written file.
pub fn policy_file(files: &Path, id: i64, pid: u32) -> PathBuf {
    PathBuf::from(format!("{}.trial-{id}.pid-{pid}.json", files.display()))
}

/// The policy file's content: the policy's own file (`weights`, `lengthscale`, and a learned
/// line's `line` and a `base_line` other than the centre, [`RacedPolicy`]) and its `table` of
/// [x, a] rows, [x, a, d] with a line (d before the road's bounds).
pub fn policy_json(raced: &RacedPolicy) -> serde_json::Value {
    let line = raced.policy.line.is_some();
    let table: Vec<Vec<f64>> = raced
        .policy
        .table(TABLE_POINTS)
        .into_iter()
        .map(|(x, a, d)| if line { vec![x, a, d] } else { vec![x, a] })
        .collect();
    let mut v = serde_json::to_value(raced).unwrap_or_default();
    v["table"] = table.into();
    v
}

/// `'text'` for `sh`, with single quotes escaped.
fn shell_quote(text: &str) -> String {
    format!("'{}'", text.replace('\'', r"'\''"))
}

/// The outcome a command's standard output reports.
pub fn parse_output(stdout: &str) -> Outcome {
    let text = stdout.trim();
    let last = text.lines().last().unwrap_or("").trim();
    if let Ok(r) = last.parse::<f64>() {
        return if r.is_finite() {
            Outcome::Reward(r)
        } else {
            Outcome::Failed {
                at: None,
                reason: Some(format!("the command reported a non-finite reward {last}")),
            }
        };
    }
    let unparsable = || Outcome::Failed {
        at: None,
        reason: Some(format!(
            "unparsable output {:?} (expected a number or a JSON object with \"reward\")",
            text.chars().take(200).collect::<String>()
        )),
    };
    let Ok(serde_json::Value::Object(v)) = serde_json::from_str::<serde_json::Value>(text) else {
        return unparsable();
    };
    if v.get("completed").and_then(|c| c.as_bool()) == Some(false) {
        let failure = v.get("failure");
        return Outcome::Failed {
            at: failure.and_then(|f| f.get("x")).and_then(|x| x.as_f64()),
            reason: Some(
                failure
                    .and_then(|f| f.get("reason"))
                    .and_then(|r| r.as_str())
                    .unwrap_or("reported not completed")
                    .to_owned(),
            ),
        };
    }
    if v.get("failed").and_then(|f| f.as_bool()) == Some(true) {
        return Outcome::Failed {
            at: v.get("at").and_then(|x| x.as_f64()),
            reason: Some(
                v.get("reason")
                    .and_then(|r| r.as_str())
                    .unwrap_or("reported failed")
                    .to_owned(),
            ),
        };
    }
    match v
        .get("reward")
        .or_else(|| v.get("reward_mps"))
        .and_then(|r| r.as_f64())
    {
        Some(r) if r.is_finite() => Outcome::Reward(r),
        _ => unparsable(),
    }
}

impl Evaluator for CommandEvaluator {
    fn evaluate(&mut self, trial: i64, weights: &[f64]) -> Result<Outcome> {
        let file = policy_file(&self.files, trial, std::process::id());
        let outcome = self.drive(&file, weights);
        let _ = std::fs::remove_file(&file);
        outcome
    }

    /// The policy files of processes that no longer exist (killed while driving); a live
    /// worker's file stays.
    fn remove_leftovers(&mut self) -> Vec<(PathBuf, u32)> {
        let Some(name) = self
            .files
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
        else {
            return Vec::new();
        };
        let folder = match self.files.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
            _ => PathBuf::from("."),
        };
        let Ok(entries) = std::fs::read_dir(&folder) else {
            return Vec::new();
        };
        let prefix = format!("{name}.trial-");
        let mut removed = Vec::new();
        for entry in entries.flatten() {
            let file = entry.file_name().to_string_lossy().into_owned();
            let Some(rest) = file
                .strip_prefix(&prefix)
                .and_then(|r| r.strip_suffix(".json"))
            else {
                continue;
            };
            let pid = rest
                .split_once(".pid-")
                .and_then(|(_, p)| p.parse::<u32>().ok());
            if let Some(pid) = pid.filter(|p| *p != std::process::id() && !process_exists(*p)) {
                if std::fs::remove_file(entry.path()).is_ok() {
                    removed.push((entry.path(), pid));
                }
            }
        }
        removed
    }
}

impl CommandEvaluator {
    /// Writes the policy with `weights` to `file`, runs the command on it, reads the outcome.
    fn drive(&self, file: &Path, weights: &[f64]) -> Result<Outcome> {
        let policy = RacedPolicy {
            policy: self.shape.policy(weights)?,
            base_line: self.base_line,
            steering: self.steering,
        };
        let text = serde_json::to_string(&policy_json(&policy))
            .map_err(|e| Error::json(file.display().to_string(), e))?;
        std::fs::write(file, text).map_err(|e| Error::Io {
            path: file.to_owned(),
            source: e,
        })?;
        let line = self
            .template
            .replace("{policy}", &shell_quote(&file.display().to_string()));
        let mut child = Command::new("sh")
            .arg("-c")
            .arg(&line)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|source| Error::Command {
                line: line.clone(),
                source,
            })?;
        // Each output is read through its bound; the first refused stops the command.
        let refused = Arc::new(OnceLock::new());
        let out = read_output(child.stdout.take(), &line, "standard output", &refused);
        let err = read_output(child.stderr.take(), &line, "standard error", &refused);
        let start = Instant::now();
        let status = loop {
            match child.try_wait() {
                Ok(Some(status)) => break status,
                Ok(None) if refused.get().is_some() => {
                    let _ = child.kill();
                    let _ = child.wait();
                    return Ok(Outcome::Failed {
                        at: None,
                        reason: refused.get().cloned(),
                    });
                }
                Ok(None) if start.elapsed() > self.timeout => {
                    let _ = child.kill();
                    let _ = child.wait();
                    return Ok(Outcome::Failed {
                        at: None,
                        reason: Some(format!(
                            "timeout: no result after {:.1} s",
                            self.timeout.as_secs_f64()
                        )),
                    });
                }
                Ok(None) => std::thread::sleep(Duration::from_millis(5)),
                Err(source) => return Err(Error::Command { line, source }),
            }
        };
        let stdout = out.join().unwrap_or_default();
        let stderr = err.join().unwrap_or_default();
        if let Some(why) = refused.get() {
            return Ok(Outcome::Failed {
                at: None,
                reason: Some(why.clone()),
            });
        }
        if !status.success() {
            let tail: String = stderr
                .trim()
                .lines()
                .last()
                .unwrap_or("")
                .chars()
                .take(200)
                .collect();
            return Ok(Outcome::Failed {
                at: None,
                reason: Some(format!("the command exited with {status}: {tail}")),
            });
        }
        Ok(parse_output(&stdout))
    }
}

/// Reads `which` output of the command `line` on a thread of its own, through
/// [`bounded::LAP_COMMAND_OUTPUT`], as text (empty if it is not UTF-8 or cannot be read); a
/// refusal is set in `refused`, for the command to be stopped and the lap failed with it.
fn read_output(
    pipe: Option<impl Read + Send + 'static>,
    line: &str,
    which: &str,
    refused: &Arc<OnceLock<String>>,
) -> JoinHandle<String> {
    let name = format!("`sh -c {line}` ({which})");
    let refused = Arc::clone(refused);
    std::thread::spawn(move || {
        let Some(pipe) = pipe else {
            return String::new();
        };
        match bounded::read(pipe, &name, &bounded::LAP_COMMAND_OUTPUT) {
            Ok(bytes) => String::from_utf8(bytes).unwrap_or_default(),
            Err(e) => {
                if matches!(e, Error::InputTooLarge { .. }) {
                    let _ = refused.set(e.to_string());
                }
                String::new()
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_parse_as_rewards_or_failures() {
        assert_eq!(parse_output("lap done\n23.5\n"), Outcome::Reward(23.5));
        assert_eq!(parse_output(r#"{"reward": 12}"#), Outcome::Reward(12.0));
        assert_eq!(
            parse_output(r#"{"reward_mps": 7.5, "x": 1}"#),
            Outcome::Reward(7.5)
        );
        assert_eq!(
            parse_output(r#"{"failed": true, "at": 0.4, "reason": "spun"}"#),
            Outcome::Failed {
                at: Some(0.4),
                reason: Some("spun".into())
            }
        );
        // `cdbo lap --json`'s own report of a failed lap.
        assert_eq!(
            parse_output(
                r#"{"completed": false, "reward_mps": 0.0, "failure": {"reason": "spun", "x": 0.4}}"#
            ),
            Outcome::Failed {
                at: Some(0.4),
                reason: Some("spun".into())
            }
        );
        for bad in ["", "fast!", "NaN", r#"{"reward": "x"}"#] {
            assert!(
                matches!(parse_output(bad), Outcome::Failed { .. }),
                "{bad:?}"
            );
        }
    }

    #[test]
    fn exit_codes_and_timeouts_are_failed_laps() {
        let dir = crate::scratch::dir("command");
        let mut e = CommandEvaluator {
            template: "test -s {policy} && echo 3.25".into(),
            timeout: Duration::from_secs(5),
            files: dir.join("p"),
            shape: PolicyShape::pedal(crate::policy::Block::new(2, 0.5).unwrap()),
            base_line: BaseLine::Centre,
            steering: SteeringLaw::Pi,
        };
        assert_eq!(e.evaluate(1, &[0.1, 0.2]).unwrap(), Outcome::Reward(3.25));
        // The lap's policy file is gone after it; a killed process's is removed, a live one's
        // kept.
        assert!(!policy_file(&e.files, 1, std::process::id()).exists());
        let mut child = Command::new("true").spawn().unwrap();
        let dead = child.id();
        child.wait().unwrap();
        let left = policy_file(&e.files, 7, dead);
        let live = policy_file(&e.files, 8, std::process::id());
        std::fs::write(&left, "{}").unwrap();
        std::fs::write(&live, "{}").unwrap();
        assert_eq!(e.remove_leftovers(), vec![(left.clone(), dead)]);
        assert!(!left.exists() && live.exists());
        e.template = "echo boom >&2; exit 3".into();
        let Outcome::Failed { reason, .. } = e.evaluate(1, &[0.1, 0.2]).unwrap() else {
            panic!()
        };
        assert!(reason.unwrap().contains("boom"));
        e.template = "sleep 5".into();
        e.timeout = Duration::from_millis(100);
        let Outcome::Failed { reason, .. } = e.evaluate(1, &[0.1, 0.2]).unwrap() else {
            panic!()
        };
        assert!(reason.unwrap().contains("timeout"));
    }

    /// A command whose output never ends is stopped at the output's bound, long before its
    /// timeout: a failed lap saying which output, and the bound.
    #[test]
    fn an_endless_output_fails_the_lap_at_its_bound() {
        let dir = crate::scratch::dir("command-endless");
        let mut e = CommandEvaluator {
            template: "yes".into(),
            timeout: Duration::from_secs(600),
            files: dir.join("p"),
            shape: PolicyShape::pedal(crate::policy::Block::new(2, 0.5).unwrap()),
            base_line: BaseLine::Centre,
            steering: SteeringLaw::Pi,
        };
        for (template, which) in [("yes", "standard output"), ("yes >&2", "standard error")] {
            e.template = template.into();
            let Outcome::Failed { reason, .. } = e.evaluate(1, &[0.1, 0.2]).unwrap() else {
                panic!("{template}")
            };
            assert_eq!(
                reason.unwrap(),
                format!(
                    "`sh -c {template}` ({which}): the lap command's output is larger than its bound of 16 MiB"
                )
            );
        }
    }
}
