//! Any bytes sent to `cdbo serve-sim`: every non-blank line gets exactly one JSON reply, a lap
//! only for a request of the right number of finite weights, never a panic; a line reader
//! with a small cap never holds more than its cap.
#![no_main]

use cdbo::evaluator::{Evaluator, Outcome};
use cdbo::serve::{Info, Line, LineReader, Request, Server};
use libfuzzer_sys::fuzz_target;

const DIM: usize = 3;

/// A lap source that checks what it is given: the reward is the weights' sum.
struct Checked;

impl Evaluator for Checked {
    fn evaluate(&mut self, _trial: i64, weights: &[f64]) -> cdbo::Result<Outcome> {
        assert_eq!(weights.len(), DIM);
        assert!(weights.iter().all(|w| w.is_finite()));
        Ok(Outcome::Reward(weights.iter().sum::<f64>().clamp(-1e300, 1e300)))
    }
}

fuzz_target!(|data: &[u8]| {
    // A small cap: lines over it are dropped whole, the others come back intact.
    let mut lines = LineReader::with_cap(data, 64);
    let mut read = Vec::new();
    while let Some(line) = lines.next_line().unwrap() {
        match line {
            Line::TooLong => read.push(None),
            Line::Complete(bytes) => {
                assert!(bytes.len() <= 64 && !bytes.contains(&b'\n'));
                read.push(Some(bytes.to_vec()));
            }
        }
    }
    let whole: Vec<&[u8]> = data.strip_suffix(b"\n").unwrap_or(data).split(|&b| b == b'\n').collect();
    if !data.is_empty() {
        assert_eq!(read.len(), whole.len());
        for (r, w) in read.iter().zip(&whole) {
            match r {
                Some(bytes) => assert_eq!(bytes.as_slice(), *w),
                None => assert!(w.len() > 64),
            }
        }
    }
    // The service (its cap is far above any input here) answers each non-blank line once.
    let mut expected = 0;
    for line in whole.iter().filter(|_| !data.is_empty()) {
        match Request::parse(line, DIM) {
            Ok(Some(Request::Lap { weights })) => {
                assert_eq!(weights.len(), DIM);
                assert!(weights.iter().all(|w| w.is_finite()));
                expected += 1;
            }
            Ok(Some(Request::Info)) | Err(_) => expected += 1,
            Ok(None) => {}
        }
    }
    let info = Info {
        dim: DIM,
        w0: vec![0.0; DIM],
        lower: vec![-1.0; DIM],
        upper: vec![1.0; DIM],
        lengthscale: 0.5,
        track: "fuzz".into(),
        length_m: 1000.0,
        limit_reward_mps: 40.0,
        line: None,
        base_line: Default::default(),
    };
    let mut out = Vec::new();
    Server { info, evaluator: Checked }.serve(data, &mut out).unwrap();
    let replies: Vec<&str> = std::str::from_utf8(&out).unwrap().split_terminator('\n').collect();
    assert_eq!(replies.len(), expected);
    for reply in replies {
        let v: serde_json::Value = serde_json::from_str(reply).unwrap();
        assert!(v.is_object());
    }
});
