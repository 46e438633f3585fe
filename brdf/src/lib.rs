#![doc = include_str!("../README.md")]

mod albedo;
pub mod beckmann;
mod error;
mod frame;
pub mod fresnel;
pub mod quadrature;
mod real;
mod torrance_sparrow;
mod v_cavity;

pub use albedo::{TABLE_NODES, TABLE_SIZE};
pub use error::{BrdfError, check_eta, check_oiliness, check_roughness};
pub use frame::Frame;
pub use torrance_sparrow::{
    DEFAULT_ETA, DEFAULT_OILINESS, DEFAULT_ROUGHNESS, Sample, TorranceSparrow,
};
