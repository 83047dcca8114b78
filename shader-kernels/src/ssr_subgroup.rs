//! Kernels that use subgroup operations (the second SPIR-V module, built with the
//! `subgroup-module` feature and the GroupNonUniform / GroupNonUniformArithmetic capabilities).

use shader_core::ssr::stochastic;
use spirv_std::arch::{subgroup_inclusive_i_add, workgroup_memory_barrier_with_group_sync};
use spirv_std::spirv;

/// Stochastic SSR, compaction step 1 with a subgroup scan: the same segments, exclusive prefix
/// sum and dispatch record as `ssr::sssr_scan` (each lane sums its segment of the tiles,
/// `stochastic::scan_segment`), the 64 segment totals scanned by `OpGroupNonUniformIAdd`
/// inclusive scans within subgroups plus the totals of the preceding subgroups (exchanged in
/// workgroup memory). A segment is numbered subgroup * subgroup size + lane in subgroup, so the
/// result does not depend on how the device maps local invocations to subgroups; it needs full
/// subgroups, and where they are not full (subgroups x size != 64) the kernel writes `u32::MAX`
/// as the ray count of the dispatch record and the host reports it. `args[2]` = tile count,
/// `args[3]` = the column scanned.
#[spirv(compute(threads(64)))]
#[allow(clippy::too_many_arguments)]
pub fn sssr_scan_subgroup(
    #[spirv(subgroup_id)] sg: u32,
    #[spirv(num_subgroups)] n_sg: u32,
    #[spirv(subgroup_local_invocation_id)] sg_lane: u32,
    #[spirv(subgroup_size)] sg_size: u32,
    #[spirv(storage_buffer, descriptor_set = 0, binding = 0)] args: &[u32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 1)] tiles: &[f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 2)] offsets: &mut [f32],
    #[spirv(storage_buffer, descriptor_set = 0, binding = 3)] dispatch: &mut [u32],
    #[spirv(workgroup)] totals: &mut [u32; stochastic::SCAN_LANES as usize],
) {
    let full = n_sg * sg_size == stochastic::SCAN_LANES;
    let pos = sg * sg_size + sg_lane;
    let n = if full { args[2] } else { 0 };
    let column = args[3] as usize;
    let (first, end) = stochastic::scan_segment(n, pos);
    let own = stochastic::segment_total(tiles, column, first, end);
    let inclusive = subgroup_inclusive_i_add(own);
    if sg_lane == sg_size - 1 {
        totals[sg as usize] = inclusive;
    }
    workgroup_memory_barrier_with_group_sync();
    let mut before: u32 = 0;
    let mut total: u32 = 0;
    let mut k: u32 = 0;
    while k < n_sg {
        let v = totals[k as usize];
        if k < sg {
            before += v;
        }
        total += v;
        k += 1;
    }
    stochastic::segment_offsets(tiles, column, first, end, before + inclusive - own, offsets);
    if pos == 0 {
        let rays = if full { Some(total) } else { None };
        stochastic::store_scan_total(offsets, dispatch, args[2], rays, crate::WORKGROUP_SIZE);
    }
}
