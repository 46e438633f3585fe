#![doc = include_str!("../README.md")]

pub mod adding_doubling;
pub mod fit;
