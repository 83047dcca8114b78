//! The launchers of the shading kernels: the same per-invocation functions of `shader-kernels`
//! run under a GPU launch (wgpu on Vulkan, the committed rust-gpu SPIR-V: [`gpu`]) or a CPU loop
//! on all cores (rayon: [`cpu`]); [`Backend`] picks one (`--device auto|cpu|gpu`).
//!
//! No CLI, plotting or image crates: another program can depend on this crate alone to dispatch
//! a kernel. What the runner tells a user (the backend `--device auto` picked and why, a driver
//! whose division is not correctly rounded) goes to the `log` facade: info and warn levels. With the `clap` feature, [`DeviceChoice`] is also a command-line value.
//!
//! ```no_run
//! use runner::{Backend, DeviceChoice};
//! // Evaluate GGX D on whichever backend is available, rows of (wm_x, wm_y, wm_z, alpha_x, alpha_y).
//! let backend = Backend::select(DeviceChoice::Auto)?;
//! let f = shader_kernels::eval::find("ggx_d").expect("registered");
//! let rows = [0.0, 0.0, 1.0, 0.5, 0.5, 0.6, 0.0, 0.8, 0.3, 0.3];
//! let (d, timing) = backend.eval_table(f, &rows, 2)?;
//! println!("D = {d:?} in {:.3} ms ({})", timing.seconds * 1e3, timing.source);
//! # Ok::<(), anyhow::Error>(())
//! ```

pub mod backend;
pub mod cpu;
mod device;
pub mod div_sqrt_probe;
pub mod float_controls;
pub mod gpu;
mod gpu_error;
mod kernel_module;
pub mod launches;
pub mod shaders;
pub mod timing;

pub use backend::{Backend, DeviceChoice, Launch, LaunchArgs};
pub use shader_kernels::launch::Kernel;
pub use launches::in_launches;
pub use timing::{Timing, TimingSource};
