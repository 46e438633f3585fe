//! `skin fit`.

use clap::Args;

/// Arguments of `skin fit`.
#[derive(Args, Debug, Clone)]
pub struct FitArgs {}

/// Run `skin fit`.
pub fn run(_args: &FitArgs) -> anyhow::Result<()> {
    anyhow::bail!("`skin fit` is not available yet in this build")
}
