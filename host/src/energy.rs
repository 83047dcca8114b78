//! `host energy precompute | furnace`: the command line of the `energy` crate (tables, the white
//! furnace) with its EXR/PNG/CSV outputs; `host bench energy` is in energy_bench.rs.

pub use ::energy::*;

use crate::{Backend, DeviceChoice};
use anyhow::{bail, Result};
use shader_core::energy as core_energy;
use std::path::{Path, PathBuf};

/// A progress bar over a precompute's chunks, as [`precompute`]'s `progress` callback; the bar
/// clears itself when dropped.
pub struct ChunkBar(indicatif::ProgressBar);

impl ChunkBar {
    pub fn new() -> ChunkBar {
        let pb = indicatif::ProgressBar::new(0);
        pb.set_style(
            indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} chunks, {elapsed} (eta {eta})")
                .expect("progress template")
                .progress_chars("=> "),
        );
        ChunkBar(pb)
    }

    /// The callback `precompute` takes.
    pub fn report(&self, stage: &str, done: u64, total: u64) {
        self.0.set_length(total);
        self.0.set_position(done);
        self.0.set_message(stage.to_string());
    }
}

impl Default for ChunkBar {
    fn default() -> Self {
        ChunkBar::new()
    }
}

impl Drop for ChunkBar {
    fn drop(&mut self) {
        self.0.finish_and_clear();
    }
}

/// [`::energy::tables_cached`] with a progress bar while it precomputes.
pub fn tables_cached(backend: &Backend, lut: &Option<PathBuf>) -> Result<Tables> {
    let bar = ChunkBar::new();
    ::energy::tables_cached(backend, lut, Some(&|s: &str, d: u64, t: u64| bar.report(s, d, t)), &|m: &str| eprintln!("{m}"))
}

// ---------------------------------------------------------------------------------------------
// CLI
// ---------------------------------------------------------------------------------------------

/// `host energy ...`.
#[derive(clap::Args, Debug)]
pub struct EnergyCli {
    #[command(subcommand)]
    pub what: EnergyWhat,
}

/// The energy-compensation commands.
#[derive(clap::Subcommand, Debug)]
pub enum EnergyWhat {
    /// Precompute E(mu, roughness), E'(mu, roughness) (Schlick split) and E_avg(roughness) of GGX
    /// with F = 1 and write them as EXR (channels E, E_prime; E_avg in <stem>.e_avg.exr), the
    /// compact binary LUT the kernels read (<stem>.bin) and PNG previews.
    Precompute(PrecomputeArgs),
    /// White furnace: spheres (roughness 0..1 left to right) in a uniform white environment, one
    /// row per (metallic, compensation); writes EXR + PNG and the per-sphere albedo (CSV and markdown).
    Furnace(FurnaceArgs),
}

/// Options of `host energy precompute`.
#[derive(clap::Args, Debug, Clone)]
pub struct PrecomputeArgs {
    /// Cells per axis of the E / E' table and of E_avg.
    #[arg(long, default_value_t = 32)]
    pub resolution: u32,
    /// Samples per E / E' cell.
    #[arg(long, default_value_t = 4096)]
    pub samples: u32,
    /// Samples per E_avg cell (default: 4 x --samples).
    #[arg(long)]
    pub avg_samples: Option<u32>,
    /// Samples per dispatch (progress-bar step).
    #[arg(long, default_value_t = 1024)]
    pub chunk: u32,
    /// Sample sequence: sobol (scrambled per cell) or pcg (random).
    #[arg(long, value_parser = crate::cli_args::named(&Sequence::ALL, Sequence::label), default_value = "sobol")]
    pub sequence: Sequence,
    /// Seed of the sequence's scrambling / random numbers.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Backend: auto, cpu or gpu (see `host --help`).
    #[arg(long, value_enum, default_value = "auto")]
    pub device: DeviceChoice,
    /// Output EXR; the binary LUT, E_avg EXR and PNGs go beside it.
    #[arg(long, short, default_value = "out/energy/ggx_energy.exr")]
    pub output: PathBuf,
}

