//! The dashboard's JSON API over HTTP, against a real study written by the library (told more
//! laps while the server runs) and a tiny experiment folder of run records.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::{Path, PathBuf};

use cdbo::car::catalog as cars;
use cdbo::data_path::DataPath;
use cdbo::experiment::grid::RunSpec;
use cdbo::experiment::race::LapRecord;
use cdbo::experiment::record::RunRecord;
use cdbo::policy::RkhsPolicy;
use cdbo::sim::{FailureReason, Simulator};
use cdbo::study::{Outcome, Study, StudyConfig};
use cdbo_dashboard::store::{Files, Kind, Source, Store};
use cdbo_dashboard::view::POLICY_POINTS;
use cdbo_dashboard::{Dashboard, map::MAP_POINTS};
use serde_json::Value;

fn fresh_dir(name: &str) -> PathBuf {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("cdbo-dashboard-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `GET path` over a plain TCP connection: (status, JSON body or the text as a JSON string).
fn get(addr: SocketAddr, path: &str) -> (u16, Value) {
    let mut stream = TcpStream::connect(addr).unwrap();
    write!(
        stream,
        "GET {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut text = String::new();
    stream.read_to_string(&mut text).unwrap();
    let (head, body) = text.split_once("\r\n\r\n").unwrap();
    let status = head.split(' ').nth(1).unwrap().parse().unwrap();
    let value = serde_json::from_str(body).unwrap_or_else(|_| Value::String(body.to_owned()));
    (status, value)
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

const KERNELS: usize = 5;
const LENGTHSCALE: f64 = 0.25;

fn study_config() -> StudyConfig {
    StudyConfig {
        method: cdbo::method::Method::Random,
        kernels: KERNELS,
        lengthscale: LENGTHSCALE,
        seed: 3,
        beta: 1.0,
        w0: vec![0.2, 0.3, -0.1, 0.4, 0.1],
        track: None,
        track_length: None,
        knob: None,
        max_failed_laps: None,
        box_radius: None,
        warm_start: None,
        line_kernels: None,
        base_line: Default::default(),
        steering: Default::default(),
    }
}

fn lap(lap: usize, reward: f64, best: f64, failure: Option<FailureReason>) -> LapRecord {
    LapRecord {
        lap,
        reward_mps: reward,
        best_mps: best,
        lap_time_s: failure.is_none().then_some(1000.0 / reward),
        failure,
        x_fail: failure.map(|_| 0.5),
        optimizer_s: 0.0,
        simulator_s: 0.0,
    }
}

/// Run `method` repeat `r` on Ridgeway with the given best-so-far rewards per lap.
fn run_record(method: &str, repeat: usize, rewards: &[f64]) -> RunRecord {
    let mut best = f64::NEG_INFINITY;
    let laps = rewards
        .iter()
        .enumerate()
        .map(|(i, &r)| {
            best = best.max(r);
            let failure = (r == 0.0).then_some(FailureReason::OffTrack);
            lap(i + 1, r, best, failure)
        })
        .collect();
    RunRecord {
        spec: RunSpec {
            track: "ridgeway".into(),
            kernels: KERNELS,
            method: method.into(),
            repeat,
        },
        laps_planned: rewards.len(),
        track_name: "Ridgeway".into(),
        length_m: 1000.0,
        demo_speed: 15.0,
        demo_reward_mps: 14.0,
        limit_reward_mps: 40.0,
        ceiling_reward_mps: None,
        initial_reward_mps: rewards[0],
        best_reward_mps: best,
        best_weights: vec![0.1 * (repeat as f64 + 1.0); KERNELS],
        lengthscale: LENGTHSCALE,
        line_kernels: None,
        base_line: Default::default(),
        steering: Default::default(),
        target: None,
        laps,
        wall_s: 1.0,
    }
}

struct Served {
    addr: SocketAddr,
    study: Study,
    experiment: PathBuf,
}

fn serve(dir: &Path) -> Served {
    let db = dir.join("car.cdbo.db");
    let mut study = Study::create(&db, study_config()).unwrap();
    for outcome in [
        Outcome::Lap {
            time_s: 100.0,
            length_m: 2000.0,
        },
        Outcome::Failed {
            at: Some(0.4),
            reason: Some("off_track".into()),
        },
        Outcome::Reward(25.0),
    ] {
        let trial = study.ask().unwrap();
        study.tell(trial.id, &outcome).unwrap();
    }
    let experiment = dir.join("grid");
    for record in [
        run_record("cdbo", 0, &[10.0, 12.0, 12.0]),
        run_record("cdbo", 1, &[14.0, 0.0, 18.0]),
        run_record("random", 0, &[9.0, 11.0, 0.0]),
    ] {
        record.save(&experiment).unwrap();
    }
    let dashboard = Dashboard {
        sources: vec![
            Files::study_source(&db).unwrap(),
            Files::experiment_source(&experiment).unwrap(),
        ],
        databases: Vec::new(),
        store: Box::new(Files),
        study_track: Some("ridgeway".into()),
        car: cars::DEFAULT.into(),
        data: DataPath::default(),
    };
    let bound = dashboard.bind("127.0.0.1:0").unwrap();
    let addr = bound.local_addr().unwrap();
    std::thread::spawn(move || bound.serve().unwrap());
    Served {
        addr,
        study,
        experiment,
    }
}

fn redriven(weights: &[f64]) -> f64 {
    let track = cdbo::track::catalog::find("ridgeway", &DataPath::default()).unwrap();
    let car = cars::find(cars::DEFAULT, &DataPath::default()).unwrap();
    let policy = RkhsPolicy::new(weights.to_vec(), LENGTHSCALE).unwrap();
    Simulator::new(track, &car)
        .lap(&mut policy.pedal())
        .reward_mps
}

#[test]
fn a_study_is_shown_live_and_its_trials_redriven() {
    let dir = fresh_dir("study");
    let Served {
        addr, mut study, ..
    } = serve(&dir);

    let (status, sources) = get(addr, "/api/sources");
    assert_eq!(status, 200);
    assert_eq!(sources[0]["kind"], "study");
    assert_eq!(sources[0]["laps"], 3);
    assert_eq!(sources[0]["best"], 25.0);
    assert_eq!(sources[1]["kind"], "experiment");
    assert_eq!(sources[1]["laps"], 9);
    assert_eq!(sources[1]["best"], 18.0);

    let (status, view) = get(addr, "/api/sources/0");
    assert_eq!(status, 200);
    assert_eq!(view["laps_total"], 3);
    assert_eq!(numbers(&view["curves"][0]["mean"]), [20.0, 20.0, 25.0]);
    assert_eq!(view["curves"][0]["method"], "random");
    let laps = view["laps"].as_array().unwrap();
    assert_eq!(
        laps.iter()
            .map(|l| l["reward"].as_f64().unwrap())
            .collect::<Vec<_>>(),
        [20.0, 0.0, 25.0]
    );
    assert_eq!(laps[0]["lap_time_s"], 100.0);
    assert_eq!(laps[1]["failure"], "off_track");
    assert_eq!(laps[1]["x_fail"], 0.4);
    assert!(laps[2]["failure"].is_null());

    // The best and the latest policy are trial 3; the curve is π(x) of its weights.
    let history = study.history().unwrap();
    let policy = RkhsPolicy::new(history[2].weights.clone(), LENGTHSCALE).unwrap();
    let policies = view["policies"].as_array().unwrap();
    assert_eq!(policies.len(), 2);
    assert_eq!(policies[0]["key"], "3");
    assert_eq!(policies[1]["key"], "3");
    let pedal = numbers(&policies[0]["pedal"]);
    assert_eq!(pedal.len(), POLICY_POINTS);
    for i in [0, 37, 100, 200] {
        let x = i as f64 / (POLICY_POINTS - 1) as f64;
        assert_eq!(pedal[i], policy.action(x), "π({x})");
    }

    // A lap told while the server runs shows at the next poll; the best stays trial 3.
    let trial = study.ask().unwrap();
    study.tell(trial.id, &Outcome::Reward(22.0)).unwrap();
    let (_, view) = get(addr, "/api/sources/0");
    assert_eq!(view["laps_total"], 4);
    assert_eq!(
        numbers(&view["curves"][0]["mean"]),
        [20.0, 20.0, 25.0, 25.0]
    );
    assert_eq!(view["policies"][0]["key"], "3");
    assert_eq!(view["policies"][1]["key"], "4");

    // The map re-drives trial 4 in the simulator: the same reward as driving it here.
    let (status, map) = get(addr, "/api/sources/0/map?key=4");
    assert_eq!(status, 200, "{map}");
    assert_eq!(map["reward"].as_f64().unwrap(), redriven(&trial.weights));
    let speed = numbers(&map["speed"]);
    assert!(
        speed.len() > 100 && speed.len() <= MAP_POINTS,
        "{}",
        speed.len()
    );
    assert_eq!(numbers(&map["x"]).len(), speed.len());
    assert!(speed.iter().all(|v| v.is_finite() && *v >= 0.0));
    assert!(speed.iter().cloned().fold(0.0, f64::max) > 5.0);

    let (status, err) = get(addr, "/api/sources/0/map?key=99");
    assert_eq!(status, 404);
    assert!(
        err["error"].as_str().unwrap().contains("no trial 99"),
        "{err}"
    );
    let (status, _) = get(addr, "/api/sources/7");
    assert_eq!(status, 404);

    // The page and its plotting library come from the binary.
    let (status, page) = get(addr, "/");
    assert_eq!(status, 200);
    assert!(page.as_str().unwrap().contains("/uplot.js"));
    let (status, js) = get(addr, "/uplot.js");
    assert_eq!(status, 200);
    assert!(js.as_str().unwrap().contains("uPlot"));
    let (_, licence) = get(addr, "/licenses/uplot");
    assert!(licence.as_str().unwrap().contains("MIT"));
}

#[test]
fn an_experiment_shows_the_mean_and_band_over_seeds() {
    let dir = fresh_dir("experiment");
    let Served {
        addr, experiment, ..
    } = serve(&dir);

    let (status, view) = get(addr, "/api/sources/1");
    assert_eq!(status, 200, "{view}");
    assert_eq!(view["laps_total"], 9);
    let curves = view["curves"].as_array().unwrap();
    assert_eq!(curves.len(), 2);
    assert_eq!(curves[0]["label"], "ridgeway m5 cdbo");
    assert_eq!(curves[0]["runs"], 2);
    // Best so far: r0 10, 12, 12 and r1 14, 14, 18: mean (a + b)/2, standard error |a − b|/2.
    assert_eq!(numbers(&curves[0]["mean"]), [12.0, 13.0, 15.0]);
    assert_eq!(numbers(&curves[0]["lo"]), [10.0, 12.0, 12.0]);
    assert_eq!(numbers(&curves[0]["hi"]), [14.0, 14.0, 18.0]);
    assert_eq!(curves[1]["label"], "ridgeway m5 random");
    assert_eq!(numbers(&curves[1]["lo"]), numbers(&curves[1]["hi"]));

    // The best run's laps by default; a chosen run's on request.
    assert_eq!(view["policies"][0]["key"], "ridgeway-m5-cdbo-r1");
    assert_eq!(view["laps"][1]["failure"], "off_track");
    assert_eq!(view["runs"].as_array().unwrap().len(), 3);
    let (_, chosen) = get(addr, "/api/sources/1?run=ridgeway-m5-random-r0");
    let rewards: Vec<f64> = chosen["laps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["reward"].as_f64().unwrap())
        .collect();
    assert_eq!(rewards, [9.0, 11.0, 0.0]);
    assert_eq!(chosen["policies"][1]["key"], "ridgeway-m5-random-r0");

    // A run that finishes while the server runs shows at the next poll.
    run_record("random", 1, &[8.0, 8.0, 13.0])
        .save(&experiment)
        .unwrap();
    let (_, view) = get(addr, "/api/sources/1");
    assert_eq!(view["laps_total"], 12);
    assert_eq!(view["curves"][1]["runs"], 2);

    // A run's best policy re-driven on its own track.
    let (status, map) = get(addr, "/api/sources/1/map?key=ridgeway-m5-cdbo-r0");
    assert_eq!(status, 200, "{map}");
    assert_eq!(map["track"], "Ridgeway");
    assert_eq!(map["reward"].as_f64().unwrap(), redriven(&[0.1; KERNELS]));
}

#[test]
fn bad_sources_and_a_port_in_use_are_one_line_errors() {
    let dir = fresh_dir("errors");
    let missing = dir.join("nope.db");
    let e = Files::study_source(&missing).unwrap_err().to_string();
    assert!(e.contains("nope.db") && e.contains("no such study"), "{e}");
    let text = dir.join("notes.txt");
    std::fs::write(&text, "not a study at all, just some words here\n").unwrap();
    let e = Files::study_source(&text).unwrap_err().to_string();
    assert!(
        e.contains("notes.txt") && e.contains("not a cdbo study"),
        "{e}"
    );
    let e = Files::experiment_source(&dir.join("no-grid"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("no-grid") && e.contains("no such folder"), "{e}");
    let e = Files::experiment_source(&text).unwrap_err().to_string();
    assert!(e.contains("not a folder"), "{e}");
    for e in [
        Files::study_source(&missing).unwrap_err().to_string(),
        Files::study_source(&text).unwrap_err().to_string(),
    ] {
        assert!(!e.contains('\n'), "{e}");
    }

    // An experiment folder with no finished run yet is shown empty.
    let empty = dir.join("starting");
    std::fs::create_dir_all(&empty).unwrap();
    let source = Files::experiment_source(&empty).unwrap();
    assert_eq!(source.kind, Kind::Experiment);

    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = taken.local_addr().unwrap().to_string();
    let dashboard = Dashboard {
        sources: vec![source],
        databases: Vec::new(),
        store: Box::new(Files),
        study_track: None,
        car: cars::DEFAULT.into(),
        data: DataPath::default(),
    };
    let e = dashboard.bind(&addr).err().unwrap().to_string();
    assert!(e.contains(&addr) && e.contains("in use"), "{e}");
}

/// A store whose "database" is a folder of study files, listed as `Files` lists a PostgreSQL
/// database: every study in it, those known aside.
struct Folder;

impl Store for Folder {
    fn study(&self, source: &Source) -> cdbo::Result<(StudyConfig, Vec<cdbo::study::Trial>)> {
        Files.study(source)
    }

    fn runs(&self, source: &Source) -> cdbo::Result<Vec<RunRecord>> {
        Files.runs(source)
    }

    fn database(&self, database: &str, known: &[Source]) -> cdbo::Result<Vec<Source>> {
        let mut files: Vec<PathBuf> = std::fs::read_dir(database)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.to_string_lossy().ends_with(".cdbo.db"))
            .collect();
        files.sort();
        files
            .iter()
            .filter(|p| !known.iter().any(|s| Path::new(&s.location) == p.as_path()))
            .map(|p| Files::study_source(p))
            .collect()
    }
}

/// A database shown whole is listed again on every `GET /api/sources`: a study created after
/// start-up joins the list with the next id, and the sources listed before keep theirs. (The
/// database here is a folder, through [`Folder`]; `.ci/dashboard-check` checks the same of a
/// real PostgreSQL database in headless Chromium.)
#[test]
fn a_study_created_after_start_up_is_listed() {
    let dir = fresh_dir("later");
    let tell = |study: &mut Study, laps: usize| {
        for _ in 0..laps {
            let trial = study.ask().unwrap();
            study.tell(trial.id, &Outcome::Reward(20.0)).unwrap();
        }
    };
    tell(
        &mut Study::create(&dir.join("a.cdbo.db"), study_config()).unwrap(),
        1,
    );
    let database = dir.display().to_string();
    let dashboard = Dashboard {
        sources: Folder.database(&database, &[]).unwrap(),
        databases: vec![database],
        store: Box::new(Folder),
        study_track: None,
        car: cars::DEFAULT.into(),
        data: DataPath::default(),
    };
    let bound = dashboard.bind("127.0.0.1:0").unwrap();
    let addr = bound.local_addr().unwrap();
    std::thread::spawn(move || bound.serve().unwrap());
    let (status, listed) = get(addr, "/api/sources");
    assert_eq!(status, 200, "{listed}");
    assert_eq!(listed.as_array().unwrap().len(), 1, "{listed}");

    tell(
        &mut Study::create(&dir.join("b.cdbo.db"), study_config()).unwrap(),
        2,
    );
    let (_, listed) = get(addr, "/api/sources");
    let listed = listed.as_array().unwrap();
    assert_eq!(listed.len(), 2, "{listed:?}");
    for (id, (file, laps)) in [("a.cdbo.db", 1), ("b.cdbo.db", 2)].into_iter().enumerate() {
        assert_eq!(listed[id]["id"], id, "{listed:?}");
        assert!(listed[id]["location"].as_str().unwrap().ends_with(file));
        assert_eq!(listed[id]["laps"], laps, "{listed:?}");
    }
    let (status, view) = get(addr, "/api/sources/1");
    assert_eq!(status, 200, "{view}");
    assert_eq!(view["laps_total"], 2, "{view}");
}
