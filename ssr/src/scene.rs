//! Built-in procedural scenes and the analytic CPU ray caster that renders their G-buffers and
//! the ray-traced reference (f64 throughout; independent of the kernels' f32 code).
//!
//! Shading is view independent (diffuse sun with shadows + a hemispherical ambient term +
//! emission), so the colour a screen-space tracer reads at a hit pixel is exactly the radiance the
//! hit point sends along any reflected ray: the reference and SSR see the same signal.

use super::camera::{Camera, V3};
use super::gbuffer::GBuffer;
use anyhow::{bail, Result};
use rayon::prelude::*;

/// A primitive.
#[derive(Clone, Copy, Debug)]
pub enum Shape {
    Sphere { c: V3, r: f64 },
    /// Axis-aligned box.
    Aabb { lo: V3, hi: V3 },
}

/// Surface properties; roughness may vary in bands along a world axis.
#[derive(Clone, Debug)]
pub struct Material {
    pub albedo: V3,
    pub emission: V3,
    pub roughness: f32,
    pub metalness: f32,
    /// (axis, band edges, roughness per band): band k is below edge k (the last band beyond the
    /// last edge); overrides `roughness`.
    pub bands: Option<(usize, Vec<f64>, Vec<f32>)>,
}

impl Material {
    pub fn diffuse(albedo: V3, roughness: f32) -> Material {
        Material { albedo, emission: V3::ZERO, roughness, metalness: 0.0, bands: None }
    }
    pub fn emissive(albedo: V3, emission: V3) -> Material {
        Material { albedo, emission, roughness: 1.0, metalness: 0.0, bands: None }
    }
    fn with_bands(mut self, axis: usize, edges: &[f64], values: &[f32]) -> Material {
        assert_eq!(edges.len() + 1, values.len());
        self.bands = Some((axis, edges.to_vec(), values.to_vec()));
        self
    }
    fn with_metal(mut self, m: f32) -> Material {
        self.metalness = m;
        self
    }

    /// Perceptual roughness at world point `p`.
    pub fn roughness_at(&self, p: V3) -> f32 {
        match &self.bands {
            Some((axis, edges, vals)) => {
                let k = edges.iter().position(|&e| p[*axis] < e).unwrap_or(edges.len());
                vals[k]
            }
            None => self.roughness,
        }
    }
}

#[derive(Clone, Debug)]
pub struct Object {
    pub shape: Shape,
    pub material: Material,
}

/// The result of a ray cast.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub t: f64,
    pub p: V3,
    pub n: V3,
    pub object: usize,
}

/// A procedural scene.
#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    pub objects: Vec<Object>,
    /// Unit direction towards the sun.
    pub sun_dir: V3,
    pub sun_irradiance: V3,
    pub ambient: V3,
    /// Radiance of the sky (what a ray that escapes sees; also the SSR fallback).
    pub sky: [f32; 3],
    pub eye: V3,
    pub target: V3,
    /// Camera path: eye offset per frame (animated scenes).
    pub eye_velocity: V3,
    pub sway: f64,
    pub fov_y_degrees: f32,
    pub near: f32,
}

/// Names of the built-in scenes.
pub const SCENES: [&str; 4] = ["floor", "hallway", "thin", "animated"];

fn intersect(shape: &Shape, o: V3, d: V3, t_min: f64) -> Option<(f64, V3)> {
    match *shape {
        Shape::Sphere { c, r } => {
            let oc = o - c;
            let b = oc.dot(d);
            let cc = oc.dot(oc) - r * r;
            let disc = b * b - cc;
            if disc < 0.0 {
                return None;
            }
            let s = disc.sqrt();
            let mut t = -b - s;
            if t <= t_min {
                t = -b + s;
            }
            if t <= t_min {
                return None;
            }
            let p = o + (d * t);
            Some((t, (p - c) * (1.0 / r)))
        }
        Shape::Aabb { lo, hi } => {
            let mut t0 = f64::NEG_INFINITY;
            let mut t1 = f64::INFINITY;
            let mut axis0 = 0;
            let mut axis1 = 0;
            for a in 0..3 {
                let inv = 1.0 / d[a];
                let mut ta = (lo[a] - o[a]) * inv;
                let mut tb = (hi[a] - o[a]) * inv;
                if ta > tb {
                    std::mem::swap(&mut ta, &mut tb);
                }
                if ta > t0 {
                    t0 = ta;
                    axis0 = a;
                }
                if tb < t1 {
                    t1 = tb;
                    axis1 = a;
                }
            }
            if t0 > t1 {
                return None;
            }
            let (t, axis, entering) = if t0 > t_min { (t0, axis0, true) } else if t1 > t_min { (t1, axis1, false) } else { return None };
            let mut n = V3::ZERO;
            let s = if d[axis] > 0.0 { -1.0 } else { 1.0 };
            n[axis] = if entering { s } else { -s };
            Some((t, n))
        }
    }
}

