//! Error metrics against the reference: composite, RMSE, relative RMSE, masks, tone mapping.

/// SSR output (premultiplied rgb, opacity; 4 per pixel) composited over the fallback `sky`:
/// rgb + (1 - opacity) * sky.
pub fn composite(reflection: &[f32], sky: [f32; 3]) -> Vec<f32> {
    reflection
        .chunks_exact(4)
        .flat_map(|c| {
            let k = 1.0 - c[3];
            [c[0] + k * sky[0], c[1] + k * sky[1], c[2] + k * sky[2]]
        })
        .collect()
}

/// Error of an RGB image against a reference over the pixels of a mask. An empty mask measures
/// nothing: `pixels` = 0 and `rmse` = `rel` = NaN, shown as "n/a" by [`figure`], never as 0.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct ErrorStats {
    pub pixels: usize,
    /// sqrt(mean over pixels and channels of (a - ref)^2); NaN when no pixel was measured.
    pub rmse: f64,
    /// RMSE / RMS(ref): the error relative to the reference's magnitude; NaN when no pixel was
    /// measured or the reference is black there.
    pub rel: f64,
}

impl ErrorStats {
    /// Nothing measured.
    pub const EMPTY: ErrorStats = ErrorStats { pixels: 0, rmse: f64::NAN, rel: f64::NAN };
}

/// A measured figure with `digits` decimals, or "n/a" where nothing was measured (NaN).
pub fn figure(v: f64, digits: usize) -> String {
    if v.is_finite() {
        format!("{v:.digits$}")
    } else {
        "n/a".into()
    }
}

/// RMSE and relative RMSE of `a` against `reference` (RGB interleaved) over pixels where `mask`;
/// [`ErrorStats::EMPTY`] for an empty mask.
pub fn error(a: &[f32], reference: &[f32], mask: &[bool]) -> ErrorStats {
    let mut se = 0.0f64;
    let mut sr = 0.0f64;
    let mut n = 0usize;
    for (i, &m) in mask.iter().enumerate() {
        if !m {
            continue;
        }
        n += 1;
        for k in 0..3 {
            let (x, r) = (f64::from(a[3 * i + k]), f64::from(reference[3 * i + k]));
            se += (x - r) * (x - r);
            sr += r * r;
        }
    }
    if n == 0 {
        return ErrorStats::EMPTY;
    }
    let rmse = (se / (3 * n) as f64).sqrt();
    let rms = (sr / (3 * n) as f64).sqrt();
    ErrorStats { pixels: n, rmse, rel: if rms > 0.0 { rmse / rms } else { f64::NAN } }
}

/// Reinhard + sRGB tone map of linear RGB to [0, 1] (the same curve as the PNG previews).
pub fn tonemap(rgb: &[f32]) -> Vec<f32> {
    rgb.iter()
        .map(|&v| {
            let v = if v.is_finite() { v.max(0.0) } else { 0.0 };
            let t = v / (1.0 + v);
            if t <= 0.003_130_8 {
                12.92 * t
            } else {
                1.055 * t.powf(1.0 / 2.4) - 0.055
            }
        })
        .collect()
}
