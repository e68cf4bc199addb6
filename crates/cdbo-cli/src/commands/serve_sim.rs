//! `cdbo serve-sim`: the simulator as a JSON-lines service ([`cdbo::serve`]), so that any
//! optimiser in any language can race on our tracks: `{"info": true}` and
//! `{"weights": [...]}` in, one reply line out for each, `{"error": ...}` for a bad line.

use clap::Args;

use super::{CliResult, Setup};
use cdbo::data_path::DataPath;
use cdbo::evaluator::simulator::SimEvaluator;
use cdbo::experiment::race::demonstrate;
use cdbo::optimizers::{DEFAULT_BOX_RADIUS, SearchBox};
use cdbo::policy::RkhsPolicy;
use cdbo::policy::rkhs::{DEFAULT_RIDGE, default_lengthscale};
use cdbo::serve::{Info, Server};
use cdbo::sim::Simulator;

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

pub fn run(args: &ServeSimArgs, data: &DataPath) -> CliResult {
    let (track, car) = args.setup.load(data)?;
    let limit = cdbo::limit::limit_lap(&track, &car);
    let sim = Simulator::new(track, &car);
    let (_, demo) = demonstrate(&sim, args.demo_speed);
    let lengthscale = default_lengthscale(args.kernels);
    let w0 = RkhsPolicy::fit(&demo, args.kernels, lengthscale, DEFAULT_RIDGE)?;
    let bounds = SearchBox::around(&w0.weights, DEFAULT_BOX_RADIUS)?;
    let info = Info {
        dim: args.kernels,
        w0: w0.weights,
        lower: bounds.lower,
        upper: bounds.upper,
        lengthscale,
        track: sim.track.name.clone(),
        length_m: sim.track.length,
        limit_reward_mps: limit.reward_mps,
    };
    let evaluator = SimEvaluator { sim, lengthscale };
    Server { info, evaluator }.serve(std::io::stdin().lock(), std::io::stdout().lock())?;
    Ok(())
}
