//! `cdbo ceiling`: the best lap this drive stack can do, beside the physical limit.

use clap::Args;

use super::{CliResult, Setup, print_json};
use cdbo::ceiling::ceiling_with;
use cdbo::data_path::DataPath;
use cdbo::drive::steering::SteeringLaw;
use cdbo::policy::RacedPolicy;

#[derive(Debug, Args)]
pub struct CeilingArgs {
    #[command(flatten)]
    setup: Setup,
    /// Policy kernels M of the fitted policy.
    #[arg(long, default_value_t = 30)]
    kernels: usize,
    /// How the car steers.
    #[arg(long, value_parser = super::steering_parser(), default_value_t)]
    steering: SteeringLaw,
    /// The line the car holds: on the minimum-curvature line the profile tracked is that
    /// line's crest-aware limit (read at the centre line's stations) and the shares are of
    /// that line's crest-blind limit, then of the centre line's.
    #[arg(long, value_enum, default_value_t)]
    line: super::line::FixedLine,
    /// Write the fitted policy here, as `cdbo race` writes `best_policy.json` (its line and
    /// steering named): `cdbo lap --policy FILE` drives it, `cdbo race --warm-start FILE`
    /// learns on from it, in cdbo's simulator or the game. Nothing is written when no fitted
    /// policy completes.
    #[arg(long, value_name = "POLICY.json")]
    out: Option<std::path::PathBuf>,
    /// The flying lap's ceiling: the second of two laps from the standing start, timed line
    /// to line, tracking the flying lap's profile (it crosses the line at speed and brakes
    /// before it for the next lap's first corner).
    #[arg(long)]
    flying: bool,
    /// Print JSON.
    #[arg(long)]
    json: bool,
}

/// `--json`: the ceiling, and the centre line's limit when it was measured on another line.
#[derive(serde::Serialize)]
struct CeilingReport<'a> {
    #[serde(flatten)]
    ceiling: &'a cdbo::ceiling::Ceiling,
    #[serde(skip_serializing_if = "Option::is_none")]
    centre_line_limit_mps: Option<f64>,
}

pub fn run(args: &CeilingArgs, data: &DataPath) -> CliResult {
    if args.kernels < 2 {
        return Err(format!("--kernels {}: a policy needs at least 2", args.kernels).into());
    }
    let (track, car) = args.setup.load(data)?;
    let name = track.name.clone();
    let line = args.line.base_line().line(&track, &car)?;
    // The shares are of the crest-blind limit, the profile tracked is the crest-aware one's.
    let limit = match &line {
        Some(line) => cdbo::limit::line_limit_on_centre(&track, line, &car),
        None => cdbo::limit::limit_lap(&track, &car),
    };
    let profile = if args.flying {
        cdbo::ceiling::flying_profile(&track, &car, line.as_deref())
    } else {
        cdbo::ceiling::profile(&track, &car, line.as_deref())
    };
    let which = if line.is_some() {
        "minimum-curvature-line"
    } else {
        "centre-line"
    };
    // Every "% of the limit" elsewhere is of the centre line's: said beside the line's own.
    let centre_mps = line
        .as_ref()
        .map(|_| cdbo::limit::limit_lap(&track, &car).reward_mps);
    let mut sim = cdbo::sim::Simulator::new(track, &car);
    sim.config.steering = args.steering.steering();
    sim.config.line = line;
    sim.config.flying = args.flying;
    let c = ceiling_with(&sim, &limit, &profile, args.kernels)?;
    if args.json {
        print_json(&CeilingReport {
            ceiling: &c,
            centre_line_limit_mps: centre_mps,
        })?;
    } else {
        print_summary(&c, &car.name, &name, which, centre_mps);
    }
    // The figures are printed first: a fit that completes no lap still reports its ceiling.
    if let Some(out) = &args.out {
        let Some(policy) = &c.policy else {
            return Err(format!(
                "{}: no fitted policy completes within {} repairs, so none is written",
                out.display(),
                cdbo::ceiling::MOST_REPAIR_LAPS
            )
            .into());
        };
        let raced = RacedPolicy {
            policy: policy.clone().into(),
            base_line: args.line.base_line(),
            steering: args.steering,
        };
        std::fs::write(out, serde_json::to_string_pretty(&raced)?)
            .map_err(|e| format!("{}: {e}", out.display()))?;
    }
    Ok(())
}

/// The one-line report: the limit, the tracked profile's lap (and the locally lowered one's,
/// where the fit targets it) and the fitted policy's.
fn print_summary(
    c: &cdbo::ceiling::Ceiling,
    car: &str,
    track: &str,
    which: &str,
    centre_mps: Option<f64>,
) {
    let of_centre = centre_mps.map_or(String::new(), |v| {
        format!(
            ", {:.1} % of the centre-line limit {v:.2} m/s",
            100.0 * c.tracked_mps / v
        )
    });
    let pct = |v: f64| 100.0 * v / c.limit_mps;
    let policy = if c.policy.is_some() {
        format!(
            "{:.2} m/s ({:.1} %) after {} repairs",
            c.policy_mps,
            pct(c.policy_mps),
            c.repairs
        )
    } else {
        format!(
            "none completes within {} laps",
            cdbo::ceiling::MOST_REPAIR_LAPS
        )
    };
    let fitted = c.lowered_mps.map_or("its".to_owned(), |v| {
        format!(
            "the lap of {:.3} x lowered only where it fails ({v:.2} m/s, {:.1} %), its",
            cdbo::ceiling::lowering_from(c.k),
            pct(v)
        )
    });
    println!(
        "{car} on {track}: {which} limit {:.2} m/s; tracking {:.3} x the crest-aware limit's speed profile (its lap {:.2} m/s): {:.2} m/s ({:.1} % of the {which} limit{of_centre}); {}-kernel policy fitted to {fitted} pedal, repaired where it fails: {}",
        c.limit_mps,
        c.k,
        c.profile_mps,
        c.tracked_mps,
        pct(c.tracked_mps),
        c.kernels,
        policy
    );
}