/// Bisection steps of [`Scene::far_depth`] towards an outline between two grid points.
pub const FAR_DEPTH_BISECTIONS: u32 = 16;

impl Scene {
    /// The G-buffer's far depth of the pixel centre (sx, sy) whose primary ray hit `h` at view
    /// depth `z`: the largest view depth of the same object over the primary rays through a
    /// `FAR_DEPTH_GRID`^2 grid spanning [-r, r]^2 pixels around the centre (r =
    /// `FAR_DEPTH_RADIUS`, both `shader_core::ssr::trace`), and, between two neighbouring grid
    /// points of which only one sees the object, at the object's outline on that segment (found
    /// by bisection to 2^-[`FAR_DEPTH_BISECTIONS`] of the grid spacing: near an outline the depth
    /// grows like a square root, which the grid alone misses), i.e. the depth extent of the
    /// surface the pixel shows, visible, near it (`super::gbuffer`'s `depth_far`).
    pub fn far_depth(&self, cam: &Camera, width: usize, height: usize, sx: f64, sy: f64, h: &Hit, z: f64) -> f64 {
        use shader_core::ssr::trace::{FAR_DEPTH_GRID, FAR_DEPTH_RADIUS};
        let eye = cam.eye();
        let (k, radius) = (FAR_DEPTH_GRID as usize - 1, f64::from(FAR_DEPTH_RADIUS));
        let at = |ox: f64, oy: f64| -> Option<f64> {
            let d = cam.ray_dir(width, height, sx + ox, sy + oy);
            self.cast(eye, d, 1e-9).filter(|hs| hs.object == h.object).map(|hs| cam.to_view(hs.p)[2])
        };
        let offset = |a: usize| radius * (2.0 * a as f64 / k as f64 - 1.0);
        let grid: Vec<Option<f64>> = (0..=k).flat_map(|b| (0..=k).map(move |a| (a, b))).map(|(a, b)| at(offset(a), offset(b))).collect();
        let mut far = grid.iter().flatten().fold(z, |m, &v| m.max(v));
        for b in 0..=k {
            for a in 0..=k {
                for (a2, b2) in [(a + 1, b), (a, b + 1)] {
                    if a2 > k || b2 > k {
                        continue;
                    }
                    let (p, q) = (grid[b * (k + 1) + a], grid[b2 * (k + 1) + a2]);
                    if p.is_some() == q.is_some() {
                        continue;
                    }
                    // Bisect from the grid point on the object (in) towards the one off it (out).
                    let (mut inp, mut out) = ((offset(a), offset(b)), (offset(a2), offset(b2)));
                    let mut depth = p.or(q).expect("one of the two sees the object");
                    if p.is_none() {
                        std::mem::swap(&mut inp, &mut out);
                    }
                    for _ in 0..FAR_DEPTH_BISECTIONS {
                        let mid = (0.5 * (inp.0 + out.0), 0.5 * (inp.1 + out.1));
                        match at(mid.0, mid.1) {
                            Some(v) => {
                                inp = mid;
                                depth = v;
                            }
                            None => out = mid,
                        }
                    }
                    far = far.max(depth);
                }
            }
        }
        far
    }

