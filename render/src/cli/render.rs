//! `skin render`.

use clap::Args;

/// Arguments of `skin render`.
#[derive(Args, Debug, Clone)]
pub struct RenderArgs {}

/// Run `skin render`.
pub fn run(_args: &RenderArgs) -> anyhow::Result<()> {
    anyhow::bail!("`skin render` is not available yet in this build")
}
