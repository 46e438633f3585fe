//! `skin-validate`: Monte Carlo reference runs and diffusion-versus-exact charts.
fn main() {}
