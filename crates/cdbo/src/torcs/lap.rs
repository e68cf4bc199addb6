//! One lap in the game: a fresh `torcs-bin -r RACE.xml` in its own process group, in a lap
//! folder of its own under the tree's `laps/` (so parallel laps never share a file), killed
//! with its group when it outlives its time-out, and the folder removed afterwards.
//!
//! The lap folder is the game's local directory (`-l`): it holds the race (one car, our robot,
//! standing on the start line), the robot's `drivers/cdbo/cdbo.xml` naming the car and the
//! settings file, the settings themselves (pedal, line, steering gains, shift points, driver
//! aids, failure margins; see `torcs-robot/cdbo.cpp`) and the JSON line the robot writes.

use std::fmt::Write as _;
use std::io::{Read, Seek, SeekFrom};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use serde::Deserialize;

use super::line::LineTable;
use super::{Game, ROBOT};
use crate::bounded;
use crate::car::Car;
use crate::drive::steering::Steering;
use crate::error::{Error, Result};
use crate::policy::RkhsPolicy;
use crate::sim::lap::{Failure, LapConfig, LapResult};
use crate::vehicle::Vehicle;
use crate::vehicle::powertrain::{DOWNSHIFT_MARGIN, THROTTLE_LEVELS};

/// What the robot's pedal follows.
#[derive(Debug, Clone, PartialEq)]
pub enum GamePedal {
    /// The demonstrator holding this speed (m/s).
    Demo(f64),
    /// The same command everywhere.
    Constant(f64),
    /// The paper's RKHS policy π(x).
    Rkhs(RkhsPolicy),
    /// An (x, a) table, linear in between.
    Table(Vec<(f64, f64)>),
    /// The profile hold ([`crate::drive::profile::ProfileHold`]): k times these speeds (m/s) at
    /// stations spaced evenly over a lap of this length (m), the first on the start line, the
    /// last at the finish.
    Profile {
        /// The scale k.
        k: f64,
        /// The lap's length (m) the stations span, cdbo's length of the track.
        length: f64,
        /// The speeds (m/s), at least 2.
        speed: Vec<f64>,
    },
}

/// One lap to drive.
#[derive(Debug, Clone)]
pub struct LapRequest {
    /// TORCS track name (`forza`).
    pub track: String,
    /// TORCS car name (`car1-trb1`); its parameters must be `car`'s.
    pub car_name: String,
    /// The car as cdbo reads it: wheelbase, gears and shift points, tyres (driver aids).
    pub car: Car,
    /// The pedal.
    pub pedal: GamePedal,
    /// The line both steerings hold, sampled ([`LineTable`]); `None`: the centre line.
    pub line: Option<LineTable>,
    /// Lap settings: the steering gains, the off-track margin and the time limit.
    pub config: LapConfig,
    /// Write the robot's 50 Hz trace here (CSV, the columns of `cdbo lap --trace`).
    pub trace: Option<PathBuf>,
    /// Return the trace in the lap's [`LapResult::trace`] (written to the lap folder unless
    /// `trace` names a file).
    pub record: bool,
    /// Wall-clock time after which the game is killed and the lap fails.
    pub timeout: Duration,
}

/// The default wall-clock time-out of one lap: the game runs many times faster than real
/// time, so a lap within its time limit takes seconds (docs/results/design.md).
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(120);

/// Lap folders made by this process.
static LAPS: AtomicU64 = AtomicU64::new(0);

/// The line the robot writes.
#[derive(Debug, Deserialize)]
struct RobotLine {
    completed: bool,
    #[serde(default)]
    lap_time_s: Option<f64>,
    #[serde(default)]
    reward_mps: f64,
    #[serde(default)]
    failure: Option<Failure>,
    #[serde(default)]
    simulated_s: f64,
    #[serde(default)]
    standing_lap_s: Option<f64>,
    #[serde(default)]
    error: Option<String>,
}

/// A lap folder, removed when dropped.
struct LapDir(PathBuf);

impl Drop for LapDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// How far behind the start line (m) the shipped robots stand when they are timed: a hair, so
/// the game's first lap is a standing lap on every track. With the grid on the line (0 m), on
/// Aalborg the car stands just past it and the game's first lap is a standing lap plus a flying
/// one (berniw2: 152.19 s; 78.15 s from 0.1 m behind, 78.25 s from 1 m, 78.32 s from 5 m).
/// cdbo's own robot stands on the line and times one track length itself.
pub const ROBOT_GRID_BEHIND: f64 = 0.1;

