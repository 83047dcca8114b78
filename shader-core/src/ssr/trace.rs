//! Screen-space ray tracing against a depth buffer: HDRP's hierarchical (Hi-Z) traversal, a
//! linear march with a fixed number of steps, and a brute-force per-pixel DDA with the same hit
//! rules (the test oracle for Hi-Z).
//!
//! A ray is traced in (screen x, screen y, device depth d = near / z) where d varies linearly
//! along the projected ray. The depth buffer stores linear depth; its pyramid stores device depth,
//! converted once when it is built ([`device_depth`] of every texel), and each coarser cell the
//! maximum device depth of the cells it covers (the closest surface, HDRP's pyramid), so the
//! tracers read it without a division. Every surface is
//! given a thickness: it occupies d in [d_s * thickness_scale + thickness_bias, d_s] (HDRP:
//! `_SsrThicknessScale = 1 / (1 + thickness)`, bias 0 for an infinite far plane), so a point is
//! "inside" a surface when it lies behind it by at most `thickness` times its linear depth.
//! When the G-buffer carries a far depth (the farthest depth the surface seen at each pixel
//! reaches, visibly, within one pixel of its centre: the texel's depth extent), the mip-0 slab
//! ends there instead ([`slab_base`]), so a grazing outline texel's slab ends where its visible
//! surface does.
//!
//! ```
//! use shader_core::ssr::params::SsrParams;
//! use shader_core::ssr::trace::{clampf, device_depth, floor_index, minf};
//! let p = SsrParams { near: 0.1, ..SsrParams::default() };
//! // Reverse-Z: device depth 1 at the near plane, 0 for the sky (infinite linear depth).
//! assert_eq!(device_depth(&p, 0.1), 1.0);
//! assert_eq!(device_depth(&p, f32::INFINITY), 0.0);
//! // The comparison helpers' NaN rules are fixed, so both backends pick the same operand.
//! assert_eq!(minf(f32::NAN, 2.0), 2.0);
//! assert_eq!(clampf(7.0, 0.0, 1.0), 1.0);
//! assert_eq!((floor_index(3.7, 10), floor_index(-1.0, 10), floor_index(f32::NAN, 10), floor_index(99.0, 10)), (3, 0, 0, 10));
//! ```

use crate::buffer::{load, store};
use crate::ieee;
use super::params::{mip_block_texels, mip_children, mip_size, MipBlock, SsrParams, FLAG_BACKFACE_REJECT, FLAG_STOCHASTIC};
use crate::vector::Vec3;
pub use super::compare::{clampf, floor_index, maxf, minf};
pub use super::layout::{gbuf, info, GBufferTexel, Surface, GBUF_STRIDE, RAY_INFO, RAY_PDF, RAY_STRIDE};

/// HDRP's `SSR_TRACE_EPS`: how far a position is nudged past a cell edge along the ray (2^-11 px).
pub const TRACE_EPS: f32 = 0.000_488_281_25;
/// HDRP's ray-towards-sky cut-off: the device depth the ray is clipped at when moving away.
pub const SKY_DEPTH_CUT: f32 = 0.000_000_238_418_58;

/// The outcome of one trace.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TraceHit {
    /// True when the ray hit a surface (then `x`, `y`, `d` describe it).
    pub hit: bool,
    /// The pixel hit.
    pub x: u32,
    /// The row of the pixel hit (row 0 at the top).
    pub y: u32,
    /// Device depth of the surface at the hit pixel.
    pub d: f32,
    /// Iterations of the tracer's loop.
    pub steps: u32,
}

/// Device depth d = near / z of a linear depth z (0 for the sky, z = +inf).
#[inline]
pub fn device_depth(p: &SsrParams, z: f32) -> f32 {
    ieee::div(p.near, z)
}

/// View-space position of screen point (sx, sy) at linear depth z (inverse of the projection
/// described in [`super::params`]).
#[inline]
pub fn view_position(p: &SsrParams, sx: f32, sy: f32, z: f32) -> Vec3 {
    let ndc_x = ieee::div(sx, p.width as f32) * 2.0 - 1.0;
    let ndc_y = 1.0 - ieee::div(sy, p.height as f32) * 2.0;
    let x = ieee::div((ndc_x - p.proj.r0.z) * z, p.proj.r0.x);
    let y = ieee::div((ndc_y - p.proj.r1.z) * z, p.proj.r1.y);
    Vec3::new(x, y, z)
}

