//! Energy compensation for GGX (docs/energy.md): the E / E' / E_avg tables precomputed on either
//! backend, their binary LUT and EXR files, the compensation modes (Kulla-Conty 2017, Turquin
//! 2019) and the white-furnace renderer.
//!
//! Both backends run the same per-invocation functions of `shader_kernels::energy` over the same
//! sample chunks; the f32 partial sums of each chunk are added in f64 on the host in chunk order,
//! so the tables are bit-identical across backends for the same (resolution, samples, chunk,
//! sequence, seed).
//!
//! ```
//! // small tables on the CPU backend: E(mu, roughness) falls with roughness at grazing mu
//! let spec = energy::TableSpec { n_mu: 8, n_r: 8, n_avg: 8, samples: 256, avg_samples: 256, ..Default::default() };
//! let (tables, _times) = energy::precompute(&runner::Backend::Cpu, &spec, None)?;
//! assert_eq!(tables.e.len(), 64);
//! assert!(tables.e_avg[7] < tables.e_avg[0]);
//! # Ok::<(), anyhow::Error>(())
//! ```

use runner::{Backend, Launch, Timing};
use shader_kernels::launch::ItemFn;
use anyhow::{bail, Context, Result};
use shader_core::energy as core_energy;
use shader_kernels::energy as kern;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The sample sequence of the precompute and furnace kernels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Sequence {
    /// PCG32 random numbers, one generator per (cell, sample index).
    Pcg,
    /// Sobol (0,2)-sequence points, XOR-scrambled per cell.
    Sobol,
}

impl Sequence {
    pub const ALL: [Sequence; 2] = [Sequence::Pcg, Sequence::Sobol];
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
        fileio::write_file(path, bytes)
    }

    /// Read [`Tables::write_bin`]'s file (or the older GGXELUT1 form, without sample counts:
    /// `samples` and `avg_samples` are then 0, and not checked) and [`Tables::validate`] it;
    /// errors name the file.
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
        if let Some((s, a)) = counts {
            (t.samples, t.avg_samples) = (s, a);
        }
        t.validate().with_context(|| format!("energy LUT {} is unusable", path.display()))?;
        Ok(t)
    }

    /// EXR with channels E and E_prime (n_mu wide, n_r high, top row = roughness cell 0) and
    /// `<stem>.e_avg.exr` (n_avg x 1, channels E_avg = the kernel's Monte-Carlo E_avg and
    /// E_avg_lut = [`Tables::lut_consistent_e_avg`]). Returns the second path.
    pub fn write_exr(&self, path: &Path) -> Result<PathBuf> {
        fileio::write_exr(path, self.n_mu as usize, self.n_r as usize, &[("E", &self.e), ("E_prime", &self.e_prime)])?;
        let avg = path.with_extension("e_avg.exr");
        let lut_avg = self.lut_consistent_e_avg();
        fileio::write_exr(&avg, self.n_avg as usize, 1, &[("E_avg", &self.e_avg), ("E_avg_lut", &lut_avg)])?;
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

/// Progress of a precompute: called with (stage, chunks done, chunks in all) before the first
/// launch of each stage and after every launch.
pub type Progress<'a> = Option<&'a dyn Fn(&str, u64, u64)>;

/// Precompute the tables on `backend`, reporting to `progress`.
pub fn precompute(backend: &Backend, spec: &TableSpec, progress: Progress) -> Result<(Tables, PrecomputeTimes)> {
    precompute_in_launches_of(backend, spec, progress, TABLE_INVOCATIONS_PER_LAUNCH)
}

/// [`precompute`] with launches of whole chunks of about `invocations` invocations (at least one
/// chunk each).
fn precompute_in_launches_of(backend: &Backend, spec: &TableSpec, progress: Progress, invocations: usize) -> Result<(Tables, PrecomputeTimes)> {
    spec.validate()?;
    let t0 = Instant::now();
    let chunks = |s: u32| s.div_ceil(spec.chunk) as u64;
    let total = chunks(spec.samples) + chunks(spec.avg_samples);
    let done = std::cell::Cell::new(0u64);
    let stage = std::cell::Cell::new("E, E'");
    let report = |n: u64| {
        done.set(done.get() + n);
        if let Some(p) = progress {
            p(stage.get(), done.get(), total)
        }
    };
    report(0);
    let cells = spec.n_mu as usize * spec.n_r as usize;
    let (mut sum_e, mut sum_ep) = (vec![0.0f64; cells], vec![0.0f64; cells]);
    let table = |s: kern::SampleChunks| kern::AlbedoTableArgs { n_mu: spec.n_mu, n_r: spec.n_r, s, seq: spec.seq.id(), seed: spec.seed, ..Default::default() };
    let t_table = chunked_sums(backend, &kern::ALBEDO_TABLE, kern::TABLE_STRIDE, table, cells, spec.samples, spec.chunk, invocations, &report, |out, c| {
        let s = core_energy::TableSums::load(out, kern::TABLE_STRIDE * c);
        sum_e[c] += f64::from(s.e);
        sum_ep[c] += f64::from(s.e_prime);
    })
    .context("E table")?;
    stage.set("E_avg");
    report(0);
    let n_avg = spec.n_avg as usize;
    let mut sum_avg = vec![0.0f64; n_avg];
    let avg = |s: kern::SampleChunks| kern::AlbedoAvgArgs { n_avg: spec.n_avg, s, seq: spec.seq.id(), seed: spec.seed, ..Default::default() };
    let t_avg = chunked_sums(backend, &kern::ALBEDO_AVG, 1, avg, n_avg, spec.avg_samples, spec.chunk, invocations, &report, |out, c| sum_avg[c] += f64::from(out[c]))
        .context("E_avg")?;
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

/// Run a table kernel over `samples` samples of `cells` cells in chunks of `chunk` samples, as
/// few launches of whole chunks as `invocations` per launch allows, and call
/// `add(chunk_output, cell)` for every chunk in sample order and every cell (the output of one
/// chunk: the kernel's `out` for that chunk's items). Returns the summed launch time.
fn chunked_sums<A: runner::LaunchArgs>(
    backend: &Backend,
    kernel: &runner::Kernel<ItemFn<A>>,
    stride: usize,
    args: impl Fn(kern::SampleChunks) -> A,
    cells: usize,
    samples: u32,
    chunk: u32,
    invocations: usize,
    progress: &dyn Fn(u64),
    mut add: impl FnMut(&[f32], usize),
) -> Result<Timing> {
    let chunks = samples.div_ceil(chunk);
    let per_launch = (invocations / cells).max(1).min(chunks as usize) as u32;
    let (_, total) = runner::in_launches(chunks, per_launch, || false, |k, n| {
        let s = kern::SampleChunks { start: k * chunk, chunk, end: samples };
        let a = args(s);
        let (out, t) = backend
            .run(kernel, Launch::new(a, &[]), cells * n as usize, stride)
            .with_context(|| format!("samples {}..{}", s.start, (u64::from(s.start) + u64::from(n) * u64::from(chunk)).min(u64::from(samples))))?;
        for per_chunk in out.chunks_exact(cells * stride) {
            for c in 0..cells {
                add(per_chunk, c);
            }
        }
        progress(u64::from(n));
        Ok(t)
    })?;
    Ok(total)
}

/// Compensation modes of the furnace.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
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
        backend.run(&kern::FURNACE, Launch::new(args, &[bytemuck::cast_slice(lut)]), n, kern::FURNACE_STRIDE)
    }
}

