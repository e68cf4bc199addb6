fn main() {
    let car = cdbo::car::Car::spirit_300();
    let t = cdbo::track::torcs::read(std::path::Path::new(
        "/work/shared/torcs/tracks/road/forza/forza.xml",
    ))
    .unwrap();
    let sim = cdbo::sim::Simulator::new(t, &car);
    let t0 = std::time::Instant::now();
    let mut simulated = 0.0;
    for _ in 0..10 {
        simulated += sim
            .lap(&mut cdbo::drive::demo::SpeedHold::new(15.0))
            .simulated_s;
    }
    let wall = t0.elapsed().as_secs_f64();
    println!(
        "rtf {:.0} ns/step {:.0}",
        simulated / wall,
        wall / (simulated / 0.002) * 1e9
    );
}