/// Screen position and device depth (sx, sy, d) of a view-space point with z > 0.
#[inline]
pub fn project(p: &SsrParams, v: Vec3) -> Vec3 {
    let c = p.proj.transform_point4(v);
    let ndc_x = ieee::div(c.x, c.w);
    let ndc_y = ieee::div(c.y, c.w);
    Vec3::new(
        (ndc_x * 0.5 + 0.5) * p.width as f32,
        (0.5 - ndc_y * 0.5) * p.height as f32,
        ieee::div(c.z, c.w),
    )
}

/// Read pixel (x, y) of the G-buffer as a view-space surface (see [`Surface::valid`]).
pub fn load_surface(p: &SsrParams, gbuf: &[f32], x: u32, y: u32) -> Surface {
    let b = ((y * p.width + x) as usize) * GBUF_STRIDE;
    let [z, nx, ny, nz] = crate::buffer::load4(gbuf, b);
    let nw = Vec3::new(nx, ny, nz);
    let rough = crate::buffer::load(gbuf, b + super::layout::gbuf::ROUGHNESS);
    let sx = x as f32 + 0.5;
    let sy = y as f32 + 0.5;
    let mut s = Surface { perceptual_roughness: rough, ..Default::default() };
    if !(z > 0.0 && z < f32::INFINITY) {
        return s;
    }
    let n = p.view.transform_dir(nw).normalize_or_zero();
    let pos = view_position(p, sx, sy, z);
    let v = (-pos).normalize_or_zero();
    s.pos = pos;
    s.n = n;
    s.v = v;
    s.origin = Vec3::new(sx, sy, device_depth(p, z));
    // Rougher than the fade end: HDRP traces no ray (its opacity would be 0).
    s.valid = n.dot(v) > 0.0 && rough >= 0.0 && rough <= p.roughness_fade_end;
    s
}

/// Mirror reflection of the eye direction about n: 2 (n.v) n - v ([`crate::fresnel::reflect`],
/// the one home of the formula).
pub use crate::fresnel::reflect;

/// The screen-space ray of view-space direction `r` from surface `s`: its origin (the pixel
/// centre) and direction (the screen-space image of pos + k r with k chosen so the end point stays
/// in front of the camera; any such point spans the same projected line). Zero components of the
/// direction are replaced by a tiny positive value so the reciprocal is finite.
pub fn screen_ray(p: &SsrParams, s: &Surface, r: Vec3) -> (Vec3, Vec3) {
    let k = if r.z < 0.0 { minf(1.0, ieee::div(0.5 * s.pos.z, -r.z)) } else { 1.0 };
    let end = project(p, s.pos + r * k);
    let mut dir = end - s.origin;
    if dir.x == 0.0 {
        dir.x = 1e-20;
    }
    if dir.y == 0.0 {
        dir.y = 1e-20;
    }
    if dir.z == 0.0 {
        dir.z = 1e-20;
    }
    (s.origin, dir)
}

/// Device depth of the depth pyramid at `level`, cell (cx, cy) (the pyramid holds device depth;
/// sky = 0).
#[inline]
pub fn pyramid_depth(p: &SsrParams, pyr: &[f32], level: u32, cx: u32, cy: u32) -> f32 {
    let w = mip_size(p.width, level);
    let base = p_mip_offset(p, level);
    load(pyr, (base + cy * w + cx) as usize)
}

/// Half-width, in pixels, of the square around a pixel centre over which a G-buffer's far depth
/// is taken (one pixel: a ray that crosses a surface between two texel centres crosses it within
/// that distance of both). The G-buffer producers (`host`'s analytic scenes,
/// [`crate::pt::gbuffer::gbuffer_pixel`]) use it.
pub const FAR_DEPTH_RADIUS: f32 = 1.0;
/// Primary rays per side of the square grid over [-FAR_DEPTH_RADIUS, FAR_DEPTH_RADIUS]^2 px
/// (offsets -1, -0.5, 0, 0.5, 1 px) whose largest depth on the centre's object, together with the
/// object's outline depth between neighbouring grid points, is the far depth.
pub const FAR_DEPTH_GRID: u32 = 5;

