//! Energy compensation on the host (docs/energy.md): precomputing the E / E' / E_avg tables on
//! either backend (`host energy precompute`), the white-furnace renderer (`host energy furnace`)
//! and the accuracy/time benchmark (`host energy bench`).
//!
//! Both backends run the same per-invocation functions of `shader_kernels::energy` over the same
//! sample chunks; the f32 partial sums of each chunk are added in f64 on the host in chunk order,
//! so the tables are bit-identical across backends for the same (resolution, samples, chunk,
//! sequence, seed).

use crate::timing::Timing;
use crate::{Backend, DeviceChoice};
use anyhow::{bail, Context, Result};
use shader_core::energy as core_energy;
use shader_kernels::energy as kern;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The sample sequence of the precompute and furnace kernels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Sequence {
    /// PCG32 random numbers, one generator per (cell, sample index).
    Pcg,
    /// Sobol (0,2)-sequence points, XOR-scrambled per cell.
    Sobol,
}

impl Sequence {
    pub fn id(self) -> u32 {
        match self {
            Sequence::Pcg => core_energy::SEQ_PCG,
            Sequence::Sobol => core_energy::SEQ_SOBOL,
        }
    }
    pub fn label(self) -> &'static str {
        match self {
            Sequence::Pcg => "pcg",
            Sequence::Sobol => "sobol",
        }
    }
}

/// What to precompute.
#[derive(Clone, Copy, Debug)]
pub struct TableSpec {
    /// Columns (mu) and rows (roughness) of the E / E' table.
    pub n_mu: u32,
    pub n_r: u32,
    /// Roughness cells of E_avg.
    pub n_avg: u32,
    /// Samples per E / E' cell and per E_avg cell.
    pub samples: u32,
    pub avg_samples: u32,
    /// Samples per kernel dispatch (the unit of the progress bar and of the f32 partial sums).
    pub chunk: u32,
    pub seq: Sequence,
    pub seed: u32,
}

impl Default for TableSpec {
    fn default() -> Self {
        TableSpec { n_mu: 32, n_r: 32, n_avg: 32, samples: 4096, avg_samples: 16384, chunk: 1024, seq: Sequence::Sobol, seed: 0 }
    }
}

impl TableSpec {
    /// Reject sizes the kernels cannot take.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("resolution (mu)", self.n_mu), ("resolution (roughness)", self.n_r), ("E_avg resolution", self.n_avg)] {
            if v == 0 || v > 4096 {
                bail!("{name} must be in 1..=4096, got {v}");
            }
        }
        for (name, v) in [("samples", self.samples), ("E_avg samples", self.avg_samples), ("chunk", self.chunk)] {
            if v == 0 {
                bail!("{name} must be at least 1");
            }
        }
        if u64::from(self.samples).max(u64::from(self.avg_samples)) > 1 << 31 {
            bail!("at most 2^31 samples per cell");
        }
        Ok(())
    }
}

/// The precomputed tables: E and E' roughness-major (`j * n_mu + i`), E_avg per roughness cell.
#[derive(Clone, Debug, PartialEq)]
pub struct Tables {
    pub n_mu: u32,
    pub n_r: u32,
    pub n_avg: u32,
    pub e: Vec<f32>,
    pub e_prime: Vec<f32>,
    pub e_avg: Vec<f32>,
    /// Samples per E / E' cell and per E_avg cell they were computed with; 0 = not recorded (a
    /// buffer read by [`Tables::from_words`], or a file written before the count was stored).
    pub samples: u32,
    pub avg_samples: u32,
}

/// Magic of the compact binary form before the sample counts were stored (still read).
const BIN_MAGIC_V1: &[u8; 8] = b"GGXELUT1";
/// Magic of the compact binary form: then the two sample counts (u32), then the words.
const BIN_MAGIC: &[u8; 8] = b"GGXELUT2";

/// The coarsest table a LUT file may hold, per axis (E / E' mu and roughness, E_avg): the
/// bilinear lookup of a coarser one cannot follow E's fall-off at grazing angles.
pub const MIN_LUT_CELLS: u32 = 8;
/// The fewest samples per cell a LUT file may have been computed with (when recorded).
pub const MIN_LUT_SAMPLES: u32 = 64;

