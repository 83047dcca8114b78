//! Cameras of the SSR inputs: a rigid world-to-view transform, a vertical field of view and a near
//! plane, from which the reverse-Z infinite projection of `shader_core::ssr::params` is built
//! (the G-buffer camera JSON's form). A scene's camera (`scene::Camera`) becomes one through the
//! kernel's record: `Camera::from_kernel(&scene_camera.kernel(w, h)?, near)`.

use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};
use shader_core::pt::camera::{Camera as KernelCamera, ORTHOGRAPHIC};
use shader_core::ssr::mat4::Mat4;

/// One frame's camera.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    /// World to view, row-major (view space: x right, y up, +z forward).
    pub world_to_view: [f32; 16],
    pub fov_y_degrees: f32,
    pub near: f32,
}

/// The f64 vector of the SSR scenes, cameras and reference (glam's, as everywhere on the host).
pub type V3 = glam::DVec3;

/// A glTF-world vector in the G-buffer's (x-mirrored) world: the path tracer's world is
/// right-handed (glTF), the SSR G-buffer's view space is left-handed (x right, y up, +z forward).
pub fn mirror(v: V3) -> V3 {
    V3::new(-v.x, v.y, v.z)
}

impl Camera {
    /// The SSR camera of a perspective kernel camera (`scene::Camera::kernel`), in the mirrored
    /// world ([`mirror`]), with near plane `near`; an orthographic camera is an error (the SSR
    /// pipelines project perspectively).
    pub fn from_kernel(c: &KernelCamera, near: f32) -> Result<Camera> {
        if c.kind == ORTHOGRAPHIC {
            bail!("--gbuffer needs a perspective camera (the SSR pipelines project perspectively); the chosen camera is orthographic");
        }
        let v = |a: shader_core::Vec3| mirror(V3::new(a.x as f64, a.y as f64, a.z as f64));
        let eye = v(c.origin);
        let rows = [v(c.right), v(c.up), v(c.forward)];
        let mut m = [0.0f32; 16];
        for (i, r) in rows.iter().enumerate() {
            for k in 0..3 {
                m[4 * i + k] = r[k] as f32;
            }
            m[4 * i + 3] = -(r[0] * eye[0] + r[1] * eye[1] + r[2] * eye[2]) as f32;
        }
        m[15] = 1.0;
        let cam = Camera { world_to_view: m, fov_y_degrees: (2.0 * (c.scale_y as f64).atan()).to_degrees() as f32, near };
        cam.validate("camera")?;
        Ok(cam)
    }

    /// A camera at `eye` looking at `target` with `up` roughly up.
    pub fn look_at(eye: V3, target: V3, up: V3, fov_y_degrees: f32, near: f32) -> Camera {
        let f = (target - eye).normalize();
        let r = up.cross(f).normalize();
        let u = f.cross(r);
        let row = |a: V3| [a[0] as f32, a[1] as f32, a[2] as f32, -a.dot(eye) as f32];
        let (r0, r1, r2) = (row(r), row(u), row(f));
        Camera {
            world_to_view: [
                r0[0], r0[1], r0[2], r0[3], r1[0], r1[1], r1[2], r1[3], r2[0], r2[1], r2[2], r2[3], 0.0, 0.0, 0.0, 1.0,
            ],
            fov_y_degrees,
            near,
        }
    }

    pub fn view(&self) -> Mat4 {
        Mat4::from_rows(self.world_to_view)
    }

    /// The reverse-Z infinite perspective for an image of `width` x `height`.
    pub fn proj(&self, width: usize, height: usize) -> Mat4 {
        let f = 1.0 / (f64::from(self.fov_y_degrees).to_radians() * 0.5).tan();
        let aspect = width as f64 / height as f64;
        Mat4::from_rows([
            (f / aspect) as f32, 0.0, 0.0, 0.0,
            0.0, f as f32, 0.0, 0.0,
            0.0, 0.0, 0.0, self.near,
            0.0, 0.0, 1.0, 0.0,
        ])
    }

    /// View to world (the inverse of a validated camera's transform).
    pub fn inv_view(&self) -> Result<Mat4> {
        self.view().try_inverse(1e-6).ok_or_else(|| anyhow::anyhow!("the camera's world_to_view matrix is not invertible"))
    }

    /// Check the camera: finite values, an invertible and rigid (orthonormal rotation +
    /// translation, last row 0 0 0 1) world-to-view transform, 0 < fov < 180, near > 0.
    pub fn validate(&self, what: &str) -> Result<()> {
        if self.world_to_view.iter().any(|v| !v.is_finite()) {
            bail!("{what}: world_to_view has a non-finite entry");
        }
        if !(self.fov_y_degrees > 0.0 && self.fov_y_degrees < 180.0) {
            bail!("{what}: fov_y_degrees must be in (0, 180), got {}", self.fov_y_degrees);
        }
        if !(self.near > 0.0 && self.near.is_finite()) {
            bail!("{what}: near must be positive and finite, got {}", self.near);
        }
        let m = self.world_to_view;
        let (_, det) = self.view().inverse_and_det();
        if !(det.abs() > 1e-6) || !det.is_finite() {
            bail!("{what}: world_to_view is not invertible (determinant {det:e})");
        }
        if m[12] != 0.0 || m[13] != 0.0 || m[14] != 0.0 || m[15] != 1.0 {
            bail!("{what}: world_to_view's last row must be 0 0 0 1 (got {:?})", &m[12..16]);
        }
        for i in 0..3 {
            for j in 0..3 {
                let d: f32 = (0..3).map(|k| m[4 * i + k] * m[4 * j + k]).sum();
                let want = if i == j { 1.0 } else { 0.0 };
                if (d - want).abs() > 1e-3 {
                    bail!("{what}: world_to_view is not rigid (rows {i} and {j} have dot {d}); SSR needs a rotation + translation");
                }
            }
        }
        if det < 0.0 {
            bail!("{what}: world_to_view is a reflection (determinant {det}); use a right-handed rotation");
        }
        Ok(())
    }

