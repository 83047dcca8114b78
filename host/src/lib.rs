//! Host side of the shading library: backends (GPU through wgpu, native CPU), the table
//! evaluator behind `host eval`, and file I/O.

pub mod backend;
pub mod cpu;
pub mod float_controls;
pub mod gpu;
pub mod shaders;
pub mod timing;

pub use backend::{Backend, DeviceChoice};
pub use timing::{Timing, TimingSource};
pub mod eval;
pub mod grid;
pub mod io;
pub mod ssr;
pub mod bench_microfacet;
pub mod bench_vndf;
pub mod ggx_fp16;
pub mod microfacet_ref;
pub mod energy;
pub mod energy_bench;
pub mod energy_ref;
