//! `yawcast demo` (being written).

use anyhow::Result;

/// Arguments of `yawcast demo`.
#[derive(Debug, clap::Args)]
pub struct DemoArgs {
    /// Everything after the subcommand.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, hide = true)]
    pub rest: Vec<String>,
}

/// Runs `yawcast demo`.
pub fn run(_args: &DemoArgs) -> Result<()> {
    anyhow::bail!("`yawcast demo` is not available in this build")
}
