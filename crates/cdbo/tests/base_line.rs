//! A race on the minimum-curvature line (`BaseLine::MinCurvature`): the line within the road,
//! the demonstration driving it, races on it deterministic.

use cdbo::car::Car;
use cdbo::experiment::race::{BaseLine, RaceConfig, race};
use cdbo::line::SAFETY_MARGIN;
use cdbo::method::Method;
use cdbo::track::Track;
use cdbo::venue::Venue;

fn ridgeway() -> (Track, Car) {
    let track = cdbo::track::builtin::load("ridgeway").unwrap().unwrap();
    (track, Car::spirit_300())
}

/// The base line lies within the edge laps are learned by (on Ridgeway, which gives no verges,
/// a metre inside the road's) less half the car's width and the safety margin at every
/// station, |d₀(s)| ≤ w(s)/2 − 1 m − w_car/2 − 0.5 m, and is no centre line (it uses the
/// road); the tracker's demonstration on it holds it: its offsets follow d₀(s).
#[test]
fn the_min_curvature_start_line_lies_within_the_road() {
    let (track, car) = ridgeway();
    let line = BaseLine::MinCurvature.line(&track, &car).unwrap().unwrap();
    assert!(BaseLine::Centre.line(&track, &car).unwrap().is_none());
    for (&s, &d) in line.stations.iter().zip(&line.offsets) {
        let room = track.frame(track.index_at(s)).half_width - 0.5 * car.width - SAFETY_MARGIN
            + cdbo::sim::lap::LEARNING_OFF_TRACK_MARGIN;
        assert!(
            d.abs() <= room + 1e-6,
            "d₀({s:.0} m) = {d:.3} m, room {room:.3} m"
        );
    }
    assert!(line.max_offset() > 2.0, "{}", line.max_offset());
    let steering = cdbo::drive::steering::Steering::Tracker(Default::default());
    let venue = Venue::simulator(track.clone(), &car)
        .steered(steering)
        .on_line(line.clone());
    let (demo, _) = venue.demonstrate(15.0).unwrap();
    assert!(demo.completed);
    let n = demo.trace.len() as f64;
    let rms = (demo
        .trace
        .iter()
        .map(|p| (p.lateral - line.offset_at(p.distance_m)).powi(2))
        .sum::<f64>()
        / n)
        .sqrt();
    assert!(
        rms < 0.3,
        "the demonstration is {rms:.3} m (RMS) off the line"
    );
}

/// A race on the fixed line and one learning a line from it: each twice, the same laps bit
/// for bit; the learned line starts at d = 0 (the base line itself) and the outcome names the
/// line.
#[test]
fn a_race_on_the_min_curvature_line_is_deterministic() {
    let (track, car) = ridgeway();
    let venue = Venue::simulator(track.clone(), &car);
    for line_kernels in [None, Some(8)] {
        let config = RaceConfig {
            method: Method::PatternSearch,
            kernels: 12,
            laps: 12,
            line_kernels,
            base_line: BaseLine::MinCurvature,
            ..RaceConfig::default()
        };
        let a = race(&venue, &track, &car, &config, |_| {}).unwrap();
        let b = race(&venue, &track, &car, &config, |_| {}).unwrap();
        assert!(a.line.is_some());
        assert_eq!(a.best_reward_mps, b.best_reward_mps);
        assert_eq!(a.best, b.best);
        let rewards = |o: &cdbo::experiment::race::RaceOutcome| {
            o.laps.iter().map(|l| l.reward_mps).collect::<Vec<_>>()
        };
        assert_eq!(rewards(&a), rewards(&b));
        assert!(a.best_reward_mps > 0.0);
        if let Some(m) = line_kernels {
            assert_eq!(a.initial.line.as_ref().unwrap().weights, vec![0.0; m]);
        }
    }
}

