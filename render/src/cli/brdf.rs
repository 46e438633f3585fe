//! `skin brdf`.

use clap::Args;

/// Arguments of `skin brdf`.
#[derive(Args, Debug, Clone)]
pub struct BrdfArgs {}

/// Run `skin brdf`.
pub fn run(_args: &BrdfArgs) -> anyhow::Result<()> {
    anyhow::bail!("`skin brdf` is not available yet in this build")
}
