#![doc = include_str!("../README.md")]

pub mod adding_doubling;
pub mod boundary;
pub mod dipole;
pub mod error;
pub mod fit;
pub mod medium;
pub mod skin;
pub mod slab;
pub mod stack;

pub use dipole::Dipole;
pub use error::MultipoleError;
pub use medium::Medium;
pub use skin::Method;
pub use slab::{Poles, Slab};
pub use stack::{Layer, Response, Stack};
