//! Built-in circuits, embedded in the binary so that every command works with no data files.
//!
//! They are written in the TORCS track format and read by [`super::torcs`], like real tracks,
//! but they are open circuits: no barrier stands past their edges ([`super::Verge::barrier`];
//! the game would put one at the edge of a road without sides), so a lap there leaves the road
//! only by the off-track rule.

use super::Track;
use crate::error::{Error, Result};
use crate::params::Params;

/// The default track of every command.
pub const DEFAULT: &str = "ridgeway";

/// (name, TORCS XML) of every built-in track.
const TRACKS: &[(&str, &str)] = &[("ridgeway", include_str!("builtin/ridgeway.xml"))];

/// The names of the built-in tracks.
pub fn names() -> impl Iterator<Item = &'static str> {
    TRACKS.iter().map(|(name, _)| *name)
}

/// Loads a built-in track, or `None` if no built-in track has this name.
pub fn load(name: &str) -> Option<Result<Track>> {
    let (name, xml) = TRACKS.iter().find(|(n, _)| *n == name)?;
    let source = format!("builtin:{name}");
    Some(
        Params::parse(xml, &source, None)
            .and_then(|p| super::torcs::from_params(&p, &source, super::Ends::MustMeet))
            .map(without_barriers),
    )
}

/// The track with every barrier taken away.
fn without_barriers(track: Track) -> Track {
    let mut samples = track.samples;
    for verge in samples.iter_mut().flat_map(|s| s.verges.iter_mut()) {
        verge.barrier = false;
    }
    Track::new(
        &track.name,
        &track.source,
        track.length,
        track.closure,
        samples,
        track.warnings,
    )
}

impl Track {
    /// The built-in track `name` ([`names`]), or an error naming the built-in tracks.
    pub fn builtin(name: &str) -> Result<Track> {
        load(name).unwrap_or_else(|| {
            Err(Error::NotFound {
                what: "built-in track",
                name: format!("{name:?}"),
                detail: format!("built in: {}", names().collect::<Vec<_>>().join(", ")),
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unknown_builtin_names_the_builtins() {
        let e = Track::builtin("monaco").unwrap_err().to_string();
        assert!(e.contains("\"monaco\"") && e.contains("ridgeway"), "{e}");
    }

    #[test]
    fn a_builtin_track_has_no_barrier() {
        for name in names() {
            let t = load(name).unwrap().unwrap();
            assert!((0..t.len()).all(|i| t.frame(i).barriers == [f64::INFINITY; 2]));
        }
    }

    #[test]
    fn every_builtin_track_is_a_closed_circuit_of_3_to_6_km() {
        for name in names() {
            let t = load(name).unwrap().unwrap();
            assert!(
                (3000.0..6000.0).contains(&t.length),
                "{name}: {} m",
                t.length
            );
            assert!(
                t.closure.gap_m < 0.01 && t.closure.heading_deg.abs() < 0.01,
                "{name}: {:?}",
                t.closure
            );
            assert!(t.warnings.is_empty(), "{:?}", t.warnings);
            let (lo, hi) = t.z_range();
            assert!(
                hi - lo > 10.0,
                "{name}: needs some elevation, has {} m",
                hi - lo
            );
            assert!(
                t.min_radius() < 60.0 && t.min_radius() > 30.0,
                "{name}: slow corner {}",
                t.min_radius()
            );
        }
        assert!(load("nope").is_none());
    }
}
