//! `cdbo serve-sim`: the simulator (or, with `--simulator torcs`, the game) as a JSON-lines
//! service ([`cdbo::serve`]), so that any optimiser in any language can race on our tracks:
//! `{"info": true}` and `{"weights": [...]}` in, one reply line out for each,
//! `{"error": ...}` for a bad line.

use clap::Args;

use super::{CliResult, Setup, Simulator};
use cdbo::data_path::DataPath;
use cdbo::evaluator::Evaluator;
use cdbo::optimizers::{DEFAULT_BOX_RADIUS, SearchBox};
use cdbo::policy::rkhs::{DEFAULT_RIDGE, default_lengthscale};
use cdbo::policy::{Block, PolicyShape, RkhsPolicy};
use cdbo::serve::{Info, Server};
use cdbo::track::Track;

#[derive(Debug, Args)]
pub struct ServeSimArgs {
    #[command(flatten)]
    setup: Setup,
    /// Policy kernels M.
    #[arg(long, value_parser = super::value::kernels)]
    kernels: usize,
    /// Speed of the demonstrator whose fit is w₀ (m/s).
    #[arg(long, default_value_t = 15.0, allow_negative_numbers = true, value_parser = super::value::positive)]
    demo_speed: f64,
}

pub fn run(args: &ServeSimArgs, data: &DataPath, simulator: Simulator) -> CliResult {
    // In the game, the demonstration and every lap are a fresh game process, and the limit is
    // on cdbo's reading of the game's track.
    let (venue, track, car) = super::venue(&args.setup, data, simulator)?;
    let limit = cdbo::limit::limit_lap(&track, &car);
    let (_, demo) = venue.demonstrate(args.demo_speed)?;
    let evaluator = venue.evaluator(PolicyShape::pedal(Block::paper(args.kernels)?))?;
    serve(args, &track, &limit, &demo, evaluator)
}

/// Fits w₀ to the demonstration's (x, a) pairs and answers requests with `evaluator`'s laps.
fn serve(
    args: &ServeSimArgs,
    track: &Track,
    limit: &cdbo::limit::Limit,
    demo: &[(f64, f64)],
    evaluator: impl Evaluator,
) -> CliResult {
    let lengthscale = default_lengthscale(args.kernels);
    let w0 = RkhsPolicy::fit(demo, args.kernels, lengthscale, DEFAULT_RIDGE)?;
    let bounds = SearchBox::around(&w0.weights, DEFAULT_BOX_RADIUS)?;
    let info = Info {
        dim: args.kernels,
        w0: w0.weights,
        lower: bounds.lower,
        upper: bounds.upper,
        lengthscale,
        track: track.name.clone(),
        length_m: track.length,
        limit_reward_mps: limit.reward_mps,
    };
    Server { info, evaluator }.serve(std::io::stdin().lock(), std::io::stdout().lock())?;
    Ok(())
}
