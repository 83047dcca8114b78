//! Compute entry points, compiled to SPIR-V by rust-gpu (`cargo xtask build-shaders`) and linked
//! natively by the host's CPU backend.
//!
//! Each kernel is a plain per-invocation function (e.g. `eval::basic::ggx_d::row`) that both
//! backends call; the `#[spirv(compute)]` entry points only map invocation ids to it and are the
//! only GPU-specific code. On non-SPIR-V targets the `spirv` attribute is inert. Every evaluable
//! function has its own entry point, generated with its registry entry from one declaration
//! ([`eval`]).
//!
//! Two SPIR-V modules are built from this crate: the main one (every kernel below), and, with the
//! `subgroup-module` feature, one holding only the kernels that need subgroup operations
//! ([`ssr_subgroup`]). rust-gpu declares capabilities for a whole module and a device without
//! them cannot load it, so the host loads the second module only where the adapter has subgroups.
#![no_std]
// As in shader-core (its lib.rs says why): NaN-routing negated comparisons and plain integer
// steps instead of library calls. An entry point takes one argument per buffer it binds.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::manual_div_ceil, clippy::too_many_arguments)]

#[cfg(not(feature = "subgroup-module"))]
pub mod energy;
#[cfg(not(feature = "subgroup-module"))]
pub mod eval;
#[cfg(not(target_arch = "spirv"))]
pub mod launch;
#[cfg(not(feature = "subgroup-module"))]
pub mod render;
#[cfg(not(feature = "subgroup-module"))]
pub mod ssr;
#[cfg(feature = "subgroup-module")]
pub mod ssr_subgroup;

#[cfg_attr(feature = "subgroup-module", allow(unused_imports))]
use spirv_std::glam::UVec3;

/// Threads per workgroup of the 1D kernels. Dispatches are 2D (x = 65535 groups at most) and
/// rows are numbered `x + y * groups_x * WORKGROUP_SIZE`.
pub const WORKGROUP_SIZE: u32 = 64;

/// The invocation index `id.x + id.y * groups_x * WORKGROUP_SIZE` of a 1D kernel dispatched as
/// 2D groups, or `None` at or past `count`: the one mapping every 1D entry point uses.
#[inline(always)]
pub fn invocation_index(id: UVec3, count: u32, groups_x: u32) -> Option<u32> {
    let i = id.x + id.y * groups_x * WORKGROUP_SIZE;
    if i < count {
        Some(i)
    } else {
        None
    }
}
