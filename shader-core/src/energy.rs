//! Energy compensation for single-scattering GGX: the directional-albedo tables, their lookups,
//! and the Kulla-Conty and Turquin compensation terms built on them.
//!
//! Tables (precomputed by the `energy_*` kernels, the same code on both backends):
//! * E(mu, r) = int f_ss(wo, wi) cos(theta_i) dwi, the directional albedo of GGX with F = 1 and
//!   height-correlated Smith G2 (Kulla & Conty 2017, "Revisiting Physically Based Shading at
//!   Imageworks", slide "Energy compensation"; Heitz 2014 eq. 99);
//! * E'(mu, r), the same with the Schlick weight lambda = (1 - wo.wm)^5 in the integrand, so that
//!   the albedo with Schlick's F is E'' = f0 E + (f90 - f0) E' (Karis 2013 split sum; Filament
//!   section 5.3.4.3, where DFG1 = E - E' and DFG2 = E');
//! * E_avg(r) = 2 int E(mu) mu dmu (Kulla & Conty 2017).
//!
//! Parameterization: an `n_mu x n_r` grid of cell centers mu_i = max((i + 0.5) / n_mu, 1e-4),
//! r_j = (j + 0.5) / n_r (perceptual roughness, alpha = r^2), stored roughness-major
//! (`j * n_mu + i`); E_avg over `n_avg` roughness cell centers. Lookups are bilinear between cell
//! centers and clamp to the edge cells.
//!
//! Conventions: local frame (normal = +z), `wo` unit and above the surface. Invalid input (NaN
//! mu or roughness, alpha < 0) gives NaN; mu outside (0, 1] and r outside [0, 1] are clamped by the
//! lookups to the edge cells.
//!
//! LUT buffer layout (`f32` words): a header of [`LUT_HEADER`] words `[n_mu, n_r, n_avg, 0]`
//! stored as `u32` bit patterns, then the E table (`n_r` rows of `n_mu` values), then the E'
//! table (same shape), then the `n_avg` values of E_avg. The lookups index it without checks
//! beyond the slice's own: a buffer shorter than its header says panics on the CPU (on the GPU
//! the failed bounds check returns from the entry point).
//!
//! ```
//! use shader_core::energy::{cell_center, lut_e, lut_e_avg, lut_e_prime, schlick_f_avg, turquin_scale, LUT_HEADER};
//! // A 2 x 2 table (n_mu = n_r = 2) with one E_avg value.
//! let mut lut = vec![f32::from_bits(2), f32::from_bits(2), f32::from_bits(1), 0.0];
//! assert_eq!(lut.len(), LUT_HEADER);
//! lut.extend([0.9, 0.95, 0.7, 0.8]); // E: row r = 0.25, then row r = 0.75
//! lut.extend([0.1, 0.05, 0.2, 0.1]); // E'
//! lut.push(0.85); // E_avg
//! // At a cell center the lookup returns the stored value; outside, it clamps to the edge cells.
//! assert_eq!(cell_center(1, 2), 0.75);
//! assert_eq!(lut_e(&lut, 0.25, 0.75), 0.7);
//! assert_eq!(lut_e(&lut, 1.0, 0.0), 0.95);
//! assert_eq!(lut_e_prime(&lut, 0.75, 0.25), 0.05);
//! assert_eq!(lut_e_avg(&lut, 0.3), 0.85);
//! assert!(lut_e(&lut, f32::NAN, 0.5).is_nan());
//! // No loss (E = 1): Turquin's scale is exactly 1. F_avg of (0, 1) is 1/21.
//! assert_eq!(turquin_scale(1.0, 0.5), 1.0);
//! assert_eq!(schlick_f_avg(0.0, 1.0), 1.0 / 21.0);
//! ```

use crate::ieee;
use crate::buffer::load;
use crate::fresnel;
use crate::masking;
use crate::rng::{self, Pcg32};
use crate::vector::Vec3;
use crate::vndf;
use crate::warp;
use core::f32::consts::PI;

