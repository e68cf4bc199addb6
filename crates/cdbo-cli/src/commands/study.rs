//! `cdbo study`: a persistent ask/tell study for optimising a real car, one lap at a time.

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand, ValueEnum};

use super::line::LineArgs;
use super::policy::{read_demo, read_raced_policy};
use super::{CliResult, from_flag, print_json};
use cdbo::drive::steering::SteeringLaw;
use cdbo::line::LineSetting;
use cdbo::method::{Method, Preset};
use cdbo::policy::RacedPolicy;
use cdbo::policy::RkhsPolicy;
use cdbo::policy::rkhs::{DEFAULT_RIDGE, default_lengthscale};
use cdbo::study::{Location, Outcome, Study, StudyConfig, Trial};

/// The study: `--storage URL|FILE`, or the file `NAME.cdbo.db` in the current folder.
#[derive(Debug, Args, Clone)]
pub struct StudyName {
    /// Study name (its name in a database; a file holds one study).
    name: String,
    /// Where the study lives: an SQLite file (FILE or sqlite://FILE; default NAME.cdbo.db)
    /// or a PostgreSQL database (postgresql://USER@HOST[:PORT]/DB, the study named NAME).
    #[arg(long, visible_alias = "db", value_name = "URL|FILE")]
    storage: Option<String>,
}

impl StudyName {
    pub fn location(&self) -> Result<Location, cdbo::Error> {
        match &self.storage {
            Some(s) => Location::parse(s, Some(&self.name)),
            None => Ok(Location::Sqlite(PathBuf::from(format!(
                "{}.cdbo.db",
                self.name
            )))),
        }
    }
}

/// How a policy is printed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// Trial id, weights and an (x, a) table as JSON.
    Json,
    /// The (x, a) table as CSV, after a `# trial ID` comment line.
    Csv,
}

#[derive(Debug, Args)]
pub struct InitialPolicy {
    /// Recorded (x, a) pairs of the initial controller (CSV with x,a columns): w₀ is their ridge fit.
    #[arg(long, value_name = "demo.csv", conflicts_with = "weights")]
    demo: Option<PathBuf>,
    /// Initial weights (JSON written by `cdbo policy fit` or `cdbo race`).
    #[arg(long, value_name = "w0.json")]
    weights: Option<PathBuf>,
    /// Start from a learned policy (JSON, as `cdbo race` writes `best_policy.json`): w₀ is its
    /// weights, as with `--weights`, and the study records that it was warm-started from it
    /// (the pattern search then skips its push, the policy being pushed already, and repairs
    /// it where its first lap fails).
    #[arg(long, value_name = "POLICY.json", conflicts_with_all = ["demo", "weights"])]
    warm_start: Option<PathBuf>,
    /// Policy kernels M.
    #[arg(long, value_parser = super::value::kernels)]
    pub kernels: usize,
    /// Policy length-scale (default 1/(M − 1)).
    #[arg(long, allow_negative_numbers = true, value_parser = super::value::positive)]
    lengthscale: Option<f64>,
    /// The lap's length in metres, if known: pattern search's push then repairs a failed lap
    /// over the 275 m of road before the failure (otherwise over two kernel spacings).
    #[arg(long, value_name = "METRES", allow_negative_numbers = true, value_parser = super::value::positive)]
    track_length: Option<f64>,
    /// A stack by one name, in place of the flags it sets (not with them): fast-safe, the one
    /// we recommend, is `--method safe-pattern-search --steering tracker --line
    /// min-curvature` (the safe search's budget: 30 failed laps, or --max-failed-laps).
    #[arg(long, value_parser = super::preset_parser(), conflicts_with_all = super::PRESET_SETS)]
    preset: Option<Preset>,
    /// Optimiser (default cdbo).
    #[arg(long, value_parser = super::method_parser())]
    method: Option<Method>,
    /// Seed of every random choice (default 0).
    #[arg(long)]
    seed: Option<u64>,
    /// UCB exploration weight β (default 1).
    #[arg(long, allow_negative_numbers = true, value_parser = super::value::non_negative)]
    beta: Option<f64>,
    /// The method's main knob, as `cdbo race --knob` (default: its race value).
    #[arg(long, allow_negative_numbers = true)]
    knob: Option<f64>,
    /// Failed laps allowed: once they have failed, only the best completed lap is driven
    /// again (default: no budget; the safe pattern search's own budget, 30).
    #[arg(long, value_name = "N")]
    max_failed_laps: Option<usize>,
    /// Half-width r of the box [w₀ − r, w₀ + r] the method searches, as `cdbo race
    /// --box-radius` (default 1.5).
    #[arg(long, value_name = "R", allow_negative_numbers = true, value_parser = super::value::box_radius)]
    box_radius: Option<f64>,
    /// The line, as `cdbo race --line` (with `--line learn`, w₀'s line is the base line, d = 0,
    /// unless --weights gives one).
    #[command(flatten)]
    pub line: LineArgs,
    /// How the car steers: written into each lap's policy file (`cdbo lap --policy {policy}`
    /// drives with it) and used in the game (default: the --weights or --warm-start policy's,
    /// else the paper's PI).
    #[arg(long, value_parser = super::steering_parser())]
    steering: Option<SteeringLaw>,
}

