//! `host render`: the path tracer of `shader_core::pt` on glTF scenes, on the CPU backend or a
//! Vulkan GPU, with the same per-pixel kernel function on both.

pub mod scene;
