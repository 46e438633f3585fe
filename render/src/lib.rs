#![doc = include_str!("../README.md")]

pub mod atomic;
pub mod cli;
pub mod plot;
