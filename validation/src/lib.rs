#![doc = include_str!("../README.md")]

pub mod compare;
pub mod error;
pub mod montecarlo;

pub use error::ValidationError;