/// Random numbers from PCG32 (O'Neill 2014), one generator per (cell, sample index).
pub const SEQ_PCG: u32 = 0;
/// Sobol points (Joe & Kuo dimensions 1-3), XOR-scrambled per cell.
pub const SEQ_SOBOL: u32 = 1;

/// Smallest mu of the table grid (the seed document's clamp of the cell centers).
pub const MU_MIN: f32 = 1e-4;

/// No compensation: the single-scattering glTF metal-rough model.
pub const COMP_NONE: u32 = 0;
/// Kulla & Conty 2017 multiple-scattering lobe with the F_avg correction (Filament 4.7.2).
pub const COMP_KULLA_CONTY: u32 = 1;
/// Turquin 2019 scaled lobe f = f_ss (1 + F0 (1/E - 1)).
pub const COMP_TURQUIN: u32 = 2;

/// F0 of the glTF dielectric (ior 1.5, ((1 - 1.5) / (1 + 1.5))^2).
pub const DIELECTRIC_F0: f32 = 0.04;

/// Perceptual roughness below which the specular multiple-scattering term is skipped: below it
/// the loss 1 - E(mu) of GGX is < 1e-3 for every mu >= 1/64 (the smallest cell center of the
/// 32-cell table; f64 reference: 8.6e-4 at r = 0.025, 1.8e-3 at r = 0.03). At more
/// grazing mu the loss of smooth GGX is larger (up to ~10 %), so the threshold cannot be higher.
pub const COMPENSATION_MIN_ROUGHNESS: f32 = 0.025;

/// Words before the tables in the LUT buffer: [n_mu, n_r, n_avg, 0] as u32 bits.
pub const LUT_HEADER: usize = 4;

/// Cell center (i + 0.5) / n of cell i of n (exact for n, i < 2^24).
#[inline]
pub fn cell_center(i: u32, n: u32) -> f32 {
    ieee::div(i as f32 + 0.5, n as f32)
}

/// mu of column i of an n-column table: the cell center, clamped to >= [`MU_MIN`].
#[inline]
pub fn table_mu(i: u32, n: u32) -> f32 {
    let c = cell_center(i, n);
    if c < MU_MIN {
        MU_MIN
    } else {
        c
    }
}

/// The unit direction at cos(theta) = mu in the xz plane: (sqrt(1 - mu^2), 0, mu).
#[inline]
pub fn wo_from_mu(mu: f32) -> Vec3 {
    let s2 = 1.0 - mu * mu;
    Vec3::new(if s2 > 0.0 { ieee::sqrt(s2) } else { 0.0 }, 0.0, mu)
}

/// One-sample estimate of (E, E') for GGX with F = 1 (Heitz 2018 VNDF sampling: the weight
/// f cos / pdf = G2(wo, wi) / G1(wo), Heitz 2014 eq. 99 over eq. 43), E' weighted by Schlick's
/// lambda = (1 - wo.wm)^5. A reflection below the horizon contributes (0, 0).
#[inline]
pub fn ggx_albedo_sample(wo: Vec3, alpha: f32, u0: f32, u1: f32) -> (f32, f32) {
    let wm = vndf::ggx_sample_visible_heitz2018(wo, alpha, alpha, u0, u1);
    let wi = fresnel::reflect(wo, wm);
    let vh = wo.dot(wm);
    if !(wi.z > 0.0 && vh > 0.0) {
        // NaN (invalid alpha) must stay NaN.
        if wi.z.is_nan() || vh.is_nan() {
            return (f32::NAN, f32::NAN);
        }
        return (0.0, 0.0);
    }
    let g1 = masking::ggx_g1(wo, alpha, alpha);
    let g2 = masking::ggx_g2_height_correlated(wo, wi, alpha, alpha);
    let w = ieee::div(g2, g1);
    (w, w * fresnel::schlick_weight(vh))
}

/// Per-run, per-cell scrambling word (PCG hash, Jarzynski & Olano 2020).
#[inline]
fn cell_key(seed: u32, cell: u32) -> u32 {
    rng::pcg_hash(cell ^ rng::pcg_hash(seed))
}

