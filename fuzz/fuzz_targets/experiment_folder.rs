//! Any bytes found in an experiment folder (`cdbo report DIR`): a run record `runs/ID.json`
//! (then summarised as the report does) or the session log `sessions.jsonl`. An error or
//! a value, never a panic.
#![no_main]

use cdbo::experiment::folder::Session;
use cdbo::experiment::record::RunRecord;
use cdbo::experiment::summary;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&which, rest)) = data.split_first() else {
        return;
    };
    let Ok(text) = std::str::from_utf8(rest) else {
        return;
    };
    if which % 2 == 0 {
        let _ = Session::parse_log(text, "sessions.jsonl");
    } else if let Ok(record) = RunRecord::parse(text, "runs/fuzz.json") {
        let records = [record];
        let _ = summary::curves(&records);
        let _ = summary::times(&records);
        let _ = summary::claims(&records);
        let _ = summary::cell_means(&records, |r| r.best_reward_mps);
    }
});