/// Device depth where the thickness slab of the surface in cell (cx, cy) of `level` ends: a ray
/// point at device depth in [slab_base, floor_d] is inside that surface. At mip 0 with a
/// far-depth layer ([`SsrParams::far_depth_offset`]), the texel's far depth (the farthest depth
/// its visible surface reaches within one pixel of the centre: a ray crossing that surface
/// between two texel centres is found there, while a ray that reaches a grazing outline texel
/// behind it passes under or behind the object, or hits a side of it hidden from the camera,
/// which the screen does not hold; docs/ssr.md, "Comb fringes"), made at least
/// [`SsrParams::min_thickness_scale`] thick; otherwise (coarse mips, whose min pyramid bounds
/// the closest surface, or no layer) HDRP's constant slab `floor_d * thickness_scale +
/// thickness_bias` (`ScreenSpaceReflections.compute`). A NaN far depth gives the minimum slab.
#[inline]
pub fn slab_base(p: &SsrParams, pyr: &[f32], level: u32, cx: u32, cy: u32, floor_d: f32) -> f32 {
    if level == 0 && p.far_depth_offset != 0 {
        let far_d = load(pyr, (p.far_depth_offset + cy * p.width + cx) as usize);
        minf(far_d, floor_d * p.min_thickness_scale)
    } else {
        floor_d * p.thickness_scale + p.thickness_bias
    }
}

/// Offset (in texels) of mip `level` in a packed pyramid: the sum of the sizes of the levels
/// before it (the host packs its pyramids the same way).
#[inline]
pub fn p_mip_offset(p: &SsrParams, level: u32) -> u32 {
    let mut off = 0;
    let mut l = 0;
    while l < level {
        off += mip_size(p.width, l) * mip_size(p.height, l);
        l += 1;
    }
    off
}

/// The clip distance t_max of a screen-space ray: where it leaves the screen (pixel centres of
/// the border), reaches the near plane (towards the eye) or the sky cut-off (away), whichever is
/// first (HDRP `ScreenSpaceReflectionsTracing`).
#[inline]
pub fn ray_t_max(p: &SsrParams, o: Vec3, rcp: Vec3) -> f32 {
    let bx = if rcp.x >= 0.0 { p.width as f32 - 0.5 } else { 0.5 };
    let by = if rcp.y >= 0.0 { p.height as f32 - 0.5 } else { 0.5 };
    let bz = if rcp.z >= 0.0 { 1.0 } else { SKY_DEPTH_CUT };
    minf(minf((bx - o.x) * rcp.x, (by - o.y) * rcp.y), (bz - o.z) * rcp.z)
}

/// The ray parameter where it leaves its origin texel (HDRP starts marching there to avoid
/// self-intersection).
#[inline]
pub fn ray_t_start(rcp: Vec3) -> f32 {
    minf((0.5 * rcp.x).abs(), (0.5 * rcp.y).abs())
}

/// Nudge a screen position past a cell edge it lies on, in the ray's direction (HDRP).
#[inline]
fn nudge(x: f32, sign: f32) -> f32 {
    let rounded = Float::floor(x + 0.5);
    let sgn_edge = rounded - x;
    let sat = clampf(sign * sgn_edge + TRACE_EPS, 0.0, TRACE_EPS);
    x + sign * sat
}

use spirv_std::num_traits::Float;