/// The robot's `drivers/cdbo/cdbo.xml`: one driver of `car`, whose settings are `settings`.
pub fn robot_xml(car: &str, settings: &str) -> String {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<!DOCTYPE params SYSTEM "params.dtd">
<params name="{ROBOT}" type="robotdef">
  <section name="Robots">
    <section name="index">
      <section name="0">
        <attstr name="name" val="{ROBOT}"/>
        <attstr name="desc" val="cdbo's policy, steering and gearbox"/>
        <attstr name="team" val="cdbo"/>
        <attstr name="author" val="cdbo"/>
        <attstr name="car name" val="{car}"/>
        <attnum name="race number" val="1"/>
      </section>
    </section>
  </section>
  <section name="{ROBOT}">
    <attstr name="settings" val="{settings}"/>
  </section>
</params>
"#
    )
}

/// A one-car quick race of `laps` laps on `track` (in `category`): driver `idx` of `robot`
/// standing `behind` metres behind the start line.
fn race_xml(
    track: &str,
    category: &str,
    robot: &str,
    idx: usize,
    laps: usize,
    behind: f64,
) -> String {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<!DOCTYPE params SYSTEM "params.dtd">
<params name="Quick Race" type="param" mode="mw">
  <section name="Header">
    <attstr name="name" val="Quick Race"/>
    <attnum name="priority" val="10"/>
  </section>
  <section name="Tracks">
    <attnum name="maximum number" val="1"/>
    <section name="1">
      <attstr name="name" val="{track}"/>
      <attstr name="category" val="{category}"/>
    </section>
  </section>
  <section name="Races">
    <section name="1"><attstr name="name" val="Quick Race"/></section>
  </section>
  <section name="Quick Race">
    <attnum name="distance" val="0"/>
    <attstr name="type" val="race"/>
    <attstr name="starting order" val="drivers list"/>
    <attstr name="restart" val="yes"/>
    <section name="Starting Grid">
      <attnum name="rows" val="1"/>
      <attnum name="distance to start" val="{behind}"/>
      <attnum name="distance between columns" val="0"/>
      <attnum name="offset within a column" val="0"/>
      <attnum name="initial speed" val="0"/>
      <attnum name="initial height" val="0.2"/>
    </section>
    <attnum name="laps" val="{laps}"/>
  </section>
  <section name="Drivers">
    <attnum name="maximum number" val="1"/>
    <section name="1">
      <attnum name="idx" val="{idx}"/>
      <attstr name="module" val="{robot}"/>
    </section>
  </section>
</params>
"#
    )
}

/// The index of a robot's first driver in its `drivers/NAME/NAME.xml`: the first numbered
/// section of its `Robots/index` (0 for most, 1 for the berniw family); 0 if none is found.
fn first_driver(robot_xml: &str) -> usize {
    let Some(index) = robot_xml.find("name=\"index\"") else {
        return 0;
    };
    robot_xml[index..]
        .split("<section name=\"")
        .skip(1)
        .find_map(|rest| rest.split('"').next()?.parse().ok())
        .unwrap_or(0)
}

/// The fastest speed (m/s) of the cornering-stiffness tables handed to the robot for the path
/// tracker, one point per m/s from 0: linear in between, they stay within 1e-4 of
/// [`Vehicle::cornering_stiffness`] (the test `the_robots_tracker_is_the_rust_one_on_a_recorded_lap`).
pub const CORNERING_SPEEDS: usize = 120;

/// The (speed, cornering stiffness) tables of the front and rear axle on a surface of friction
/// 1 that the robot's path tracker reads (linear in between, scaled by the road's friction):
/// [`Vehicle::cornering_stiffness`] at every m/s from 0 to [`CORNERING_SPEEDS`].
pub fn cornering_tables(vehicle: &Vehicle) -> [Vec<(f64, f64)>; 2] {
    [0, 1].map(|k| {
        (0..=CORNERING_SPEEDS)
            .map(|i| {
                let v = i as f64;
                (v, vehicle.cornering_stiffness(v, 1.0)[k])
            })
            .collect()
    })
}

