//! `cdbo report`: the paper's figures and tables from one or more experiment folders (the
//! shards of a grid are merged): Fig. 4/5 learning curves, Fig. 3 best policy and speeds,
//! Fig. 2 the policy length-scale's effect on the demonstration fit, Table 1 run times, the
//! trade-off of best reward against failed laps per panel, and `results.md` checking the
//! paper's claims with numbers and naming the best method within a failure budget.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use clap::Args;
use plotters::style::{BLACK, BLUE, GREEN, RED, RGBColor};

use super::{CliResult, load_track};
use crate::figures::{Cloud, LineChart, Panels, Scatter, draw, speed_chart};
use cdbo::car::catalog as cars;
use cdbo::data_path::DataPath;
use cdbo::experiment::folder::Session;
use cdbo::experiment::record::RunRecord;
use cdbo::experiment::shared::SharedGrid;
use cdbo::experiment::summary::{
    Cell, Curve, Tradeoff, best_within, cell_means, claims, curves, failed_laps, times, tradeoffs,
};
use cdbo::method::Method;
use cdbo::policy::RkhsPolicy;
use cdbo::policy::rkhs::{DEFAULT_RIDGE, default_lengthscale};
use cdbo::study::Location;

#[derive(Debug, Args)]
pub struct ReportArgs {
    /// Experiment folders written by `cdbo experiment` (shards of one grid are merged).
    #[arg(required_unless_present = "storage", conflicts_with = "storage")]
    dirs: Vec<PathBuf>,
    /// A grid in a database, filled by `cdbo experiment GRID --storage URL --worker`: an
    /// SQLite file (FILE or sqlite://FILE) or postgresql://USER@HOST[:PORT]/DB#GRID.
    #[arg(long, value_name = "URL|FILE")]
    storage: Option<String>,
    /// With --storage: also write the grid as an experiment folder (experiment.toml, runs/,
    /// sessions.jsonl), which `cdbo report DIR` reads the same.
    #[arg(long, value_name = "DIR", requires = "storage")]
    export: Option<PathBuf>,
    /// Output folder (default: DIR/report for the first DIR; with --storage,
    /// runs/report-GRID).
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Car the runs used.
    #[arg(long, default_value = cars::DEFAULT)]
    car: String,
}

/// The method's colour ([`Method::colour`]), the same in every figure; black for a name
/// this version does not know.
fn colour(method: &str) -> RGBColor {
    method.parse::<Method>().map_or(BLACK, |m| {
        let (r, g, b) = m.colour();
        RGBColor(r, g, b)
    })
}

/// The failure budgets a report weighs methods by, as shares of a run's laps: 10 % (30 of the
/// paper's 300 laps, the cap for a real car) and 30 % (a crash every third lap, where
/// the pattern search and CDBO sit).
const FAILURE_SHARES: [f64; 2] = [0.1, 0.3];

/// A number of laps as a cap reads: whole, or with one decimal (10 % of 25 laps is 2.5).
fn laps_text(laps: f64) -> String {
    if laps.fract() == 0.0 {
        format!("{laps:.0}")
    } else {
        format!("{laps:.1}")
    }
}

/// Figure name of a track's learning curves: the paper's Fig. 4 (Forza) and 5 (Allondaz).
fn curves_name(track: &str) -> String {
    match track {
        "forza" => "fig4_forza".into(),
        "allondaz" => "fig5_allondaz".into(),
        t => format!("curves_{t}"),
    }
}

