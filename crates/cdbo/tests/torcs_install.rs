//! Every track and car of a TORCS install loads, and each track's length is the game's own.
//!
//! Walks Debian's `torcs-data` (1.3.7) at `/usr/share/games/torcs` (or `$CDBO_TORCS_DATA`)
//! when it is installed; skips with a message otherwise. The reference lengths are TORCS's
//! own: `tTrack::length` after the game's `trkBuild`, printed by a ten-line C++ program that
//! loads `/usr/lib/x86_64-linux-gnu/torcs/modules/track/track.so` (see docs/tracks.md).

use std::path::{Path, PathBuf};

use cdbo::track::{Ends, torcs};

/// (category/name, TORCS 1.3.7's `track->length` in m) for every track of `torcs-data`.
const TORCS_LENGTHS: &[(&str, f64)] = &[
    ("dirt/dirt-1", 1072.9326),
    ("dirt/dirt-2", 1760.9418),
    ("dirt/dirt-3", 2205.9348),
    ("dirt/dirt-4", 3260.4250),
    ("dirt/dirt-5", 1072.9324),
    ("dirt/dirt-6", 3147.4573),
    ("dirt/mixed-1", 1014.2181),
    ("dirt/mixed-2", 1412.8975),
    ("oval/a-speedway", 1908.3207),
    ("oval/b-speedway", 3999.1174),
    ("oval/c-speedway", 3294.3982),
    ("oval/d-speedway", 3427.4329),
    ("oval/e-speedway", 4103.8398),
    ("oval/e-track-5", 1621.7319),
    ("oval/f-speedway", 3703.8345),
    ("oval/g-speedway", 2977.5964),
    ("oval/michigan", 2311.7903),
    ("road/aalborg", 2587.5435),
    ("road/alpine-1", 6355.6514),
    ("road/alpine-2", 3773.5750),
    ("road/brondehach", 3919.3140),
    ("road/corkscrew", 3608.4463),
    ("road/e-track-1", 3243.6440),
    ("road/e-track-2", 5380.5024),
    ("road/e-track-3", 4208.3657),
    ("road/e-track-4", 7041.6816),
    ("road/e-track-6", 4441.2891),
    ("road/eroad", 3260.4260),
    ("road/forza", 5784.0972),
    ("road/g-track-1", 2057.5593),
    ("road/g-track-2", 3185.8325),
    ("road/g-track-3", 2843.0955),
    ("road/ole-road-1", 6282.8091),
    ("road/ruudskogen", 3274.2031),
    ("road/spring", 22129.7656),
    ("road/street-1", 3823.0505),
    ("road/wheel-1", 4328.5400),
    ("road/wheel-2", 6205.4629),
];

/// How far our length may be from the game's (m).
const TOLERANCE_M: f64 = 0.5;

/// The 17 cars of `torcs-data` 1.3.7.
const TORCS_CARS: &[&str] = &[
    "155-DTM",
    "acura-nsx-sz",
    "baja-bug",
    "buggy",
    "car1-ow1",
    "car1-stock1",
    "car1-stock2",
    "car1-trb1",
    "car1-trb3",
    "car2-trb1",
    "car3-trb1",
    "car4-trb1",
    "car5-trb1",
    "car6-trb1",
    "car7-trb1",
    "car8-trb1",
    "p406",
];

fn install() -> Option<PathBuf> {
    let dir = std::env::var_os("CDBO_TORCS_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("/usr/share/games/torcs"));
    if dir.join("tracks").is_dir() {
        Some(dir)
    } else {
        eprintln!(
            "skipped: no TORCS install at {} (apt-get install torcs-data, or set CDBO_TORCS_DATA)",
            dir.display()
        );
        None
    }
}

fn subdirs(dir: &Path) -> Vec<PathBuf> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort();
    dirs
}

#[test]
fn every_track_of_the_install_loads_at_the_games_length() {
    let Some(root) = install() else { return };
    let mut failures = Vec::new();
    let (mut loaded, mut worst) = (0, (0.0_f64, String::new()));
    for category in subdirs(&root.join("tracks")) {
        for dir in subdirs(&category) {
            let name = dir.file_name().unwrap().to_string_lossy().into_owned();
            let key = format!("{}/{name}", category.file_name().unwrap().to_string_lossy());
            let file = dir.join(format!("{name}.xml"));
            let track = match torcs::read(&file, Ends::MustMeet) {
                Ok(t) => t,
                Err(e) => {
                    failures.push(format!("{key}: {e}"));
                    continue;
                }
            };
            loaded += 1;
            match TORCS_LENGTHS.iter().find(|(k, _)| *k == key) {
                Some((_, want)) => {
                    let diff = (track.length - want).abs();
                    if diff > worst.0 {
                        worst = (diff, key.clone());
                    }
                    if diff > TOLERANCE_M {
                        failures.push(format!("{key}: {} m, TORCS {want} m", track.length));
                    }
                }
                None => eprintln!("{key}: {:.2} m (no reference length)", track.length),
            }
        }
    }
    eprintln!(
        "{loaded} tracks loaded; largest difference from TORCS {:.4} m ({})",
        worst.0, worst.1
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    // Debian's torcs-data has them all; a partial install still checks what it has.
    if root == Path::new("/usr/share/games/torcs") {
        assert_eq!(loaded, TORCS_LENGTHS.len());
    }
}

#[test]
fn every_car_of_the_install_loads() {
    let Some(root) = install() else { return };
    let mut loaded = Vec::new();
    let mut failures = Vec::new();
    for dir in subdirs(&root.join("cars")) {
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        match cdbo::car::torcs::read(&dir.join(format!("{name}.xml")), None) {
            Ok(car) => {
                assert!(car.mass > 0.0 && !car.gears.is_empty(), "{name}");
                loaded.push(name);
            }
            Err(e) => failures.push(format!("{name}: {e}")),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    if root == Path::new("/usr/share/games/torcs") {
        assert_eq!(loaded, TORCS_CARS);
    }
}
