//! `yawcast simulate` (being written).

use anyhow::Result;

/// Arguments of `yawcast simulate`.
#[derive(Debug, clap::Args)]
pub struct SimulateArgs {
    /// Everything after the subcommand.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, hide = true)]
    pub rest: Vec<String>,
}

/// Runs `yawcast simulate`.
pub fn run(_args: &SimulateArgs) -> Result<()> {
    anyhow::bail!("`yawcast simulate` is not available in this build")
}