impl PrecomputeArgs {
    pub fn spec(&self) -> TableSpec {
        TableSpec {
            n_mu: self.resolution,
            n_r: self.resolution,
            n_avg: self.resolution,
            samples: self.samples,
            avg_samples: self.avg_samples.unwrap_or(self.samples.saturating_mul(4)),
            chunk: self.chunk,
            seq: self.sequence,
            seed: self.seed,
        }
    }
}

/// Options of `host energy furnace`.
#[derive(clap::Args, Debug, Clone)]
pub struct FurnaceArgs {
    /// LUT from `host energy precompute` (.bin); when omitted, the default tables, computed once
    /// and cached in the user cache directory (as `host render` and `host ssr` do).
    #[arg(long)]
    pub lut: Option<PathBuf>,
    /// Spheres per row (roughness k / (spheres - 1)).
    #[arg(long, default_value_t = 11)]
    pub spheres: u32,
    /// Pixels per sphere (square cell).
    #[arg(long, default_value_t = 64)]
    pub size: u32,
    /// Monte-Carlo samples per pixel.
    #[arg(long, default_value_t = 256)]
    pub samples: u32,
    /// Sample sequence: sobol (scrambled per cell) or pcg (random).
    #[arg(long, value_parser = crate::cli_args::named(&Sequence::ALL, Sequence::label), default_value = "sobol")]
    pub sequence: Sequence,
    /// Seed of the sequence's scrambling / random numbers.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// Roughness below which the specular compensation is skipped.
    #[arg(long, default_value_t = core_energy::COMPENSATION_MIN_ROUGHNESS)]
    pub min_roughness: f32,
    /// Backend: auto, cpu or gpu (see `host --help`).
    #[arg(long, value_enum, default_value = "auto")]
    pub device: DeviceChoice,
    /// Output EXR (channels albedo, mu); PNG, CSV and markdown beside it.
    #[arg(long, short, default_value = "out/energy/furnace.exr")]
    pub output: PathBuf,
}

impl EnergyCli {
    pub fn run(self) -> Result<()> {
        match self.what {
            EnergyWhat::Precompute(a) => run_precompute(&a),
            EnergyWhat::Furnace(a) => run_furnace(&a),
        }
    }
}

fn run_precompute(a: &PrecomputeArgs) -> Result<()> {
    let spec = a.spec();
    spec.validate()?;
    crate::io::prepare_output(&a.output)?;
    let backend = Backend::select(a.device)?;
    eprintln!("{}", backend.describe());
    let bar = ChunkBar::new();
    let (t, times) = precompute(&backend, &spec, Some(&|s: &str, d: u64, t: u64| bar.report(s, d, t)))?;
    drop(bar);
    eprintln!(
        "E, E' {}x{} x {} samples ({}, seed {}): {:.3} ms ({}); E_avg {} x {} samples: {:.3} ms ({}); total wall {:.3} ms",
        spec.n_mu,
        spec.n_r,
        spec.samples,
        spec.seq.label(),
        spec.seed,
        times.table.seconds * 1e3,
        times.table.source,
        spec.n_avg,
        spec.avg_samples,
        times.avg.seconds * 1e3,
        times.avg.source,
        times.wall * 1e3
    );
    if t.n_mu.min(t.n_r).min(t.n_avg) < MIN_LUT_CELLS || spec.samples.min(spec.avg_samples) < MIN_LUT_SAMPLES {
        eprintln!(
            "warning: tables under {MIN_LUT_CELLS} cells per axis or {MIN_LUT_SAMPLES} samples per cell: `--lut` will reject this .bin (fine for studying convergence)"
        );
    }
    let avg = t.write_exr(&a.output)?;
    let bin = a.output.with_extension("bin");
    t.write_bin(&bin)?;
    let (w, h) = (t.n_mu as usize, t.n_r as usize);
    let png_e = a.output.with_extension("E.png");
    let png_ep = a.output.with_extension("E_prime.png");
    // each table enlarged to the legend's width, with what it is, its axes and a colour bar
    for (png, v, what) in [(&png_e, &t.e, "E (directional albedo)"), (&png_ep, &t.e_prime, "E' (Schlick split)")] {
        use crate::ssr::legend;
        let l = legend::Legend {
            title: format!("{what}; x: mu (cell centres), y: roughness (cell centres)"),
            bar: Some((0.0, 1.0, legend::ticks(0.0, 1.0, 5))),
            swatches: vec![(legend::NON_FINITE, "not finite".to_string())],
            axes: Some(legend::Axes {
                x: legend::Axes::cells(w, 5, |i| f64::from(core_energy::table_mu(i as u32, t.n_mu))),
                y: legend::Axes::cells(h, 5, |j| f64::from(core_energy::cell_center(j as u32, t.n_r))),
            }),
        };
        let px: Vec<[u8; 3]> = v.iter().map(|&x| legend::ramp(x, 0.0, 1.0)).collect();
        legend::write_png(png, w, h, &px, &l)?;
    }
    for p in [&a.output, &avg, &bin, &png_e, &png_ep] {
        eprintln!("wrote {}", p.display());
    }
    let last = t.e_avg.len() - 1;
    eprintln!("E_avg at roughness {:.4}: {:.5} (loss {:.2} %)", core_energy::cell_center(last as u32, t.n_avg), t.e_avg[last], 100.0 * (1.0 - t.e_avg[last]));
    Ok(())
}

