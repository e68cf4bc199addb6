//! The lap service behind `cdbo serve-sim`: laps as JSON lines, so that any optimiser in any
//! language can race on our tracks. Each request line is answered by one reply line:
//! - `{"info": true}` → [`Info`]: the dimension, w₀, the search box, the track;
//! - `{"weights": [...]}` → a [`Reply::Lap`] driven by the [`Evaluator`]:
//!   `{"reward_mps", "lap_time_s", "failure"}`;
//! - anything else → `{"error": "line N: ..."}` naming what was wrong ([`RequestError`]): not
//!   UTF-8, longer than [`MAX_LINE_BYTES`], not JSON (NaN and numbers past `f64` are not JSON),
//!   wrong types, a wrong number of weights. The service keeps answering the next line.
//!
//! Blank lines are skipped without a reply. Memory stays bounded by the line cap whatever the
//! client sends ([`LineReader`]).

use std::io::{BufRead, Read, Write};

use serde::Serialize;
use serde_json::Value;

use crate::evaluator::{Evaluator, Outcome};

/// The longest request line: 1 MiB, forty times the 1000 weights of the largest policy.
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// A well-formed request.
#[derive(Debug, Clone, PartialEq)]
pub enum Request {
    /// `{"info": true}`: what the service drives.
    Info,
    /// `{"weights": [...]}`: one lap with these policy weights, as many as the dimension, each
    /// a finite number.
    Lap {
        /// The policy weights.
        weights: Vec<f64>,
    },
}

/// What was wrong with a request line; the text of an error reply.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RequestError {
    /// Over the cap: read to its end and dropped, never held whole.
    #[error("longer than {cap} bytes (the cap on a request line); skipped")]
    TooLong {
        /// The cap, [`MAX_LINE_BYTES`] in the service.
        cap: usize,
    },
    /// Bytes that are not UTF-8.
    #[error("not UTF-8 text: {0}")]
    NotUtf8(String),
    /// Text that is not JSON (NaN, `1e999` and a cut line land here).
    #[error("not JSON: {0}")]
    NotJson(String),
    /// JSON, but neither request.
    #[error(r#"expected {{"weights": [...]}} or {{"info": true}}"#)]
    Unknown,
    /// A weight that is not a number.
    #[error("weight {index} is not a number: {value}")]
    NotANumber {
        /// Its 0-based index.
        index: usize,
        /// The JSON value given, cut to 80 characters.
        value: String,
    },
    /// A wrong number of weights.
    #[error("expected {expected} weights, got {got}")]
    Dimension {
        /// The policy's dimension.
        expected: usize,
        /// The number given.
        got: usize,
    },
}

impl Request {
    /// Parses one request line (without its newline) for a policy of `dim` weights; `None`
    /// for a blank line.
    pub fn parse(line: &[u8], dim: usize) -> Result<Option<Request>, RequestError> {
        let text = std::str::from_utf8(line).map_err(|e| RequestError::NotUtf8(e.to_string()))?;
        if text.trim().is_empty() {
            return Ok(None);
        }
        let v: Value =
            serde_json::from_str(text).map_err(|e| RequestError::NotJson(e.to_string()))?;
        if v.get("info").and_then(Value::as_bool) == Some(true) {
            return Ok(Some(Request::Info));
        }
        let Some(ws) = v.get("weights").and_then(Value::as_array) else {
            return Err(RequestError::Unknown);
        };
        let weights = ws
            .iter()
            .enumerate()
            .map(|(index, w)| {
                // serde_json holds only finite numbers, so every f64 here is finite.
                w.as_f64().ok_or_else(|| RequestError::NotANumber {
                    index,
                    value: w.to_string().chars().take(80).collect(),
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        if weights.len() != dim {
            return Err(RequestError::Dimension {
                expected: dim,
                got: weights.len(),
            });
        }
        Ok(Some(Request::Lap { weights }))
    }
}

/// The answer to `{"info": true}`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Info {
    /// The number of policy weights.
    pub dim: usize,
    /// The initial policy's weights (the demonstration's fit).
    pub w0: Vec<f64>,
    /// The search box's lower corner.
    pub lower: Vec<f64>,
    /// The search box's upper corner.
    pub upper: Vec<f64>,
    /// The policy kernels' length-scale.
    pub lengthscale: f64,
    /// The track's name.
    pub track: String,
    /// The track's length (m).
    pub length_m: f64,
    /// The quasi-steady-state limit's reward (m/s), the best any policy can do.
    pub limit_reward_mps: f64,
    /// With a learned line: its kernels M_d, the last M_d weights (after the pedal's), and
    /// their length-scale; absent: the weights are the pedal's.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub line: Option<crate::policy::Block>,
    /// The line the car holds, from which a learned line's offsets are measured; absent: the
    /// centre line.
    #[serde(skip_serializing_if = "crate::line::BaseLine::is_centre")]
    pub base_line: crate::line::BaseLine,
}

/// Where and why a lap failed, as replied.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FailureReply {
    /// Why (`off_track`, `stalled`, ...), or `failed` when the evaluator did not say.
    pub reason: String,
    /// The lap fraction where it failed, when known.
    pub x: Option<f64>,
    /// The distance from the start where it failed (m): `x` times the track's length.
    pub distance_m: Option<f64>,
}

/// One reply line.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Reply {
    /// The answer to `{"info": true}`.
    Info(Info),
    /// A lap: its reward (length / time, 0 for a failed lap), its time when it completed, and
    /// where it failed otherwise.
    Lap {
        /// The reward (m/s).
        reward_mps: f64,
        /// The lap time (s) of a completed lap.
        lap_time_s: Option<f64>,
        /// Where and why a failed lap failed.
        failure: Option<FailureReply>,
    },
    /// A request that could not be answered: `line N: what was wrong`.
    Error {
        /// The message.
        error: String,
    },
}

/// A line as [`LineReader`] read it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Line<'a> {
    /// A whole line, without its newline.
    Complete(&'a [u8]),
    /// A line over the cap, read to its end and dropped.
    TooLong,
}

/// Reads lines as bytes, never holding more than a cap of any line.
#[derive(Debug)]
pub struct LineReader<R> {
    input: R,
    cap: usize,
    buffer: Vec<u8>,
}

impl<R: BufRead> LineReader<R> {
    /// A reader with the service's cap, [`MAX_LINE_BYTES`].
    pub fn new(input: R) -> Self {
        Self::with_cap(input, MAX_LINE_BYTES)
    }

