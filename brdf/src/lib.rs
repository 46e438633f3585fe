#![doc = include_str!("../README.md")]
// Citations such as [DJ06] are keys of REFERENCES.md, not paths: rustdoc would report each one as
// an unresolved intra-doc link.
#![allow(rustdoc::broken_intra_doc_links)]

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