/// Dimension 3 of the Sobol sequence (Joe & Kuo direction numbers: primitive polynomial
/// x^2 + x + 1, m = 1, 3; Bratley & Fox 1988 recurrence m_k = 2 m_{k-1} ^ 4 m_{k-2} ^ m_{k-2}),
/// XOR-scrambled, as a float in [0, 1).
#[inline]
pub fn sobol_dim3(i: u32, scramble: u32) -> f32 {
    let mut m_prev2: u32 = 1; // m_{k-2}
    let mut m_prev1: u32 = 3; // m_{k-1}
    let mut y: u32 = 0;
    let mut bits = i;
    let mut k: u32 = 1;
    while bits != 0 && k <= 32 {
        let m = if k == 1 {
            1
        } else if k == 2 {
            3
        } else {
            let m = (m_prev1 << 1) ^ (m_prev2 << 2) ^ m_prev2;
            m_prev2 = m_prev1;
            m_prev1 = m;
            m
        };
        if bits & 1 != 0 {
            y ^= m << (32 - k);
        }
        bits >>= 1;
        k += 1;
    }
    rng::u32_to_unit_f32(y ^ scramble)
}

/// The 2D point `index` of cell `cell`: PCG32 seeded by pcg_hash(index) on the cell's stream, or
/// the cell-scrambled Sobol point (dimensions 1-2, `rng::sobol_2d`).
#[inline]
pub fn sample_2d(seq: u32, seed: u32, cell: u32, index: u32) -> (f32, f32) {
    let key = cell_key(seed, cell);
    if seq == SEQ_SOBOL {
        rng::sobol_2d(index, key, rng::pcg_hash(key))
    } else {
        let mut r = Pcg32::new(rng::pcg_hash(index), key);
        let u0 = r.next_f32();
        let u1 = r.next_f32();
        (u0, u1)
    }
}

/// The 3D point `index` of cell `cell` (as [`sample_2d`], Sobol dimensions 1-3).
#[inline]
pub fn sample_3d(seq: u32, seed: u32, cell: u32, index: u32) -> (f32, f32, f32) {
    let key = cell_key(seed, cell);
    if seq == SEQ_SOBOL {
        let k1 = rng::pcg_hash(key);
        let (a, b) = rng::sobol_2d(index, key, k1);
        (a, b, sobol_dim3(index, rng::pcg_hash(k1)))
    } else {
        let mut r = Pcg32::new(rng::pcg_hash(index), key);
        let u0 = r.next_f32();
        let u1 = r.next_f32();
        let u2 = r.next_f32();
        (u0, u1, u2)
    }
}

/// Kahan compensated sum in f32 (Kahan 1965), exact-operation only so both backends agree.
#[derive(Clone, Copy, Debug, Default)]
pub struct KahanSum {
    /// The running sum (the estimate).
    pub sum: f32,
    /// The running compensation: minus the low-order part lost by the last additions.
    pub c: f32,
}

impl KahanSum {
    /// sum += x with the rounding error carried in `c`.
    #[inline]
    pub fn add(&mut self, x: f32) {
        let y = x - self.c;
        let t = self.sum + y;
        self.c = (t - self.sum) - y;
        self.sum = t;
    }
}

/// One E / E' table item's sums as the table kernel writes them ([`TableSums::WORDS`] words).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TableSums {
    /// Sum of the E estimator over the item's samples.
    pub e: f32,
    /// Sum of the E' estimator.
    pub e_prime: f32,
}

impl TableSums {
    /// f32 words of the record: E, E'.
    pub const WORDS: usize = 2;

    /// Write the record at `out[o..o + WORDS]`.
    #[inline]
    pub fn store(&self, out: &mut [f32], o: usize) {
        crate::buffer::store(out, o, self.e);
        crate::buffer::store(out, o + 1, self.e_prime);
    }

    /// The record at `buf[o..o + WORDS]`.
    #[inline]
    pub fn load(buf: &[f32], o: usize) -> TableSums {
        TableSums { e: load(buf, o), e_prime: load(buf, o + 1) }
    }
}

