use cdbo::car::Car;
use cdbo::drive::{Observation, Pedal, demo::SpeedHold};
use cdbo::sim::Simulator;
use std::path::Path;

struct Follow {
    profile: Vec<f64>,
    scale: f64,
}
impl Pedal for Follow {
    fn pedal(&mut self, o: &Observation) -> f64 {
        let i = ((o.x * (self.profile.len() - 1) as f64) as usize + 25).min(self.profile.len() - 1);
        let target = self.profile[i] * self.scale;
        (2.0 * (target - o.speed)).clamp(-1.0, 1.0)
    }
}

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
    for t in tracks {
        let lim = cdbo::limit::limit_lap(&t, &car);
        let sim = Simulator::new(t, &car);
        let t0 = std::time::Instant::now();
        let d = sim.lap(&mut SpeedHold::new(15.0));
        let wall = t0.elapsed().as_secs_f64();
        let mut best = (0.0, 0.0);
        for scale in [0.6, 0.7, 0.8, 0.85, 0.9, 0.95, 1.0, 1.05] {
            let r = sim.lap(&mut Follow {
                profile: lim.speed.clone(),
                scale,
            });
            if r.reward_mps > best.0 {
                best = (r.reward_mps, scale);
            }
        }
        println!(
            "{:10} L {:.1} limit {:.1}s {:.2} m/s | demo {:.2} m/s rtf {:.0} | follower best {:.2} m/s ({:.0}%) at scale {}",
            sim.track.name,
            sim.track.length,
            lim.lap_time_s,
            lim.reward_mps,
            d.reward_mps,
            d.simulated_s / wall,
            best.0,
            100.0 * best.0 / lim.reward_mps,
            best.1
        );
    }
}