impl Tables {
    /// E_avg(r) = 2 int E_lut(mu, r) mu dmu of the LUT's own E (the shader's lookup,
    /// `shader_core::energy::cell_taps`: linear in mu between cell centers, the edge value
    /// below the first, the extrapolated quadratic above the last), integrated exactly in f64
    /// at the centers of the E_avg grid.
    ///
    /// This, not the Monte-Carlo E_avg of the kernel, is what the LUT buffer carries: Kulla-Conty
    /// conserves energy only if E_avg is the integral of the E the shader reads. At low roughness
    /// the loss 1 - E peaks at grazing mu below the first cell center and linear interpolation
    /// overestimates it, so with the true E_avg the compensated albedo overshoots by up to 1.5 %
    /// at mu = 1/64, r = 0.11 (measured, docs/energy.md).
    pub fn lut_consistent_e_avg(&self) -> Vec<f32> {
        let (n, nr) = (self.n_mu as usize, self.n_r as usize);
        (0..self.n_avg)
            .map(|k| {
                let r = f64::from(core_energy::cell_center(k, self.n_avg));
                // Row weights as the shader's lookup (shader_core::energy's roughness taps):
                // linear between the row centres, the quadratic through the outer three rows
                // in the outer half cells.
                let t = r * nr as f64 - 0.5;
                let (rows, w): ([usize; 3], [f64; 3]) = if nr >= 3 && (t < 0.0 || t > (nr - 1) as f64) {
                    let (j, s) = if t < 0.0 { (0, t.max(-0.5)) } else { (nr - 3, t.min(nr as f64 - 0.5) - (nr - 3) as f64) };
                    ([j, j + 1, j + 2], [(s - 1.0) * (s - 2.0) * 0.5, s * (2.0 - s), s * (s - 1.0) * 0.5])
                } else {
                    let t = t.clamp(0.0, (nr - 1) as f64);
                    let j0 = t.floor() as usize;
                    let j1 = (j0 + 1).min(nr - 1);
                    ([j0, j1, j1], [1.0 - (t - j0 as f64), t - j0 as f64, 0.0])
                };
                let e = |i: usize| (0..3).map(|k| f64::from(self.e[rows[k] * n + i]) * w[k]).sum::<f64>();
                let c = |i: usize| (i as f64 + 0.5) / n as f64;
                // Constant below the first center: 2 int e mu dmu = e (b^2 - a^2).
                let mut sum = e(0) * c(0) * c(0);
                // Above the last center, the shader extrapolates the quadratic through the last
                // three centers: 2 int q(mu) mu dmu over [c(n-1), 1] by Simpson's rule (exact for
                // the cubic integrand); constant when the table has fewer than 3 columns.
                if n >= 3 {
                    let q = |mu: f64| {
                        let s = mu * n as f64 - 0.5 - (n - 3) as f64;
                        e(n - 3) * (s - 1.0) * (s - 2.0) * 0.5 + e(n - 2) * s * (2.0 - s) + e(n - 1) * s * (s - 1.0) * 0.5
                    };
                    let (a, b) = (c(n - 1), 1.0);
                    let m = 0.5 * (a + b);
                    sum += 2.0 * (b - a) / 6.0 * (q(a) * a + 4.0 * q(m) * m + q(b) * b);
                } else {
                    sum += e(n - 1) * (1.0 - c(n - 1) * c(n - 1));
                }
                for i in 0..n - 1 {
                    // Linear from (a, ea) to (b, eb): 2 int (ea + s (mu - a)) mu dmu.
                    let (a, b, ea, eb) = (c(i), c(i + 1), e(i), e(i + 1));
                    let s = (eb - ea) / (b - a);
                    sum += (ea - s * a) * (b * b - a * a) + s * 2.0 / 3.0 * (b * b * b - a * a * a);
                }
                sum as f32
            })
            .collect()
    }

