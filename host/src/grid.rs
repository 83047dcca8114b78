//! `host grid`: the GGX D / Lambda / G1 maps over (angle, roughness), written as EXR + PNG.
//!
//! Columns are the polar angle theta in [0, 90) degrees (left to right) of `wm` (for D) or `w`
//! (for Lambda and G1), at azimuth 0; rows are alpha_x from `alpha_max` (top) down to
//! `alpha_min` (bottom), log-spaced, and alpha_y = alpha_x * aspect.

use crate::backend::Backend;
use crate::eval::find_function;
use anyhow::Result;
use std::path::{Path, PathBuf};

/// What to evaluate.
#[derive(Clone, Debug)]
pub struct GridSpec {
    pub width: usize,
    pub height: usize,
    pub alpha_min: f32,
    pub alpha_max: f32,
    pub aspect: f32,
}

impl GridSpec {
    /// Check the parameters; every error names the parameter.
    pub fn validate(&self) -> Result<()> {
        anyhow::ensure!(self.width >= 2 && self.height >= 2, "--width and --height must be at least 2");
        anyhow::ensure!(self.width * self.height <= 1 << 26, "--width x --height must be at most 2^26 pixels");
        anyhow::ensure!(
            self.alpha_min.is_finite() && self.alpha_min > 0.0,
            "--alpha-min must be a positive number (got {})",
            self.alpha_min
        );
        anyhow::ensure!(
            self.alpha_max.is_finite() && self.alpha_max > self.alpha_min,
            "--alpha-max must be finite and above --alpha-min (got {})",
            self.alpha_max
        );
        anyhow::ensure!(self.aspect.is_finite() && self.aspect > 0.0, "--aspect must be positive (got {})", self.aspect);
        Ok(())
    }

    /// The rows `[x, y, z, alpha_x, alpha_y]`, one per pixel, top row first.
    /// alpha_x of row `j` (`alpha_max` at the top row, `alpha_min` at the bottom one,
    /// log-spaced).
    pub fn alpha_at_row(&self, j: usize) -> f64 {
        let (l0, l1) = (f64::from(self.alpha_min).ln(), f64::from(self.alpha_max).ln());
        let t = 1.0 - j as f64 / (self.height - 1) as f64;
        (l0 + (l1 - l0) * t).exp()
    }

    pub fn rows(&self) -> Vec<f32> {
        let mut v = Vec::with_capacity(self.width * self.height * 5);
        for j in 0..self.height {
            let ax = self.alpha_at_row(j) as f32;
            for i in 0..self.width {
                let theta = (90.0 * i as f64 / self.width as f64).to_radians();
                v.extend_from_slice(&[theta.sin() as f32, 0.0, theta.cos() as f32, ax, ax * self.aspect]);
            }
        }
        v
    }
}

/// One evaluated map.
pub struct GridResult {
    pub name: &'static str,
    pub values: Vec<f32>,
    pub seconds: f64,
    pub timing_source: String,
}

/// Evaluate the three maps on `backend`.
pub fn evaluate(backend: &Backend, spec: &GridSpec) -> Result<Vec<GridResult>> {
    spec.validate()?;
    let rows = spec.rows();
    let n = spec.width * spec.height;
    let mut out = Vec::new();
    for name in ["ggx_d", "ggx_lambda", "ggx_g1"] {
        let f = find_function(name)?;
        let (values, t) = backend.eval_table(f, &rows, n)?;
        out.push(GridResult { name: f.name, values, seconds: t.seconds, timing_source: t.source.to_string() });
    }
    Ok(out)
}

/// Write `<out>` (EXR with one channel per map) and a PNG preview per map next to it; returns
/// the PNG paths.
pub fn write(out: &Path, spec: &GridSpec, results: &[GridResult]) -> Result<Vec<PathBuf>> {
    let channels: Vec<(&str, &[f32])> = results.iter().map(|r| (r.name, r.values.as_slice())).collect();
    crate::io::write_exr(out, spec.width, spec.height, &channels)?;
    let mut pngs = Vec::new();
    for r in results {
        // D spans many decades: show log10. Lambda is unbounded: show log10(1 + Lambda).
        let (data, lo, hi): (Vec<f32>, f32, f32) = match r.name {
            "ggx_d" => (r.values.iter().map(|v| v.max(1e-6).log10()).collect(), -6.0, 6.0),
            "ggx_lambda" => (r.values.iter().map(|v| v.ln_1p() / std::f32::consts::LN_10).collect(), 0.0, 3.0),
            _ => (r.values.clone(), 0.0, 1.0),
        };
        let png = out.with_file_name(format!(
            "{}.{}.png",
            out.file_stem().unwrap_or_default().to_string_lossy(),
            r.name
        ));
        // the legend: what is shown, the axes and their ranges, the colour bar with its values
        let what = match r.name {
            "ggx_d" => "log10 D",
            "ggx_lambda" => "log10(1 + Lambda)",
            _ => "G1",
        };
        let legend = crate::ssr::legend::Legend {
            title: format!("{what}; x: theta (deg), y: alpha_x (log scale)"),
            bar: Some((lo, hi, crate::ssr::legend::ticks(lo, hi, 6))),
            swatches: vec![([255, 0, 255], "not finite".to_string())],
            axes: Some(crate::ssr::legend::Axes {
                x: crate::ssr::legend::Axes::cells(spec.width, 7, |i| 90.0 * i as f64 / spec.width as f64),
                y: crate::ssr::legend::Axes::cells(spec.height, 5, |j| spec.alpha_at_row(j)),
            }),
        };
        let pixels: Vec<[u8; 3]> = data.iter().map(|&v| crate::ssr::legend::ramp(v, lo, hi)).collect();
        crate::ssr::legend::write_png(&png, spec.width, spec.height, &pixels, &legend)?;
        pngs.push(png);
    }
    Ok(pngs)
}
