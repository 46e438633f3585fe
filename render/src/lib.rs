#![doc = include_str!("../README.md")]

pub mod atomic;
pub mod cli;
pub mod plot;
pub mod accel;
pub mod error;
pub mod mesh;
pub mod spectrum;
pub mod camera;
pub mod film;
pub mod light;
pub mod texture;