/// The runs and sessions to report, where they came from, and the default output folder:
/// from experiment folders, or from a grid in a database (the same records).
fn load(args: &ReportArgs) -> Result<(Vec<RunRecord>, Vec<Session>, String, PathBuf), String> {
    if let Some(storage) = &args.storage {
        let location = Location::parse(storage, None).map_err(|e| e.to_string())?;
        let mut grid = SharedGrid::open_read_only(&location).map_err(|e| e.to_string())?;
        if let Some(dir) = &args.export {
            let n = grid.export(dir).map_err(|e| match e {
                cdbo::Error::DifferentGrid { .. } => format!("{e}; choose another --export"),
                e => e.to_string(),
            })?;
            println!("{n} runs exported to {}", dir.display());
        }
        let records = grid.records().map_err(|e| e.to_string())?;
        let sessions = grid.sessions().map_err(|e| e.to_string())?;
        let name = match &location {
            Location::Postgres { study, .. } => study.clone(),
            Location::Sqlite(path) => path
                .file_stem()
                .map_or("grid".into(), |s| s.to_string_lossy().into_owned()),
        };
        let label = grid.path().display().to_string();
        if records.is_empty() {
            return Err(format!(
                "no finished runs in the grid at {label} (run `cdbo experiment GRID --storage URL --worker` first)"
            ));
        }
        return Ok((
            records,
            sessions,
            format!("the grid at {label}"),
            PathBuf::from("runs").join(format!("report-{name}")),
        ));
    }
    let records = RunRecord::load_all(&args.dirs).map_err(|e| match e {
        cdbo::Error::Io { .. } => format!("{e} (expected the output folder of `cdbo experiment`)"),
        e => e.to_string(),
    })?;
    if records.is_empty() {
        return Err(format!(
            "no finished runs under {} (run `cdbo experiment` first)",
            args.dirs
                .iter()
                .map(|d| d.join("runs").display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    let sessions = Session::load_all(&args.dirs).map_err(|e| e.to_string())?;
    Ok((
        records,
        sessions,
        format!("{} folder(s)", args.dirs.len()),
        args.dirs[0].join("report"),
    ))
}

pub fn run(args: &ReportArgs, data: &DataPath) -> CliResult {
    let (records, sessions, source, default_out) = load(args)?;
    let out = args.out.clone().unwrap_or(default_out);
    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let car = cars::find(&args.car, data)?;
    let curves = curves(&records);
    let tradeoffs = tradeoffs(&records);
    let mut tracks: Vec<String> = records.iter().map(|r| r.spec.track.clone()).collect();
    tracks.dedup();
    let mut figures = Vec::new();
    for track in &tracks {
        let name = curves_name(track);
        learning_curves(&out, &name, track, &curves)?;
        figures.push((
            format!("Best reward vs laps on {track}, mean ± standard error"),
            name,
        ));
        figures.extend(tradeoff_figures(&out, track, &tradeoffs)?);
        if let Some(best) = best_cdbo_run(&records, track) {
            let mut sim = cdbo::sim::Simulator::new(load_track(track, data)?, &car);
            // Driven on the line and with the steering the run was raced with, the
            // demonstration's included.
            sim.config.line = best.base_line.line(&sim.track, &car)?;
            sim.config.steering = best.steering.steering();
            let (_, demo) = sim.demonstrate(best.demo_speed);
            let names = best_policy_figures(&out, track, sim, &car, &demo, best)?;
            figures.push((
                format!(
                    "Best CDBO policy on {track} ({} kernels, line {}) against π(w₀)",
                    best.spec.kernels,
                    best.line().label()
                ),
                names.0,
            ));
            figures.push((
                format!("Speeds of π(w₀), the best CDBO policy and the limit on {track}"),
                names.1,
            ));
            let name = lengthscale_figure(&out, track, &demo, best.spec.kernels)?;
            figures.push((
                format!("Fit of the demonstration on {track} for three length-scales"),
                name,
            ));
        }
    }
    let table = table1(&records);
    std::fs::write(out.join("table1.md"), &table)?;
    let results = results_md(&records, &curves, &tradeoffs, &figures, &table, &sessions);
    std::fs::write(out.join("results.md"), results)?;
    println!(
        "{} runs from {source}: report in {}",
        records.len(),
        out.display()
    );
    Ok(())
}

/// The policy sizes raced on `track`, ascending (the cells are ordered by track, size, method).
fn sizes_on<V>(cells: &std::collections::BTreeMap<Cell, V>, track: &str) -> Vec<usize> {
    let mut sizes: Vec<usize> = cells.keys().filter(|c| c.0 == track).map(|c| c.1).collect();
    sizes.dedup();
    sizes
}

fn learning_curves(
    out: &Path,
    name: &str,
    track: &str,
    curves: &std::collections::BTreeMap<(String, usize, String), Curve>,
) -> CliResult {
    let sizes = sizes_on(curves, track);
    let panels = Panels {
        titles: sizes
            .iter()
            .map(|m| format!("{track}, {m} kernels"))
            .collect(),
        x_label: "lap".into(),
        y_label: "best reward L/T (m/s)".into(),
        panels: sizes
            .iter()
            .map(|&m| {
                curves
                    .iter()
                    .filter(|(c, _)| c.0 == track && c.1 == m)
                    .map(|(c, curve)| {
                        (
                            format!("{} ({} runs)", c.2, curve.runs),
                            colour(&c.2),
                            curve
                                .mean
                                .iter()
                                .zip(&curve.se)
                                .enumerate()
                                .map(|(k, (m, s))| ((k + 1) as f64, *m, *s))
                                .collect(),
                        )
                    })
                    .collect()
            })
            .collect(),
    };
    for ext in ["png", "svg"] {
        draw(&out.join(format!("{name}.{ext}")), &panels)?;
    }
    Ok(())
}

/// One figure per panel of `track` (policy size): each method's best reward against its
/// failed laps, every run a faint dot and the mean ± standard error a filled one, with the
/// [`FAILURE_SHARES`] as dashed lines. Returns (caption, file name) of each.
fn tradeoff_figures(
    out: &Path,
    track: &str,
    tradeoffs: &std::collections::BTreeMap<Cell, Tradeoff>,
) -> Result<Vec<(String, String)>, Box<dyn std::error::Error>> {
    let sizes = sizes_on(tradeoffs, track);
    let mut figures = Vec::new();
    for m in sizes {
        let panel: Vec<(&Cell, &Tradeoff)> = tradeoffs
            .iter()
            .filter(|(c, _)| c.0 == track && c.1 == m)
            .collect();
        let laps = panel.iter().map(|(_, t)| t.laps).max().unwrap_or(0);
        let chart = Scatter {
            title: format!("{track}, {m} kernels: best reward against failed laps"),
            x_label: format!("failed laps per run (of {laps})"),
            y_label: "best reward L/T (m/s)".into(),
            clouds: panel
                .iter()
                .map(|(c, t)| Cloud {
                    label: format!(
                        "{} ({} runs): {:.2} m/s, {:.0} failed",
                        c.2,
                        t.runs.len(),
                        t.best.0,
                        t.failed.0
                    ),
                    colour: colour(&c.2),
                    points: t.runs.clone(),
                    mean: (t.failed.0, t.best.0),
                    se: (t.failed.1, t.best.1),
                })
                .collect(),
            marks: FAILURE_SHARES
                .iter()
                .map(|s| {
                    let cap = s * laps as f64;
                    (
                        format!("{:.0} % of the laps ({})", 100.0 * s, laps_text(cap)),
                        cap,
                    )
                })
                .collect(),
        };
        let name = format!("tradeoff_{track}_{m}");
        for ext in ["png", "svg"] {
            draw(&out.join(format!("{name}.{ext}")), &chart)?;
        }
        figures.push((
            format!(
                "Best reward against failed laps on {track}, {m} kernels (each run faint, mean ± standard error)"
            ),
            name,
        ));
    }
    Ok(figures)
}

/// The lines of `results.md` naming, per panel, the method with the best mean reward within
/// each of the [`FAILURE_SHARES`] of failed laps, and the best with no cap.
fn budget_lines(tradeoffs: &std::collections::BTreeMap<Cell, Tradeoff>) -> String {
    let mut panels: Vec<(&str, usize)> = tradeoffs.keys().map(|c| (c.0.as_str(), c.1)).collect();
    panels.dedup();
    let mut s = String::new();
    for (track, m) in panels {
        let panel = || {
            tradeoffs
                .iter()
                .filter(move |(c, _)| c.0 == track && c.1 == m)
                .map(|(c, t)| (c.2.as_str(), t))
        };
        let named = |best: Option<(&str, &Tradeoff)>| match best {
            Some((method, t)) => format!(
                "{method} {:.2} ± {:.2} m/s ({:.1} failed)",
                t.best.0, t.best.1, t.failed.0
            ),
            None => "none".into(),
        };
        let laps = panel().map(|(_, t)| t.laps).max().unwrap_or(0);
        let _ = write!(s, "- {track} {m}:");
        for share in FAILURE_SHARES {
            let _ = write!(
                s,
                " at most {:.0} % ({} a run): {};",
                100.0 * share,
                laps_text(share * laps as f64),
                named(best_within(panel(), share))
            );
        }
        let _ = writeln!(s, " no cap: {}", named(best_within(panel(), f64::INFINITY)));
    }
    s
}

/// The best CDBO run on a track at its middle policy size.
fn best_cdbo_run<'a>(records: &'a [RunRecord], track: &str) -> Option<&'a RunRecord> {
    let cdbo: Vec<&RunRecord> = records
        .iter()
        .filter(|r| r.spec.track == track && r.spec.method == Method::Cdbo.name())
        .collect();
    let mut sizes: Vec<usize> = cdbo.iter().map(|r| r.spec.kernels).collect();
    sizes.sort();
    sizes.dedup();
    let middle = *sizes.get(sizes.len() / 2)?;
    cdbo.into_iter()
        .filter(|r| r.spec.kernels == middle)
        .max_by(|a, b| a.best_reward_mps.total_cmp(&b.best_reward_mps))
}

/// Fig. 3: the best policy against π(w₀) (a) and their speeds against the limit (b).
fn best_policy_figures(
    out: &Path,
    track_name: &str,
    mut sim: cdbo::sim::Simulator,
    car: &cdbo::car::Car,
    demo: &[(f64, f64)],
    best: &RunRecord,
) -> Result<(String, String), Box<dyn std::error::Error>> {
    let limit = cdbo::limit::limit_lap(&sim.track, car);
    let initial = RkhsPolicy::fit(demo, best.spec.kernels, best.lengthscale, DEFAULT_RIDGE)?;
    let raced = best.best_policy()?;
    let best_policy = &raced.policy.pedal;
    sim.config.trace = true;
    let initial_lap = sim.lap(&mut initial.pedal());
    let best_lap = sim.lap(&mut raced.policy.driver());
    let xs = || (0..=500).map(|i| i as f64 / 500.0);
    let policies = LineChart {
        title: format!("{track_name}: policies ({} kernels)", best.spec.kernels),
        x_label: "x (fraction of the lap)".into(),
        y_label: "a (throttle + / brake −)".into(),
        series: vec![
            (
                "initial π(w₀)".into(),
                GREEN,
                xs().map(|x| (x, initial.action(x))).collect(),
            ),
            (
                format!("best CDBO ({:.2} m/s)", best.best_reward_mps),
                BLUE,
                xs().map(|x| (x, best_policy.action(x))).collect(),
            ),
        ],
    };
    let speeds = speed_chart(
        &sim.track,
        &[
            ("initial π(w₀)", GREEN, &initial_lap),
            ("best CDBO", BLUE, &best_lap),
        ],
        &limit,
    );
    let (a, b) = (
        format!("fig3a_policy_{track_name}"),
        format!("fig3b_speed_{track_name}"),
    );
    for ext in ["png", "svg"] {
        draw(&out.join(format!("{a}.{ext}")), &policies)?;
        draw(&out.join(format!("{b}.{ext}")), &speeds)?;
    }
    Ok((a, b))
}

/// Fig. 2: the demonstration and its ridge fits with ¼, 1 and 4 times the default length-scale
/// 1/(M − 1), with each fit's RMS error.
fn lengthscale_figure(
    out: &Path,
    track_name: &str,
    demo: &[(f64, f64)],
    kernels: usize,
) -> Result<String, Box<dyn std::error::Error>> {
    let mut series = vec![(
        "demonstration".to_owned(),
        BLACK,
        demo.iter().step_by(5).copied().collect::<Vec<_>>(),
    )];
    for (factor, c) in [(0.25, RED), (1.0, BLUE), (4.0, GREEN)] {
        let l = factor * default_lengthscale(kernels);
        let p = RkhsPolicy::fit(demo, kernels, l, DEFAULT_RIDGE)?;
        let rms = (demo
            .iter()
            .map(|(x, a)| (p.action(*x) - a).powi(2))
            .sum::<f64>()
            / demo.len() as f64)
            .sqrt();
        series.push((
            format!("l = {l:.4} (RMS error {rms:.4})"),
            c,
            (0..=1000)
                .map(|i| i as f64 / 1000.0)
                .map(|x| (x, p.action(x)))
                .collect(),
        ));
    }
    let chart = LineChart {
        title: format!("{track_name}: fitting the demonstration with {kernels} kernels"),
        x_label: "x (fraction of the lap)".into(),
        y_label: "a".into(),
        series,
    };
    let name = format!("fig2_lengthscale_{track_name}");
    for ext in ["png", "svg"] {
        draw(&out.join(format!("{name}.{ext}")), &chart)?;
    }
    Ok(name)
}

/// Table 1: average seconds per run, by method (rows) and track / size (columns).
fn table1(records: &[RunRecord]) -> String {
    let times = times(records);
    let mut columns: Vec<(String, usize)> = times.keys().map(|c| (c.0.clone(), c.1)).collect();
    columns.dedup();
    let mut methods: Vec<String> = Vec::new();
    for c in times.keys() {
        if !methods.contains(&c.2) {
            methods.push(c.2.clone());
        }
    }
    let mut s = String::from(
        "Average time per run in seconds: optimiser (wall clock of the whole run incl. the simulator).\n\n| method |",
    );
    for (t, m) in &columns {
        let _ = write!(s, " {t} {m} |");
    }
    s += "\n|---|";
    s += &"---:|".repeat(columns.len());
    s += "\n";
    for method in &methods {
        let _ = write!(s, "| {method} |");
        for (t, m) in &columns {
            match times.get(&(t.clone(), *m, method.clone())) {
                Some((wall, opt, _, _)) => {
                    let _ = write!(s, " {opt:.1} ({wall:.1}) |");
                }
                None => s += " – |",
            }
        }
        s += "\n";
    }
    s
}

fn results_md(
    records: &[RunRecord],
    curves: &std::collections::BTreeMap<(String, usize, String), Curve>,
    tradeoffs: &std::collections::BTreeMap<Cell, Tradeoff>,
    figures: &[(String, String)],
    table: &str,
    sessions: &[Session],
) -> String {
    let mut s = String::from("# Results\n\n");
    let wall: f64 = records.iter().map(|r| r.wall_s).sum();
    let _ = writeln!(
        s,
        "{} runs; {:.0} s of run time in total, summed over the runs.",
        records.len(),
        wall
    );
    let mut lines = std::collections::BTreeMap::<String, usize>::new();
    for r in records {
        *lines.entry(r.line().label()).or_default() += 1;
    }
    let lines: Vec<String> = lines
        .into_iter()
        .map(|(line, n)| format!("{line} ({n} runs)"))
        .collect();
    let _ = writeln!(
        s,
        "The line the cars held (`line` in the grid, as `cdbo race --line`): {}.",
        lines.join(", ")
    );
    for session in sessions.iter().filter(|s| s.runs > 0) {
        let _ = writeln!(
            s,
            "`cdbo experiment` ran {} of them in {:.1} min of wall clock with {} parallel jobs.",
            session.runs,
            session.wall_s / 60.0,
            session.jobs
        );
    }
    s += "\n";
    s += "## The paper's claims\n\n";
    for c in claims(records) {
        let verdict = match c.holds {
            Some(true) => "**holds**",
            Some(false) => "**does not hold**",
            None => "cannot be checked on these runs",
        };
        let _ = writeln!(s, "- {}: {verdict}. {}", c.statement, c.evidence);
    }
    s += "\n## Final best reward (m/s), mean ± standard error\n\n% of limit: of the quasi-steady-state limit on the centre line (`cdbo limit`, which gives the minimum-curvature line's beside it); % of the ceiling: of the tracked limit profile's lap (`cdbo ceiling`), where the runs recorded it; failed laps: mean per run.\n\n| track | kernels | method | runs | best | × demonstration | % of limit | % of ceiling | failed laps |\n|---|---:|---|---:|---:|---:|---:|---:|---:|\n";
    let demos = cell_means(records, |r| r.demo_reward_mps);
    let limits = cell_means(records, |r| r.limit_reward_mps);
    let ceilings = cell_means(records, |r| r.ceiling_reward_mps.unwrap_or(f64::NAN));
    let failed = cell_means(records, |r| failed_laps(r) as f64);
    for (cell, curve) in curves {
        let (t, m, method) = cell;
        let (demo, limit, ceiling) = (demos[cell], limits[cell], ceilings[cell]);
        let (mean, se) = curve.last();
        let of_ceiling = if ceiling.is_finite() {
            format!("{:.1}", 100.0 * mean / ceiling)
        } else {
            "–".into()
        };
        let _ = writeln!(
            s,
            "| {t} | {m} | {method} | {} | {mean:.2} ± {se:.2} | {:.2} | {:.1} | {of_ceiling} | {:.0} |",
            curve.runs,
            mean / demo,
            100.0 * mean / limit,
            failed[cell]
        );
    }
    s += "\n## Best reward within a budget of failed laps\n\nPer panel, the method with the highest mean best reward among those whose failed laps a run, on average, are at most the share of the laps named (mean ± standard error over the runs; mean failed laps a run); the figures `tradeoff_TRACK_KERNELS` below show every method and run.\n\n";
    s += &budget_lines(tradeoffs);
    s += "\n## Run times (Table 1)\n\n";
    s += table;
    s += "\n## Figures\n\n";
    for (caption, name) in figures {
        let _ = writeln!(
            s,
            "- {caption}: [{name}.png]({name}.png) ([svg]({name}.svg))"
        );
    }
    s
}