/// The robot's settings file (format in `torcs-robot/cdbo.cpp`).
fn settings(
    req: &LapRequest,
    output: &Path,
    trace: Option<&Path>,
    time_limit: f64,
) -> Result<String> {
    let car = &req.car;
    let vehicle = Vehicle::new(car);
    let list = |v: &mut dyn Iterator<Item = f64>| {
        v.map(|x| format!("{x:e}")).collect::<Vec<_>>().join(" ")
    };
    let mut s = String::from("# cdbo lap settings (torcs-robot/cdbo.cpp)\n");
    let _ = writeln!(s, "output {}", output.display());
    if let Some(trace) = trace {
        let _ = writeln!(s, "trace {}", trace.display());
    }
    let pedal = match &req.pedal {
        GamePedal::Demo(v) => format!("demo {v:e}"),
        GamePedal::Constant(a) => format!("constant {a:e}"),
        GamePedal::Rkhs(p) => format!(
            "rkhs {:e} {}",
            p.lengthscale,
            list(&mut p.weights.iter().copied())
        ),
        GamePedal::Table(points) => format!(
            "table {}",
            list(&mut points.iter().flat_map(|&(x, a)| [x, a]))
        ),
        GamePedal::Profile { k, length, speed } => format!(
            "profile {k:e} {length:e} {}",
            list(&mut speed.iter().copied())
        ),
    };
    let _ = writeln!(s, "pedal {pedal}");
    let _ = writeln!(s, "wheelbase {:e}", car.wheelbase);
    if let Some(line) = &req.line {
        let _ = writeln!(
            s,
            "line {:e} {}",
            line.length,
            list(&mut line.offsets.iter().copied())
        );
    }
    match &req.config.steering {
        Steering::Pi(st) => {
            let _ = writeln!(
                s,
                "steering pi {:e} {:e} {:e}",
                st.lookahead_time, st.lookahead_min, st.ki
            );
        }
        Steering::Tracker(t) => {
            let _ = writeln!(
                s,
                "steering tracker {:e} {:e} {:e} {:e} {:e} {:e}",
                t.preview_time,
                t.preview_min,
                t.feedforward_time,
                t.yaw_rate_gain,
                t.yaw_rate_speed,
                t.yaw_step_gain
            );
            let (a, b, iz) = (car.cg_to_front(), car.cg_to_rear(), car.yaw_inertia());
            let _ = writeln!(s, "chassis {:e} {a:e} {b:e} {iz:e}", car.mass);
            for (axle, table) in ["front", "rear"].iter().zip(cornering_tables(&vehicle)) {
                let mut pairs = table.into_iter().flat_map(|(v, c)| [v, c]);
                let _ = writeln!(s, "cornering_{axle} {}", list(&mut pairs));
            }
        }
    }
    let fd = car.final_drive;
    let _ = writeln!(s, "ratios {}", list(&mut car.gears.iter().map(|g| g * fd)));
    let _ = writeln!(s, "throttle_levels {THROTTLE_LEVELS}");
    let _ = writeln!(
        s,
        "upshift {}",
        list(&mut vehicle.shift_map().upshift.iter().flatten().copied())
    );
    let _ = writeln!(s, "downshift_margin {DOWNSHIFT_MARGIN:e}");
    let _ = writeln!(s, "shift_time {:e}", car.shift_time);
    let [f, r] = vehicle.driven();
    let _ = writeln!(s, "driven {f:e} {r:e}");
    let [f, r] = vehicle.aid_threshold();
    let _ = writeln!(s, "aid_slip {f:e} {r:e}");
    let _ = writeln!(s, "off_track_margin {:e}", req.config.off_track_margin);
    let _ = writeln!(s, "time_limit {:e}", req.config.laps() * time_limit);
    if req.config.flying {
        let _ = writeln!(s, "flying 1");
    }
    Ok(s)
}

impl Game {
    /// The game's car of this name, read from its own car file.
    pub fn car(&self, name: &str) -> Result<crate::car::Car> {
        self.install.check_car(name)?;
        let file = self
            .install
            .data_dir
            .join("cars")
            .join(name)
            .join(format!("{name}.xml"));
        crate::car::torcs::read(&file, None)
    }

    /// A lap of `pedal` with the game's `car` on its `track` (TORCS names), with cdbo's
    /// default lap settings; the car's parameters are read from the game's own car file.
    pub fn request(&self, track: &str, car: &str, pedal: GamePedal) -> Result<LapRequest> {
        self.install.track_category(track)?;
        Ok(LapRequest {
            track: track.to_owned(),
            car_name: car.to_owned(),
            car: self.car(car)?,
            pedal,
            line: None,
            config: LapConfig::default(),
            trace: None,
            record: false,
            timeout: DEFAULT_TIMEOUT,
        })
    }

