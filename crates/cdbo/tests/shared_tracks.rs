//! The paper's real tracks, read from ../shared (the TORCS / Speed Dreams data, never copied).

use std::path::PathBuf;

use cdbo::track::{Track, torcs};

/// `../shared` beside the repository root.
pub fn shared(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared")
        .join(rel)
}

fn load(rel: &str) -> Track {
    let t = torcs::read(&shared(rel)).unwrap_or_else(|e| panic!("{e}"));
    // The shared subset lacks objects.xml: that entity is skipped with a warning; every
    // surface must still be found.
    assert!(
        t.warnings.iter().all(|w| !w.contains("surface")),
        "{:?}",
        t.warnings
    );
    t
}

fn assert_closed(t: &Track) {
    assert!(
        t.closure.gap_m < 2.0,
        "{}: gap {} m",
        t.name,
        t.closure.gap_m
    );
    assert!(
        t.closure.heading_deg.abs() < 1.0,
        "{}: heading {}°",
        t.name,
        t.closure.heading_deg
    );
}

#[test]
fn forza_has_the_papers_length_and_width() {
    let t = load("torcs/tracks/road/forza/forza.xml");
    assert!((t.length - 5784.1).abs() < 0.5, "length {}", t.length);
    assert_eq!(t.samples[0].width, 11.0);
    assert_eq!(t.name, "Forza");
    assert_closed(&t);
}

#[test]
fn allondaz_has_the_papers_length_and_width() {
    let t = load("speed-dreams/tracks/road/allondaz/allondaz.xml");
    assert!((t.length - 6355.6).abs() < 0.5, "length {}", t.length);
    assert_eq!(t.samples[0].width, 12.0);
    assert_closed(&t);
}

#[test]
fn e_track_2_and_aalborg_match_torcs() {
    let t = load("torcs/tracks/road/e-track-2/e-track-2.xml");
    assert!((t.length - 5380.5).abs() < 0.5, "length {}", t.length);
    assert_closed(&t);
    let t = load("torcs/tracks/road/aalborg/aalborg.xml");
    assert!((t.length - 2587.5).abs() < 0.5, "length {}", t.length);
    assert_eq!(t.samples[0].width, 10.0);
    assert_closed(&t);
}