/// HDRP's hierarchical ray march through the max-device-depth pyramid (`ScreenSpaceReflections.compute`,
/// `ScreenSpaceReflectionsTracing`): step to the cell wall and climb while the ray stays in
/// front of the cell's closest surface (in either direction of depth; HDRP always descends for
/// rays towards the eye), descend where it reaches it or is behind it; a hit is the first mip-0 cell
/// whose surface the ray crosses, or whose thickness slab it is inside. A ray that was behind a
/// surface's slab at mip 0 and then lands inside a slab is a miss (HDRP's rule), and so is a hit
/// on the sky.
pub fn trace_hiz(p: &SsrParams, pyr: &[f32], o: Vec3, dir: Vec3, max_mip: u32, max_iter: u32) -> TraceHit {
    let rcp = Vec3::new(ieee::div(1.0, dir.x), ieee::div(1.0, dir.y), ieee::div(1.0, dir.z));
    let step_x: u32 = if rcp.x >= 0.0 { 1 } else { 0 };
    let step_y: u32 = if rcp.y >= 0.0 { 1 } else { 0 };
    let sign_x: f32 = if rcp.x >= 0.0 { 1.0 } else { -1.0 };
    let sign_y: f32 = if rcp.y >= 0.0 { 1.0 } else { -1.0 };
    let t_max = ray_t_max(p, o, rcp);
    let mut t = ray_t_start(rcp);
    let mut mip: u32 = 0;
    // Offset of mip `mip` in the packed pyramid ([`p_mip_offset`]), kept up to date as the ray
    // climbs and descends instead of summed again at every step.
    let mut base: u32 = 0;
    let mut iter: u32 = 0;
    let mut hit = false;
    let mut miss = false;
    let mut below_mip0 = false;
    let mut pos = o;
    while !(hit || miss) && t <= t_max && iter < max_iter {
        pos = o + dir * t;
        pos.x = nudge(pos.x, sign_x);
        pos.y = nudge(pos.y, sign_y);
        let w = mip_size(p.width, mip);
        let h = mip_size(p.height, mip);
        let cx = floor_index(pos.x, p.width - 1) >> mip;
        let cy = floor_index(pos.y, p.height - 1) >> mip;
        let cx = if cx < w { cx } else { w - 1 };
        let cy = if cy < h { cy } else { h - 1 };
        let floor_d = load(pyr, (base + cy * w + cx) as usize);
        let base_d = slab_base(p, pyr, mip, cx, cy, floor_d);
        let wall_x = ((cx + step_x) << mip) as f32;
        let wall_y = ((cy + step_y) << mip) as f32;
        let dist_wall = minf((wall_x - o.x) * rcp.x, (wall_y - o.y) * rcp.y);
        let dist_floor = (floor_d - o.z) * rcp.z;
        let below_floor = pos.z < floor_d;
        let above_base = pos.z >= base_d;
        let inside_floor = below_floor && above_base;
        let hit_floor = t <= dist_floor && dist_floor <= dist_wall;
        // Victory conditions, in HDRP's order.
        miss = below_mip0 && inside_floor;
        hit = mip == 0 && (hit_floor || inside_floor);
        below_mip0 = mip == 0 && below_floor;
        // At a coarse mip, a ray behind the cell's closest surface stays where it is and
        // descends. (A ray towards the eye that reaches that surface inside the cell is behind it
        // first, and may cross a farther finer-mip surface before reaching it: advancing it to
        // the coarse surface, as HDRP does, would skip that hit. For rays away from the eye the
        // two conditions exclude each other, so this is HDRP's order.)
        t = if mip != 0 && below_floor {
            t
        } else if hit_floor {
            dist_floor
        } else {
            dist_wall
        };
        pos.z = floor_d;
        // Descend only where the ray reaches the cell's closest surface (or is behind it); a ray
        // in front of it that leaves the cell without reaching it cannot hit anything inside the
        // cell, whatever its direction, so it climbs. HDRP also descends for every ray towards
        // the eye (`rayTowardsEye`): such rays then march one texel per iteration and run out of
        // iterations at 1080p (tests/tests/ssr_1080p.rs).
        if hit_floor || below_floor {
            if mip > 0 {
                mip -= 1;
                base -= mip_size(p.width, mip) * mip_size(p.height, mip);
            }
        } else if mip < max_mip {
            base += w * h;
            mip += 1;
        }
        iter += 1;
    }
    // Intersections with the sky are misses.
    miss = miss || pos.z == 0.0;
    let hit = hit && !miss;
    TraceHit {
        hit,
        x: floor_index(pos.x, p.width - 1),
        y: floor_index(pos.y, p.height - 1),
        d: pos.z,
        steps: iter,
    }
}