/// One white-furnace pixel as the furnace kernel writes it ([`FurnaceSample::WORDS`] words).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FurnaceSample {
    /// Directional albedo estimate (1 outside the spheres: the environment).
    pub albedo: f32,
    /// cos(theta) of the view direction at the pixel (0 outside the spheres).
    pub mu: f32,
    /// The sphere's roughness.
    pub roughness: f32,
}

impl FurnaceSample {
    /// f32 words of the record: albedo, mu, roughness.
    pub const WORDS: usize = 3;

    /// Write the record at `out[o..o + WORDS]`.
    #[inline]
    pub fn store(&self, out: &mut [f32], o: usize) {
        crate::buffer::store(out, o, self.albedo);
        crate::buffer::store(out, o + 1, self.mu);
        crate::buffer::store(out, o + 2, self.roughness);
    }

    /// The record at `buf[o..o + WORDS]`.
    #[inline]
    pub fn load(buf: &[f32], o: usize) -> FurnaceSample {
        FurnaceSample { albedo: load(buf, o), mu: load(buf, o + 1), roughness: load(buf, o + 2) }
    }
}

/// Sums of the (E, E') samples [start, start + count) of cell (i, j) of an n_mu x n_r table, in
/// sample order (Monte-Carlo estimate of Kulla & Conty 2017's E(mu), Karis 2013's split sum).
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn albedo_cell_sums(i: u32, j: u32, n_mu: u32, n_r: u32, start: u32, count: u32, seq: u32, seed: u32) -> (f32, f32) {
    let mu = table_mu(i, n_mu);
    let r = cell_center(j, n_r);
    let alpha = r * r;
    let wo = wo_from_mu(mu);
    let cell = j * n_mu + i;
    let mut e = KahanSum::default();
    let mut ep = KahanSum::default();
    let mut k = 0;
    while k < count {
        let (u0, u1) = sample_2d(seq, seed, cell, start + k);
        let (a, b) = ggx_albedo_sample(wo, alpha, u0, u1);
        e.add(a);
        ep.add(b);
        k += 1;
    }
    (e.sum, ep.sum)
}

/// Stream offset of the E_avg samples, so they never share points with the 2D table's cells.
const AVG_SEED_XOR: u32 = 0x9e37_79b9;

/// Sum of the E_avg samples [start, start + count) of roughness cell j of n_r: mu = sqrt(u)
/// (density 2 mu), so each sample of E is one of E_avg = 2 int E(mu) mu dmu (Kulla & Conty 2017).
#[inline]
pub fn albedo_avg_sums(j: u32, n_r: u32, start: u32, count: u32, seq: u32, seed: u32) -> f32 {
    let r = cell_center(j, n_r);
    let alpha = r * r;
    let mut e = KahanSum::default();
    let mut k = 0;
    while k < count {
        let (um, u0, u1) = sample_3d(seq, seed ^ AVG_SEED_XOR, j, start + k);
        let mu = ieee::sqrt(um);
        let mu = if mu < MU_MIN { MU_MIN } else { mu };
        let (a, _) = ggx_albedo_sample(wo_from_mu(mu), alpha, u0, u1);
        e.add(a);
        k += 1;
    }
    e.sum
}

/// Linear interpolation weight and the two cell indices for coordinate x in [0, 1] on n cells
/// whose centers are (i + 0.5) / n, clamped to the edge cells.
#[inline]
fn lerp_cells(x: f32, n: u32) -> (u32, u32, f32) {
    let t = x * n as f32 - 0.5;
    let last = (n - 1) as f32;
    let t = if t > 0.0 { t } else { 0.0 };
    let t = if t < last { t } else { last };
    let i0 = t as u32;
    let i1 = if i0 + 1 < n { i0 + 1 } else { i0 };
    (i0, i1, t - i0 as f32)
}

