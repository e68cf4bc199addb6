use cdbo::car::Car;
use cdbo::drive::{ConstantPedal, demo::SpeedHold};
use cdbo::sim::Simulator;
use std::path::Path;

fn main() {
    let car = Car::spirit_300();
    let mut tracks = vec![cdbo::track::builtin::load("ridgeway").unwrap().unwrap()];
    for p in [
        "torcs/tracks/road/forza/forza.xml",
        "speed-dreams/tracks/road/allondaz/allondaz.xml",
        "torcs/tracks/road/e-track-2/e-track-2.xml",
        "torcs/tracks/road/aalborg/aalborg.xml",
    ] {
        tracks.push(cdbo::track::torcs::read(&Path::new("/work/shared").join(p)).unwrap());
    }
    tracks.push(cdbo::track::csv::read(Path::new("/work/shared/tracks/csv/Monza.csv")).unwrap());
    for t in tracks {
        let mut sim = Simulator::new(t, &car);
        sim.config.trace = true;
        for (name, r) in [
            ("demo15", {
                let t0 = std::time::Instant::now();
                let r = sim.lap(&mut SpeedHold::new(15.0));
                eprintln!("  wall {:?}", t0.elapsed());
                r
            }),
            ("demo25", sim.lap(&mut SpeedHold::new(25.0))),
            ("full", sim.lap(&mut ConstantPedal(1.0))),
        ] {
            let maxlat = r.trace.iter().map(|p| p.lateral.abs()).fold(0.0, f64::max);
            let maxv = r.trace.iter().map(|p| p.speed).fold(0.0, f64::max);
            println!(
                "{:10} {:7} completed {} time {:?} reward {:.2} fail {:?} maxlat {:.2} maxv {:.1}",
                sim.track.name,
                name,
                r.completed,
                r.lap_time_s,
                r.reward_mps,
                r.failure,
                maxlat,
                maxv
            );
        }
    }
}
