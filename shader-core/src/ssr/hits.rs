//! Per-ray hit records for the neighbourhood resolves (Stachowiak 2015 "ray reuse"; HDRP's
//! non-approximate reprojection): a ray's hit position, the density its pixel drew it with at
//! the direction to that hit, the hit's previous-frame UV and edge fade, its
//! filtered-importance-sampling cone and the colour at the hit (mip 0, or with `FLAG_RAY_COLOR`
//! at the ray's own cone footprint) depend on the ray alone,
//! so one pass computes them once per ray ([`super::layout::HIT_STRIDE`] layout) and the
//! resolves, which visit every ray from up to nine pixels, read them.
//!
//! The values are the very functions the resolves called per (pixel, ray) pair before, on the same
//! inputs, so the resolves' outputs are unchanged to the bit (the colour is used where the
//! resolve's mip clamps to 0, `super::resolve::hit_color`).

use super::params::{SsrParams, FLAG_FIS};
use super::layout::{HIT_COLOR, HIT_FADE, HIT_PDF, HIT_TAN_HALF, HIT_UV, RAY_PDF, RAY_STRIDE};
use super::resolve::{edge_of_screen_fade, hit_colors_stored, hit_footprints_stored, hit_position, load_ray_hit, reproject_hit, sample_color};
use super::sampling::MIRROR_ROUGHNESS;
use super::stochastic::{fis_mip, fis_rays_in_window, fis_tan_half, ray_pdf_at_hit};
use super::trace::load_surface;
use crate::buffer::{load, store};

/// Write the hit record of ray slot `slot` (pixel `slot / samples_per_pixel`, in the ray records'
/// order) at `out[ob..ob + HIT_STRIDE]`, its colour sampled from the colour pyramid `color` where
/// the resolves use it (`super::resolve::hit_colors_stored`); nothing when the slot holds no
/// hitting ray. The record's output starts zeroed on both backends (a new GPU buffer, the CPU
/// launchers' zeroed records and buffers), so the slots of misses and the colour, UV and cone
/// words left unwritten (`hit_colors_stored`, `hit_footprints_stored`) read as zeros, and no pass
/// reads a miss's record.
#[inline]
pub fn hit_record_slot(p: &SsrParams, gbuf: &[f32], color: &[f32], rays: &[f32], slot: u32, out: &mut [f32], ob: usize) {
    // The ray's hit and its pdf: five of its record's eight words (not its direction).
    let rb = (slot as usize) * RAY_STRIDE;
    let (hit, hx, hy) = load_ray_hit(rays, rb);
    if !hit {
        return;
    }
    let pdf = load(rays, rb + RAY_PDF);
    let q = slot / p.samples_per_pixel;
    let sq = load_surface(p, gbuf, q % p.width, q / p.width);
    let hp = hit_position(p, gbuf, hx, hy);
    let (u, v) = reproject_hit(p, gbuf, hx, hy);
    store(out, ob, hp.x);
    store(out, ob + 1, hp.y);
    store(out, ob + 2, hp.z);
    store(out, ob + HIT_PDF, ray_pdf_at_hit(p, &sq, hp, pdf));
    store(out, ob + HIT_FADE, edge_of_screen_fade(u, v, p.edge_fade_rcp_length));
    let tan_half = fis_tan_half(pdf, fis_rays_in_window(p));
    if hit_footprints_stored(p) {
        store(out, ob + HIT_UV, u);
        store(out, ob + HIT_UV + 1, v);
        store(out, ob + HIT_TAN_HALF, tan_half);
    }
    if hit_colors_stored(p) {
        // The mip the resolve would use for this ray at its own pixel (mip 0 without filtered
        // importance sampling or for a mirror pixel, whose ray no other pixel reuses).
        let mip = if p.flags & FLAG_FIS != 0 && !(sq.perceptual_roughness < MIRROR_ROUGHNESS) { fis_mip(sq.origin, hx, hy, tan_half) } else { 0.0 };
        let c = sample_color(p, color, u, v, mip);
        store(out, ob + HIT_COLOR, c.x);
        store(out, ob + HIT_COLOR + 1, c.y);
        store(out, ob + HIT_COLOR + 2, c.z);
    }
}
