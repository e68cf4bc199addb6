//! Scratch folders for the unit tests, where the integration tests keep theirs: cargo's
//! `target/tmp` (which cargo names only to integration tests, as `CARGO_TARGET_TMPDIR`), not
//! the system's temporary folder.

use std::path::PathBuf;

/// An empty folder of its own for unit test `name`, made afresh (a run's folder is removed by
/// the next run of the test): `target/tmp/cdbo-unit-NAME`, the target folder being the one
/// above the test binary that holds cargo's `CACHEDIR.TAG`; under the system's temporary
/// folder where none does.
pub(crate) fn dir(name: &str) -> PathBuf {
    let exe = std::env::current_exe().unwrap_or_default();
    let target = exe
        .ancestors()
        .find(|d| d.join("CACHEDIR.TAG").is_file())
        .map_or_else(std::env::temp_dir, |d| d.join("tmp"));
    let dir = target.join(format!("cdbo-unit-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn scratch_folders_are_empty_and_under_the_target_folder() {
    let d = dir("scratch");
    std::fs::write(d.join("x"), "1").unwrap();
    let again = dir("scratch");
    assert_eq!(again, d);
    assert_eq!(std::fs::read_dir(&again).unwrap().count(), 0);
    assert!(
        again.ancestors().any(|a| a.join("CACHEDIR.TAG").is_file()),
        "{}",
        again.display()
    );
}
