//! The host's camera (glTF 2.0 section 3.10 "Cameras": a node's -Z looks, its +Y is up): what a
//! glTF file, the built-in scene or the command line describes, and its conversions to the path
//! tracer's kernel record (`shader_core::pt::camera::Camera`, [`Camera::kernel`]) and, through
//! that, to the SSR G-buffer's view camera (`ssr::camera::Camera::from_kernel`).
//!
//! ```
//! use scene::{Camera, Projection};
//! let c = Camera::look("eye", [0.0, 1.0, 3.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0], Projection::Perspective { yfov: 0.8, aspect: None });
//! let k = c.kernel(64, 32)?;
//! assert_eq!(k.scale_x, 2.0 * k.scale_y); // the image's aspect, the vertical field of view kept
//! assert!(c.orbited([0.0; 3], 90.0).position[0] > 2.9);
//! # Ok::<(), anyhow::Error>(())
//! ```

use crate::Aabb;
use anyhow::{bail, Result};
use shader_core::pt::camera::{Camera as KernelCamera, ORTHOGRAPHIC, PERSPECTIVE};
use shader_core::Vec3;

/// A camera's projection (glTF `camera.perspective` / `camera.orthographic`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Vertical field of view in radians, and the aspect ratio (width / height) if the file
    /// gives one.
    Perspective {
        /// Vertical field of view (radians).
        yfov: f32,
        /// Width / height, if given.
        aspect: Option<f32>,
    },
    /// Half extents of the view volume (glTF `xmag`, `ymag`).
    Orthographic {
        /// Half width.
        xmag: f32,
        /// Half height.
        ymag: f32,
    },
}

/// A camera in world space: it looks along `forward` with `up` upwards (glTF: its node's -Z and
/// +Y).
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Name (glTF camera or node name; "camera N" when it has none).
    pub name: String,
    /// World position.
    pub position: [f32; 3],
    /// View direction (unit from a glTF node; any length from the command line).
    pub forward: [f32; 3],
    /// Up direction (orthogonal to `forward` from a glTF node; from the command line, any
    /// direction not parallel to it).
    pub up: [f32; 3],
    /// Projection.
    pub projection: Projection,
}

impl Camera {
    /// A camera named `name` at `position` looking along `forward`.
    pub fn look(name: &str, position: [f32; 3], forward: [f32; 3], up: [f32; 3], projection: Projection) -> Camera {
        Camera { name: name.into(), position, forward, up, projection }
    }

    /// The kernel's camera for a `width x height` image (perspective: the image's aspect ratio
    /// with the vertical field of view kept; orthographic: `ymag` kept, `xmag` from the
    /// image's aspect). Errors name a zero or non-finite direction, an up along the view, a
    /// field of view outside (0, pi) and a non-positive orthographic extent.
    pub fn kernel(&self, width: u32, height: u32) -> Result<KernelCamera> {
        let v = |a: [f32; 3]| Vec3::new(a[0], a[1], a[2]);
        let f = v(self.forward);
        if !(f.length() > 0.0) || !f.is_finite() {
            bail!("camera forward direction {:?} is not a direction", self.forward);
        }
        let f = f.normalize();
        let right = f.cross(v(self.up));
        if !(right.length() > 1e-6) {
            bail!("camera up {:?} is parallel to its forward direction {:?}", self.up, self.forward);
        }
        let right = right.normalize();
        let up = right.cross(f);
        let aspect = width as f32 / height as f32;
        let (kind, sx, sy) = match self.projection {
            Projection::Perspective { yfov: y, .. } => {
                if !(y > 0.0 && y < std::f32::consts::PI) {
                    bail!("camera yfov {y} rad: must be in (0, pi)");
                }
                let t = (y as f64 * 0.5).tan() as f32;
                (PERSPECTIVE, t * aspect, t)
            }
            Projection::Orthographic { xmag, ymag } => {
                if !(xmag > 0.0 && ymag > 0.0) {
                    bail!("orthographic camera xmag/ymag {:?}: must be positive", [xmag, ymag]);
                }
                (ORTHOGRAPHIC, ymag * aspect, ymag)
            }
        };
        Ok(KernelCamera { kind, origin: v(self.position), right, up, forward: f, scale_x: sx, scale_y: sy })
    }

    /// A perspective camera framing `bounds` (its bounding sphere) from its +z side (yfov 40
    /// degrees), named "framing".
    pub fn framing(bounds: &Aabb) -> Camera {
        let (c, r) = bounds.bounding_sphere();
        let yfov = 40f32.to_radians();
        let d = r.max(1e-3) / (yfov * 0.5).sin();
        Camera::look("framing", [c[0], c[1], c[2] + d], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0], Projection::Perspective { yfov, aspect: None })
    }

    /// This camera turned by `degrees` about +y through `pivot` (a camera path).
    pub fn orbited(&self, pivot: [f32; 3], degrees: f64) -> Camera {
        let (s, c) = degrees.to_radians().sin_cos();
        let rot = |a: [f32; 3]| -> [f32; 3] {
            let (x, z) = (a[0] as f64, a[2] as f64);
            [(c * x + s * z) as f32, a[1], (-s * x + c * z) as f32]
        };
        let rel = [self.position[0] - pivot[0], self.position[1] - pivot[1], self.position[2] - pivot[2]];
        let r = rot(rel);
        Camera {
            position: [r[0] + pivot[0], r[1] + pivot[1], r[2] + pivot[2]],
            forward: rot(self.forward),
            up: rot(self.up),
            ..self.clone()
        }
    }

    /// Whether the projection is perspective.
    pub fn is_perspective(&self) -> bool {
        matches!(self.projection, Projection::Perspective { .. })
    }
}
