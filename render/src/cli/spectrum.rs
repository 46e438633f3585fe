//! `skin spectrum`.

use clap::Args;

/// Arguments of `skin spectrum`.
#[derive(Args, Debug, Clone)]
pub struct SpectrumArgs {}

/// Run `skin spectrum`.
pub fn run(_args: &SpectrumArgs) -> anyhow::Result<()> {
    anyhow::bail!("`skin spectrum` is not available yet in this build")
}