    /// The storage-buffer form the kernels read: [n_mu, n_r, n_avg, 0] as u32 bits, E, E', and
    /// the LUT-consistent E_avg ([`Tables::lut_consistent_e_avg`]).
    pub fn lut_buffer(&self) -> Vec<f32> {
        let mut v = Vec::with_capacity(core_energy::LUT_HEADER + self.e.len() * 2 + self.e_avg.len());
        v.extend([f32::from_bits(self.n_mu), f32::from_bits(self.n_r), f32::from_bits(self.n_avg), 0.0]);
        v.extend_from_slice(&self.e);
        v.extend_from_slice(&self.e_prime);
        v.extend(self.lut_consistent_e_avg());
        v
    }

    /// Parse a LUT buffer followed by the kernel's E_avg (`n_avg` more words), as [`Tables::write_bin`] writes.
    pub fn from_words(v: &[f32]) -> Result<Tables> {
        if v.len() < core_energy::LUT_HEADER {
            bail!("LUT buffer too short");
        }
        let (n_mu, n_r, n_avg) = (v[0].to_bits(), v[1].to_bits(), v[2].to_bits());
        if n_mu == 0 || n_r == 0 || n_avg == 0 || n_mu > 4096 || n_r > 4096 || n_avg > 4096 {
            bail!("bad LUT dims {n_mu} x {n_r}, {n_avg}");
        }
        let cells = n_mu as usize * n_r as usize;
        let h = core_energy::LUT_HEADER;
        let want = h + 2 * cells + 2 * n_avg as usize;
        if v.len() != want {
            bail!("bad LUT: {} words, expected {want} for {n_mu} x {n_r}, {n_avg}", v.len());
        }
        Ok(Tables {
            n_mu,
            n_r,
            n_avg,
            e: v[h..h + cells].to_vec(),
            e_prime: v[h + cells..h + 2 * cells].to_vec(),
            e_avg: v[h + 2 * cells + n_avg as usize..].to_vec(),
            samples: 0,
            avg_samples: 0,
        })
    }

    /// Check tables read from a file before a kernel uses them: at least [`MIN_LUT_CELLS`] cells
    /// per axis, at least [`MIN_LUT_SAMPLES`] samples per cell (when recorded), and values the
    /// compensation formulas can use: 0 < E' <= E <= 1 (within 1e-6; Turquin divides by E) and
    /// 0 < E_avg <= 1. The error names the first offending value.
    pub fn validate(&self) -> Result<()> {
        let (n_mu, n_r, n_avg) = (self.n_mu, self.n_r, self.n_avg);
        if n_mu.min(n_r).min(n_avg) < MIN_LUT_CELLS {
            bail!(
                "the table is {n_mu} x {n_r} (E_avg {n_avg}): too coarse, at least {MIN_LUT_CELLS} cells per axis are needed \
                 (`host energy precompute --resolution`)"
            );
        }
        for (name, v) in [("E / E'", self.samples), ("E_avg", self.avg_samples)] {
            if v != 0 && v < MIN_LUT_SAMPLES {
                bail!("the {name} cells were computed with {v} samples: too few, at least {MIN_LUT_SAMPLES} are needed (`host energy precompute --samples`)");
            }
        }
        const EPS: f32 = 1e-6;
        let cell = |i: usize| format!("mu cell {}, roughness cell {}", i % n_mu as usize, i / n_mu as usize);
        for (i, (&e, &ep)) in self.e.iter().zip(&self.e_prime).enumerate() {
            if !(e > 0.0 && e <= 1.0 + EPS) {
                bail!("E at {} is {e}: must be in (0, 1]", cell(i));
            }
            if !(ep > 0.0 && ep <= e + EPS) {
                bail!("E' at {} is {ep}: must be in (0, E = {e}]", cell(i));
            }
        }
        for (k, &a) in self.e_avg.iter().enumerate() {
            if !(a > 0.0 && a <= 1.0 + EPS) {
                bail!("E_avg at roughness cell {k} is {a}: must be in (0, 1]");
            }
        }
        Ok(())
    }

    /// Write the compact binary form: "GGXELUT2", the sample counts per E / E' cell and per
    /// E_avg cell (u32), the LUT buffer ([`Tables::lut_buffer`]) and the kernel's Monte-Carlo
    /// E_avg as f32 words, all little-endian.
    pub fn write_bin(&self, path: &Path) -> Result<()> {
        let mut bytes = BIN_MAGIC.to_vec();
        bytes.extend_from_slice(&self.samples.to_le_bytes());
        bytes.extend_from_slice(&self.avg_samples.to_le_bytes());
        for w in self.lut_buffer().into_iter().chain(self.e_avg.iter().copied()) {
            bytes.extend_from_slice(&w.to_bits().to_le_bytes());
        }
        crate::io::write_file(path, bytes)
    }