/// Furnace output: per pixel (albedo, mu, roughness), mu = 0 outside the spheres.
pub struct FurnaceImage {
    pub width: u32,
    pub height: u32,
    pub data: Vec<f32>,
    pub time: Timing,
}

impl FurnaceImage {
    /// Pixel `i`'s record (row-major).
    pub fn sample(&self, i: u32) -> core_energy::FurnaceSample {
        core_energy::FurnaceSample::load(&self.data, i as usize * kern::FURNACE_STRIDE)
    }
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
    Ok(data.chunks_exact(kern::FURNACE_STRIDE).map(|c| core_energy::FurnaceSample::load(c, 0).albedo).collect())
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
                    let p = img.sample(y * img.width + x);
                    r = p.roughness;
                    if p.mu > 0.0 {
                        sum += f64::from(p.albedo);
                        n += 1;
                        lo = lo.min(p.albedo);
                        hi = hi.max(p.albedo);
                    }
                }
            }
            (r, sum / n.max(1) as f64, lo, hi)
        })
        .collect()
}

/// The tables at `lut`, or the default tables from the user cache directory
/// (`$XDG_CACHE_HOME` or `~/.cache`, `one-source-shading/ggx-energy-<shader source hash>.bin`),
/// precomputed and cached there on first use (a cache that cannot be written is reported, not
/// fatal). The precompute kernels give the same bits on every backend, so one cache serves all.
/// What a user should know but that is not an error (an unusable cache, a file without sample
/// counts, a precompute starting) goes to `notice`.
pub fn tables_cached(backend: &Backend, lut: &Option<PathBuf>, progress: Progress, notice: &dyn Fn(&str)) -> Result<Tables> {
    if lut.is_some() {
        return load_or_precompute(backend, lut, progress, notice);
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
                Ok(t) if t.samples > 0 => return Ok(t),
                Ok(_) => notice(&format!("notice: ignoring the cached tables {}: no sample counts (GGXELUT1)", f.display())),
                Err(e) => notice(&format!("notice: ignoring the cached tables {}: {e:#}", f.display())),
            }
        }
    }
    notice("precomputing the default energy tables (once; cached for later runs)");
    let t = precompute(backend, &TableSpec::default(), progress)?.0;
    if let Some(f) = &file {
        if let Err(e) = fileio::create_parent_dir(f).and_then(|()| t.write_bin(f)) {
            notice(&format!("notice: could not cache the energy tables at {}: {e:#}", f.display()));
        }
    }
    Ok(t)
}

/// The tables at `lut`, or the default tables precomputed now (notices as [`tables_cached`]).
pub fn load_or_precompute(backend: &Backend, lut: &Option<PathBuf>, progress: Progress, notice: &dyn Fn(&str)) -> Result<Tables> {
    match lut {
        Some(p) => {
            let t = Tables::read_bin(p)?;
            if t.samples == 0 {
                notice(&format!("warning: energy LUT {} does not record its sample count (GGXELUT1); not checked", p.display()));
            }
            Ok(t)
        }
        None => {
            notice("no LUT given: precomputing the default tables");
            Ok(precompute(backend, &TableSpec::default(), progress)?.0)
        }
    }
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
            let (t, _) = precompute_in_launches_of(&Backend::Cpu, &spec, None, invocations).unwrap();
            assert_eq!(t.e, want(&e, 700.0), "E, launches of {invocations} invocations");
            assert_eq!(t.e_prime, want(&ep, 700.0), "E', launches of {invocations} invocations");
            assert_eq!(t.e_avg, want(&avg, 300.0), "E_avg, launches of {invocations} invocations");
        }
    }
}
