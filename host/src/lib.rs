//! The `host` CLI's library: commands, the `host bench <feature>` tree, plots, PNG previews and
//! reports on top of the feature crates (`scene`, `render`, `ssr`, `energy`, `eval`, `fileio`),
//! which it re-exports under their old paths (`host::render::scene`, `host::ssr`, ...).

pub mod cli_args;
// The launchers live in the `runner` crate (usable without the CLI's dependencies); re-exported
// so the features here and the tests keep one path.
pub use runner::{backend, cpu, div_sqrt_probe, float_controls, gpu, shaders, timing};
pub use runner::{Backend, DeviceChoice, Timing, TimingSource};
// The f64 references live in the `reference` crate (no GPU dependencies).
pub use reference::{energy as energy_ref, microfacet as microfacet_ref};
// Registry dispatch and table I/O are the `eval` crate.
pub use ::eval::{self, npy};
pub mod grid;
pub mod io;
pub mod plot;
pub mod render;
pub mod report;
pub mod ssr;
pub mod bench;
pub mod bench_kernels;
pub mod bench_storage;
pub mod bench_microfacet;
pub mod bench_vndf;
pub mod ggx_fp16;
pub mod energy;
pub mod energy_bench;
