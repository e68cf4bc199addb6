//! `cdbo torcs`: set up the game TORCS as a source of laps, and check it with a lap.

use clap::Subcommand;
use serde::Serialize;

use super::{CliResult, print_json};
use cdbo::torcs::{self, Game, GamePedal, Install};

#[derive(Debug, Subcommand)]
pub enum TorcsCommand {
    /// Compile cdbo's robot against the TORCS headers (CDBO_TORCS_SDK, else
    /// ../shared/torcs-sdk) and lay out a private game tree in the cache folder
    /// (CDBO_TORCS_CACHE, else ~/.cache/cdbo/torcs).
    Setup {
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Drive one demonstration lap in the game; print the game's version, paths and the lap.
    Check {
        /// TORCS track name.
        #[arg(long, default_value = "forza")]
        track: String,
        /// TORCS car name.
        #[arg(long, default_value = torcs::DEFAULT_CAR)]
        car: String,
        /// Demonstration speed (m/s).
        #[arg(long, default_value_t = 15.0)]
        demo: f64,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// cdbo's simulator against the game: demonstrations, full throttle, policies drawn
    /// around a learned one, speed along the lap, the limit against a built-in robot.
    Compare(super::torcs_compare::CompareArgs),
    /// cdbo's simulator scored again against the game's laps a compare kept
    /// (OUT/panel_TRACK.jsonl), without the game: completion agreement and lap-time error per
    /// track, in seconds, for a change to the model or a calibrated car (--car car.toml).
    Panel(super::torcs_panel::PanelArgs),
    /// Fit the simulator's uncertain car parameters (grip, peak slip, drag, downforce,
    /// rolling resistance, launch) to traced laps of chosen policies in the game, or to a real
    /// car's logged laps (--log); write the calibrated car (car.toml, for --car) and the
    /// agreement before and after, on the calibration and the check tracks.
    Calibrate(super::torcs_calibrate::CalibrateArgs),
    /// Learn in cdbo's simulator, race in the game: on each track (default: every road track
    /// installed) a policy learned as `cdbo race` learns it, its best driven once in the game,
    /// beside its simulated lap.
    Transfer(super::torcs_transfer::TransferArgs),
    /// From a track to a race-ready policy: cdbo's simulator (the ceiling's policy, or the
    /// recommended learner's), then a bounded number of the recommended learner's laps in the
    /// game, the best policy's standing and flying laps beside the fastest shipped robot's.
    Learn(super::torcs_learn::LearnArgs),
    /// Time every shipped TORCS robot that can drive the car: its standing first lap and its
    /// best (flying) lap of two, alone, from a clean start, headless — the table cdbo's
    /// learned laps are judged against — beside cdbo's QSS limit on the centre line.
    Robots {
        /// TORCS track names, comma-separated, or `road` for every road track installed; more
        /// than one track ends with a table of the fastest robot on each.
        #[arg(long, default_value = "forza", value_delimiter = ',')]
        track: Vec<String>,
        /// TORCS car name.
        #[arg(long, default_value = torcs::DEFAULT_CAR)]
        car: String,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
}

#[derive(Debug, Serialize)]
struct SetupReport {
    version: String,
    game: String,
    data: String,
    tree: String,
    robot: String,
}

fn report(game: &Game) -> SetupReport {
    SetupReport {
        version: game.install.version(),
        game: game.install.lib_dir.display().to_string(),
        data: game.install.data_dir.display().to_string(),
        tree: game.root.display().to_string(),
        robot: game.robot().display().to_string(),
    }
}

pub fn run(cmd: &TorcsCommand, data: &cdbo::data_path::DataPath) -> CliResult {
    match cmd {
        TorcsCommand::Compare(args) => super::torcs_compare::run(args, data),
        TorcsCommand::Panel(args) => super::torcs_panel::run(args, data),
        TorcsCommand::Calibrate(args) => super::torcs_calibrate::run(args, data),
        TorcsCommand::Transfer(args) => super::torcs_transfer::run(args, data),
        TorcsCommand::Learn(args) => super::torcs_learn::run(args, data),
        TorcsCommand::Robots { track, car, json } => robots(track, car, *json),
        TorcsCommand::Setup { json } => {
            let install = Install::find()?;
            let game = torcs::setup(&install, &torcs::sdk_dir()?, &torcs::cache_dir()?)?;
            let r = report(&game);
            if *json {
                return print_json(&r);
            }
            println!(
                "TORCS {} ready: robot {}, private tree {} (game {}, data {})",
                r.version, r.robot, r.tree, r.game, r.data
            );
            Ok(())
        }
        TorcsCommand::Check {
            track,
            car,
            demo,
            json,
        } => {
            if !(demo.is_finite() && *demo > 0.0) {
                return Err(
                    format!("--demo {demo}: the target speed must be positive (m/s)").into(),
                );
            }
            let game = Game::ready()?;
            let req = game.request(track, car, GamePedal::Demo(*demo))?;
            let start = std::time::Instant::now();
            let lap = game
                .lap(&req)?
                .map_err(|reason| format!("TORCS drove no lap: {reason}"))?;
            let wall_s = start.elapsed().as_secs_f64();
            #[derive(Serialize)]
            struct Check {
                #[serde(flatten)]
                setup: SetupReport,
                track: String,
                car: String,
                lap: cdbo::sim::LapResult,
                wall_s: f64,
            }
            let c = Check {
                setup: report(&game),
                track: track.clone(),
                car: car.clone(),
                lap,
                wall_s,
            };
            if *json {
                return print_json(&c);
            }
            println!(
                "TORCS {} (game {}, data {})",
                c.setup.version, c.setup.game, c.setup.data
            );
            println!("private tree {}, robot {}", c.setup.tree, c.setup.robot);
            println!(
                "{} on {}, demonstration at {demo} m/s: {} ({:.1} s of wall clock)",
                c.car,
                c.track,
                super::lap::describe(&c.lap),
                c.wall_s
            );
            Ok(())
        }
    }
}

/// One row of the robots table: a shipped robot's laps and damage
/// ([`cdbo::torcs::RobotLaps`]), or why it drove none.
#[derive(Debug, Serialize)]
struct RobotRow {
    robot: String,
    /// The first lap from the standing start (s).
    first_lap_s: Option<f64>,
    /// The best of its two laps, the second a flying one (s).
    best_lap_s: Option<f64>,
    /// The car's damage after the two laps (0: no barrier struck harder than a graze).
    damage: Option<f64>,
    /// Why it drove no lap.
    error: Option<String>,
}

/// A robot and its lap (s).
type RobotLap<'a> = Option<(&'a str, f64)>;

/// The robots table of one track ([`robots_on`]).
#[derive(Debug, Serialize)]
pub(super) struct RobotsTable {
    track: String,
    car: String,
    limit_lap_time_s: f64,
    robots: Vec<RobotRow>,
}

impl RobotsTable {
    /// The fastest robot's standing first lap and best (flying) lap, each with its robot.
    pub(super) fn fastest(&self) -> (RobotLap<'_>, RobotLap<'_>) {
        let best = |lap: fn(&RobotRow) -> Option<f64>| {
            self.robots
                .iter()
                .filter_map(|r| Some((r.robot.as_str(), lap(r)?)))
                .min_by(|a, b| a.1.total_cmp(&b.1))
        };
        (best(|r| r.first_lap_s), best(|r| r.best_lap_s))
    }
}

/// A lap time in a table's cell: `83.85 s`, or `–` where there is none.
fn lap_cell(lap: Option<f64>) -> String {
    lap.map_or("–".into(), |v| format!("{v:.2} s"))
}

/// `cdbo torcs robots`: the robots table of each track (`road`: every road track installed),
/// then, for more than one track, the fastest robot on each.
fn robots(tracks: &[String], car: &str, json: bool) -> CliResult {
    let game = Game::ready()?;
    let tracks: Vec<String> = if tracks.iter().any(|t| t == "road") {
        game.install.tracks("road")
    } else {
        tracks.to_vec()
    };
    if tracks.is_empty() {
        return Err(format!(
            "no road tracks in the game's {}: name them with --track",
            game.install.data_dir.join("tracks/road").display()
        )
        .into());
    }
    let tables = tracks
        .iter()
        .map(|track| robots_on(&game, track, car, json))
        .collect::<Result<Vec<_>, _>>()?;
    if json {
        return match tables.as_slice() {
            [one] => print_json(one),
            _ => print_json(&tables),
        };
    }
    for table in &tables {
        println!(
            "{} on {}, each robot alone from a standing start; cdbo's QSS limit on the centre line {:.2} s",
            table.car, table.track, table.limit_lap_time_s
        );
        println!("| robot | standing first lap | best (flying) lap | first lap / limit | damage |");
        println!("| --- | --- | --- | --- | --- |");
        for r in &table.robots {
            println!(
                "| {} | {} | {} | {} | {} |",
                r.robot,
                r.first_lap_s.map_or_else(
                    || format!("– ({})", r.error.as_deref().unwrap_or("no lap")),
                    |v| format!("{v:.2} s")
                ),
                lap_cell(r.best_lap_s),
                r.first_lap_s.map_or("–".into(), |v| format!(
                    "{:.1} %",
                    100.0 * table.limit_lap_time_s / v
                )),
                r.damage.map_or("–".into(), |d| format!("{d:.0}")),
            );
        }
        println!();
    }
    if tables.len() > 1 {
        println!("{car}: the fastest robot on each track, alone, headless, from a clean start");
        println!("| track | fastest standing lap | fastest flying lap | cdbo's QSS limit |");
        println!("| --- | --- | --- | --- |");
        for table in &tables {
            let (standing, flying) = table.fastest();
            let cell = |lap: RobotLap| {
                lap.map_or("–".into(), |(robot, t)| format!("{t:.2} s ({robot})"))
            };
            println!(
                "| {} | {} | {} | {:.2} s |",
                table.track,
                cell(standing),
                cell(flying),
                table.limit_lap_time_s
            );
        }
    }
    Ok(())
}

/// Every robot of the installed game but the human driver and cdbo's own (those with a
/// `drivers/NAME/NAME.xml`) on one track, one at a time, fastest standing first lap first.
pub(super) fn robots_on(
    game: &Game,
    track: &str,
    car: &str,
    json: bool,
) -> Result<RobotsTable, Box<dyn std::error::Error>> {
    let req = game.request(track, car, GamePedal::Demo(15.0))?;
    let data = cdbo::data_path::DataPath::new(std::slice::from_ref(&game.install.data_dir));
    let limit = cdbo::limit::limit_lap(&cdbo::track::catalog::find(track, &data)?, &req.car);
    let drivers = game.install.data_dir.join("drivers");
    let mut names: Vec<String> = std::fs::read_dir(&drivers)
        .map_err(|e| format!("{}: {e}", drivers.display()))?
        .filter_map(|d| Some(d.ok()?.file_name().to_string_lossy().into_owned()))
        .filter(|n| n != "human" && n != torcs::ROBOT)
        .filter(|n| drivers.join(n).join(format!("{n}.xml")).is_file())
        .collect();
    names.sort();
    let mut laps: Vec<RobotRow> = names
        .into_iter()
        .map(|robot| {
            let laps = game.robot_laps(&robot, track, car);
            if !json {
                eprintln!(
                    "{track}, {robot}: {}",
                    laps.as_ref().map_or_else(
                        |e| e.to_string(),
                        |l| format!(
                            "first lap {:.2} s, best {}, damage {}",
                            l.first,
                            lap_cell(l.best),
                            l.damage
                        )
                    )
                );
            }
            RobotRow {
                first_lap_s: laps.as_ref().ok().map(|l| l.first),
                best_lap_s: laps.as_ref().ok().and_then(|l| l.best),
                damage: laps.as_ref().ok().map(|l| l.damage),
                error: laps.err().map(|e| e.to_string()),
                robot,
            }
        })
        .collect();
    laps.sort_by(|a, b| {
        let key = |r: &RobotRow| r.first_lap_s.unwrap_or(f64::INFINITY);
        key(a).total_cmp(&key(b))
    });
    Ok(RobotsTable {
        track: track.to_owned(),
        car: car.to_owned(),
        limit_lap_time_s: limit.lap_time_s,
        robots: laps,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(robot: &str, first: Option<f64>, best: Option<f64>) -> RobotRow {
        RobotRow {
            robot: robot.into(),
            first_lap_s: first,
            best_lap_s: best,
            damage: first.map(|_| 0.0),
            error: first.is_none().then(|| "no lap".into()),
        }
    }

    /// The fastest standing and flying laps are each the least of their column, with their own
    /// robots, and a lap that is missing prints as a dash, not as an `Option`.
    #[test]
    fn the_fastest_robot_is_taken_per_lap() {
        let table = RobotsTable {
            track: "aalborg".into(),
            car: "car1-trb1".into(),
            limit_lap_time_s: 79.32,
            robots: vec![
                row("berniw2", Some(78.15), Some(73.96)),
                row("bt", Some(81.56), None),
                row("olethros", None, None),
                row("inferno", Some(85.65), Some(72.5)),
            ],
        };
        assert_eq!(
            table.fastest(),
            (Some(("berniw2", 78.15)), Some(("inferno", 72.5)))
        );
        assert_eq!(lap_cell(Some(105.278)), "105.28 s");
        assert_eq!(lap_cell(None), "–");
    }
}
