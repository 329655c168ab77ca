//! `yawcast augment` (being written).

use anyhow::Result;

/// Arguments of `yawcast augment`.
#[derive(Debug, clap::Args)]
pub struct AugmentArgs {
    /// Everything after the subcommand.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, hide = true)]
    pub rest: Vec<String>,
}

/// Runs `yawcast augment`.
pub fn run(_args: &AugmentArgs) -> Result<()> {
    anyhow::bail!("`yawcast augment` is not available in this build")
}
