//! The command line: one `Cli` with a subcommand per tool, and the glue to the library.

use anyhow::Result;
use clap::{Parser, Subcommand};

pub mod augment;
pub mod common;
pub mod compare;
pub mod demo;
pub mod diagnose;
#[cfg(test)]
mod fuzz;
pub mod hil;
pub mod pipeline;
pub mod resid;
pub mod simulate;
pub mod split;

/// yawcast — ship trials to a yaw-rate predictor that runs on the ship's controller.
///
/// Exit codes: 0 success, 2 bad input (unreadable or invalid files, bad arguments, data
/// errors), 1 any other failure. The first line of an error names its cause. Negative
/// numbers are values wherever a number is expected (`--max-angle -1` is refused as a
/// negative limit, not as an unknown flag).
#[derive(Debug, Parser)]
#[command(name = "yawcast", version, about, long_about = None, max_term_width = 100)]
pub struct Cli {
    /// The tool to run.
    #[command(subcommand)]
    pub command: Command,
}

/// Every tool.
#[allow(clippy::large_enum_variant)] // parsed once; boxing buys nothing
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate records of the built-in (or your) ship: identification inputs, trials, manoeuvres.
    #[command(allow_negative_numbers = true)]
    Simulate(simulate::SimulateArgs),
    /// Identify a model from records (prediction-error method), or select the order.
    #[command(allow_negative_numbers = true)]
    Identify(pipeline::IdentifyArgs),
    /// Tune the regularisation (λ, R) with the genetic algorithm, scored on trial records.
    #[command(allow_negative_numbers = true)]
    Tune(pipeline::TuneArgs),
    /// Combine several models: plain average, covariance-weighted merge, multi-record PEM.
    #[command(allow_negative_numbers = true)]
    Average(pipeline::AverageArgs),
    /// Export a model as the firmware blob (+ JSON twin), checked through the firmware predictor.
    #[command(allow_negative_numbers = true)]
    Export(pipeline::ExportArgs),
    /// Fit % of a model on records per horizon; measured vs predicted series.
    #[command(allow_negative_numbers = true)]
    Compare(compare::CompareArgs),
    /// Residual tests (MATLAB `resid`): autocorrelation and input cross-correlation with
    /// their bands, Ljung–Box, error by regime, worst windows.
    #[command(allow_negative_numbers = true)]
    Resid(resid::ResidArgs),
    /// Which physical effect is missing from the model? Evidence for every effect, and a verdict.
    #[command(allow_negative_numbers = true)]
    Diagnose(diagnose::DiagnoseArgs),
    /// Add an effect to a model, re-identify, and show the error before and after.
    #[command(allow_negative_numbers = true)]
    Augment(augment::AugmentArgs),
    /// The whole story on the built-in ship with a hidden effect, ending in report.html.
    #[command(allow_negative_numbers = true)]
    Demo(demo::DemoArgs),
    /// Cut record tables at their gaps and clock restarts into pieces read whole.
    Split(split::SplitArgs),
    /// Hardware in the loop: the simulator sails, the firmware (QEMU or a board) predicts.
    #[command(allow_negative_numbers = true)]
    Hil(hil::HilArgs),
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    match &cli.command {
        Command::Compare(a) => compare::run(a),
        Command::Resid(a) => resid::run(a),
        Command::Hil(a) => hil::run(a),
        Command::Identify(a) => pipeline::identify(a),
        Command::Tune(a) => pipeline::tune(a),
        Command::Average(a) => pipeline::average(a),
        Command::Export(a) => pipeline::export_cmd(a),
        Command::Simulate(a) => simulate::run(a),
        Command::Diagnose(a) => diagnose::run(a),
        Command::Augment(a) => augment::run(a),
        Command::Demo(a) => demo::run(a),
        Command::Split(a) => split::run(a),
    }
}

/// A seeded voyage of `steps` samples for the live loop: pseudo-random pod commands
/// (random switching intervals, several amplitudes) and the yaw rate the model itself
/// produces, with gyro noise.
pub fn sail(
    model: &yawcast::identify::model::Model,
    steps: usize,
    seed: u64,
) -> Result<yawcast::io::data::Record> {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut u = Vec::with_capacity(steps);
    let mut cur = 0.0;
    let mut left = 0usize;
    for _ in 0..steps {
        if left == 0 {
            let amp = [5.0, 10.0, 20.0, 30.0][rng.random_range(0..4)];
            cur = if rng.random_bool(0.5) { amp } else { -amp };
            left = rng.random_range(4..30);
        }
        left -= 1;
        u.push(cur);
    }
    let rec = yawcast::io::data::Record::from_uy("voyage", model.ts, u, vec![0.0; steps]);
    let clean = yawcast::identify::predict::simulate(model, &rec, &vec![0.0; model.n]);
    let y = clean
        .iter()
        .map(|v| v + 0.01 * (rng.random::<f64>() - 0.5))
        .collect();
    Ok(yawcast::io::data::Record { y, ..rec })
}