    /// The nearest hit along the unit ray o + t d with t > t_min.
    pub fn cast(&self, o: V3, d: V3, t_min: f64) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        for (i, obj) in self.objects.iter().enumerate() {
            if let Some((t, n)) = intersect(&obj.shape, o, d, t_min) {
                if best.map(|b| t < b.t).unwrap_or(true) {
                    best = Some(Hit { t, p: (o + (d * t)), n, object: i });
                }
            }
        }
        best
    }

    /// Outgoing radiance of a hit (view independent): emission + albedo/pi (sun n.l shadowed +
    /// ambient (0.6 + 0.4 n.y)).
    pub fn shade(&self, h: &Hit) -> V3 {
        let m = &self.objects[h.object].material;
        let nl = h.n.dot(self.sun_dir);
        let mut sun = 0.0;
        if nl > 0.0 {
            let o = h.p + (h.n * (1e-6));
            if self.cast(o, self.sun_dir, 1e-6).is_none() {
                sun = nl;
            }
        }
        let amb = 0.6 + 0.4 * h.n[1];
        let mut c = V3::ZERO;
        for k in 0..3 {
            c[k] = m.emission[k] + m.albedo[k] / std::f64::consts::PI * (self.sun_irradiance[k] * sun + self.ambient[k] * amb);
        }
        c
    }

    /// The camera of frame `frame` (animated scenes move along a path; others are static).
    pub fn camera(&self, frame: u32) -> Camera {
        let f = frame as f64;
        let sway = V3::new(self.sway * (0.21 * f).sin(), 0.25 * self.sway * (0.13 * f).sin(), 0.0);
        let eye = (self.eye + (self.eye_velocity * f)) + sway;
        let target = (self.target + (self.eye_velocity * f)) + (sway * 0.5);
        Camera::look_at(eye, target, V3::Y, self.fov_y_degrees, self.near)
    }

    /// Is this scene's camera animated?
    pub fn animated(&self) -> bool {
        self.sway != 0.0 || self.eye_velocity.dot(self.eye_velocity) > 0.0
    }

    /// Render the G-buffer of frame `frame` at `width` x `height`: primary rays through pixel
    /// centres (with the far depth of [`Scene::far_depth`]); the colour buffer is rendered from
    /// the previous frame's camera (frame - 1 for animated scenes), motion vectors from reprojecting each pixel's point (or direction, for
    /// the sky) with the previous camera.
    pub fn render_gbuffer(&self, width: usize, height: usize, frame: u32) -> GBuffer {
        let cam = self.camera(frame);
        let prev = if self.animated() && frame > 0 { self.camera(frame - 1) } else { cam };
        let eye = cam.eye();
        let n = width * height;
        let rows: Vec<(f32, f32, [f32; 3], f32, f32, [f32; 3], [f32; 2])> = (0..n)
            .into_par_iter()
            .map(|i| {
                let (x, y) = (i % width, i / width);
                let (sx, sy) = (x as f64 + 0.5, y as f64 + 0.5);
                let d = cam.ray_dir(width, height, sx, sy);
                match self.cast(eye, d, 1e-9) {
                    Some(h) => {
                        let v = cam.to_view(h.p);
                        let m = &self.objects[h.object].material;
                        let mv = cam.motion(&prev, width, height, sx, sy, Some(h.p));
                        let far = self.far_depth(&cam, width, height, sx, sy, &h, v[2]);
                        (
                            v[2] as f32,
                            (far as f32).max(v[2] as f32),
                            [h.n[0] as f32, h.n[1] as f32, h.n[2] as f32],
                            m.roughness_at(h.p),
                            m.metalness,
                            [m.albedo[0] as f32, m.albedo[1] as f32, m.albedo[2] as f32],
                            mv,
                        )
                    }
                    None => (f32::INFINITY, f32::INFINITY, [0.0, 1.0, 0.0], 1.0, 0.0, [0.0; 3], cam.motion(&prev, width, height, sx, sy, None)),
                }
            })
            .collect();
        let color = self.render_color(width, height, &prev);
        let mut g = GBuffer::empty(width, height, color, cam, prev, self.sky);
        for (z, zb, nn, r, m, bc, mv) in rows {
            g.depth.push(z);
            g.depth_far.as_mut().unwrap().push(zb);
            g.normal.extend_from_slice(&nn);
            g.roughness.push(r);
            g.metalness.push(m);
            g.base_color.extend_from_slice(&bc);
            g.motion.extend_from_slice(&mv);
        }
        g
    }

    /// The HDR colour image seen by `cam` (diffuse radiance of the first hit, or the sky).
    pub fn render_color(&self, width: usize, height: usize, cam: &Camera) -> Vec<f32> {
        let eye = cam.eye();
        (0..width * height)
            .into_par_iter()
            .flat_map_iter(|i| {
                let (x, y) = (i % width, i / width);
                let d = cam.ray_dir(width, height, x as f64 + 0.5, y as f64 + 0.5);
                let c = match self.cast(eye, d, 1e-9) {
                    Some(h) => {
                        let c = self.shade(&h);
                        [c[0] as f32, c[1] as f32, c[2] as f32]
                    }
                    None => self.sky,
                };
                c.into_iter()
            })
            .collect()
    }
}

