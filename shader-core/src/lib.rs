//! Shading math shared bit-for-bit by the CPU backend and the rust-gpu SPIR-V kernels.
//!
//! Every function is written once and used by both backends; arithmetic is restricted to the
//! operations Vulkan requires correctly rounded (`+ - *`, conversions) plus the software division
//! and square root of [`ieee`], with a fixed evaluation order, so CPU and GPU results agree to the
//! bit on any conformant device (see README, "Bit-exactness", and docs/exactness.md).
#![no_std]

pub mod buffer;
pub mod bxdf;
pub mod complex;
pub mod energy;
pub mod fresnel;
pub mod ieee;
pub mod masking;
pub mod math;
pub mod ndf;
pub mod pt;
pub mod rng;
pub mod ssr;
pub mod vector;
pub mod vndf;
pub mod warp;

pub use vector::Vec3;
