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