    /// Drives one lap. `Err` when no lap could be attempted (the setup is broken, the track or
    /// car unknown); `Ok(Err(reason))` when the game produced no lap (it hung and was killed,
    /// or crashed); otherwise the robot's lap, judged by cdbo's rules.
    pub fn lap(&self, req: &LapRequest) -> Result<std::result::Result<LapResult, String>> {
        let category = self.install.track_category(&req.track)?;
        self.install.check_car(&req.car_name)?;
        let io = |path: &Path| {
            let path = path.to_owned();
            move |source| Error::Io { path, source }
        };
        let n = LAPS.fetch_add(1, Ordering::Relaxed);
        let dir = LapDir(
            self.root
                .join("laps")
                .join(format!("{}-{n}", std::process::id())),
        );
        let _ = std::fs::remove_dir_all(&dir.0);
        let robot_dir = dir.0.join("drivers").join(ROBOT);
        for d in [&robot_dir, &dir.0.join("config"), &dir.0.join("results")] {
            std::fs::create_dir_all(d).map_err(io(d))?;
        }
        let engine = self.root.join("conf/config/raceengine.xml");
        std::fs::copy(&engine, dir.0.join("config/raceengine.xml")).map_err(io(&engine))?;
        let time_limit = req
            .config
            .time_limit
            .unwrap_or_else(|| default_time_limit(&self.install, &req.track, &category));
        let output = dir.0.join("lap.jsonl");
        let trace = req
            .trace
            .clone()
            .or_else(|| req.record.then(|| dir.0.join("trace.csv")));
        let files = [
            (
                robot_dir.join(format!("{ROBOT}.xml")),
                robot_xml(&req.car_name, "lap.txt"),
            ),
            (
                dir.0.join("lap.txt"),
                settings(req, &output, trace.as_deref(), time_limit)?,
            ),
            (
                dir.0.join("race.xml"),
                race_xml(&req.track, &category, ROBOT, 0, 2, 0.0),
            ),
        ];
        for (path, text) in &files {
            std::fs::write(path, text).map_err(io(path))?;
        }
        let stderr_path = dir.0.join("stderr.txt");
        let status = match self.run_race(&dir.0, req.timeout)? {
            Ok(status) => status,
            Err(hung) => return Ok(Err(hung)),
        };
        let line = game_file(&output)?;
        let Some(line) = line.lines().rfind(|l| !l.trim().is_empty()) else {
            return Ok(Err(format!(
                "the game ended ({status}) without a lap: {}",
                tail(&stderr_path)
            )));
        };
        let robot: RobotLine = serde_json::from_str(line).map_err(|e| Error::External {
            program: "the TORCS robot".into(),
            message: format!("an unreadable line ({e}): {line}"),
        })?;
        if let Some(error) = robot.error {
            return Err(Error::External {
                program: "the TORCS robot".into(),
                message: error,
            });
        }
        let trace = match trace.filter(|_| req.record) {
            Some(path) => crate::sim::trace::read(&path)?,
            None => Vec::new(),
        };
        Ok(Ok(LapResult {
            completed: robot.completed,
            lap_time_s: robot.lap_time_s,
            reward_mps: robot.reward_mps,
            failure: robot.failure,
            simulated_s: robot.simulated_s,
            standing_lap_s: robot.standing_lap_s,
            trace,
        }))
    }
}