fn run_furnace(a: &FurnaceArgs) -> Result<()> {
    crate::io::prepare_output(&a.output)?;
    let backend = Backend::select(a.device)?;
    eprintln!("{}", backend.describe());
    let tables = tables_cached(&backend, &a.lut)?;
    let lut = tables.lut_buffer();
    let rows: Vec<(f32, Compensation)> = [1.0f32, 0.0].iter().flat_map(|&m| Compensation::ALL.map(|c| (m, c))).collect();
    let (w, h) = (a.spheres * a.size, a.size);
    let mut albedo = Vec::new();
    let mut mu = Vec::new();
    let mut csv = String::from("metallic,compensation,sphere,roughness,mean_albedo,min_albedo,max_albedo\n");
    let mut md = format!(
        "| metallic | compensation | {} |\n|---|---|{}\n",
        (0..a.spheres).map(|k| format!("r={:.2}", if a.spheres > 1 { k as f32 / (a.spheres - 1) as f32 } else { 0.0 })).collect::<Vec<_>>().join(" | "),
        "---|".repeat(a.spheres as usize)
    );
    for &(metallic, mode) in &rows {
        let cfg = FurnaceConfig { mode, metallic, base: 1.0, samples: a.samples, seq: a.sequence, seed: a.seed, min_roughness: a.min_roughness };
        let img = furnace_spheres(&backend, &lut, &cfg, a.spheres, a.size)?;
        eprintln!("metallic {metallic} {:<12} {}x{} x {} spp: {:.3} ms ({})", mode.label(), w, h, a.samples, img.time.seconds * 1e3, img.time.source);
        for i in 0..img.width * img.height {
            let s = img.sample(i);
            albedo.push(s.albedo);
            mu.push(s.mu);
        }
        let stats = sphere_stats(&img, a.spheres);
        let mut cells = Vec::new();
        for (k, (r, mean, lo, hi)) in stats.iter().enumerate() {
            csv += &format!("{metallic},{},{k},{r},{mean:.6},{lo:.6},{hi:.6}\n", mode.label());
            cells.push(format!("{mean:.4}"));
        }
        md += &format!("| {metallic} | {} | {} |\n", mode.label(), cells.join(" | "));
    }
    let height = h * rows.len() as u32;
    crate::io::write_exr(&a.output, w as usize, height as usize, &[("albedo", &albedo), ("mu", &mu)])?;
    let png = a.output.with_extension("png");
    let row_labels: Vec<String> = rows.iter().map(|(m, c)| format!("{} {}", if *m == 1.0 { "metal" } else { "dielectric" }, c.label())).collect();
    write_furnace_png(&png, w, height, &albedo, &mu, &row_labels, a.spheres)?;
    let csv_path = a.output.with_extension("csv");
    let md_path = a.output.with_extension("md");
    crate::io::write_file(&csv_path, &csv)?;
    let md = format!(
        "Mean directional albedo over each sphere's pixels (= 2 int albedo(mu) mu dmu), base colour 1, rows top to bottom:\n\n{md}"
    );
    crate::io::write_file(&md_path, &md)?;
    print!("{md}");
    for p in [&a.output, &png, &csv_path, &md_path] {
        eprintln!("wrote {}", p.display());
    }
    let bad = albedo.iter().filter(|v| !v.is_finite()).count();
    if bad > 0 {
        bail!("{bad} of {} furnace pixels are NaN or infinite (magenta in {}): the energy tables or options are unusable", albedo.len(), png.display());
    }
    Ok(())
}

