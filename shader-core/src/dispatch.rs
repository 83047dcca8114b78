//! Compute dispatch geometry (Vulkan 1.2 §"Dispatching Commands": at most
//! `maxComputeWorkGroupCount[0]` = 65535 workgroups per dimension on every conformant device):
//! how many workgroups a 1D launch spreads over x and y. Used by the host launchers and by the
//! kernels that write an indirect dispatch record (`ssr::stochastic::dispatch_record`).
//!
//! ```
//! use shader_core::dispatch::groups_2d;
//! assert_eq!(groups_2d(0), (1, 0));
//! assert_eq!(groups_2d(64), (64, 1));
//! assert_eq!(groups_2d(70_000), (65535, 2));
//! ```

/// 2D dispatch for `groups` workgroups: x <= 65535 groups (at least 1), y rows of them
/// (ceil(groups / x); 0 rows for 0 groups).
#[inline]
pub fn groups_2d(groups: u32) -> (u32, u32) {
    let gx = if groups < 1 { 1 } else if groups > 65535 { 65535 } else { groups };
    (gx, (groups + gx - 1) / gx)
}
