#![doc = include_str!("../README.md")]

pub mod error;
pub mod montecarlo;

pub use error::ValidationError;
pub mod compare;
