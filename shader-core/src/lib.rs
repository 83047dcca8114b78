//! Shading math shared bit-for-bit by the CPU backend and the rust-gpu SPIR-V kernels.
//!
//! Every function is written once and used by both backends; arithmetic is restricted to the
//! operations Vulkan requires correctly rounded (`+ - *`, conversions) plus the software division
//! and square root of [`ieee`], with a fixed evaluation order, so CPU and GPU results agree to the
//! bit on any conformant device.
//!
//! # Conventions (every module)
//!
//! * **Frame.** Shading functions work in the local shading frame: the surface normal is +z
//!   ([`Vec3::Z`]), so `cos(theta) = w.z`; `x`/`y` are the tangent and bitangent (the axes of
//!   anisotropic roughness `alpha_x`, `alpha_y`). Directions such as `wo`, `wi` (PBRT naming) point
//!   *away* from the surface. World-space code (the [`ssr`] module) says so per function.
//! * **Units.** Angles in radians; roughness as the microfacet `alpha` (perceptual roughness
//!   squared where a function takes "roughness"); densities per steradian (solid angle);
//!   reflectances and albedos in [0, 1]; indices of refraction as ratios `eta = eta_t / eta_i`.
//! * **Invalid input.** Each function states what NaN, infinite, negative or degenerate input
//!   gives (typically NaN out for NaN in, 0 for back-facing directions). No function panics on
//!   any `f32` argument; functions reading buffers state the length they need.
//! * **Arithmetic.** Only `+ - *`, comparisons, bit casts and integer operations are used
//!   directly; division and square root go through [`ieee::div`] / [`ieee::sqrt`], and
//!   transcendentals through [`math`]. Expressions are written in the order they are evaluated;
//!   nothing relies on fused multiply-add or reassociation.
//!
//! # Using it from a rust-gpu shader crate
//!
//! Depend on `shader-core` (and `spirv-std` 0.11) from a `#![no_std]` shader crate, call these
//! functions from a `#[spirv(compute(...))]` entry point, and call the same functions natively
//! on the CPU. The results agree bit for bit only if the SPIR-V is post-processed the way this
//! project's own kernels are: built without `spirv-opt` (its folding rules reassociate float
//! arithmetic), every float arithmetic instruction decorated `NoContraction` (so the driver
//! neither fuses nor reassociates), and the `SignedZeroInfNanPreserve` execution mode on every
//! entry point (so the driver keeps `-0`, infinities and NaN).
//!
//! ```
//! use shader_core::{fresnel, ieee, masking, ndf, Vec3};
//! // A GGX specular lobe, evaluated the same way on the CPU as in a shader.
//! let (wo, wi) = (Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.6, 0.0, 0.8));
//! let alpha = 0.3;
//! let wm = (wo + wi).normalize();
//! assert_eq!(wm, Vec3::Z); // mirror configuration: the half vector is the normal
//! let d = ndf::ggx_d(wm, alpha, alpha);
//! let g = masking::ggx_g2_height_correlated(wo, wi, alpha, alpha);
//! let f = fresnel::schlick(wo.dot(wm), 0.04, 1.0);
//! let lobe = ieee::div(d * g * f, 4.0 * wo.z * wi.z);
//! assert!(lobe > 0.0 && lobe.is_finite());
//! ```
#![no_std]
// Clippy suggestions this crate does not take. NaN: `!(x > 0.0)` sends a NaN to the branch the
// function documents, which `x <= 0.0` would not (`neg_cmp_op_on_partial_ord`). Kernel code is
// written with plain operators, so the SPIR-V rust-gpu emits is what the source says and the
// committed, cross-checked modules do not move: no `f32::clamp` / `Ord::clamp` (they assert
// min <= max, a panic path in every kernel), `div_ceil`, `rotate_left`, `mem::swap` or
// `Range::contains` for the comparisons and integer steps they stand for, and `a = a + b` where
// the vector types have no compound assignment.
#![allow(
    clippy::neg_cmp_op_on_partial_ord,
    clippy::manual_clamp,
    clippy::manual_div_ceil,
    clippy::manual_rotate,
    clippy::manual_swap,
    clippy::manual_range_contains,
    clippy::assign_op_pattern
)]

pub mod buffer;
pub mod bxdf;
pub mod complex;
pub mod dispatch;
pub mod energy;
pub mod frame;
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