    /// Read [`Tables::write_bin`]'s file (or the older GGXELUT1 form, without sample counts)
    /// and [`Tables::validate`] it; errors name the file.
    pub fn read_bin(path: &Path) -> Result<Tables> {
        let bytes = std::fs::read(path).with_context(|| format!("reading energy LUT {}", path.display()))?;
        let word = |c: &[u8]| u32::from_le_bytes([c[0], c[1], c[2], c[3]]);
        let (counts, body) = match bytes.get(..8) {
            Some(m) if m == BIN_MAGIC && bytes.len() >= 16 => (Some((word(&bytes[8..12]), word(&bytes[12..16]))), &bytes[16..]),
            Some(m) if m == BIN_MAGIC_V1 => (None, &bytes[8..]),
            _ => bail!("{} is not an energy LUT (expected the GGXELUT2 or GGXELUT1 header of `host energy precompute`)", path.display()),
        };
        if body.len() % 4 != 0 {
            bail!("energy LUT {}: {} bytes after the header, not whole 4-byte words (truncated?)", path.display(), body.len());
        }
        let words: Vec<f32> = body.chunks_exact(4).map(|c| f32::from_bits(word(c))).collect();
        let mut t = Tables::from_words(&words).with_context(|| format!("energy LUT {}", path.display()))?;
        match counts {
            Some((s, a)) => (t.samples, t.avg_samples) = (s, a),
            None => eprintln!("warning: energy LUT {} does not record its sample count (GGXELUT1); not checked", path.display()),
        }
        t.validate().with_context(|| format!("energy LUT {} is unusable", path.display()))?;
        Ok(t)
    }

    /// EXR with channels E and E_prime (n_mu wide, n_r high, top row = roughness cell 0) and
    /// `<stem>.e_avg.exr` (n_avg x 1, channels E_avg = the kernel's Monte-Carlo E_avg and
    /// E_avg_lut = [`Tables::lut_consistent_e_avg`]). Returns the second path.
    pub fn write_exr(&self, path: &Path) -> Result<PathBuf> {
        crate::io::write_exr(path, self.n_mu as usize, self.n_r as usize, &[("E", &self.e), ("E_prime", &self.e_prime)])?;
        let avg = path.with_extension("e_avg.exr");
        let lut_avg = self.lut_consistent_e_avg();
        crate::io::write_exr(&avg, self.n_avg as usize, 1, &[("E_avg", &self.e_avg), ("E_avg_lut", &lut_avg)])?;
        Ok(avg)
    }
}

/// Precompute timings: the E / E' table and E_avg, each summed over its dispatches.
#[derive(Clone, Copy, Debug)]
pub struct PrecomputeTimes {
    pub table: Timing,
    pub avg: Timing,
    /// Host wall clock of the whole precompute (uploads, readbacks and host sums included).
    pub wall: f64,
}

/// Precompute the tables on `backend`, `progress` showing a bar over the chunks.
pub fn precompute(backend: &Backend, spec: &TableSpec, progress: bool) -> Result<(Tables, PrecomputeTimes)> {
    precompute_in_launches_of(backend, spec, progress, TABLE_INVOCATIONS_PER_LAUNCH)
}