impl InitialPolicy {
    /// The optimiser given, or CDBO.
    pub fn method(&self) -> Method {
        self.method_given().unwrap_or(Method::Cdbo)
    }

    /// The optimiser `--method` or `--preset` gives (clap refuses both).
    fn method_given(&self) -> Option<Method> {
        self.preset.map(Preset::method).or(self.method)
    }

    /// The steering `--steering` or `--preset` gives.
    fn steering_given(&self) -> Option<SteeringLaw> {
        self.preset.map(Preset::steering).or(self.steering)
    }

    /// The line flags, with `--preset`'s line.
    fn line_given(&self) -> LineArgs {
        self.line.with_preset(self.preset)
    }

    /// The study's settings from the demonstration or the weights.
    pub fn config(&self) -> Result<StudyConfig, Box<dyn std::error::Error>> {
        let lengthscale = self
            .lengthscale
            .unwrap_or_else(|| default_lengthscale(self.kernels));
        let (base_line, line_kernels) = self.line_given().resolve(self.kernels)?;
        let mut line_w0 = None;
        let mut steering = self.steering_given();
        let (policy, file) = match (
            &self.demo,
            self.weights.as_ref().or(self.warm_start.as_ref()),
        ) {
            (Some(demo), _) => (
                RkhsPolicy::fit(&read_demo(demo)?, self.kernels, lengthscale, DEFAULT_RIDGE)
                    .map_err(|e| format!("{}: {e}", demo.display()))?,
                demo,
            ),
            (None, Some(w)) => {
                let raced = read_raced_policy(w)?;
                // A study's laps are driven by its pedal, open loop (a real car's among them).
                if raced.policy.target.is_some() {
                    return Err(format!(
                        "{}: a policy whose action asks for a target speed (learned from the \
                         profile start); a study learns an open-loop pedal: start it from a \
                         demonstration (--demo) or a policy without a \"target\"",
                        w.display()
                    )
                    .into());
                }
                // A policy drives the line it was raced on; a warm start is a pedal-only
                // policy, as a race's.
                let study_line = LineSetting::of(base_line, line_kernels).label();
                let policy_line = LineSetting::of(
                    raced.base_line,
                    raced.policy.line.as_ref().map(|l| l.kernels()),
                )
                .label();
                let refused = if raced.base_line != base_line
                    || (raced.policy.line.is_some() && line_kernels.is_none())
                {
                    Some(format!("the study's line is {study_line}"))
                } else if self.warm_start.is_some() && line_kernels.is_some() {
                    Some("a warm start is a pedal-only policy, not with --line learn".into())
                } else {
                    None
                };
                if let Some(why) = refused {
                    return Err(format!(
                        "{}: a policy raced on line {policy_line}; {why}",
                        w.display()
                    )
                    .into());
                }
                if steering.is_some_and(|s| s != raced.steering) {
                    return Err(format!(
                        "{}: a policy raced with --steering {}; the study's is {}",
                        w.display(),
                        raced.steering.name(),
                        steering.unwrap_or_default().name()
                    )
                    .into());
                }
                steering = Some(raced.steering);
                line_w0 = raced.policy.line.map(|l| l.weights);
                (raced.policy.pedal, w)
            }
            (None, None) => {
                return Err(
                    "give the initial policy: --demo demo.csv, --weights w0.json or --warm-start POLICY.json"
                        .into(),
                );
            }
        };
        if policy.weights.len() != self.kernels {
            return Err(format!(
                "{}: the initial policy has {} kernels but --kernels is {}",
                file.display(),
                policy.weights.len(),
                self.kernels
            )
            .into());
        }
        let mut w0 = policy.weights;
        if let Some(m) = line_kernels {
            let line = line_w0.unwrap_or_else(|| vec![0.0; m]);
            if line.len() != m {
                return Err(format!(
                    "{}: the initial policy's line has {} kernels but the study's has {m}",
                    file.display(),
                    line.len()
                )
                .into());
            }
            w0.extend(line);
        }
        Ok(StudyConfig {
            method: self.method(),
            kernels: self.kernels,
            lengthscale: policy.lengthscale,
            seed: self.seed.unwrap_or(0),
            beta: self.beta.unwrap_or(cdbo::acquisition::ucb::DEFAULT_BETA),
            w0,
            track: None,
            track_length: self.track_length,
            knob: self.knob,
            max_failed_laps: self.max_failed_laps,
            box_radius: self.box_radius,
            warm_start: self.warm_start.as_ref().map(|p| p.display().to_string()),
            line_kernels,
            base_line,
            steering: steering.unwrap_or_default(),
        })
    }

