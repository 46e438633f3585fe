//! `skin profile`.

use clap::Args;

/// Arguments of `skin profile`.
#[derive(Args, Debug, Clone)]
pub struct ProfileArgs {}

/// Run `skin profile`.
pub fn run(_args: &ProfileArgs) -> anyhow::Result<()> {
    anyhow::bail!("`skin profile` is not available yet in this build")
}