    /// World position of the eye.
    pub fn eye(&self) -> V3 {
        let m = self.world_to_view;
        // eye = -R^T t
        let t = [m[3] as f64, m[7] as f64, m[11] as f64];
        let mut e = [0.0; 3];
        for (k, ek) in e.iter_mut().enumerate() {
            *ek = -(m[k] as f64 * t[0] + m[4 + k] as f64 * t[1] + m[8 + k] as f64 * t[2]);
        }
        V3::from(e)
    }

    /// World-space direction (unit) of the primary ray through screen point (sx, sy).
    pub fn ray_dir(&self, width: usize, height: usize, sx: f64, sy: f64) -> V3 {
        let t = (f64::from(self.fov_y_degrees).to_radians() * 0.5).tan();
        let aspect = width as f64 / height as f64;
        let nx = sx / width as f64 * 2.0 - 1.0;
        let ny = 1.0 - sy / height as f64 * 2.0;
        let dv = [nx * t * aspect, ny * t, 1.0];
        let m = self.world_to_view;
        // world = R^T dv
        let mut w = [0.0; 3];
        for (k, wk) in w.iter_mut().enumerate() {
            *wk = m[k] as f64 * dv[0] + m[4 + k] as f64 * dv[1] + m[8 + k] as f64 * dv[2];
        }
        V3::from(w).normalize()
    }

    /// World point to view space.
    pub fn to_view(&self, p: V3) -> V3 {
        let m = self.world_to_view;
        let mut v = [0.0; 3];
        for (i, vi) in v.iter_mut().enumerate() {
            *vi = m[4 * i] as f64 * p[0] + m[4 * i + 1] as f64 * p[1] + m[4 * i + 2] as f64 * p[2] + m[4 * i + 3] as f64;
        }
        V3::from(v)
    }

    /// Screen position (pixels) of a view-space point with z > 0.
    pub fn view_to_screen(&self, width: usize, height: usize, v: V3) -> (f64, f64) {
        let t = (f64::from(self.fov_y_degrees).to_radians() * 0.5).tan();
        let aspect = width as f64 / height as f64;
        let nx = v[0] / v[2] / (t * aspect);
        let ny = v[1] / v[2] / t;
        ((nx * 0.5 + 0.5) * width as f64, (0.5 - ny * 0.5) * height as f64)
    }

    /// World point at linear view depth `depth` through screen point (sx, sy) (pixels): the
    /// inverse of [`Camera::view_to_screen`] with [`Camera::to_view`].
    pub fn unproject(&self, width: usize, height: usize, sx: f64, sy: f64, depth: f64) -> V3 {
        let t = (f64::from(self.fov_y_degrees).to_radians() * 0.5).tan();
        let aspect = width as f64 / height as f64;
        let nx = sx / width as f64 * 2.0 - 1.0;
        let ny = 1.0 - sy / height as f64 * 2.0;
        let v = [nx * t * aspect * depth, ny * t * depth, depth];
        let m = self.world_to_view;
        let d = [v[0] - m[3] as f64, v[1] - m[7] as f64, v[2] - m[11] as f64];
        // world = R^T (v - t)
        V3::from(std::array::from_fn::<f64, 3, _>(|k| m[k] as f64 * d[0] + m[4 + k] as f64 * d[1] + m[8 + k] as f64 * d[2]))
    }

    /// [`Camera::motion`] of the point a G-buffer stores at screen point (sx, sy): at linear
    /// view depth `depth`, or the sky's direction where `depth` is not finite.
    pub fn motion_at_depth(&self, previous: &Camera, width: usize, height: usize, sx: f64, sy: f64, depth: f32) -> [f32; 2] {
        let point = depth.is_finite().then(|| self.unproject(width, height, sx, sy, depth as f64));
        self.motion(previous, width, height, sx, sy, point)
    }

    /// The motion vector UV(this camera) - UV(`previous`) of screen point (sx, sy) (pixels):
    /// of world point `point`, or for the sky (`None`) of the direction through (sx, sy)
    /// (a point at infinity, which only the rotation moves); 0 where the previous camera does
    /// not see it in front, and exactly 0 when the two cameras are equal.
    pub fn motion(&self, previous: &Camera, width: usize, height: usize, sx: f64, sy: f64, point: Option<V3>) -> [f32; 2] {
        // An unmoved camera moves nothing (exactly: no unproject/reproject round-off).
        if previous == self {
            return [0.0, 0.0];
        }
        let v = match point {
            Some(p) => previous.to_view(p),
            None => {
                let d = self.ray_dir(width, height, sx, sy);
                previous.to_view(previous.eye() + d) - previous.to_view(previous.eye())
            }
        };
        if !(v[2] > 1e-9) {
            return [0.0, 0.0];
        }
        let (px, py) = previous.view_to_screen(width, height, v);
        [((sx - px) / width as f64) as f32, ((sy - py) / height as f64) as f32]
    }
}
