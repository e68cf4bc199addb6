//! `cdbo serve-sim`: the simulator (or, with `--simulator torcs`, the game) as a JSON-lines
//! service ([`cdbo::serve`]), so that any optimiser in any language can race on our tracks:
//! `{"info": true}` and `{"weights": [...]}` in, one reply line out for each,
//! `{"error": ...}` for a bad line.

use clap::Args;

use super::{CliResult, Setup, Simulator};
use cdbo::data_path::DataPath;
use cdbo::evaluator::Evaluator;
use cdbo::line::BaseLine;
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
    /// The line, as `cdbo race --line`: the demonstration and every lap on its base line; with
    /// `--line learn` the weights are [w_a, w_d], the line's after the pedal's (`info` gives
    /// its kernels), w₀'s line the base line (d = 0).
    #[command(flatten)]
    line: super::line::LineArgs,
    /// Where the laps leave the road, as `cdbo race` learns (default: the learning reserve in
    /// cdbo's simulator, the game's rule in the game).
    #[command(flatten)]
    off_track: super::OffTrackArgs,
}

pub fn run(args: &ServeSimArgs, data: &DataPath, simulator: Simulator) -> CliResult {
    // In the game, the demonstration and every lap are a fresh game process, and the limit is
    // on cdbo's reading of the game's track.
    let (base_line, line_kernels) = args.line.resolve(args.kernels)?;
    let (venue, track, car) = super::venue(&args.setup, data, simulator)?;
    let venue = venue.for_learning(args.off_track.off_track_margin);
    let venue = match base_line.line(&track, &car)? {
        Some(line) => venue.on_line(line),
        None => venue,
    };
    let limit = cdbo::limit::limit_lap(&track, &car);
    let (_, demo) = venue.demonstrate(args.demo_speed)?;
    let pedal = PolicyShape::pedal(Block::paper(args.kernels)?);
    let shape = match line_kernels {
        Some(m) => pedal.with_line(Block::paper(m)?),
        None => pedal,
    };
    let evaluator = venue.evaluator(shape, None)?;
    serve(args, &track, &limit, &demo, (shape, base_line), evaluator)
}

/// Fits w₀ to the demonstration's (x, a) pairs (a learned line's weights 0 after them) and
/// answers requests with `evaluator`'s laps of policies of `shape` on `base_line`.
fn serve(
    args: &ServeSimArgs,
    track: &Track,
    limit: &cdbo::limit::Limit,
    demo: &[(f64, f64)],
    (shape, base_line): (PolicyShape, BaseLine),
    evaluator: impl Evaluator,
) -> CliResult {
    let lengthscale = default_lengthscale(args.kernels);
    let mut w0 = RkhsPolicy::fit(demo, args.kernels, lengthscale, DEFAULT_RIDGE)?.weights;
    w0.resize(shape.dims(), 0.0);
    let bounds = SearchBox::around(&w0, DEFAULT_BOX_RADIUS)?;
    let info = Info {
        dim: shape.dims(),
        w0,
        lower: bounds.lower,
        upper: bounds.upper,
        lengthscale,
        track: track.name.clone(),
        length_m: track.length,
        limit_reward_mps: limit.reward_mps,
        line: shape.line,
        base_line,
    };
    Server { info, evaluator }.serve(std::io::stdin().lock(), std::io::stdout().lock())?;
    Ok(())
}
