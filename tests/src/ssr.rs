//! The stochastic SSR passes on both backends, pass by pass: the comparison `ssr_sssr.rs` runs on
//! the analytic scenes and `ssr_gltf.rs` on G-buffers exported from the glTF scenes.

use crate::assert_bits_equal;
use host::ssr::pipeline::Runner;
use shader_core::ssr::params::{SsrParams, REPROJECT_HIT, REPROJECT_SURFACE};
use shader_core::ssr::resolve::{hit_footprints_stored, HIT_STRIDE, HIT_TAN_HALF, HIT_UV};
use shader_core::ssr::stochastic::{HISTORY_STRIDE, LIST_STRIDE, TILE_ELIGIBLE, TILE_RAYS, TILE_STRIDE};
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
/// trace, hit records (over the ray list, and equal to those of every slot), resolve (over the
/// pixel list), hit distance, and the temporal pass with both reprojections
/// (`consts` is left with the last) against the previous frame's G-buffer `prev`, with a history
/// that is the resolve itself at n = 3 (an accepted texel gives n = 4, a rejected one restarts
/// at n = 1).
#[allow(clippy::too_many_arguments)]
pub fn sssr_passes_bit_equal(tag: &str, c: &mut Runner, q: &mut Runner, consts: &mut SsrParams, gbuf: &[f32], prev: &[f32], dp: &[f32], cp: &[f32]) -> SssrPasses {
    let tiles = c.sssr_classify(consts, gbuf).unwrap();
    assert_bits_equal(&format!("{tag} classify"), TILE_STRIDE, &tiles, &q.sssr_classify(consts, gbuf).unwrap());
    let off = c.sssr_prefix(&tiles, TILE_RAYS).unwrap();
    assert_bits_equal(&format!("{tag} prefix (rays)"), 1, &off, &q.sssr_prefix(&tiles, TILE_RAYS).unwrap());
    let pixel_off = c.sssr_prefix(&tiles, TILE_ELIGIBLE).unwrap();
    assert_bits_equal(&format!("{tag} prefix (pixels)"), 1, &pixel_off, &q.sssr_prefix(&tiles, TILE_ELIGIBLE).unwrap());
    let (list, pixels) = c.sssr_emit(consts, gbuf, &off, &pixel_off).unwrap();
    let (list_q, pixels_q) = q.sssr_emit(consts, gbuf, &off, &pixel_off).unwrap();
    assert_bits_equal(&format!("{tag} ray list"), LIST_STRIDE, &list, &list_q);
    assert_bits_equal(&format!("{tag} pixel list"), 1, &pixels, &pixels_q);
    let count = list.len() / LIST_STRIDE;
    assert_eq!(count, off[off.len() - 1].to_bits() as usize, "{tag}: ray list length");
    assert_eq!(pixels.len(), pixel_off[pixel_off.len() - 1].to_bits() as usize, "{tag}: pixel list length");
    let rays = c.sssr_trace(consts, gbuf, dp, &list).unwrap();
    assert_bits_equal(&format!("{tag} trace"), RAY_STRIDE, &rays, &q.sssr_trace(consts, gbuf, dp, &list).unwrap());
    let hits = c.sssr_hits(consts, gbuf, cp, &rays, &list).unwrap();
    assert_bits_equal(&format!("{tag} hit records"), HIT_STRIDE, &hits, &q.sssr_hits(consts, gbuf, cp, &rays, &list).unwrap());
    // Over the list or over every slot: the same records (slots without a ray are zero in both).
    assert_bits_equal(&format!("{tag} hit records, list = every slot"), HIT_STRIDE, &hits, &c.ray_hits(consts, gbuf, cp, &rays).unwrap());
    // The UV and cone words are written where a resolve reads them, and only there.
    let footprints = hits.chunks(HIT_STRIDE).filter(|r| r[HIT_UV] != 0.0 || r[HIT_UV + 1] != 0.0 || r[HIT_TAN_HALF] != 0.0).count();
    if hit_footprints_stored(consts) {
        assert!(footprints > 0, "{tag}: no hit record has its UV or cone");
    } else {
        assert_eq!(footprints, 0, "{tag}: hit records with a UV or cone no resolve reads");
    }
    let reflection = c.sssr_resolve(consts, gbuf, cp, &rays, &hits, &pixels).unwrap();
    assert_bits_equal(&format!("{tag} resolve"), 4, &reflection, &q.sssr_resolve(consts, gbuf, cp, &rays, &hits, &pixels).unwrap());
    // A colour pyramid of the wrong size is refused, by name, by every pass that reads it.
    let short = &cp[..cp.len() - 3];
    for err in [
        c.ray_hits(consts, gbuf, short, &rays).unwrap_err(),
        c.sssr_hits(consts, gbuf, short, &rays, &list).unwrap_err(),
        c.sssr_resolve(consts, gbuf, short, &rays, &hits, &pixels).unwrap_err(),
    ] {
        assert!(err.to_string().contains("colour pyramid has"), "{tag}: {err}");
    }
    let hit_distance = c.sssr_hit_distance(consts, gbuf, &rays, &hits, &pixels).unwrap();
    assert_bits_equal(&format!("{tag} hit distance"), 1, &hit_distance, &q.sssr_hit_distance(consts, gbuf, &rays, &hits, &pixels).unwrap());
    let hist: Vec<f32> = reflection.chunks_exact(4).flat_map(|c| [c[0] * 0.5, c[1], c[2] * 2.0, c[3], 3.0]).collect();
    let temporal = [REPROJECT_HIT, REPROJECT_SURFACE].map(|mode| {
        consts.temporal_reprojection = mode;
        let tc = c.sssr_temporal(consts, gbuf, prev, &hit_distance, &reflection, &hist).unwrap();
        let tg = q.sssr_temporal(consts, gbuf, prev, &hit_distance, &reflection, &hist).unwrap();
        assert_bits_equal(&format!("{tag} temporal (reprojection {mode})"), HISTORY_STRIDE, &tc, &tg);
        tc
    });
    SssrPasses { list, count, rays, reflection, hit_distance, temporal }
}
