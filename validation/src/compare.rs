//! The diffusion-versus-Monte-Carlo comparison (placeholder until the charts land).

use std::path::Path;

/// Run the comparison and write its charts into `out`.
pub fn run_comparison(_quick: bool, _out: &Path) -> anyhow::Result<()> {
    anyhow::bail!("the comparison is not available yet in this build")
}