    /// Refuses to resume a study with settings other than its own: every flag given must
    /// match the stored value (a flag left out takes the stored one).
    pub fn check_resume(&self, study: &Path, stored: &StudyConfig) -> Result<(), String> {
        let differs = |flag: &str, given: String, kept: String| {
            Err(format!(
                "{}: the study was created with {flag} {kept}, not {given}; resume it with {flag} {kept} (or leave the flag out), or start a new study elsewhere",
                study.display()
            ))
        };
        if let Some(p) = self.preset {
            let kept = LineSetting::of(stored.base_line, stored.line_kernels);
            let line = LineSetting {
                line: p.line(),
                ..LineSetting::centre()
            };
            if (stored.method, stored.steering, kept) != (p.method(), p.steering(), line) {
                return Err(format!(
                    "{}: the study was created with --method {} --steering {} {}, not --preset {p} ({}); resume it without --preset, or start a new study elsewhere",
                    study.display(),
                    stored.method,
                    stored.steering.name(),
                    super::line::flags(&kept),
                    p.flags()
                ));
            }
        }
        if self.kernels != stored.kernels {
            return differs(
                "--kernels",
                self.kernels.to_string(),
                stored.kernels.to_string(),
            );
        }
        if let Some(m) = self.method_given().filter(|m| *m != stored.method) {
            return differs("--method", m.to_string(), stored.method.to_string());
        }
        if let Some(s) = self.seed.filter(|s| *s != stored.seed) {
            return differs("--seed", s.to_string(), stored.seed.to_string());
        }
        if let Some(b) = self.beta.filter(|b| *b != stored.beta) {
            return differs("--beta", b.to_string(), stored.beta.to_string());
        }
        if let Some(l) = self.lengthscale.filter(|l| *l != stored.lengthscale) {
            return differs(
                "--lengthscale",
                l.to_string(),
                stored.lengthscale.to_string(),
            );
        }
        // A flag whose stored value may be absent (a study made without it, or before it).
        let optional = |flag: &str, given: Option<String>, kept: Option<String>| match given {
            Some(g) if Some(&g) != kept.as_ref() => {
                differs(flag, g, kept.unwrap_or_else(|| format!("no {flag}")))
            }
            _ => Ok(()),
        };
        let text = |v: Option<f64>| v.map(|v| v.to_string());
        optional(
            "--track-length",
            text(self.track_length),
            text(stored.track_length),
        )?;
        optional("--knob", text(self.knob), text(stored.knob))?;
        optional(
            "--max-failed-laps",
            self.max_failed_laps.map(|n| n.to_string()),
            stored.max_failed_laps.map(|n| n.to_string()),
        )?;
        optional(
            "--box-radius",
            text(self.box_radius),
            text(stored.box_radius),
        )?;
        optional(
            "--steering",
            self.steering_given().map(|s| s.name().to_owned()),
            Some(stored.steering.name().to_owned()),
        )?;
        optional(
            "--warm-start",
            self.warm_start.as_ref().map(|p| p.display().to_string()),
            stored.warm_start.clone(),
        )?;
        let line = self.line_given();
        if line.given() {
            let given = line
                .resolve(self.kernels)
                .map(|(base, kernels)| LineSetting::of(base, kernels))?;
            let kept = LineSetting::of(stored.base_line, stored.line_kernels);
            if given != kept {
                return Err(format!(
                    "{}: the study was created with {}, not {}; resume it with those flags (or leave them out), or start a new study elsewhere",
                    study.display(),
                    super::line::flags(&kept),
                    super::line::flags(&given)
                ));
            }
        }
        Ok(())
    }
}

