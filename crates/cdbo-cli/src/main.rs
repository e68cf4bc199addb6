//! `cdbo`: learn a fast racing policy in few laps with Coordinate Descent Bayesian Optimisation.

// The commands' doc comments are the command line's help text (`postgresql://USER@HOST[:PORT]/DB`
// reads as a link to rustdoc).
#![allow(rustdoc::broken_intra_doc_links)]

mod commands;
mod figures;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Learn to race in few laps: Coordinate Descent Bayesian Optimisation on real TORCS tracks.
#[derive(Debug, Parser)]
#[command(name = "cdbo", version, about, propagate_version = true)]
struct Cli {
    /// A folder to search for tracks and cars by name (repeatable; also CDBO_DATA_PATH and the
    /// TORCS / Speed Dreams install folders).
    #[arg(long = "data-dir", global = true, value_name = "DIR")]
    data_dirs: Vec<PathBuf>,
    /// Where laps are driven: cdbo's simulator, or the game TORCS (`cdbo torcs setup` first).
    #[arg(long, global = true, value_enum, default_value_t = commands::Simulator::Cdbo)]
    simulator: commands::Simulator,
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Learn a fast policy for a track: demonstration, then CDBO for N laps (the main job).
    Race(commands::race::RaceArgs),
    /// Run a grid of races (a TOML file or a preset: paper, paper-plus, quick), resumable and
    /// shardable.
    Experiment(commands::experiment::ExperimentArgs),
    /// Figures, tables and the paper's claims from experiment folders (shards are merged).
    Report(commands::report::ReportArgs),
    /// A persistent ask/tell study for a real car: create, ask, tell, status, best, history,
    /// export.
    #[command(subcommand)]
    Study(commands::study::StudyCommand),
    /// Optimise with an external lap command, every lap saved to a study (resumable).
    Optimize(commands::optimize::OptimizeArgs),
    /// The simulator as a JSON-lines service on stdin/stdout for other optimisers.
    ServeSim(commands::serve_sim::ServeSimArgs),
    /// Drive one lap and report its time, reward and the physical limit.
    Lap(commands::lap::LapArgs),
    /// Drive a logged lap's own steering and pedal through cdbo's car, window by window: where
    /// the model and the car that drove it part.
    Replay(commands::replay::ReplayArgs),
    /// The quasi-steady-state minimum lap time of a car on a track.
    Limit(commands::limit::LimitArgs),
    /// The ceiling: the fastest completed lap tracking k x the limit's speed profile, and the
    /// M-kernel policy fitted to its pedal and repaired where it fails.
    Ceiling(commands::ceiling::CeilingArgs),
    /// A live local web page over studies and experiment folders (read-only).
    Dashboard(commands::dashboard::DashboardArgs),
    /// Inspect tracks.
    #[command(subcommand)]
    Track(commands::track::TrackCommand),
    /// Plot tracks.
    #[command(subcommand)]
    Plot(commands::plot::PlotCommand),
    /// Fit and print RKHS policies.
    #[command(subcommand)]
    Policy(commands::policy::PolicyCommand),
    /// The game TORCS: set it up, check it with a lap.
    #[command(subcommand)]
    Torcs(commands::torcs::TorcsCommand),
    /// Measure speed.
    #[command(subcommand)]
    Bench(commands::bench::BenchCommand),
}

fn main() -> ExitCode {
    // Like other Unix tools, end quietly when the reader of our output goes away
    // (`cdbo study history | head`) instead of panicking on a failed print.
    // SAFETY: restoring a signal's default action, before any other thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return usage_error(&e),
    };
    let data = cdbo::data_path::DataPath::new(&cli.data_dirs);
    // Only these drive laps in the game; anything else would silently drive cdbo's
    // simulator instead.
    let drives_torcs = matches!(
        cli.command,
        Command::Lap(_)
            | Command::Race(_)
            | Command::Optimize(_)
            | Command::Experiment(_)
            | Command::ServeSim(_)
            | Command::Torcs(_)
    );
    if cli.simulator == commands::Simulator::Torcs && !drives_torcs {
        eprintln!(
            "error: --simulator torcs works with `lap`, `race`, `experiment`, `serve-sim` and `optimize --track T` (and `cdbo torcs ...`)"
        );
        return ExitCode::from(2);
    }
    let result = match cli.command {
        Command::Race(args) => commands::race::run(&args, &data, cli.simulator),
        Command::Experiment(args) => commands::experiment::run_grid(&args, &data, cli.simulator),
        Command::Report(args) => commands::report::run(&args, &data),
        Command::Study(cmd) => commands::study::run(&cmd),
        Command::Optimize(args) => commands::optimize::run(&args, cli.simulator, &data),
        Command::ServeSim(args) => commands::serve_sim::run(&args, &data, cli.simulator),
        Command::Lap(args) => commands::lap::run(&args, &data, cli.simulator),
        Command::Replay(args) => commands::replay::run(&args, &data),
        Command::Limit(args) => commands::limit::run(&args, &data),
        Command::Ceiling(args) => commands::ceiling::run(&args, &data),
        Command::Dashboard(args) => commands::dashboard::run(&args, &data),
        Command::Track(cmd) => commands::track::run(&cmd, &data),
        Command::Plot(cmd) => commands::plot::run(&cmd, &data),
        Command::Policy(cmd) => commands::policy::run(&cmd),
        Command::Bench(cmd) => commands::bench::run(&cmd, &data),
        Command::Torcs(cmd) => commands::torcs::run(&cmd, &data),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // The library names no flags: point at the one that adds a data folder.
            let hint = match e.downcast_ref::<cdbo::Error>() {
                Some(cdbo::Error::NotFound {
                    what: "track" | "car",
                    ..
                }) => "; or add a folder with --data-dir DIR",
                _ => "",
            };
            eprintln!("error: {e}{hint}");
            ExitCode::from(2)
        }
    }
}

/// Help and version as clap prints them; a bad command line as one line (the first paragraph
/// of clap's message, without its "For more information" tip), exit status 2.
fn usage_error(e: &clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    if matches!(
        e.kind(),
        ErrorKind::DisplayHelp
            | ErrorKind::DisplayVersion
            | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        let _ = e.print();
        return ExitCode::from(if e.use_stderr() { 2 } else { 0 });
    }
    let text = e.render().to_string();
    let first: Vec<&str> = text
        .lines()
        .take_while(|l| !l.trim().is_empty())
        .map(str::trim)
        .collect();
    eprintln!("{}", first.join(" "));
    ExitCode::from(2)
}