/// [`precompute`] with launches of whole chunks of about `invocations` invocations (at least one
/// chunk each).
fn precompute_in_launches_of(backend: &Backend, spec: &TableSpec, progress: bool, invocations: usize) -> Result<(Tables, PrecomputeTimes)> {
    spec.validate()?;
    let t0 = Instant::now();
    let chunks = |s: u32| s.div_ceil(spec.chunk) as u64;
    let pb = if progress {
        let pb = indicatif::ProgressBar::new(chunks(spec.samples) + chunks(spec.avg_samples));
        pb.set_style(
            indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} chunks, {elapsed} (eta {eta})")
                .expect("progress template")
                .progress_chars("=> "),
        );
        pb
    } else {
        indicatif::ProgressBar::hidden()
    };
    pb.set_message("E, E'");
    let cells = spec.n_mu as usize * spec.n_r as usize;
    let (mut sum_e, mut sum_ep) = (vec![0.0f64; cells], vec![0.0f64; cells]);
    let table = |s: kern::SampleChunks| kern::AlbedoTableArgs { n_mu: spec.n_mu, n_r: spec.n_r, s, seq: spec.seq.id(), seed: spec.seed, ..Default::default() };
    let t_table = chunked_sums(backend, table, cells, spec.samples, spec.chunk, invocations, &pb, |out, c| {
        sum_e[c] += f64::from(out[kern::TABLE_STRIDE * c]);
        sum_ep[c] += f64::from(out[kern::TABLE_STRIDE * c + 1]);
    })
    .context("E table")?;
    pb.set_message("E_avg");
    let n_avg = spec.n_avg as usize;
    let mut sum_avg = vec![0.0f64; n_avg];
    let avg = |s: kern::SampleChunks| kern::AlbedoAvgArgs { n_avg: spec.n_avg, s, seq: spec.seq.id(), seed: spec.seed, ..Default::default() };
    let t_avg = chunked_sums(backend, avg, n_avg, spec.avg_samples, spec.chunk, invocations, &pb, |out, c| sum_avg[c] += f64::from(out[c]))
        .context("E_avg")?;
    pb.finish_and_clear();
    let ns = f64::from(spec.samples);
    let na = f64::from(spec.avg_samples);
    let tables = Tables {
        n_mu: spec.n_mu,
        n_r: spec.n_r,
        n_avg: spec.n_avg,
        e: sum_e.iter().map(|s| (s / ns) as f32).collect(),
        e_prime: sum_ep.iter().map(|s| (s / ns) as f32).collect(),
        e_avg: sum_avg.iter().map(|s| (s / na) as f32).collect(),
        samples: spec.samples,
        avg_samples: spec.avg_samples,
    };
    let times = PrecomputeTimes { table: t_table, avg: t_avg, wall: t0.elapsed().as_secs_f64() };
    Ok((tables, times))
}

/// Invocations one table launch aims at: whole chunks of every cell, at least one chunk. A
/// launch of every (cell, chunk) pair at once fills a GPU that one chunk's cells (16-1024
/// invocations) leaves idle; several launches keep the progress bar moving on long precomputes.
const TABLE_INVOCATIONS_PER_LAUNCH: usize = 1 << 16;

/// A table kernel's launch record: its entry point, outputs per item, and the CPU launcher's call
/// of its per-invocation function for one item.
trait TableKernel: runner::LaunchArgs {
    const ENTRY: &'static str;
    const STRIDE: usize;
    /// Item `first + i` into `out` (its `STRIDE` values).
    fn cpu_item(&self, i: u32, out: &mut [f32]);
}

impl TableKernel for kern::AlbedoTableArgs {
    const ENTRY: &'static str = "energy::energy_albedo_table";
    const STRIDE: usize = kern::TABLE_STRIDE;
    fn cpu_item(&self, i: u32, out: &mut [f32]) {
        kern::albedo_table_cell(0, &kern::AlbedoTableArgs { first: self.first + i, ..*self }, out)
    }
}

impl TableKernel for kern::AlbedoAvgArgs {
    const ENTRY: &'static str = "energy::energy_albedo_avg";
    const STRIDE: usize = 1;
    fn cpu_item(&self, i: u32, out: &mut [f32]) {
        kern::albedo_avg_cell(0, &kern::AlbedoAvgArgs { first: self.first + i, ..*self }, out)
    }
}