/// The ceiling on the line: its limit read at the centre line's stations keeps the line's lap
/// time and reward, one speed per centre-line sample, none above the line's own fastest; the
/// tracker holding the line tracks most of that profile (k = 0.984 on Ridgeway, a lap of
/// 89 % of the line's limit) and beats its tracked lap on the centre line (k = 0.965).
#[test]
fn the_line_limit_read_on_the_centre_line_is_tracked() {
    let (track, car) = ridgeway();
    let line = BaseLine::MinCurvature.line(&track, &car).unwrap().unwrap();
    let along = cdbo::limit::line_limit(&track, &line, &car).limit;
    let limit = cdbo::limit::line_limit_on_centre(&track, &line, &car);
    assert_eq!(limit.lap_time_s, along.lap_time_s);
    assert_eq!(limit.reward_mps, along.reward_mps);
    assert_eq!(limit.speed.len(), track.len() + 1);
    let fastest = along.speed.iter().copied().fold(0.0, f64::max);
    assert!(limit.speed.iter().all(|&v| (0.0..=fastest).contains(&v)));
    let mut sim = cdbo::sim::Simulator::new(track.clone(), &car);
    sim.config.steering = cdbo::drive::steering::Steering::Tracker(Default::default());
    sim.config.line = Some(line);
    let (k, reward) = cdbo::ceiling::tracked_profile(&sim, &limit).unwrap();
    assert!(
        k > 0.95 && reward > 0.85 * limit.reward_mps,
        "k {k}, {reward} m/s"
    );
    sim.config.line = None;
    let centre = cdbo::limit::limit_lap(&track, &car);
    let (_, on_centre) = cdbo::ceiling::tracked_profile(&sim, &centre).unwrap();
    assert!(
        reward > on_centre,
        "{reward} m/s, centre line {on_centre} m/s"
    );
}

/// The line a policy holds, as drawn ([`cdbo::sim::Simulator::held_line`]: `plot track
/// --policy`, the race's map, the dashboard): a line far wider than the road (±30 m) is drawn
/// within the road less half the car's width at every sample, on the centre line and from the
/// minimum-curvature line, each point |d| from the centre line along its normal; where the
/// bound does not bite, the offset is d₀(s) + d(s/L) exactly.
#[test]
fn a_learned_line_drawn_never_leaves_the_road_less_the_margin() {
    use cdbo::policy::{Policy, RkhsPolicy};
    let (track, car) = ridgeway();
    let wide = Policy {
        pedal: RkhsPolicy::new(vec![0.5; 6], 0.2).unwrap(),
        line: Some(
            RkhsPolicy::new(
                vec![30.0, -30.0, 4.0, -30.0, 30.0, 0.5, -2.0, 1.0],
                1.0 / 7.0,
            )
            .unwrap(),
        ),
        target: None,
    };
    let mut sim = cdbo::sim::Simulator::new(track.clone(), &car);
    for base in [BaseLine::Centre, BaseLine::MinCurvature] {
        sim.config.line = base.line(&track, &car).unwrap();
        let held = sim.held_line(|x| wide.line_offset(x));
        assert_eq!(held.len(), track.samples.len());
        let (mut clamped, mut free) = (0, 0);
        for (p, c) in held.iter().zip(&track.samples) {
            let room = 0.5 * c.width - 0.5 * car.width;
            assert!(
                p.offset.abs() <= room + 1e-12,
                "{base:?}: d({:.0} m) = {:.3} m, room {room:.3} m",
                p.s,
                p.offset
            );
            let from_centre = (p.x - c.x).hypot(p.y - c.y);
            assert!(
                (from_centre - p.offset.abs()).abs() < 1e-9,
                "{from_centre} {}",
                p.offset
            );
            let d0 = sim.config.line.as_ref().map_or(0.0, |l| l.offset_at(p.s));
            let wanted = d0 + wide.line_offset(p.s / track.length);
            if wanted.abs() < room {
                assert_eq!(p.offset, wanted);
                free += 1;
            } else {
                clamped += 1;
            }
        }
        assert!(
            clamped > 100 && free > 100,
            "{base:?}: {clamped} clamped, {free} free"
        );
    }
}
