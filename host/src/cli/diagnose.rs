//! `yawcast diagnose` (being written).

use anyhow::Result;

/// Arguments of `yawcast diagnose`.
#[derive(Debug, clap::Args)]
pub struct DiagnoseArgs {
    /// Everything after the subcommand.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, hide = true)]
    pub rest: Vec<String>,
}

/// Runs `yawcast diagnose`.
pub fn run(_args: &DiagnoseArgs) -> Result<()> {
    anyhow::bail!("`yawcast diagnose` is not available in this build")
}