/// Linear march: `steps` equal steps from the texel exit to the clip distance, sampling mip 0 at
/// each; the first sample behind the surface there is a hit if it is within the surface's
/// thickness or, with `crossing`, if the ray was still in front of that depth at the previous
/// step (it crossed the surface during the step: without this a coarse march steps over the thin
/// slabs; with it, rays passing behind foreground objects hit their silhouettes).
pub fn trace_linear(p: &SsrParams, pyr: &[f32], o: Vec3, dir: Vec3, steps: u32, crossing: bool) -> TraceHit {
    let rcp = Vec3::new(ieee::div(1.0, dir.x), ieee::div(1.0, dir.y), ieee::div(1.0, dir.z));
    let t_max = ray_t_max(p, o, rcp);
    let t0 = ray_t_start(rcp);
    let mut out = TraceHit::default();
    if !(t_max > t0) || steps == 0 {
        return out;
    }
    let dt = ieee::div(t_max - t0, steps as f32);
    let mut i: u32 = 1;
    while i <= steps {
        let t = t0 + dt * i as f32;
        let pos = o + dir * t;
        let cx = floor_index(pos.x, p.width - 1);
        let cy = floor_index(pos.y, p.height - 1);
        let floor_d = pyramid_depth(p, pyr, 0, cx, cy);
        let base_d = slab_base(p, pyr, 0, cx, cy, floor_d);
        out.steps = i;
        let prev_z = o.z + dir.z * (t - dt);
        if floor_d > 0.0 && pos.z <= floor_d && (pos.z >= base_d || (crossing && prev_z >= floor_d)) {
            out.hit = true;
            out.x = cx;
            out.y = cy;
            out.d = floor_d;
            return out;
        }
        i += 1;
    }
    out
}

/// Brute force: visit every mip-0 cell the projected ray crosses, in order (a DDA), with HDRP's
/// mip-0 hit rules (crossing the surface inside the cell, or entering it inside its slab; entering
/// a slab from behind a previous one is a miss). The oracle the Hi-Z tracer is tested against.
pub fn trace_brute_force(p: &SsrParams, pyr: &[f32], o: Vec3, dir: Vec3) -> TraceHit {
    let rcp = Vec3::new(ieee::div(1.0, dir.x), ieee::div(1.0, dir.y), ieee::div(1.0, dir.z));
    let step_x: u32 = if rcp.x >= 0.0 { 1 } else { 0 };
    let step_y: u32 = if rcp.y >= 0.0 { 1 } else { 0 };
    let sign_x: f32 = if rcp.x >= 0.0 { 1.0 } else { -1.0 };
    let sign_y: f32 = if rcp.y >= 0.0 { 1.0 } else { -1.0 };
    let t_max = ray_t_max(p, o, rcp);
    let mut t = ray_t_start(rcp);
    let mut out = TraceHit::default();
    let mut was_behind = false;
    let limit = 2 * (p.width + p.height) + 4;
    let mut n: u32 = 0;
    while t <= t_max && n < limit {
        n += 1;
        let mut pos = o + dir * t;
        pos.x = nudge(pos.x, sign_x);
        pos.y = nudge(pos.y, sign_y);
        let cx = floor_index(pos.x, p.width - 1);
        let cy = floor_index(pos.y, p.height - 1);
        let floor_d = pyramid_depth(p, pyr, 0, cx, cy);
        let base_d = slab_base(p, pyr, 0, cx, cy, floor_d);
        let t_exit = minf(
            ((cx + step_x) as f32 - o.x) * rcp.x,
            ((cy + step_y) as f32 - o.y) * rcp.y,
        );
        let t_floor = (floor_d - o.z) * rcp.z;
        let below = pos.z < floor_d;
        let inside = below && pos.z >= base_d;
        let crosses = t <= t_floor && t_floor <= t_exit;
        out.steps = n;
        if was_behind && inside {
            break;
        }
        if crosses || inside {
            out.hit = floor_d != 0.0;
            out.x = cx;
            out.y = cy;
            out.d = floor_d;
            return out;
        }
        was_behind = below;
        t = t_exit;
    }
    out.hit = false;
    out
}