fn aabb(lo: V3, hi: V3, m: Material) -> Object {
    Object { shape: Shape::Aabb { lo, hi }, material: m }
}
fn sphere(c: V3, r: f64, m: Material) -> Object {
    Object { shape: Shape::Sphere { c, r }, material: m }
}

fn base_scene(name: &str, objects: Vec<Object>, eye: V3, target: V3) -> Scene {
    Scene {
        name: name.into(),
        objects,
        sun_dir: (V3::new(0.45, 0.8, -0.35)).normalize(),
        sun_irradiance: V3::new(3.0, 2.85, 2.6),
        ambient: V3::new(0.55, 0.6, 0.7),
        sky: [0.35, 0.45, 0.65],
        eye,
        target,
        eye_velocity: V3::ZERO,
        sway: 0.0,
        fov_y_degrees: 60.0,
        near: 0.1,
    }
}

/// A glossy floor in roughness bands along x (0 for x < 0.2, then 0.08, 0.2, 0.35) with spheres,
/// boxes and a back wall.
fn floor_scene(name: &str) -> Scene {
    let floor = Material::diffuse(V3::new(0.5, 0.5, 0.52), 0.0).with_bands(0, &[0.2, 0.9, 1.6], &[0.0, 0.08, 0.2, 0.35]);
    let objects = vec![
        aabb(V3::new(-4.0, -0.2, -2.0), V3::new(4.0, 0.0, 12.0), floor),
        aabb(V3::new(-4.0, 0.0, 8.0), V3::new(4.0, 3.0, 8.4), Material::diffuse(V3::new(0.75, 0.7, 0.55), 1.0)),
        sphere(V3::new(-2.2, 0.6, 4.0), 0.6, Material::diffuse(V3::new(0.85, 0.2, 0.15), 1.0)),
        sphere(V3::new(0.3, 0.45, 5.5), 0.45, Material::diffuse(V3::new(0.15, 0.7, 0.25), 1.0)),
        sphere(V3::new(2.3, 0.8, 4.6), 0.8, Material::diffuse(V3::new(0.2, 0.35, 0.9), 0.4).with_metal(1.0)),
        sphere(V3::new(-0.8, 0.25, 3.0), 0.25, Material::emissive(V3::new(0.9, 0.9, 0.9), V3::new(4.0, 3.0, 1.2))),
        aabb(V3::new(-3.4, 0.0, 6.2), V3::new(-2.4, 1.4, 7.0), Material::diffuse(V3::new(0.9, 0.85, 0.3), 1.0)),
        aabb(V3::new(0.9, 0.0, 6.6), V3::new(1.9, 0.7, 7.4), Material::diffuse(V3::new(0.6, 0.25, 0.7), 1.0)),
        aabb(V3::new(-1.2, 0.0, 7.0), V3::new(-0.6, 2.2, 7.6), Material::diffuse(V3::new(0.3, 0.75, 0.8), 1.0)),
    ];
    base_scene(name, objects, V3::new(0.0, 1.5, -0.6), V3::new(0.0, 0.55, 5.0))
}

