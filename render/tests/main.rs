//! The renderer end to end: scenes rendered and compared with closed forms, the volumetric
//! reference and each other.

mod adaptive;
mod fidelity;
mod hetero;
mod hetero_thin;
mod majorant;
mod passes;
mod sampler;
mod scene_presets;
mod subsurface;
mod tracer;
mod volumetric;
