#![doc = include_str!("../README.md")]

pub mod atomic;
pub mod cache;
pub mod input;