/// Interpolation taps of coordinate `x` in [0, 1] on `n` cells with centres (i + 0.5) / n:
/// three cells (j0, j1, j2) and their weights. Between the centres, linear interpolation
/// (w2 = 0). In the outer half cell at the low end (x below the first centre) when `low`, and at
/// the high end when `high`, the quadratic through the three outermost centres, extrapolated
/// (Lagrange); otherwise that half cell holds the edge value. With fewer than three cells:
/// linear, clamped to the edge.
///
/// The roughness axis extrapolates at both ends (E at r = 1, glTF's default roughness, follows
/// the table's curvature instead of holding the value at r = 1 - 1/(2 n_r)); the mu axis at the
/// normal-incidence end only (E is smooth there; towards grazing angles 1 - E peaks sharply and
/// the edge value is kept).
#[inline]
pub fn cell_taps(x: f32, n: u32, low: bool, high: bool) -> (u32, u32, u32, f32, f32, f32) {
    let t = x * n as f32 - 0.5;
    let last = (n - 1) as f32;
    if n >= 3 && ((low && t < 0.0) || (high && t > last)) {
        let (j, s) = if t < 0.0 { (0u32, if t > -0.5 { t } else { -0.5 }) } else { (n - 3, (if t < last + 0.5 { t } else { last + 0.5 }) - (n - 3) as f32) };
        let w0 = (s - 1.0) * (s - 2.0) * 0.5;
        let w1 = s * (2.0 - s);
        let w2 = s * (s - 1.0) * 0.5;
        return (j, j + 1, j + 2, w0, w1, w2);
    }
    let (i0, i1, f) = lerp_cells(x, n);
    (i0, i1, i1, 1.0 - f, f, 0.0)
}

/// The interpolation taps of (x, y) on a table of n_x columns (mu) by n_y rows (roughness):
/// [`cell_taps`] on both axes (mu: extrapolated at the high end; roughness: at both ends).
#[derive(Clone, Copy)]
struct Taps {
    i: (u32, u32, u32, f32, f32, f32),
    j: (u32, u32, u32, f32, f32, f32),
}

#[inline]
fn taps(n_x: u32, n_y: u32, x: f32, y: f32) -> Taps {
    Taps { i: cell_taps(x, n_x, false, true), j: cell_taps(y, n_y, true, true) }
}

/// Lookup with taps `t` in the table at word `offset` of `lut` (n_x columns): the rows of the
/// roughness taps, each interpolated with the mu taps ([`weigh_taps`]), weighed alike.
#[inline]
fn lookup(lut: &[f32], offset: usize, n_x: u32, t: &Taps) -> f32 {
    let (j0, j1, j2, w0, w1, w2) = t.j;
    let s = weigh_taps(lut, offset + (j0 * n_x) as usize, t.i) * w0 + weigh_taps(lut, offset + (j1 * n_x) as usize, t.i) * w1;
    if j2 != j1 {
        s + weigh_taps(lut, offset + (j2 * n_x) as usize, t.i) * w2
    } else {
        s
    }
}

/// w0 v(i0) + w1 v(i1) + w2 v(i2) over the words v(i) = `lut[o + i]` for the taps of
/// [`cell_taps`], the third term only where it is a third cell (the quadratic end cells): the
/// linear case repeats i1 with weight 0, whose value is not read ([`lookup`] skips its third row
/// alike).
#[inline]
fn weigh_taps(lut: &[f32], o: usize, t: (u32, u32, u32, f32, f32, f32)) -> f32 {
    let (i0, i1, i2, u0, u1, u2) = t;
    let s = load(lut, o + i0 as usize) * u0 + load(lut, o + i1 as usize) * u1;
    if i2 != i1 {
        s + load(lut, o + i2 as usize) * u2
    } else {
        s
    }
}

/// (n_mu, n_r, n_avg) of a LUT buffer: its first three words read as `u32` bits, in one merging
/// range check (zeros for a buffer shorter than 3 words, which no validated table is).
#[inline]
pub fn lut_dims(lut: &[f32]) -> (u32, u32, u32) {
    let [n_mu, n_r, n_avg] = crate::buffer::load3(lut, 0);
    (n_mu.to_bits(), n_r.to_bits(), n_avg.to_bits())
}