/// Run a table kernel over `samples` samples of `cells` cells in chunks of `chunk` samples, as
/// few launches of whole chunks as `invocations` per launch allows, and call
/// `add(chunk_output, cell)` for every chunk in sample order and every cell (the output of one
/// chunk: the kernel's `out` for that chunk's items). Returns the summed launch time.
fn chunked_sums<A: TableKernel>(
    backend: &Backend,
    args: impl Fn(kern::SampleChunks) -> A,
    cells: usize,
    samples: u32,
    chunk: u32,
    invocations: usize,
    pb: &indicatif::ProgressBar,
    mut add: impl FnMut(&[f32], usize),
) -> Result<Timing> {
    let chunks = samples.div_ceil(chunk);
    let per_launch = (invocations / cells).max(1).min(chunks as usize) as u32;
    let stride = A::STRIDE;
    let mut total: Option<Timing> = None;
    let mut k = 0;
    while k < chunks {
        let n = per_launch.min(chunks - k);
        let s = kern::SampleChunks { start: k * chunk, chunk, end: samples };
        let a = args(s);
        let (out, t) = backend
            .launch(A::ENTRY, a, &[], cells * n as usize, stride, |a, i, out| a.cpu_item(i, out))
            .with_context(|| format!("samples {}..{}", s.start, (u64::from(s.start) + u64::from(n) * u64::from(chunk)).min(u64::from(samples))))?;
        for per_chunk in out.chunks_exact(cells * stride) {
            for c in 0..cells {
                add(per_chunk, c);
            }
        }
        total = Some(match total { Some(x) => x + t, None => t });
        k += n;
        pb.inc(u64::from(n));
    }
    Ok(total.expect("at least one chunk"))
}

/// Compensation modes of the furnace.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Compensation {
    None,
    KullaConty,
    Turquin,
}

impl Compensation {
    pub const ALL: [Compensation; 3] = [Compensation::None, Compensation::KullaConty, Compensation::Turquin];
    pub fn id(self) -> u32 {
        match self {
            Compensation::None => core_energy::COMP_NONE,
            Compensation::KullaConty => core_energy::COMP_KULLA_CONTY,
            Compensation::Turquin => core_energy::COMP_TURQUIN,
        }
    }
    pub fn label(self) -> &'static str {
        match self {
            Compensation::None => "none",
            Compensation::KullaConty => "kulla-conty",
            Compensation::Turquin => "turquin",
        }
    }
}

/// One furnace configuration.
#[derive(Clone, Copy, Debug)]
pub struct FurnaceConfig {
    pub mode: Compensation,
    pub metallic: f32,
    pub base: f32,
    pub samples: u32,
    pub seq: Sequence,
    pub seed: u32,
    /// Roughness below which the specular multiple-scattering term is skipped.
    pub min_roughness: f32,
}

impl FurnaceConfig {
    fn validate(&self) -> Result<()> {
        if self.samples == 0 {
            bail!("furnace samples must be at least 1");
        }
        for (name, v) in [("metallic", self.metallic), ("base", self.base), ("min roughness", self.min_roughness)] {
            if !v.is_finite() || !(0.0..=1.0).contains(&v) {
                bail!("{name} must be in [0, 1], got {v}");
            }
        }
        Ok(())
    }

    /// Run the furnace kernel over `width` x `height` pixels (`rows`: spheres or table rows).
    fn run(&self, backend: &Backend, lut: &[f32], layout: u32, width: u32, height: u32, rows: u32) -> Result<(Vec<f32>, Timing)> {
        let args = kern::FurnaceArgs {
            layout,
            width,
            height,
            rows,
            samples: self.samples,
            seq: self.seq.id(),
            seed: self.seed,
            mode: self.mode.id(),
            metallic: self.metallic,
            base: self.base,
            min_roughness: self.min_roughness,
            ..Default::default()
        };
        let n = (width * height) as usize;
        backend.launch("energy::energy_furnace", args, &[bytemuck::cast_slice(lut)], n, kern::FURNACE_STRIDE, |a, i, out| {
            kern::furnace_pixel(0, &kern::FurnaceArgs { first: a.first + i, ..*a }, lut, out)
        })
    }
}

/// Furnace output: per pixel (albedo, mu, roughness), mu = 0 outside the spheres.
pub struct FurnaceImage {
    pub width: u32,
    pub height: u32,
    pub data: Vec<f32>,
    pub time: Timing,
}

/// Render `spheres` spheres of `cell` x `cell` pixels, roughness 0..1 left to right.
pub fn furnace_spheres(backend: &Backend, lut: &[f32], cfg: &FurnaceConfig, spheres: u32, cell: u32) -> Result<FurnaceImage> {
    cfg.validate()?;
    if spheres == 0 || cell == 0 || u64::from(spheres) * u64::from(cell) * u64::from(cell) > 1 << 24 {
        bail!("need 1 or more spheres of 1 or more pixels (at most 2^24 pixels), got {spheres} x {cell}");
    }
    let (w, h) = (spheres * cell, cell);
    let (data, time) = cfg.run(backend, lut, kern::LAYOUT_SPHERES, w, h, spheres)?;
    Ok(FurnaceImage { width: w, height: h, data, time })
}

