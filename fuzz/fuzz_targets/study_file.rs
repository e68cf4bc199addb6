//! Any bytes given as a study file: an error or a study whose history can be read.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = std::env::temp_dir().join(format!("cdbo-fuzz-study-{}.db", std::process::id()));
    if std::fs::write(&path, data).is_ok()
        && let Ok(study) = cdbo::study::Study::open(&path)
    {
        let _ = study.history();
        let _ = study.best();
        let _ = study.told();
    }
    let _ = std::fs::remove_file(&path);
});