/// A hallway: a slightly glossy floor, side walls whose roughness steps along the hall
/// (0 .. 0.45), a diffuse ceiling, pillars and emissive panels at the end.
fn hallway_scene() -> Scene {
    let steps = [0.0, 0.05, 0.12, 0.22, 0.32, 0.45];
    let edges = [6.0, 8.0, 10.0, 12.0, 14.0];
    let objects = vec![
        aabb(V3::new(-2.0, -0.2, -1.0), V3::new(2.0, 0.0, 16.0), Material::diffuse(V3::new(0.45, 0.42, 0.4), 0.06)),
        aabb(V3::new(-2.2, 0.0, -1.0), V3::new(-2.0, 3.0, 16.0), Material::diffuse(V3::new(0.55, 0.5, 0.45), 0.0).with_bands(2, &edges, &steps)),
        aabb(V3::new(2.0, 0.0, -1.0), V3::new(2.2, 3.0, 16.0), Material::diffuse(V3::new(0.4, 0.45, 0.55), 0.0).with_bands(2, &edges, &steps)),
        aabb(V3::new(-2.0, 3.0, -1.0), V3::new(2.0, 3.2, 16.0), Material::diffuse(V3::new(0.8, 0.8, 0.8), 1.0)),
        aabb(V3::new(-2.0, 0.0, 15.0), V3::new(2.0, 3.0, 15.2), Material::diffuse(V3::new(0.7, 0.7, 0.7), 1.0)),
        aabb(V3::new(-1.6, 0.6, 14.9), V3::new(-0.6, 2.2, 15.0), Material::emissive(V3::new(0.9, 0.3, 0.2), V3::new(6.0, 1.5, 0.8))),
        aabb(V3::new(0.6, 0.6, 14.9), V3::new(1.6, 2.2, 15.0), Material::emissive(V3::new(0.2, 0.4, 0.9), V3::new(0.8, 2.0, 6.0))),
        aabb(V3::new(-1.9, 0.0, 5.0), V3::new(-1.5, 3.0, 5.4), Material::diffuse(V3::new(0.85, 0.8, 0.6), 1.0)),
        aabb(V3::new(1.5, 0.0, 8.0), V3::new(1.9, 3.0, 8.4), Material::diffuse(V3::new(0.85, 0.8, 0.6), 1.0)),
        sphere(V3::new(0.4, 0.5, 6.5), 0.5, Material::diffuse(V3::new(0.8, 0.3, 0.2), 1.0)),
        aabb(V3::new(-0.9, 0.0, 10.0), V3::new(-0.1, 0.8, 10.8), Material::diffuse(V3::new(0.2, 0.7, 0.3), 1.0)),
    ];
    let mut s = base_scene("hallway", objects, V3::new(0.3, 1.6, 0.2), V3::new(-0.2, 1.1, 8.0));
    s.sun_dir = (V3::new(0.2, 1.0, 0.1)).normalize();
    s.sun_irradiance = V3::ZERO;
    s.ambient = V3::new(1.0, 1.0, 1.05);
    s
}

/// Thin objects on a mirror floor: plates 2 cm thick facing the camera and thin poles, in front of
/// a striped wall; HDRP's relative thickness (1% of depth = 3-6 cm here) treats the space behind
/// them as solid.
fn thin_scene() -> Scene {
    let mut objects = vec![aabb(V3::new(-4.0, -0.2, -2.0), V3::new(4.0, 0.0, 12.0), Material::diffuse(V3::new(0.5, 0.5, 0.5), 0.0))];
    for k in 0..8 {
        let x0 = -4.0 + k as f64;
        let c = if k % 2 == 0 { V3::new(0.8, 0.75, 0.6) } else { V3::new(0.25, 0.3, 0.45) };
        objects.push(aabb(V3::new(x0, 0.0, 9.0), V3::new(x0 + 1.0, 3.0, 9.3), Material::diffuse(c, 1.0)));
    }
    let plates = [(-1.8, 4.0, V3::new(0.9, 0.2, 0.2)), (0.2, 5.0, V3::new(0.2, 0.8, 0.3)), (1.8, 3.5, V3::new(0.9, 0.8, 0.2))];
    for (x, z, c) in plates {
        objects.push(aabb(V3::new(x - 0.5, 0.25, z), V3::new(x + 0.5, 1.4, z + 0.02), Material::diffuse(c, 1.0)));
    }
    for (x, z) in [(-0.8, 3.0), (1.0, 6.0), (-2.6, 6.5)] {
        objects.push(aabb(V3::new(x - 0.02, 0.0, z - 0.02), V3::new(x + 0.02, 2.0, z + 0.02), Material::diffuse(V3::new(0.9, 0.9, 0.9), 1.0)));
    }
    base_scene("thin", objects, V3::new(0.0, 1.3, -0.5), V3::new(0.0, 0.6, 5.0))
}

/// Look a built-in scene up by name.
pub fn scene(name: &str) -> Result<Scene> {
    Ok(match name {
        "floor" => floor_scene("floor"),
        "hallway" => hallway_scene(),
        "thin" => thin_scene(),
        "animated" => {
            let mut s = floor_scene("animated");
            s.eye_velocity = V3::new(0.01, 0.0, 0.04);
            s.sway = 0.25;
            s
        }
        _ => bail!("unknown scene {name:?} (built-in scenes: {})", SCENES.join(", ")),
    })
}

/// An orthonormal basis (t, b, n) around unit n (Duff et al. 2017).
pub fn basis(n: V3) -> (V3, V3) {
    let s = if n[2] >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n[2]);
    let b = n[0] * n[1] * a;
    let t = V3::new(1.0 + s * n[0] * n[0] * a, s * b, -s * n[0]);
    let bb = V3::new(b, s + n[1] * n[1] * a, -n[1]);
    (t, bb)
}