#[derive(Debug, Subcommand)]
pub enum StudyCommand {
    /// Create a study from an initial controller's demonstration or weights.
    Create {
        #[command(flatten)]
        study: StudyName,
        #[command(flatten)]
        initial: InitialPolicy,
        /// The track the laps are driven on, recorded in the study (the dashboard re-drives
        /// its trials there).
        #[arg(long, value_name = "NAME")]
        track: Option<String>,
    },
    /// The next policy to drive (the pending one until it is told).
    Ask {
        #[command(flatten)]
        study: StudyName,
        /// Output format.
        #[arg(long, value_enum, default_value = "json")]
        format: Format,
    },
    /// Record a trial's result: a reward, a lap time and length, or a failure.
    Tell {
        #[command(flatten)]
        study: StudyName,
        /// Trial id (from `ask`).
        #[arg(long)]
        trial: i64,
        /// The reward.
        #[arg(long, conflicts_with_all = ["lap_time", "failed"], allow_negative_numbers = true, value_parser = super::value::finite)]
        reward: Option<f64>,
        /// Lap time in seconds (with --length: reward = length / time).
        #[arg(
            long,
            requires = "length",
            conflicts_with = "failed",
            allow_negative_numbers = true,
            value_parser = super::value::positive
        )]
        lap_time: Option<f64>,
        /// Lap length in metres.
        #[arg(long, requires = "lap_time", allow_negative_numbers = true, value_parser = super::value::positive)]
        length: Option<f64>,
        /// The lap failed (reward 0).
        #[arg(long)]
        failed: bool,
        /// Where it failed, as a fraction of the lap.
        #[arg(long, requires = "failed", allow_negative_numbers = true, value_parser = super::value::fraction)]
        at: Option<f64>,
        /// Why it failed: `stalled` or `time_limit` when the car was too slow there (the
        /// pattern search then adds pedal before the place), else how it left the road
        /// (`off_track`, `hit_wall`, `spun`, `backwards`) or any note; kept with the trial.
        #[arg(long, requires = "failed")]
        reason: Option<String>,
    },
    /// Progress: trials told, failures, the best reward.
    Status {
        #[command(flatten)]
        study: StudyName,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// The best policy: weights and (x, a) table.
    Best {
        #[command(flatten)]
        study: StudyName,
        /// Output format.
        #[arg(long, value_enum, default_value = "json")]
        format: Format,
    },
    /// Every trial, as CSV (or JSON).
    History {
        #[command(flatten)]
        study: StudyName,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Copy a study to a new place, row for row (e.g. a file into a PostgreSQL database).
    Copy {
        /// The study to copy: FILE, sqlite://FILE or postgresql://USER@HOST/DB#STUDY.
        from: String,
        /// Where the copy goes (must not hold the study yet), as FROM.
        to: String,
        /// The study's name in a database URL without a #STUDY.
        #[arg(long)]
        name: Option<String>,
    },
    /// Write the history (CSV, JSON), the best policy (JSON, CSV) and the learning curve (PNG,
    /// SVG) to a folder.
    Export {
        #[command(flatten)]
        study: StudyName,
        /// Output folder (default: NAME-export).
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
}

pub fn run(cmd: &StudyCommand) -> CliResult {
    match cmd {
        StudyCommand::Create {
            study,
            initial,
            track,
        } => {
            let laps = cdbo::method::cost::STUDY_LAPS_ASSUMED;
            if let Some(w) =
                cdbo::method::cost::slow_study_warning(initial.method(), initial.kernels, laps)
            {
                eprintln!("warning: {w}; {laps} laps assumed, the paper's budget");
            }
            let mut config = initial.config()?;
            config.track = track.clone();
            let s = Study::create_at(&study.location()?, config)?;
            println!(
                "created study {} in {} ({} kernels, {})",
                study.name,
                s.path().display(),
                s.config().kernels,
                s.config().method
            );
            Ok(())
        }
        StudyCommand::Ask { study, format } => {
            let mut s = Study::open_at(&study.location()?)?;
            let trial = s.ask()?;
            print_policy(&s, &trial, *format)
        }
        StudyCommand::Tell {
            study,
            trial,
            reward,
            lap_time,
            length,
            failed,
            at,
            reason,
        } => {
            let outcome = match (reward, lap_time, length, failed) {
                (Some(r), _, _, _) => Outcome::Reward(*r),
                (None, Some(t), Some(l), _) => Outcome::Lap {
                    time_s: *t,
                    length_m: *l,
                },
                (None, None, None, true) => Outcome::Failed {
                    at: *at,
                    reason: reason.clone(),
                },
                _ => return Err("give --reward R, --lap-time T --length L, or --failed".into()),
            };
            let flag = match outcome {
                Outcome::Reward(_) => "--reward",
                Outcome::Lap { .. } => "--lap-time / --length",
                Outcome::Failed { .. } => "--at",
            };
            outcome.reward().map_err(from_flag(flag))?;
            let mut s = Study::open_at(&study.location()?)?;
            let r = s.tell(*trial, &outcome)?;
            println!("trial {trial}: reward {r} saved");
            Ok(())
        }
        StudyCommand::Status { study, json } => {
            status(&Study::open_read_only_at(&study.location()?)?, *json)
        }
        StudyCommand::Best { study, format } => {
            let s = Study::open_read_only_at(&study.location()?)?;
            match s.best()? {
                Some(t) => print_policy(&s, &t, *format),
                None => Err(format!("{}: no trial has been told yet", s.path().display()).into()),
            }
        }
        StudyCommand::History { study, json } => {
            let s = Study::open_read_only_at(&study.location()?)?;
            let h = s.history()?;
            if *json {
                return print_json(&h);
            }
            print!("{}", history_csv(&h));
            Ok(())
        }
        StudyCommand::Copy { from, to, name } => {
            let from = Location::parse(from, name.as_deref())?;
            let to = Location::parse(to, name.as_deref())?;
            let copy = Study::copy(&from, &to)?;
            println!(
                "copied {} ({} trials) to {}",
                from.label().display(),
                copy.history()?.len(),
                copy.path().display()
            );
            Ok(())
        }
        StudyCommand::Export { study, out } => {
            let s = Study::open_read_only_at(&study.location()?)?;
            let out = out
                .clone()
                .unwrap_or_else(|| PathBuf::from(format!("{}-export", study.name)));
            export(&s, &out)
        }
    }
}

fn policy_of(s: &Study, t: &Trial) -> Result<RacedPolicy, cdbo::Error> {
    s.config().policy(&t.weights)
}

/// The policy's table as CSV: `x,a` rows, `x,a,d` with a line.
fn table_csv(p: &RacedPolicy) -> String {
    let line = p.policy.line.is_some();
    let mut csv = String::from(if line { "x,a,d\n" } else { "x,a\n" });
    for (x, a, d) in p.policy.table(cdbo::evaluator::command::TABLE_POINTS) {
        csv += &if line {
            format!("{x:.6},{a:.6},{d:.6}\n")
        } else {
            format!("{x:.6},{a:.6}\n")
        };
    }
    csv
}

fn print_policy(s: &Study, t: &Trial, format: Format) -> CliResult {
    let policy = policy_of(s, t)?;
    match format {
        Format::Json => {
            let mut v = cdbo::evaluator::command::policy_json(&policy);
            v["trial"] = t.id.into();
            if let Some(r) = t.reward {
                v["reward"] = r.into();
            }
            println!("{v}");
        }
        Format::Csv => {
            println!("# trial {}", t.id);
            print!("{}", table_csv(&policy));
        }
    }
    Ok(())
}

fn status(s: &Study, json: bool) -> CliResult {
    let h = s.history()?;
    let told = h.iter().filter(|t| t.reward.is_some()).count();
    let failed = h.iter().filter(|t| t.failure.is_some()).count();
    let pending = h.iter().find(|t| t.reward.is_none()).map(|t| t.id);
    let best = s.best()?;
    let c = s.config();
    let v = serde_json::json!({
        "study": s.path().display().to_string(),
        "method": c.method,
        "kernels": c.kernels,
        "track_length_m": c.track_length,
        "knob": c.knob,
        "line": LineSetting::of(c.base_line, c.line_kernels).label(),
        "steering": c.steering.name(),
        "told": told,
        "failed": failed,
        "pending_trial": pending,
        "best_trial": best.as_ref().map(|t| t.id),
        "best_reward": best.as_ref().and_then(|t| t.reward),
        "initial_reward": h.first().and_then(|t| t.reward),
    });
    if json {
        return print_json(&v);
    }
    println!(
        "{}: {} with {} kernels{}{}{}; {told} trials told ({failed} failed){}; best {}",
        s.path().display(),
        c.method,
        c.kernels,
        match LineSetting::of(c.base_line, c.line_kernels) {
            line if line == LineSetting::centre() => String::new(),
            line => format!(" on line {}", line.label()),
        },
        if c.steering.is_pi() {
            String::new()
        } else {
            format!(" steered by the {}", c.steering.name())
        },
        c.track_length
            .map_or(String::new(), |l| format!(" on a {l} m lap")),
        pending.map_or(String::new(), |p| format!(", trial {p} pending")),
        best.map_or("none yet".into(), |t| format!(
            "{:.4} (trial {})",
            t.reward.unwrap_or_default(),
            t.id
        ))
    );
    Ok(())
}

fn history_csv(h: &[Trial]) -> String {
    let mut s = String::from("trial,reward,best,lap_time_s,failure,x_fail\n");
    let mut best = f64::NEG_INFINITY;
    for t in h {
        let Some(r) = t.reward else { continue };
        best = best.max(r);
        s += &format!(
            "{},{r},{best},{},{},{}\n",
            t.id,
            t.lap_time_s.map_or(String::new(), |v| v.to_string()),
            t.failure.clone().unwrap_or_default(),
            t.x_fail.map_or(String::new(), |v| v.to_string())
        );
    }
    s
}

fn export(s: &Study, out: &Path) -> CliResult {
    use crate::figures::{LineChart, draw};
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let h = s.history()?;
    std::fs::write(out.join("history.csv"), history_csv(&h))?;
    std::fs::write(out.join("history.json"), serde_json::to_string_pretty(&h)?)?;
    if let Some(best) = s.best()? {
        let p = policy_of(s, &best)?;
        std::fs::write(
            out.join("best_policy.json"),
            serde_json::to_string_pretty(&cdbo::evaluator::command::policy_json(&p))?,
        )?;
        std::fs::write(out.join("best_policy.csv"), table_csv(&p))?;
    }
    let (mut points, mut best, mut raw) = (Vec::new(), f64::NEG_INFINITY, Vec::new());
    for t in h.iter().filter(|t| t.reward.is_some()) {
        let r = t.reward.unwrap_or_default();
        best = best.max(r);
        points.push((t.id as f64, best));
        raw.push((t.id as f64, r));
    }
    let chart = LineChart {
        title: "Learning curve".into(),
        x_label: "trial".into(),
        y_label: "reward".into(),
        series: vec![
            ("best so far".into(), plotters::style::BLUE, points),
            (
                "each trial".into(),
                plotters::style::RGBColor(160, 160, 160),
                raw,
            ),
        ],
    };
    for ext in ["png", "svg"] {
        draw(&out.join(format!("learning_curve.{ext}")), &chart)?;
    }
    println!("exported {} trials to {}", h.len(), out.display());
    Ok(())
}