/// E(mu, r) from the LUT buffer (linear in mu, [`cell_taps`] in r); NaN for NaN input.
#[inline]
pub fn lut_e(lut: &[f32], mu: f32, r: f32) -> f32 {
    if mu.is_nan() || r.is_nan() {
        return f32::NAN;
    }
    let (n_mu, n_r, _) = lut_dims(lut);
    lookup(lut, LUT_HEADER, n_mu, &taps(n_mu, n_r, mu, r))
}

/// E'(mu, r) from the LUT buffer (linear in mu, [`cell_taps`] in r); NaN for NaN input.
#[inline]
pub fn lut_e_prime(lut: &[f32], mu: f32, r: f32) -> f32 {
    if mu.is_nan() || r.is_nan() {
        return f32::NAN;
    }
    let (n_mu, n_r, _) = lut_dims(lut);
    lookup(lut, LUT_HEADER + (n_mu * n_r) as usize, n_mu, &taps(n_mu, n_r, mu, r))
}

/// (E, E')(mu, r) from the LUT buffer: [`lut_e`] and [`lut_e_prime`] with the taps computed once
/// (the two tables share their grid), bit for bit the same values; NaNs for NaN input.
#[inline]
pub fn lut_e_and_e_prime(lut: &[f32], mu: f32, r: f32) -> (f32, f32) {
    if mu.is_nan() || r.is_nan() {
        return (f32::NAN, f32::NAN);
    }
    let (n_mu, n_r, _) = lut_dims(lut);
    let t = taps(n_mu, n_r, mu, r);
    (lookup(lut, LUT_HEADER, n_mu, &t), lookup(lut, LUT_HEADER + (n_mu * n_r) as usize, n_mu, &t))
}

/// E_avg(r) from the LUT buffer ([`cell_taps`]); NaN for NaN input.
#[inline]
pub fn lut_e_avg(lut: &[f32], r: f32) -> f32 {
    if r.is_nan() {
        return f32::NAN;
    }
    let (n_mu, n_r, n_avg) = lut_dims(lut);
    let off = LUT_HEADER + (2 * n_mu * n_r) as usize;
    weigh_taps(lut, off, cell_taps(r, n_avg, true, true))
}

/// Average Schlick reflectance F_avg = 2 int F(mu) mu dmu = lerp(f0, f90, 1/21) (Kulla & Conty
/// 2017; Filament 4.7.2: 2 int (1 - mu)^5 mu dmu = 1/21).
#[inline]
pub fn schlick_f_avg(f0: f32, f90: f32) -> f32 {
    f0 + (f90 - f0) * (ieee::div(1.0, 21.0))
}

/// Kulla & Conty 2017 multiple-scattering BRDF with the F_avg term of their appendix (Filament
/// 4.7.2): (1 - E(wo)) (1 - E(wi)) F_avg^2 E_avg / (pi (1 - E_avg) (1 - F_avg (1 - E_avg)));
/// 0 when E_avg >= 1 (no loss).
#[inline]
pub fn kulla_conty_f_ms(e_o: f32, e_i: f32, e_avg: f32, f_avg: f32) -> f32 {
    let loss = 1.0 - e_avg;
    if !(loss > 0.0) {
        return if loss.is_nan() { f32::NAN } else { 0.0 };
    }
    ieee::div((1.0 - e_o) * (1.0 - e_i) * (f_avg * f_avg * e_avg), PI * loss * (1.0 - f_avg * loss))
}

/// Directional albedo of [`kulla_conty_f_ms`], int f_ms cos dwi = (1 - E(wo)) F_avg^2 E_avg /
/// (1 - F_avg (1 - E_avg)) (Kulla & Conty 2017, using (1/pi) int (1 - E) cos = 1 - E_avg).
#[inline]
pub fn kulla_conty_albedo(e_o: f32, e_avg: f32, f_avg: f32) -> f32 {
    let loss = 1.0 - e_avg;
    if !(loss > 0.0) {
        return if loss.is_nan() { f32::NAN } else { 0.0 };
    }
    ieee::div((1.0 - e_o) * (f_avg * f_avg * e_avg), 1.0 - f_avg * loss)
}