    /// A reader with another cap (bytes, at least 1).
    pub fn with_cap(input: R, cap: usize) -> Self {
        LineReader {
            input,
            cap: cap.max(1),
            buffer: Vec::new(),
        }
    }

    /// The next line; `None` at the end of the input.
    pub fn next_line(&mut self) -> std::io::Result<Option<Line<'_>>> {
        let limit = self.cap as u64 + 1;
        self.buffer.clear();
        let n = (&mut self.input)
            .take(limit)
            .read_until(b'\n', &mut self.buffer)?;
        if n == 0 {
            return Ok(None);
        }
        if self.buffer.last() == Some(&b'\n') {
            self.buffer.pop();
            return Ok(Some(Line::Complete(&self.buffer)));
        }
        if self.buffer.len() <= self.cap {
            return Ok(Some(Line::Complete(&self.buffer))); // The last line, without a newline.
        }
        // Drop the rest of the over-long line, a cap at a time.
        loop {
            self.buffer.clear();
            let n = (&mut self.input)
                .take(limit)
                .read_until(b'\n', &mut self.buffer)?;
            if n == 0 || self.buffer.last() == Some(&b'\n') {
                self.buffer.clear();
                return Ok(Some(Line::TooLong));
            }
        }
    }
}

/// The service: answers requests with laps of an [`Evaluator`].
#[derive(Debug)]
pub struct Server<E> {
    /// What `{"info": true}` answers.
    pub info: Info,
    /// The source of laps.
    pub evaluator: E,
}

impl<E: Evaluator> Server<E> {
    /// The reply to line number `k` (1-based), `None` for a blank line.
    pub fn answer(&mut self, k: u64, line: Line<'_>) -> Option<Reply> {
        let request = match line {
            Line::TooLong => Err(RequestError::TooLong {
                cap: MAX_LINE_BYTES,
            }),
            Line::Complete(bytes) => Request::parse(bytes, self.info.dim),
        };
        let reply = match request {
            Ok(None) => return None,
            Ok(Some(Request::Info)) => Ok(Reply::Info(self.info.clone())),
            Ok(Some(Request::Lap { weights })) => self.lap(k, &weights),
            Err(e) => Err(e.to_string()),
        };
        Some(reply.unwrap_or_else(|e| Reply::Error {
            error: format!("line {k}: {e}"),
        }))
    }

    /// One lap with `weights`, as replied; the evaluator's trial number is the request's line
    /// number `k`.
    fn lap(&mut self, k: u64, weights: &[f64]) -> Result<Reply, String> {
        let trial = i64::try_from(k).unwrap_or(i64::MAX);
        let outcome = self
            .evaluator
            .evaluate(trial, weights)
            .map_err(|e| e.to_string())?;
        let reward_mps = outcome.reward().map_err(|e| e.to_string())?;
        Ok(match outcome {
            Outcome::Lap { time_s, .. } => Reply::Lap {
                reward_mps,
                lap_time_s: Some(time_s),
                failure: None,
            },
            Outcome::Reward(_) => Reply::Lap {
                reward_mps,
                lap_time_s: None,
                failure: None,
            },
            Outcome::Failed { at, reason } => Reply::Lap {
                reward_mps,
                lap_time_s: None,
                failure: Some(FailureReply {
                    reason: reason.unwrap_or_else(|| "failed".into()),
                    x: at,
                    distance_m: at.map(|x| x * self.info.length_m),
                }),
            },
        })
    }