impl Game {
    /// Runs the race `dir/race.xml` with `dir` as the game's local directory, its output in
    /// `dir/stdout.txt` and `dir/stderr.txt`. `Ok(Err(why))` when it outlived `timeout` and
    /// was killed with its process group.
    fn run_race(
        &self,
        dir: &Path,
        timeout: Duration,
    ) -> Result<std::result::Result<std::process::ExitStatus, String>> {
        let io = |path: &Path| {
            let path = path.to_owned();
            move |source| Error::Io { path, source }
        };
        let file = |name: &str| {
            let path = dir.join(name);
            std::fs::File::create(&path).map_err(io(&path))
        };
        let with_slash = |p: &Path| {
            let mut s = p.as_os_str().to_owned();
            s.push("/");
            s
        };
        let mut child = Command::new(self.lib_dir().join("torcs-bin"))
            .arg("-l")
            .arg(with_slash(dir))
            .arg("-L")
            .arg(with_slash(&self.lib_dir()))
            .arg("-D")
            .arg(with_slash(&self.data_dir()))
            .arg("-r")
            .arg(dir.join("race.xml"))
            .current_dir(self.data_dir())
            .env("LD_LIBRARY_PATH", self.install.lib_dir.join("lib"))
            .stdin(Stdio::null())
            .stdout(file("stdout.txt")?)
            .stderr(file("stderr.txt")?)
            .process_group(0)
            .spawn()
            .map_err(|source| Error::Command {
                line: self.lib_dir().join("torcs-bin").display().to_string(),
                source,
            })?;
        let group = child.id() as i32;
        let start = Instant::now();
        loop {
            match child.try_wait() {
                Ok(Some(status)) => return Ok(Ok(status)),
                Ok(None) if start.elapsed() > timeout => {
                    // Its leader not yet reaped, the group cannot have been reused: kill it all.
                    kill_group(group);
                    let _ = child.wait();
                    return Ok(Err(format!(
                        "the game hung: killed after {:.0} s of wall clock",
                        timeout.as_secs_f64()
                    )));
                }
                Ok(None) => std::thread::sleep(Duration::from_millis(2)),
                Err(e) => {
                    kill_group(group);
                    let _ = child.wait();
                    return Err(Error::Command {
                        line: self.lib_dir().join("torcs-bin").display().to_string(),
                        source: e,
                    });
                }
            }
        }
    }

    /// A built-in robot (`bt`, `berniw`, ...) driving `car` on `track` for two laps from the
    /// same standing start, [`ROBOT_GRID_BEHIND`] behind the start line.
    pub fn robot_laps(&self, robot: &str, track: &str, car: &str) -> Result<RobotLaps> {
        let category = self.install.track_category(track)?;
        self.install.check_car(car)?;
        let xml = self
            .install
            .data_dir
            .join("drivers")
            .join(robot)
            .join(format!("{robot}.xml"));
        let original = bounded::read_text(&xml, &bounded::DRIVER_FILE)?;
        let n = LAPS.fetch_add(1, Ordering::Relaxed);
        let dir = LapDir(
            self.root
                .join("laps")
                .join(format!("{}-{n}", std::process::id())),
        );
        let robot_dir = dir.0.join("drivers").join(robot);
        for d in [&robot_dir, &dir.0.join("config"), &dir.0.join("results")] {
            std::fs::create_dir_all(d).map_err(|source| Error::Io {
                path: d.to_path_buf(),
                source,
            })?;
        }
        // Its driver 0 in our car: the robot's own file with every car name replaced.
        let key = "name=\"car name\" val=\"";
        let ours = original
            .lines()
            .map(|l| match l.find(key) {
                Some(i) => {
                    let (head, rest) = l.split_at(i + key.len());
                    let tail = rest.find('"').map_or("", |j| &rest[j..]);
                    format!("{head}{car}{tail}")
                }
                None => l.to_owned(),
            })
            .collect::<Vec<_>>()
            .join("\n");
        let race = race_xml(
            track,
            &category,
            robot,
            first_driver(&original),
            2,
            ROBOT_GRID_BEHIND,
        );
        let files = [
            (robot_dir.join(format!("{robot}.xml")), ours),
            (dir.0.join("race.xml"), race),
        ];
        for (path, text) in &files {
            std::fs::write(path, text).map_err(|source| Error::Io {
                path: path.clone(),
                source,
            })?;
        }
        let engine = self.root.join("conf/config/raceengine.xml");
        std::fs::copy(&engine, dir.0.join("config/raceengine.xml")).map_err(|source| {
            Error::Io {
                path: engine.clone(),
                source,
            }
        })?;
        self.run_race(&dir.0, DEFAULT_TIMEOUT)?
            .map_err(|why| Error::External {
                program: format!("the TORCS robot {robot} on {track}"),
                message: why,
            })?;
        // "Sim Time: T [s], Leader Laps: 1, ..." is printed as the first lap ends.
        let stdout = game_file(&dir.0.join("stdout.txt"))?;
        let first = stdout
            .lines()
            .find(|l| l.contains("Leader Laps:    1") || l.contains("Leader Laps: 1,"))
            .and_then(|l| l.split_whitespace().nth(2))
            .and_then(|t| t.parse::<f64>().ok());
        let results = dir.0.join("results");
        let best = find_number(&results, "best lap time")?;
        let damage = find_number(&results, "dammages")?;
        match (first, best, damage) {
            (Some(first), Some(best), Some(damage)) => Ok(RobotLaps {
                first,
                best: (best > 0.0).then_some(best),
                damage,
            }),
            _ => Err(Error::External {
                program: format!("the TORCS robot {robot} on {track} in {car}"),
                message: format!(
                    "no lap times in the game's output ({})",
                    tail(&dir.0.join("stderr.txt"))
                ),
            }),
        }
    }
}