/// Hit validation: reject hits on surfaces facing away from the ray (their normal has a
/// non-negative component along it), when the flag asks for it, and hits on the origin pixel.
/// Returns (hit, rejected).
pub fn validate_hit(p: &SsrParams, gbuf: &[f32], ox: u32, oy: u32, r: Vec3, h: &TraceHit) -> (bool, bool) {
    if !h.hit {
        return (false, false);
    }
    if h.x == ox && h.y == oy {
        return (false, true);
    }
    if p.flags & FLAG_BACKFACE_REJECT != 0 {
        let b = ((h.y * p.width + h.x) as usize) * GBUF_STRIDE;
        let n = p.view.transform_dir(Vec3::new(load(gbuf, b + super::layout::gbuf::NORMAL), load(gbuf, b + super::layout::gbuf::NORMAL + 1), load(gbuf, b + super::layout::gbuf::NORMAL + 2)));
        if n.dot(r) >= 0.0 {
            return (false, true);
        }
    }
    (true, false)
}

/// Trace one ray of direction `r` (view space, unit) from surface `s` at pixel (x, y) with
/// `mode` (see [`super::params`]) and write its record at `out[ob..ob + RAY_STRIDE]`.
#[allow(clippy::too_many_arguments)]
pub fn trace_and_store(
    p: &SsrParams,
    gbuf: &[f32],
    pyr: &[f32],
    s: &Surface,
    x: u32,
    y: u32,
    r: Vec3,
    pdf: f32,
    mode: u32,
    linear_steps: u32,
    out: &mut [f32],
    ob: usize,
) {
    let (o, dir) = screen_ray(p, s, r);
    let h = if mode == super::params::TRACE_LINEAR || mode == super::params::TRACE_LINEAR_CROSSING {
        trace_linear(p, pyr, o, dir, linear_steps, mode == super::params::TRACE_LINEAR_CROSSING)
    } else if mode == super::params::TRACE_BRUTE_FORCE {
        trace_brute_force(p, pyr, o, dir)
    } else {
        trace_hiz(p, pyr, o, dir, p.depth_max_mip, p.hiz_max_iterations)
    };
    let (hit, rejected) = validate_hit(p, gbuf, x, y, r, &h);
    let mut bits = info::VALID | (h.steps << info::STEPS_SHIFT);
    if hit {
        bits |= info::HIT;
    }
    if rejected {
        bits |= info::REJECTED;
    }
    store(out, ob, if hit { h.x as f32 + 0.5 } else { -1.0 });
    store(out, ob + 1, if hit { h.y as f32 + 0.5 } else { -1.0 });
    store(out, ob + 2, if hit { h.d } else { 0.0 });
    store(out, ob + RAY_INFO, f32::from_bits(bits));
    store(out, ob + RAY_PDF, pdf);
    store(out, ob + 5, r.x);
    store(out, ob + 6, r.y);
    store(out, ob + 7, r.z);
}

/// Write an empty ray record (no ray traced for this pixel).
#[inline]
pub fn store_no_ray(out: &mut [f32], ob: usize) {
    store(out, ob, -1.0);
    store(out, ob + 1, -1.0);
    store(out, ob + 2, 0.0);
    store(out, ob + 3, f32::from_bits(0));
    store(out, ob + 4, 0.0);
    store(out, ob + 5, 0.0);
    store(out, ob + 6, 0.0);
    store(out, ob + 7, 0.0);
}

/// HDRP tracing pass for pixel (x, y): the mirror reflection ray, or with `FLAG_STOCHASTIC` (HDRP's
/// non-approximate mode) one GGX-VNDF-sampled ray, traced with the mode in the parameters.
pub fn hdrp_trace_pixel(p: &SsrParams, gbuf: &[f32], pyr: &[f32], x: u32, y: u32, out: &mut [f32], ob: usize) {
    let s = load_surface(p, gbuf, x, y);
    if !s.valid {
        store_no_ray(out, ob);
        return;
    }
    let (r, pdf) = if p.flags & FLAG_STOCHASTIC != 0 {
        super::sampling::sample_ray(p, &s, x, y, 0)
    } else {
        (reflect(s.v, s.n), 0.0)
    };
    trace_and_store(p, gbuf, pyr, &s, x, y, r, pdf, p.trace_mode, p.linear_steps, out, ob);
}