    /// Answers every line of `input` on `output`, one reply line each, until the input ends or
    /// the client hangs up (a write fails).
    pub fn serve(&mut self, input: impl BufRead, mut output: impl Write) -> std::io::Result<()> {
        let mut lines = LineReader::new(input);
        let mut k = 0;
        while let Some(line) = lines.next_line()? {
            k += 1;
            let Some(reply) = self.answer(k, line) else {
                continue;
            };
            let text = serde_json::to_string(&reply).map_err(std::io::Error::other)?;
            if writeln!(output, "{text}")
                .and_then(|_| output.flush())
                .is_err()
            {
                break; // The client hung up.
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Result;

    /// A lap source that completes a lap when the first weight is positive and fails at half
    /// the lap otherwise.
    struct Sign;

    impl Evaluator for Sign {
        fn evaluate(&mut self, _trial: i64, weights: &[f64]) -> Result<Outcome> {
            Ok(if weights[0] > 0.0 {
                Outcome::Lap {
                    time_s: 50.0,
                    length_m: 1000.0,
                }
            } else {
                Outcome::Failed {
                    at: Some(0.5),
                    reason: Some("off_track".into()),
                }
            })
        }
    }

    fn server() -> Server<Sign> {
        Server {
            info: Info {
                dim: 2,
                w0: vec![0.1, 0.2],
                lower: vec![-1.0; 2],
                upper: vec![1.0; 2],
                lengthscale: 0.5,
                track: "test".into(),
                length_m: 1000.0,
                limit_reward_mps: 40.0,
                line: None,
                base_line: Default::default(),
            },
            evaluator: Sign,
        }
    }

    fn replies(input: &[u8]) -> Vec<Value> {
        let mut out = Vec::new();
        server().serve(input, &mut out).unwrap();
        String::from_utf8(out)
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect()
    }

    #[test]
    fn requests_are_typed_and_bad_ones_say_what_was_wrong() {
        let parse = |s: &[u8]| Request::parse(s, 3);
        assert_eq!(parse(b"  "), Ok(None));
        assert_eq!(parse(br#"{"info": true}"#), Ok(Some(Request::Info)));
        assert_eq!(
            parse(br#"{"weights": [1, -2.5, 3e-3]}"#),
            Ok(Some(Request::Lap {
                weights: vec![1.0, -2.5, 3e-3]
            }))
        );
        assert!(matches!(parse(b"\xff{}"), Err(RequestError::NotUtf8(_))));
        for not_json in [
            &b"{"[..],
            b"[NaN]",
            br#"{"weights": [NaN, 1, 2]}"#,
            b"[1e999]",
        ] {
            assert!(matches!(parse(not_json), Err(RequestError::NotJson(_))));
        }
        for unknown in [&b"[]"[..], br#"{"info": false}"#, br#"{"weights": "fast"}"#] {
            assert_eq!(parse(unknown), Err(RequestError::Unknown));
        }
        assert_eq!(
            parse(br#"{"weights": [1, "x", 3]}"#),
            Err(RequestError::NotANumber {
                index: 1,
                value: "\"x\"".into()
            })
        );
        assert_eq!(
            parse(br#"{"weights": [1, 2]}"#),
            Err(RequestError::Dimension {
                expected: 3,
                got: 2
            })
        );
    }

    #[test]
    fn the_line_reader_holds_at_most_its_cap() {
        let mut r = LineReader::with_cap(&b"abc\n0123456789\n\nxy"[..], 5);
        assert_eq!(r.next_line().unwrap(), Some(Line::Complete(b"abc")));
        assert_eq!(r.next_line().unwrap(), Some(Line::TooLong));
        assert!(r.buffer.capacity() <= 64);
        assert_eq!(r.next_line().unwrap(), Some(Line::Complete(b"")));
        assert_eq!(r.next_line().unwrap(), Some(Line::Complete(b"xy")));
        assert_eq!(r.next_line().unwrap(), None);
        // A line of exactly the cap is whole; one byte more is too long, even at the end.
        let mut r = LineReader::with_cap(&b"12345\n123456"[..], 5);
        assert_eq!(r.next_line().unwrap(), Some(Line::Complete(b"12345")));
        assert_eq!(r.next_line().unwrap(), Some(Line::TooLong));
        assert_eq!(r.next_line().unwrap(), None);
    }

    /// Each line gets one reply numbered by its line, errors do not stop the service, blank
    /// lines get none, and laps are the evaluator's outcomes.
    #[test]
    fn the_server_answers_every_line_and_keeps_going() {
        let r = replies(
            b"{\"weights\": [1, 0]}\n\xfe\n\n{\"weights\": [-1, 0]}\n{\"weights\": [1]}\n{\"info\": true}",
        );
        assert_eq!(r.len(), 5);
        assert_eq!(
            r[0],
            serde_json::json!({"reward_mps": 20.0, "lap_time_s": 50.0, "failure": null})
        );
        assert!(
            r[1]["error"]
                .as_str()
                .unwrap()
                .starts_with("line 2: not UTF-8")
        );
        assert_eq!(
            r[2],
            serde_json::json!({"reward_mps": 0.0, "lap_time_s": null,
                "failure": {"reason": "off_track", "x": 0.5, "distance_m": 500.0}})
        );
        assert_eq!(r[3]["error"], "line 5: expected 2 weights, got 1");
        assert_eq!(r[4]["dim"], 2);
        assert_eq!(r[4]["track"], "test");
    }
}
