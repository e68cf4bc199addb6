//! Deterministic mutation testing of the readers (the CI-sized cousin of the fuzz targets in
//! `fuzz/`): truncations, byte flips and deleted lines of real files give errors, never panics.

mod common;

use cdbo::params::Params;
use cdbo::track::Ends;
use common::shared;

/// A small deterministic generator (SplitMix64), so that failures reproduce.
struct Mix(u64);

impl Mix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

fn mutants(text: &str, count: usize, seed: u64) -> Vec<String> {
    let mut rng = Mix(seed);
    let bytes = text.as_bytes();
    let lines: Vec<&str> = text.lines().collect();
    (0..count)
        .map(|i| match i % 3 {
            0 => String::from_utf8_lossy(&bytes[..rng.below(bytes.len())]).into_owned(),
            1 => {
                let mut b = bytes.to_vec();
                for _ in 0..4 {
                    let k = rng.below(b.len());
                    b[k] = b"<>\"/=0.-9aZ& \n"[rng.below(14)];
                }
                String::from_utf8_lossy(&b).into_owned()
            }
            _ => {
                let skip = rng.below(lines.len());
                lines
                    .iter()
                    .enumerate()
                    .filter(|(k, _)| *k != skip)
                    .map(|(_, l)| *l)
                    .collect::<Vec<_>>()
                    .join("\n")
            }
        })
        .collect()
}

#[test]
fn mutated_track_files_never_panic() {
    let text = std::fs::read_to_string(shared("torcs/tracks/road/aalborg/aalborg.xml")).unwrap();
    let mut errors = 0;
    for m in mutants(&text, 300, 1) {
        match Params::parse(&m, "mutant.xml", None)
            .and_then(|p| cdbo::track::torcs::from_params(&p, "mutant.xml", Ends::MustMeet))
        {
            Ok(t) => assert!(t.length.is_finite() && t.length > 0.0 && t.closure.is_closed()),
            Err(e) => {
                errors += 1;
                assert!(e.to_string().starts_with("mutant.xml"), "{e}");
            }
        }
    }
    assert!(
        errors > 50,
        "mutations should mostly be caught, got {errors}"
    );
}

#[test]
fn mutated_car_files_never_panic() {
    let text = std::fs::read_to_string(shared(
        "speed-dreams/cars/models/sc-spirit-300/sc-spirit-300.xml",
    ))
    .unwrap();
    for m in mutants(&text, 300, 2) {
        if let Ok(car) =
            Params::parse(&m, "mutant.xml", None).and_then(|p| cdbo::car::torcs::from_params(&p))
        {
            assert!(car.mass > 0.0 && !car.gears.is_empty());
        }
    }
}

#[test]
fn mutated_centre_lines_never_panic() {
    let text = std::fs::read_to_string(shared("tracks/csv/Monza.csv")).unwrap();
    for m in mutants(&text, 150, 3) {
        if let Ok(t) = cdbo::track::csv::parse(&m, "mutant", "mutant.csv") {
            assert!(t.length.is_finite() && t.length > 0.0);
        }
    }
}