/// One texel of mip `level` (>= 1) of the max-device-depth pyramid: the maximum of the (up to)
/// 2x2 texels of mip `level - 1` it covers (texels past the edge of an odd-sized mip are ignored,
/// so every cell bounds exactly the pixels [x 2^level, (x + 1) 2^level)). Since the correctly
/// rounded near / z does not increase with z, this is bit for bit the device depth of the cell's
/// minimum linear depth.
pub fn hiz_downsample_texel(p: &SsrParams, pyr: &[f32], level: u32, x: u32, y: u32) -> f32 {
    hiz_children_max(pyr, p_mip_offset(p, level - 1), mip_size(p.width, level - 1), mip_size(p.height, level - 1), x, y)
}

/// [`hiz_downsample_texel`] with the mip below given as its texel offset and size.
#[inline]
fn hiz_children_max(pyr: &[f32], base: u32, pw: u32, ph: u32, x: u32, y: u32) -> f32 {
    let (x0, x1) = mip_children(x, pw);
    let (y0, y1) = mip_children(y, ph);
    let a = load(pyr, (base + y0 * pw + x0) as usize);
    let b = load(pyr, (base + y0 * pw + x1) as usize);
    let c = load(pyr, (base + y1 * pw + x0) as usize);
    let d = load(pyr, (base + y1 * pw + x1) as usize);
    hiz_max(a, b, c, d)
}

/// The max-device-depth of a 2x2 block (texels (x0, y0), (x1, y0), (x0, y1), (x1, y1)), in the one
/// order every pyramid texel uses.
#[inline]
pub fn hiz_max(a: f32, b: f32, c: f32, d: f32) -> f32 {
    maxf(maxf(a, b), maxf(c, d))
}

impl MipBlock<f32> {
    /// Write the block into the pyramid buffer (one value per texel).
    #[inline]
    pub fn store(&self, pyr: &mut [f32]) {
        store(pyr, self.texels[0] as usize, self.values[0]);
        store(pyr, self.texels[1] as usize, self.values[1]);
        store(pyr, self.texels[2] as usize, self.values[2]);
        store(pyr, self.texels[3] as usize, self.values[3]);
        if let Some((j, v)) = self.above {
            store(pyr, j as usize, v);
        }
    }
}

/// A pass of the max-device-depth pyramid, invocation `k`: mips `level` and `level + 1` in one
/// step ([`MipBlock`]; the passes are `level` = 0, 2, 4, ...). For `level` 0 the block's texels
/// hold linear depth, converted in place to device depth ([`device_depth`]); blocks
/// `w1 h1..2 w1 h1` (w1 x h1 = mip 1's size) then cover the far-depth layer at
/// [`SsrParams::far_depth_offset`] where the parameters have one (converted only: it has no mips).
/// For `level` >= 1 each texel is the maximum of the mip below ([`hiz_downsample_texel`]). Each invocation
/// reads only its own block's texels or the mip below, so the invocations of a pass are
/// independent.
pub fn hiz_block(p: &SsrParams, pyr: &[f32], level: u32, k: u32) -> MipBlock<f32> {
    let w = mip_size(p.width, level);
    let h = mip_size(p.height, level);
    let n_above = mip_size(w, 1) * mip_size(h, 1);
    let far = level == 0 && k >= n_above;
    let base = if far { p.far_depth_offset } else { p_mip_offset(p, level) };
    let b = if far { k - n_above } else { k };
    let (texels, xy) = mip_block_texels(w, h, base, b);
    let values = if level == 0 {
        [
            device_depth(p, load(pyr, texels[0] as usize)),
            device_depth(p, load(pyr, texels[1] as usize)),
            device_depth(p, load(pyr, texels[2] as usize)),
            device_depth(p, load(pyr, texels[3] as usize)),
        ]
    } else {
        let (below, pw, ph) = (p_mip_offset(p, level - 1), mip_size(p.width, level - 1), mip_size(p.height, level - 1));
        [
            hiz_children_max(pyr, below, pw, ph, xy[0].0, xy[0].1),
            hiz_children_max(pyr, below, pw, ph, xy[1].0, xy[1].1),
            hiz_children_max(pyr, below, pw, ph, xy[2].0, xy[2].1),
            hiz_children_max(pyr, below, pw, ph, xy[3].0, xy[3].1),
        ]
    };
    let above = if !far && level + 1 < p.mip_count { Some((base + w * h + b, hiz_max(values[0], values[1], values[2], values[3]))) } else { None };
    MipBlock { texels, values, above }
}