/// A shipped robot's two laps from a standing start ([`Game::robot_laps`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RobotLaps {
    /// The first lap's time (s), from the standing start.
    pub first: f64,
    /// The best lap's time (s); none where the game records none (0: the robot did not
    /// finish its second lap).
    pub best: Option<f64>,
    /// The car's damage after both laps, as the game's results give it. simuv2 (`collide.cpp`)
    /// adds ⌊k·(½(v_n²/|v|)² + 0.005·|1 − v_n/|v||·|v|)⌋ at each step a corner of the body
    /// presses into a barrier (v the car's velocity, v_n its part along the barrier's normal, k
    /// the barrier surface's damage factor), and a little for wheels on rough surfaces: 0 means
    /// no barrier struck harder than a graze.
    pub damage: f64,
}

/// The value of the first `<attnum name="NAME" val="V"/>` in the XML files under `dir`
/// (each read as a [`game_file`]).
fn find_number(dir: &Path, name: &str) -> Result<Option<f64>> {
    let key = format!("name=\"{name}\" val=\"");
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(None);
    };
    for entry in entries.filter_map(|e| e.ok()) {
        let path = entry.path();
        let found = if path.is_dir() {
            find_number(&path, name)?
        } else {
            let text = game_file(&path)?;
            text.find(&key).and_then(|i| {
                let rest = &text[i + key.len()..];
                rest[..rest.find('"')?].parse().ok()
            })
        };
        if found.is_some() {
            return Ok(found);
        }
    }
    Ok(None)
}

/// A file the game or its robot wrote, through [`bounded::GAME_OUTPUT`]: its text, empty
/// when it is missing, unreadable or not UTF-8 (the lap then says what it lacks), refused
/// when it is past the bound.
fn game_file(path: &Path) -> Result<String> {
    match bounded::read_text(path, &bounded::GAME_OUTPUT) {
        Err(e @ Error::InputTooLarge { .. }) => Err(e),
        read => Ok(read.unwrap_or_default()),
    }
}

/// cdbo's time limit, 30 s + L / (4 m/s), with L the game's track length; 30 min if the track
/// cannot be read.
fn default_time_limit(install: &crate::torcs::Install, track: &str, category: &str) -> f64 {
    let file = install
        .data_dir
        .join("tracks")
        .join(category)
        .join(track)
        .join(format!("{track}.xml"));
    crate::track::torcs::read(&file, crate::track::Ends::MayMiss)
        .map(|t| 30.0 + t.length / 4.0)
        .unwrap_or(1800.0)
}

/// Kills a process group (nothing happens if it is gone).
fn kill_group(group: i32) {
    // SAFETY: kill(2) with a negative pid signals that process group; no memory is involved.
    unsafe {
        libc::kill(-group, libc::SIGKILL);
    }
}

/// The last line of a file, at most 300 bytes of it: only its last 300 bytes are read.
fn tail(path: &Path) -> String {
    const TAIL: u64 = 300;
    let mut text = String::new();
    if let Ok(mut f) = std::fs::File::open(path) {
        let len = f.metadata().map_or(0, |m| m.len());
        let _ = f.seek(SeekFrom::Start(len.saturating_sub(TAIL)));
        let mut buf = Vec::new();
        let _ = f.take(TAIL).read_to_end(&mut buf);
        text = String::from_utf8_lossy(&buf).into_owned();
    }
    text.lines()
        .rfind(|l| !l.trim().is_empty())
        .unwrap_or("no output")
        .trim()
        .to_owned()
}

#[cfg(test)]
mod tests {
    use super::first_driver;

    #[test]
    fn a_robots_first_driver_is_its_first_numbered_index_section() {
        let berniw = r#"<section name="Robots"><section name="index">
            <section name="1"><attstr name="name" val="berniw 1"/></section>
            <section name="2"></section></section></section>"#;
        assert_eq!(first_driver(berniw), 1);
        let bt = r#"<section name="Robots"><section name="index"><section name="0">"#;
        assert_eq!(first_driver(bt), 0);
        assert_eq!(first_driver("<params/>"), 0);
    }
}