/// The furnace albedo at every (mu_i, r_j) cell center of an n_mu x n_r grid (roughness-major).
pub fn furnace_grid(backend: &Backend, lut: &[f32], cfg: &FurnaceConfig, n_mu: u32, n_r: u32) -> Result<Vec<f32>> {
    cfg.validate()?;
    if n_mu == 0 || n_r == 0 || n_mu > 4096 || n_r > 4096 {
        bail!("grid must be 1..=4096 per side, got {n_mu} x {n_r}");
    }
    let (data, _) = cfg.run(backend, lut, kern::LAYOUT_GRID, n_mu, n_r, n_r)?;
    Ok(data.chunks_exact(kern::FURNACE_STRIDE).map(|c| c[0]).collect())
}

/// Per-sphere statistics of a furnace image: roughness, mean albedo over the sphere's pixels
/// (the projected-area mean, i.e. 2 int albedo(mu) mu dmu), min and max.
pub fn sphere_stats(img: &FurnaceImage, spheres: u32) -> Vec<(f32, f64, f32, f32)> {
    let cell = img.width / spheres;
    (0..spheres)
        .map(|k| {
            let (mut sum, mut n, mut lo, mut hi, mut r) = (0.0f64, 0usize, f32::INFINITY, f32::NEG_INFINITY, 0.0);
            for y in 0..img.height {
                for x in k * cell..(k + 1) * cell {
                    let p = &img.data[((y * img.width + x) as usize) * kern::FURNACE_STRIDE..][..3];
                    r = p[2];
                    if p[1] > 0.0 {
                        sum += f64::from(p[0]);
                        n += 1;
                        lo = lo.min(p[0]);
                        hi = hi.max(p[0]);
                    }
                }
            }
            (r, sum / n.max(1) as f64, lo, hi)
        })
        .collect()
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
    /// Error of the tables vs the f64 quadrature reference for several resolutions and sample
    /// counts, and the precompute time on the CPU and GPU backends: Markdown + PNG + JSON.
    Bench(BenchArgs),
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
    #[arg(long, value_enum, default_value = "sobol")]
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
    #[arg(long, value_enum, default_value = "sobol")]
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

/// Options of `host energy bench`.
#[derive(clap::Args, Debug, Clone)]
pub struct BenchArgs {
    /// GPU backend to time besides the CPU backend (cpu = CPU only).
    #[arg(long, value_enum, default_value = "auto")]
    pub device: DeviceChoice,
    /// Resolutions to measure.
    #[arg(long, value_delimiter = ',', default_values_t = [16u32, 32, 64])]
    pub resolutions: Vec<u32>,
    /// Sample counts to measure.
    #[arg(long, value_delimiter = ',', default_values_t = [256u32, 1024, 4096, 16384])]
    pub samples: Vec<u32>,
    /// Markdown report; the PNG plot and the JSON figures go beside it
    /// (docs/reports/energy-bench.md is regenerated by `cargo xtask docs-reports`).
    #[arg(long, default_value = "out/energy-bench.md")]
    pub report: PathBuf,
}

impl EnergyCli {
    pub fn run(self) -> Result<()> {
        match self.what {
            EnergyWhat::Precompute(a) => run_precompute(&a),
            EnergyWhat::Furnace(a) => run_furnace(&a),
            EnergyWhat::Bench(a) => crate::energy_bench::run(&a),
        }
    }
}

fn run_precompute(a: &PrecomputeArgs) -> Result<()> {
    let spec = a.spec();
    spec.validate()?;
    crate::io::prepare_output(&a.output)?;
    let backend = Backend::select(a.device)?;
    eprintln!("{}", backend.describe());
    let (t, times) = precompute(&backend, &spec, true)?;
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
            title: format!("{what}; x: mu 0..1, y: roughness 0 (top)..1 (bottom)"),
            bar: Some((0.0, 1.0, legend::ticks(0.0, 1.0, 5))),
            swatches: vec![(legend::NON_FINITE, "not finite".to_string())],
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

/// The LUT of `--lut`, or the default precompute on `backend`.
/// The tables at `lut`, or the default tables from the user cache directory
/// (`$XDG_CACHE_HOME` or `~/.cache`, `one-source-shading/ggx-energy-<shader source hash>.bin`),
/// precomputed and cached there on first use (a cache that cannot be written is reported, not
/// fatal). The precompute kernels give the same bits on every backend, so one cache serves all.
pub fn tables_cached(backend: &Backend, lut: &Option<PathBuf>) -> Result<Tables> {
    if lut.is_some() {
        return load_or_precompute(backend, lut);
    }
    let dir = std::env::var_os("XDG_CACHE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .map(|d| d.join("one-source-shading"));
    let hash = runner::shaders::SOURCE_HASH;
    let file = dir.map(|d| d.join(format!("ggx-energy-{}.bin", &hash[..hash.len().min(16)])));
    if let Some(f) = &file {
        if f.exists() {
            match Tables::read_bin(f) {
                Ok(t) => return Ok(t),
                Err(e) => eprintln!("notice: ignoring the cached tables {}: {e:#}", f.display()),
            }
        }
    }
    eprintln!("precomputing the default energy tables (once; cached for later runs)");
    let t = precompute(backend, &TableSpec::default(), true)?.0;
    if let Some(f) = &file {
        if let Err(e) = crate::io::create_parent_dir(f).and_then(|()| t.write_bin(f)) {
            eprintln!("notice: could not cache the energy tables at {}: {e:#}", f.display());
        }
    }
    Ok(t)
}

pub fn load_or_precompute(backend: &Backend, lut: &Option<PathBuf>) -> Result<Tables> {
    match lut {
        Some(p) => Tables::read_bin(p),
        None => {
            eprintln!("no --lut: precomputing the default tables");
            Ok(precompute(backend, &TableSpec::default(), true)?.0)
        }
    }
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
        for c in img.data.chunks_exact(kern::FURNACE_STRIDE) {
            albedo.push(c[0]);
            mu.push(c[1]);
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The tables are the f64 sums, in chunk order, of `shader_core::energy`'s per-chunk sums,
    /// whether a launch carries one chunk or all of them (3 chunks, the last one short).
    #[test]
    fn table_sums_follow_chunk_order_whatever_the_launch_size() {
        let spec = TableSpec { n_mu: 3, n_r: 2, n_avg: 4, samples: 700, avg_samples: 300, chunk: 256, seq: Sequence::Sobol, seed: 5 };
        let cells = 6;
        let (mut e, mut ep, mut avg) = (vec![0.0f64; cells], vec![0.0f64; cells], vec![0.0f64; 4]);
        for start in (0..spec.samples).step_by(spec.chunk as usize) {
            let count = spec.chunk.min(spec.samples - start);
            for c in 0..cells as u32 {
                let (a, b) = core_energy::albedo_cell_sums(c % 3, c / 3, 3, 2, start, count, spec.seq.id(), spec.seed);
                e[c as usize] += f64::from(a);
                ep[c as usize] += f64::from(b);
            }
        }
        for start in (0..spec.avg_samples).step_by(spec.chunk as usize) {
            let count = spec.chunk.min(spec.avg_samples - start);
            for (j, s) in avg.iter_mut().enumerate() {
                *s += f64::from(core_energy::albedo_avg_sums(j as u32, 4, start, count, spec.seq.id(), spec.seed));
            }
        }
        let want = |v: &[f64], n: f64| v.iter().map(|s| (s / n) as f32).collect::<Vec<_>>();
        for invocations in [1, 7, 1 << 16] {
            let (t, _) = precompute_in_launches_of(&Backend::Cpu, &spec, false, invocations).unwrap();
            assert_eq!(t.e, want(&e, 700.0), "E, launches of {invocations} invocations");
            assert_eq!(t.e_prime, want(&ep, 700.0), "E', launches of {invocations} invocations");
            assert_eq!(t.e_avg, want(&avg, 300.0), "E_avg, launches of {invocations} invocations");
        }
    }
}
