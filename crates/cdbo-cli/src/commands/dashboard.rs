//! `cdbo dashboard`: a live local web page over studies and experiment folders (read-only).

use std::io::Write;
use std::path::PathBuf;

use cdbo::car::catalog as cars;
use cdbo::data_path::DataPath;
use cdbo::study::Location;
use cdbo_dashboard::store::{Files, is_database};
use cdbo_dashboard::{DEFAULT_BIND, Dashboard};
use clap::Args;

use super::CliResult;

/// Arguments of `cdbo dashboard`.
#[derive(Debug, Args)]
pub struct DashboardArgs {
    /// A study or grid to show (repeatable), opened read-only: an SQLite file (FILE or
    /// sqlite://FILE), one in PostgreSQL (postgresql://USER@HOST[:PORT]/DB#NAME), or every
    /// study and grid of a PostgreSQL database (its URL without #NAME).
    #[arg(long = "storage", visible_alias = "db", value_name = "URL|FILE")]
    studies: Vec<String>,
    /// An experiment output folder to show (repeatable); runs appear as they finish.
    #[arg(long = "experiment", value_name = "DIR")]
    experiments: Vec<PathBuf>,
    /// Address and port to serve on (this machine only by default).
    #[arg(long, default_value = DEFAULT_BIND)]
    bind: String,
    /// The track of the studies that record none, to re-drive their trials on the map.
    #[arg(long)]
    track: Option<String>,
    /// The car re-driven on the map.
    #[arg(long, default_value = cars::DEFAULT)]
    car: String,
}

/// Serves the dashboard until interrupted.
pub fn run(args: &DashboardArgs, data: &DataPath) -> CliResult {
    if args.studies.is_empty() && args.experiments.is_empty() {
        return Err("nothing to show: give --storage STUDY and/or --experiment DIR".into());
    }
    let mut sources = Vec::new();
    let mut databases = Vec::new();
    for storage in &args.studies {
        let found = Files::storage(storage)?;
        if found.is_empty() {
            // Only a whole database can name nothing: its studies and grids join the page as
            // they are created.
            println!(
                "{}: no study or grid in this database yet; they are listed as they are created",
                Location::parse(storage, Some("*"))?.label().display()
            );
        }
        sources.extend(found);
        if is_database(storage) {
            databases.push(storage.clone());
        }
    }
    for dir in &args.experiments {
        sources.push(Files::experiment_source(dir)?);
    }
    let studies = sources.iter().filter(|s| s.study.is_some()).count();
    let experiments = sources.len() - studies;
    let dashboard = Dashboard {
        sources,
        databases,
        store: Box::new(Files),
        study_track: args.track.clone(),
        car: args.car.clone(),
        data: data.clone(),
    };
    let bound = dashboard.bind(&args.bind)?;
    println!(
        "cdbo dashboard on http://{}/ ({} studies, {} experiments); Ctrl-C to stop",
        bound.local_addr()?,
        studies,
        experiments
    );
    std::io::stdout().flush()?;
    bound.serve()?;
    Ok(())
}