/// Colour of the environment around the furnace spheres in the PNG (its albedo is 1, white, which
/// a white sphere would vanish against).
pub const FURNACE_BACKGROUND: [u8; 3] = [40, 60, 90];

/// Grey-scale PNG of furnace albedo (1 = white), values above 1 tinted red, non-finite magenta,
/// the environment (`mu` = 0) [`FURNACE_BACKGROUND`]; each row of spheres labelled on the left
/// (`row_labels`, top to bottom) and each column with its roughness on top.
pub fn write_furnace_png(path: &Path, w: u32, h: u32, albedo: &[f32], mu: &[f32], row_labels: &[String], spheres: u32) -> Result<()> {
    use plotters::prelude::*;
    use plotters::style::text_anchor::{HPos, Pos, VPos};
    anyhow::ensure!(albedo.len() == (w * h) as usize && mu.len() == albedo.len(), "furnace image: {} values for {w}x{h}", albedo.len());
    let fs = 13u32;
    let left = row_labels.iter().map(|l| l.chars().count() as u32).max().unwrap_or(0) * fs * 6 / 10 + 12;
    let top = 2 * fs;
    let (tw, th) = (left + w, top + h);
    let mut buf = vec![255u8; (tw * th * 3) as usize];
    let enc = |x: f32| {
        let x = x.clamp(0.0, 1.0);
        let s = if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 };
        (s * 255.0).round() as u8
    };
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let v = albedo[i];
            let c = if !v.is_finite() {
                [255, 0, 255]
            } else if mu[i] == 0.0 {
                FURNACE_BACKGROUND
            } else if v > 1.0 + 1e-3 {
                [255, enc(2.0 - v), enc(2.0 - v)]
            } else {
                let g = enc(v);
                [g, g, g]
            };
            let o = (((top + y) * tw + left + x) * 3) as usize;
            buf[o..o + 3].copy_from_slice(&c);
        }
    }
    crate::ssr::legend::register_font();
    {
        let root = BitMapBackend::with_buffer(&mut buf, (tw, th)).into_drawing_area();
        let text = |p: Pos| ("ssr-legend", fs).into_font().color(&BLACK).pos(p);
        let err = |e: DrawingAreaErrorKind<_>| anyhow::anyhow!("drawing the furnace labels: {e}");
        let rows = row_labels.len().max(1) as u32;
        let row_h = h / rows;
        for (k, l) in row_labels.iter().enumerate() {
            let y = (top + row_h * k as u32 + row_h / 2) as i32;
            root.draw(&Text::new(l.clone(), (4, y), text(Pos::new(HPos::Left, VPos::Center)))).map_err(err)?;
        }
        let cell = w / spheres.max(1);
        for k in 0..spheres {
            let r = if spheres > 1 { k as f32 / (spheres - 1) as f32 } else { 0.0 };
            let x = (left + cell * k + cell / 2) as i32;
            root.draw(&Text::new(format!("r={r:.2}"), (x, (fs / 2) as i32), text(Pos::new(HPos::Center, VPos::Top)))).map_err(err)?;
        }
        root.present().map_err(err)?;
    }
    let img = image::RgbImage::from_raw(tw, th, buf).ok_or_else(|| anyhow::anyhow!("furnace image buffer size"))?;
    crate::io::write_png(path, &img)
}