/// Turquin 2019 ("Practical multiple scattering compensation for microfacet models", eq. 16-18)
/// scale of the single-scattering lobe: f = f_ss (1 + F0 (1/E(wo) - 1)), i.e. f_ms = F0 (1/E - 1) f_ss.
#[inline]
pub fn turquin_scale(e_o: f32, f0: f32) -> f32 {
    1.0 + f0 * (ieee::div(1.0, e_o) - 1.0)
}

/// Albedo of the single-scattering lobe with Schlick's F: E'' = f0 E + (f90 - f0) E' (Karis 2013
/// split sum; Filament 5.3.4.3).
#[inline]
pub fn schlick_albedo(e: f32, e_prime: f32, f0: f32, f90: f32) -> f32 {
    f0 * e + (f90 - f0) * e_prime
}

/// A glTF metal-rough material in a white furnace: scalar base colour, metallic, perceptual
/// roughness, compensation mode ([`COMP_NONE`], [`COMP_KULLA_CONTY`], [`COMP_TURQUIN`]) and the
/// roughness below which the specular multiple-scattering term is skipped.
#[derive(Clone, Copy, Debug)]
pub struct FurnaceMaterial {
    /// Scalar base colour in [0, 1] (F0 of the metal, albedo of the diffuse lobe).
    pub base: f32,
    /// Metallic factor in [0, 1]: 0 dielectric, 1 metal, blended linearly in between.
    pub metallic: f32,
    /// Perceptual roughness in [0, 1] (alpha = roughness^2).
    pub roughness: f32,
    /// Compensation mode: [`COMP_NONE`], [`COMP_KULLA_CONTY`] or [`COMP_TURQUIN`].
    pub mode: u32,
    /// Perceptual roughness below which the specular multiple-scattering term is skipped (usually
    /// [`COMPENSATION_MIN_ROUGHNESS`]).
    pub min_roughness: f32,
}

/// The per-wo constants of a compensated material (LUT lookups done once per shading point).
#[derive(Clone, Copy, Debug)]
pub struct CompensationTerms {
    /// Turquin scale of the metal specular lobe (1 when off).
    pub turquin_m: f32,
    /// Turquin scale of the dielectric specular lobe (1 when off).
    pub turquin_d: f32,
    /// Factor of (1 - E(wi)) in pi f_ms of the metal lobe (0 when off).
    pub kc_m: f32,
    /// Factor of (1 - E(wi)) in pi f_ms of the dielectric lobe (0 when off).
    pub kc_d: f32,
    /// Scale of the dielectric diffuse lobe, 1 - (specular albedo); < 0 means glTF's 1 - F(v.h).
    pub diffuse: f32,
}

/// Compensation constants at wo = (.., mu) for material `m` (Kulla & Conty 2017; Turquin 2019;
/// dielectric diffuse scaled by 1 - E'' as Filament 4.7.2 / the glTF energy-conservation note).
/// Below `m.min_roughness` the specular terms are skipped and a metal does no lookup at all.
#[inline]
pub fn compensation_terms(lut: &[f32], m: &FurnaceMaterial, mu: f32) -> CompensationTerms {
    let mut c = CompensationTerms { turquin_m: 1.0, turquin_d: 1.0, kc_m: 0.0, kc_d: 0.0, diffuse: -1.0 };
    if m.mode == COMP_NONE {
        return c;
    }
    let ms = m.roughness >= m.min_roughness;
    let need_e = ms || m.metallic < 1.0;
    if !need_e {
        return c;
    }
    let (e_o, e_p) = lut_e_and_e_prime(lut, mu, m.roughness);
    let e2_d = schlick_albedo(e_o, e_p, DIELECTRIC_F0, 1.0);
    let mut spec_d = e2_d;
    if ms && m.mode == COMP_TURQUIN {
        c.turquin_m = turquin_scale(e_o, m.base);
        c.turquin_d = turquin_scale(e_o, DIELECTRIC_F0);
        spec_d = e2_d * c.turquin_d;
    }
    if ms && m.mode == COMP_KULLA_CONTY {
        let e_avg = lut_e_avg(lut, m.roughness);
        let fa_m = schlick_f_avg(m.base, 1.0);
        let fa_d = schlick_f_avg(DIELECTRIC_F0, 1.0);
        // pi f_ms / (1 - E(wi)) for each Fresnel.
        c.kc_m = kulla_conty_f_ms(e_o, 0.0, e_avg, fa_m) * PI;
        c.kc_d = kulla_conty_f_ms(e_o, 0.0, e_avg, fa_d) * PI;
        spec_d = e2_d + kulla_conty_albedo(e_o, e_avg, fa_d);
    }
    let d = 1.0 - spec_d;
    c.diffuse = if d > 0.0 { d } else { 0.0 };
    c
}

