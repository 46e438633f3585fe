//! Properties across crates: diffusion's energy and limits, and diffusion against the Monte Carlo
//! where diffusion is valid.

mod diffusion;
mod physiology;
