//! The stochastic SSR passes on both backends, pass by pass: the comparison `ssr_sssr.rs` runs on
//! the analytic scenes and `ssr_gltf.rs` on G-buffers exported from the glTF scenes.

use crate::assert_bits_equal;
use host::ssr::pipeline::Runner;
use shader_core::ssr::params::{idx, REPROJECT_HIT, REPROJECT_SURFACE};
use shader_core::ssr::resolve::HIT_STRIDE;
use shader_core::ssr::stochastic::{HISTORY_STRIDE, LIST_STRIDE, TILE_STRIDE};
use shader_core::ssr::trace::RAY_STRIDE;

/// The CPU backend's outputs of [`sssr_passes_bit_equal`], for a test's own checks.
pub struct SssrPasses {
    pub list: Vec<f32>,
    pub count: usize,
    pub rays: Vec<f32>,
    pub reflection: Vec<f32>,
    pub hit_distance: Vec<f32>,
    /// The temporal pass's output for hit reprojection, then for surface reprojection.
    pub temporal: [Vec<f32>; 2],
}

/// Every stochastic pass after the pyramids (`dp` depth, `cp` colour) on the CPU runner `c` and
/// the GPU runner `q`, each output compared to the bit: classification, prefix sum, emission,
/// trace, hit records, resolve, hit distance, and the temporal pass with both reprojections
/// (`consts` is left with the last) against the previous frame's G-buffer `prev`, with a history
/// that is the resolve itself at n = 3 (an accepted texel gives n = 4, a rejected one restarts
/// at n = 1).
#[allow(clippy::too_many_arguments)]
pub fn sssr_passes_bit_equal(tag: &str, c: &mut Runner, q: &mut Runner, consts: &mut [f32], gbuf: &[f32], prev: &[f32], dp: &[f32], cp: &[f32]) -> SssrPasses {
    let tiles = c.sssr_classify(consts, gbuf).unwrap();
    assert_bits_equal(&format!("{tag} classify"), TILE_STRIDE, &tiles, &q.sssr_classify(consts, gbuf).unwrap());
    let off = c.sssr_prefix(&tiles).unwrap();
    assert_bits_equal(&format!("{tag} prefix"), 1, &off, &q.sssr_prefix(&tiles).unwrap());
    let list = c.sssr_emit(consts, gbuf, &off).unwrap();
    assert_bits_equal(&format!("{tag} list"), LIST_STRIDE, &list, &q.sssr_emit(consts, gbuf, &off).unwrap());
    let count = off[off.len() - 1].to_bits() as usize;
    let rays = c.sssr_trace(consts, gbuf, dp, &list, count).unwrap();
    assert_bits_equal(&format!("{tag} trace"), RAY_STRIDE, &rays, &q.sssr_trace(consts, gbuf, dp, &list, count).unwrap());
    let hits = c.ray_hits(consts, gbuf, &rays).unwrap();
    assert_bits_equal(&format!("{tag} hit records"), HIT_STRIDE, &hits, &q.ray_hits(consts, gbuf, &rays).unwrap());
    let reflection = c.sssr_resolve(consts, gbuf, cp, &rays).unwrap();
    assert_bits_equal(&format!("{tag} resolve"), 4, &reflection, &q.sssr_resolve(consts, gbuf, cp, &rays).unwrap());
    let hit_distance = c.sssr_hit_distance(consts, gbuf, &rays).unwrap();
    assert_bits_equal(&format!("{tag} hit distance"), 1, &hit_distance, &q.sssr_hit_distance(consts, gbuf, &rays).unwrap());
    let hist: Vec<f32> = reflection.chunks_exact(4).flat_map(|c| [c[0] * 0.5, c[1], c[2] * 2.0, c[3], 3.0]).collect();
    let temporal = [REPROJECT_HIT, REPROJECT_SURFACE].map(|mode| {
        consts[idx::TEMPORAL_REPROJECTION] = f32::from_bits(mode);
        let tc = c.sssr_temporal(consts, gbuf, prev, &hit_distance, &reflection, &hist).unwrap();
        let tg = q.sssr_temporal(consts, gbuf, prev, &hit_distance, &reflection, &hist).unwrap();
        assert_bits_equal(&format!("{tag} temporal (reprojection {mode})"), HISTORY_STRIDE, &tc, &tg);
        tc
    });
    SssrPasses { list, count, rays, reflection, hit_distance, temporal }
}