/// One-sample estimate of the directional albedo int f(wo, wi) cos dwi of material `m` (glTF 2.0
/// appendix B.3 with height-correlated G2 and scalar base colour), plus its compensation: the
/// specular lobe by VNDF sampling (Heitz 2018), the diffuse and Kulla-Conty lobes by cosine
/// sampling (Malley), both from the same (u0, u1).
#[inline]
fn material_albedo_sample(lut: &[f32], m: &FurnaceMaterial, c: &CompensationTerms, wo: Vec3, u0: f32, u1: f32) -> f32 {
    let alpha = m.roughness * m.roughness;
    let met = m.metallic;
    let mut acc = 0.0;
    // Specular: weight G2 / G1 times F(v.h) and the Turquin scale.
    let wm = vndf::ggx_sample_visible_heitz2018(wo, alpha, alpha, u0, u1);
    let wi = fresnel::reflect(wo, wm);
    let vh = wo.dot(wm);
    if wi.z > 0.0 && vh > 0.0 {
        let w = ieee::div(masking::ggx_g2_height_correlated(wo, wi, alpha, alpha), masking::ggx_g1(wo, alpha, alpha));
        let lam = fresnel::schlick_weight(vh);
        let f_m = m.base + (1.0 - m.base) * lam;
        let f_d = DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) * lam;
        acc = w * (met * f_m * c.turquin_m + (1.0 - met) * f_d * c.turquin_d);
    }
    // Cosine lobes: f cos / pdf = pi f.
    let wc = warp::sample_cosine_hemisphere(u0, u1);
    if c.kc_m > 0.0 || c.kc_d > 0.0 {
        let e_i = lut_e(lut, wc.z, m.roughness);
        acc = acc + (1.0 - e_i) * (met * c.kc_m + (1.0 - met) * c.kc_d);
    }
    if met < 1.0 {
        let diffuse = if c.diffuse < 0.0 {
            let h = (wo + wc).normalize();
            1.0 - fresnel::schlick(wo.dot(h), DIELECTRIC_F0, 1.0)
        } else {
            c.diffuse
        };
        acc = acc + (1.0 - met) * m.base * diffuse;
    }
    acc
}

/// Monte-Carlo directional albedo of material `m` at cos(theta_o) = mu in a white furnace
/// (environment radiance 1): the mean of `samples` samples of cell `cell` (Heitz 2014's white
/// furnace test, section 7).
#[inline]
pub fn furnace_albedo(lut: &[f32], m: &FurnaceMaterial, mu: f32, samples: u32, seq: u32, seed: u32, cell: u32) -> f32 {
    let wo = wo_from_mu(mu);
    let c = compensation_terms(lut, m, mu);
    let mut s = KahanSum::default();
    let mut k = 0;
    while k < samples {
        let (u0, u1) = sample_2d(seq, seed, cell, k);
        s.add(material_albedo_sample(lut, m, &c, wo, u0, u1));
        k += 1;
    }
    ieee::div(s.sum, samples as f32)
}
