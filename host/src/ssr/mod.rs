//! `host ssr` and `host bench ssr | ssr-ablate | ssr-wall | ssr-passes`: the command line,
//! benchmarks and PNG legends of the `ssr` crate.

pub mod bench;
pub mod cli;
pub mod legend;
pub mod passes;

pub use ::ssr::*;
