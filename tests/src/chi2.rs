//! Chi-square goodness-of-fit tests for direction samplers, in the style of Mitsuba 3's
//! `ChiSquareTest` (`mitsuba/python/chi2.py`): draw N directions from a sampler, histogram them on a
//! 2D grid over a parameterization of the sphere, integrate the sampler's claimed density over
//! every cell to get the expected counts, pool the cells with fewer than 5 expected samples, and
//! compare with Pearson's statistic against the chi-square distribution.
//!
//! What is specific here:
//! * Two parameterizations ([`Domain`]): [`SphereDomain`] (cos theta, phi) of wo itself, as Mitsuba,
//!   and [`HalfVectorDomain`], the half vector h = normalize(wi + wo) in the stretched (alpha = 1)
//!   configuration around the stretched wi, which resolves lobes of any roughness and incidence
//!   with the same grid (a lobe of alpha = 1e-3 is a single cell of a sphere grid).
//! * Expected counts by adaptive cubature ([`integrate_cells`]): a 4x4 Gauss-Legendre rule per
//!   cell, split in four while the children disagree with their parent by more than a tolerance
//!   tied to the cell's own sampling noise (a fraction of sqrt(expected count)). Near-grazing,
//!   low-roughness lobes and the pdfs' discontinuities (the wm.z = 0 edge, the bounded cap) are
//!   where it refines; nothing is excluded. A fixed 16x16 rule per cell overshoots such lobes by
//!   10-16 % (89 degrees, alpha_y = 0.05).
//! * Significance: the caller divides its level by the number of tests (Bonferroni).

use host::Backend;
use rayon::prelude::*;
use std::f64::consts::PI;

/// A bijection between (almost all of) the sphere of directions and the unit square.
pub trait Domain: Sync {
    /// The unit-square coordinates of direction `w`, or `None` where the domain has no point for it.
    fn to_unit(&self, w: [f64; 3]) -> Option<(f64, f64)>;
    /// The direction at (u, v) and the Jacobian |d omega / (du dv)| there (0: no direction).
    #[allow(clippy::wrong_self_convention)] // the inverse of `to_unit`, for this domain
    fn from_unit(&self, u: f64, v: f64) -> ([f64; 3], f64);
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: [f64; 3]) -> [f64; 3] {
    let l = dot(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn phi_unit(y: f64, x: f64) -> f64 {
    let p = y.atan2(x) / (2.0 * PI);
    if p < 0.0 {
        p + 1.0
    } else {
        p
    }
}

/// Directions by (u, v) = ((cos theta + 1) / 2, phi / 2 pi) about +z; Jacobian 4 pi everywhere.
#[derive(Clone, Copy, Debug, Default)]
pub struct SphereDomain;

impl Domain for SphereDomain {
    fn to_unit(&self, w: [f64; 3]) -> Option<(f64, f64)> {
        let l = dot(w, w).sqrt();
        if !(l > 0.0) || !l.is_finite() {
            return None;
        }
        Some(((w[2] / l + 1.0) * 0.5, phi_unit(w[1], w[0])))
    }

    fn from_unit(&self, u: f64, v: f64) -> ([f64; 3], f64) {
        let z = 2.0 * u - 1.0;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let p = 2.0 * PI * v;
        ([r * p.cos(), r * p.sin(), z], 4.0 * PI)
    }
}

/// Where [`HalfVectorDomain`] puts the pole of its (cos theta, phi) coordinates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pole {
    /// About the stretched wi, p = normalize(alpha_x wi.x, alpha_y wi.y, wi.z): u = cos theta' in
    /// [0, 1] covers exactly the reachable hemisphere h_std.p > 0. Suits NDF sampling, whose
    /// density jumps at that hemisphere's rim (u = 0, a domain edge) and nowhere inside.
    StretchedWi,
    /// About the normal: u = (h_std.z + 1) / 2, so the jump of the VNDF densities at the horizon
    /// of the half vector (h_std.z = 0) is the row edge u = 1/2; the unreachable half
    /// h_std.p <= 0 has Jacobian 0 (the VNDF densities vanish continuously towards it).
    Normal,
}

/// Reflected directions wo parameterized by their half vector in the stretched configuration:
/// h = normalize(wi + wo), h_std = normalize(h.x / alpha_x, h.y / alpha_y, h.z), and (u, v) the
/// (cos theta, phi) coordinates of h_std about a [`Pole`]. h.wi > 0 <=> h_std.p > 0 with
/// p = normalize(alpha_x wi.x, alpha_y wi.y, wi.z), so the hemisphere about p is the whole sphere
/// of wo (less wo = -wi). For the VNDF methods the density in h_std is a clipped cosine lobe
/// whatever alpha and theta_i are, so one grid resolves every lobe.
///
/// Jacobian: |d wo / d h| = 4 (wi.h), |d h / d h_std| = alpha_x alpha_y / |A h_std|^3 (A =
/// diag(alpha_x, alpha_y, 1)), |d h_std / du dv| = 2 pi (pole p) or 4 pi (pole z).
#[derive(Clone, Copy, Debug)]
pub struct HalfVectorDomain {
    pub wi: [f64; 3],
    pub alpha_x: f64,
    pub alpha_y: f64,
    pub pole: Pole,
    p: [f64; 3],
    t1: [f64; 3],
    t2: [f64; 3],
}

impl HalfVectorDomain {
    /// `wi` non-zero (normalized here: a sampler given the f32 rounding of a unit vector reflects
    /// its direction), alphas > 0.
    pub fn new(wi: [f64; 3], alpha_x: f64, alpha_y: f64, pole: Pole) -> Self {
        assert!(alpha_x > 0.0 && alpha_y > 0.0, "HalfVectorDomain needs alpha > 0");
        let wi = norm(wi);
        let p = norm([alpha_x * wi[0], alpha_y * wi[1], wi[2]]);
        let (t1, t2) = match pole {
            Pole::StretchedWi => {
                let helper = if p[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
                let t1 = norm(cross(helper, p));
                (t1, cross(p, t1))
            }
            Pole::Normal => ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        };
        HalfVectorDomain { wi, alpha_x, alpha_y, pole, p, t1, t2 }
    }

    fn axis(&self) -> [f64; 3] {
        match self.pole {
            Pole::StretchedWi => self.p,
            Pole::Normal => [0.0, 0.0, 1.0],
        }
    }
}

impl Domain for HalfVectorDomain {
    fn to_unit(&self, w: [f64; 3]) -> Option<(f64, f64)> {
        // Normalized first: near wo = -wi (grazing incidence) h = wi + wo cancels, and the
        // length error of an f32 unit vector (up to 6e-8) would shift h by up to 2 % of a lobe
        // of alpha = 1e-3 at theta_i = 89.9 degrees.
        let lw = dot(w, w).sqrt();
        if !(lw > 0.0) || !lw.is_finite() {
            return None;
        }
        let w = [w[0] / lw, w[1] / lw, w[2] / lw];
        let h = [self.wi[0] + w[0], self.wi[1] + w[1], self.wi[2] + w[2]];
        let hs = [h[0] / self.alpha_x, h[1] / self.alpha_y, h[2]];
        let l = dot(hs, hs).sqrt();
        if !(l > 0.0) || !l.is_finite() {
            return None;
        }
        let hs = [hs[0] / l, hs[1] / l, hs[2] / l];
        let c = dot(hs, self.axis());
        let phi = phi_unit(dot(hs, self.t2), dot(hs, self.t1));
        Some(match self.pole {
            // Rounding can put a sample a hair below the rim; keep it in the first row.
            Pole::StretchedWi => (c.max(0.0), phi),
            Pole::Normal => ((c + 1.0) * 0.5, phi),
        })
    }

    fn from_unit(&self, u: f64, v: f64) -> ([f64; 3], f64) {
        let (c, dudv) = match self.pole {
            Pole::StretchedWi => (u, 2.0 * PI),
            Pole::Normal => (2.0 * u - 1.0, 4.0 * PI),
        };
        let s = (1.0 - c * c).max(0.0).sqrt();
        let ph = 2.0 * PI * v;
        let (cx, cy) = (s * ph.cos(), s * ph.sin());
        let axis = self.axis();
        let hs: [f64; 3] = std::array::from_fn(|k| cx * self.t1[k] + cy * self.t2[k] + c * axis[k]);
        if dot(hs, self.p) <= 0.0 {
            return ([0.0, 0.0, 0.0], 0.0);
        }
        let h = [self.alpha_x * hs[0], self.alpha_y * hs[1], hs[2]];
        let l = dot(h, h).sqrt();
        let h = [h[0] / l, h[1] / l, h[2] / l];
        let d = dot(self.wi, h);
        let wo = [2.0 * d * h[0] - self.wi[0], 2.0 * d * h[1] - self.wi[1], 2.0 * d * h[2] - self.wi[2]];
        let jac = dudv * (self.alpha_x * self.alpha_y / (l * l * l)) * 4.0 * d.abs();
        (wo, jac)
    }
}

/// Grid and integration settings.
#[derive(Clone, Debug)]
pub struct Grid {
    /// Cells along u (cos theta).
    pub res_u: usize,
    /// Cells along v (phi).
    pub res_v: usize,
    /// Cells with fewer expected samples are pooled (Mitsuba: 5).
    pub min_expected: f64,
    /// Integration tolerance per cell, as a fraction of sqrt(max(expected count, 1)).
    pub tol_sigma: f64,
    /// Maximum number of 2x2 subdivisions of a cell.
    pub max_depth: u32,
    /// Values of u where the density is known to jump along the whole line (e.g. the edge
    /// wo.z = -wi.z of the half vectors above the surface in [`SphereDomain`]): cells are split
    /// there before integrating, so no quadrature rule straddles the jump.
    pub u_breaks: Vec<f64>,
}

impl Default for Grid {
    fn default() -> Self {
        Grid { res_u: 32, res_v: 64, min_expected: 5.0, tol_sigma: 0.1, max_depth: 12, u_breaks: Vec::new() }
    }
}

/// 4-point Gauss-Legendre nodes and weights on [-1, 1].
const GL_X: [f64; 4] = [-0.861_136_311_594_052_6, -0.339_981_043_584_856_3, 0.339_981_043_584_856_3, 0.861_136_311_594_052_6];
const GL_W: [f64; 4] = [0.347_854_845_137_453_9, 0.652_145_154_862_546_1, 0.652_145_154_862_546_1, 0.347_854_845_137_453_9];

/// A function of the unit square (the density times the domain's Jacobian).
struct Integrand<'a> {
    domain: &'a dyn Domain,
    pdf: &'a (dyn Fn([f64; 3]) -> f64 + Sync),
    evals: std::cell::Cell<u64>,
}

impl Integrand<'_> {
    fn at(&self, u: f64, v: f64) -> f64 {
        self.evals.set(self.evals.get() + 1);
        let (w, jac) = self.domain.from_unit(u, v);
        if jac == 0.0 || !jac.is_finite() {
            return 0.0;
        }
        let p = (self.pdf)(w);
        // 0, and the non-finite values a density can reach at a measure-zero set by f32 rounding
        // (NDF sampling's 1 / |wi.wm| at wo = -wi), contribute nothing.
        if p == 0.0 || !p.is_finite() {
            0.0
        } else {
            p * jac
        }
    }

    fn gl(&self, u0: f64, u1: f64, v0: f64, v1: f64) -> f64 {
        let (hu, hv) = (0.5 * (u1 - u0), 0.5 * (v1 - v0));
        let (cu, cv) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
        let mut s = 0.0;
        for i in 0..4 {
            let u = cu + hu * GL_X[i];
            let mut row = 0.0;
            for j in 0..4 {
                row += GL_W[j] * self.at(u, cv + hv * GL_X[j]);
            }
            s += GL_W[i] * row;
        }
        s * hu * hv
    }

    /// Adaptive 2x2 subdivision of cell `c` whose 4x4 rule gave `whole`: accept the children's
    /// sum when it is within `tol` of `whole` (after at least `MIN_DEPTH` splits).
    fn adapt(&self, c: [f64; 4], whole: f64, tol: f64, depth: u32, max_depth: u32) -> f64 {
        const MIN_DEPTH: u32 = 1;
        let [u0, u1, v0, v1] = c;
        let (um, vm) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
        let kids = [[u0, um, v0, vm], [um, u1, v0, vm], [u0, um, vm, v1], [um, u1, vm, v1]];
        let vals = kids.map(|k| self.gl(k[0], k[1], k[2], k[3]));
        let sum: f64 = vals.iter().sum();
        if depth >= max_depth || (depth >= MIN_DEPTH && (sum - whole).abs() <= tol) {
            return sum;
        }
        kids.iter().zip(vals).map(|(k, v)| self.adapt(*k, v, tol * 0.5, depth + 1, max_depth)).sum()
    }
}

/// Expected probability of every cell: the density `pdf` (per steradian, of a direction) integrated
/// over each cell of `grid` in `domain`, cell (i, j) at index i * res_v + j. `n` is the number of
/// samples the tolerance is tuned for. Returns the probabilities and the number of evaluations.
pub fn integrate_cells(
    domain: &dyn Domain,
    pdf: &(dyn Fn([f64; 3]) -> f64 + Sync),
    grid: &Grid,
    n: f64,
) -> (Vec<f64>, u64) {
    let cells: Vec<(f64, u64)> = (0..grid.res_u * grid.res_v)
        .into_par_iter()
        .map(|idx| {
            let f = Integrand { domain, pdf, evals: std::cell::Cell::new(0) };
            let (i, j) = (idx / grid.res_v, idx % grid.res_v);
            let c = [
                i as f64 / grid.res_u as f64,
                (i + 1) as f64 / grid.res_u as f64,
                j as f64 / grid.res_v as f64,
                (j + 1) as f64 / grid.res_v as f64,
            ];
            // Split at the known jumps of the density, then integrate every piece adaptively.
            let mut us = vec![c[0]];
            us.extend(grid.u_breaks.iter().copied().filter(|&b| b > c[0] && b < c[1]));
            us.push(c[1]);
            let whole = f.gl(c[0], c[1], c[2], c[3]);
            let tol = grid.tol_sigma * (whole.abs() * n).max(1.0).sqrt() / n / (us.len() - 1) as f64;
            let v = us
                .windows(2)
                .map(|w| {
                    let piece = [w[0], w[1], c[2], c[3]];
                    let g = f.gl(w[0], w[1], c[2], c[3]);
                    f.adapt(piece, g, tol, 0, grid.max_depth)
                })
                .sum();
            (v, f.evals.get())
        })
        .collect();
    let evals = cells.iter().map(|c| c.1).sum();
    (cells.into_iter().map(|c| c.0).collect(), evals)
}

/// The integral of `pdf` over the part of the unit square of `domain` where `mask(direction)`
/// holds (adaptive, as [`integrate_cells`] with `grid`'s cells and breaks, tuned for `n` samples;
/// the mask's edge is refined like any discontinuity unless it lies on a cell edge or a break).
pub fn integrate_masked(
    domain: &dyn Domain,
    pdf: &(dyn Fn([f64; 3]) -> f64 + Sync),
    mask: &(dyn Fn([f64; 3]) -> bool + Sync),
    grid: &Grid,
    n: f64,
) -> f64 {
    let masked = |w: [f64; 3]| if mask(w) { pdf(w) } else { 0.0 };
    integrate_cells(domain, &masked, grid, n).0.iter().sum()
}

/// Observed counts of `dirs` on `grid` in `domain`, the number of directions that are not finite,
/// and the number that have no point in the domain (e.g. wo = -wi exactly in [`HalfVectorDomain`]).
pub fn histogram(domain: &dyn Domain, dirs: &[[f32; 3]], grid: &Grid) -> (Vec<f64>, usize, usize) {
    let mut counts = vec![0.0; grid.res_u * grid.res_v];
    let mut invalid = 0;
    let mut outside = 0;
    for d in dirs {
        let w = [f64::from(d[0]), f64::from(d[1]), f64::from(d[2])];
        if !w.iter().all(|x| x.is_finite()) {
            invalid += 1;
            continue;
        }
        match domain.to_unit(w) {
            Some((u, v)) => {
                let i = ((u * grid.res_u as f64) as usize).min(grid.res_u - 1);
                let j = ((v * grid.res_v as f64) as usize).min(grid.res_v - 1);
                counts[i * grid.res_v + j] += 1.0;
            }
            None => outside += 1,
        }
    }
    (counts, invalid, outside)
}

/// The outcome of one chi-square test.
#[derive(Clone, Debug)]
pub struct Chi2Result {
    /// Pearson's statistic over the kept cells and the pool.
    pub stat: f64,
    /// Degrees of freedom (kept cells + pool - 1).
    pub dof: usize,
    /// P(chi2 >= stat) under the hypothesis that the samples follow the density.
    pub p_value: f64,
    /// Samples drawn.
    pub n: usize,
    /// Samples that were not finite.
    pub invalid: usize,
    /// Samples with no point in the domain (a measure-zero set of directions, reached by rounding).
    pub outside: usize,
    /// Samples in cells whose expected count came out exactly 0 (no quadrature point saw any
    /// density; such cells join the pool, where a real mismatch shows as a large term).
    pub in_zero_cells: f64,
    /// Cells pooled for having fewer than `min_expected` expected samples.
    pub pooled_cells: usize,
    /// The density's integral over the whole domain (sum of the cell probabilities).
    pub integral: f64,
    /// Density evaluations spent on the expected counts.
    pub evals: u64,
}

impl Chi2Result {
    /// Accept at significance `alpha` (already Bonferroni-corrected by the caller): p >= alpha, no
    /// non-finite samples, and at most 1e-5 of the samples outside the domain.
    pub fn passes(&self, alpha: f64) -> bool {
        self.p_value >= alpha && self.invalid == 0 && self.outside as f64 <= 1e-5 * self.n as f64
    }

    pub fn summary(&self) -> String {
        format!(
            "chi2 = {:.1}, dof = {}, p = {:.3e}, n = {}, invalid = {}, outside = {}, in zero cells = {}, pooled = {}, integral = {:.6}, evals = {}",
            self.stat, self.dof, self.p_value, self.n, self.invalid, self.outside, self.in_zero_cells, self.pooled_cells, self.integral, self.evals
        )
    }
}

/// Pearson's chi-square test of `observed` counts against cell probabilities `expected_p`
/// (scaled by the number of samples), pooling cells with fewer than `min_expected` expected
/// samples (zero included) into one cell, and that pool into the smallest kept cell if it is
/// still below `min_expected`.
pub fn pearson(observed: &[f64], expected_p: &[f64], n: usize, invalid: usize, outside: usize, min_expected: f64, evals: u64) -> Chi2Result {
    let nf = n as f64;
    let mut cells: Vec<(f64, f64)> = observed.iter().zip(expected_p).map(|(&o, &p)| (o, p * nf)).collect();
    let in_zero_cells: f64 = cells.iter().filter(|c| c.1 == 0.0).map(|c| c.0).sum();
    cells.sort_by(|a, b| a.1.partial_cmp(&b.1).unwrap());
    let (mut pool_o, mut pool_e, mut pooled) = (0.0, 0.0, 0);
    let mut kept: Vec<(f64, f64)> = Vec::new();
    for &(o, e) in &cells {
        if e < min_expected {
            pool_o += o;
            pool_e += e;
            pooled += 1;
        } else {
            kept.push((o, e));
        }
    }
    if pooled > 0 {
        if pool_e < min_expected && !kept.is_empty() {
            // Merge the pool into the smallest kept cell.
            kept[0].0 += pool_o;
            kept[0].1 += pool_e;
        } else {
            kept.push((pool_o, pool_e));
        }
    }
    let stat: f64 = kept.iter().map(|&(o, e)| (o - e) * (o - e) / e).sum();
    let dof = kept.len().saturating_sub(1);
    let p_value = if dof == 0 { 1.0 } else { gamma_q(dof as f64 / 2.0, stat / 2.0) };
    Chi2Result {
        stat,
        dof,
        p_value,
        n,
        invalid,
        outside,
        in_zero_cells,
        pooled_cells: pooled,
        integral: expected_p.iter().sum(),
        evals,
    }
}

/// Run the whole test: histogram `dirs`, integrate `pdf`, compare.
pub fn test(domain: &dyn Domain, dirs: &[[f32; 3]], pdf: &(dyn Fn([f64; 3]) -> f64 + Sync), grid: &Grid) -> Chi2Result {
    let (obs, invalid, outside) = histogram(domain, dirs, grid);
    let (exp, evals) = integrate_cells(domain, pdf, grid, dirs.len() as f64);
    pearson(&obs, &exp, dirs.len(), invalid, outside, grid.min_expected, evals)
}

/// ln Gamma(x) for x > 0 (Lanczos, g = 7, n = 9; relative error ~1e-15).
pub fn ln_gamma(x: f64) -> f64 {
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return (PI / (PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + 7.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularized upper incomplete gamma function Q(a, x) = Gamma(a, x) / Gamma(a): the series
/// for P when x < a + 1, Lentz's continued fraction otherwise (as in Numerical Recipes 6.2).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let ln_pre = a * x.ln() - x - ln_gamma(a);
    if x < a + 1.0 {
        let (mut sum, mut term, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..100_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (1.0 - sum * ln_pre.exp()).max(0.0)
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..100_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (ln_pre.exp() * h).clamp(0.0, 1.0)
    }
}

/// Column order of the `sample_*` table functions: wi, alpha_x, alpha_y, u1, u2.
pub fn sample_rows(wi: [f32; 3], alpha_x: f32, alpha_y: f32, n: usize, seed: u32) -> Vec<f32> {
    let mut rng = shader_core::rng::Pcg32::new(seed, 0x5eed);
    let mut rows = Vec::with_capacity(n * 7);
    for _ in 0..n {
        let u1 = rng.next_f32();
        let u2 = rng.next_f32();
        rows.extend_from_slice(&[wi[0], wi[1], wi[2], alpha_x, alpha_y, u1, u2]);
    }
    rows
}

/// Draw `n` samples of registered sampler `name` (`sample_ndf`, `sample_vndf_heitz`, ...) on
/// `backend` with PCG32 random numbers (stream `seed`); returns (wo, pdf) per sample.
pub fn draw(backend: &Backend, name: &str, wi: [f32; 3], alpha_x: f32, alpha_y: f32, n: usize, seed: u32) -> Vec<([f32; 3], f32)> {
    let f = crate::function(name);
    assert_eq!(f.inputs.len(), 7, "{name} is not a sampler");
    let rows = sample_rows(wi, alpha_x, alpha_y, n, seed);
    let (out, _) = backend.eval_table(f, &rows, n).expect("sampling");
    out.chunks_exact(4).map(|c| ([c[0], c[1], c[2]], c[3])).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gamma_q_matches_known_values() {
        // Q(1, x) = exp(-x); chi2 with 2 dof: P(X >= 2 * 3) = exp(-3).
        assert!((gamma_q(1.0, 3.0) - (-3.0f64).exp()).abs() < 1e-14);
        // Q(0.5, x) = erfc(sqrt(x)); erfc(1) = 0.157299207050285.
        assert!((gamma_q(0.5, 1.0) - 0.157_299_207_050_285_1).abs() < 1e-12);
        // Large dof: the median of chi2(1000) is about 999.33: Q(500, 499.67) ~ 0.5.
        let q = gamma_q(500.0, 999.333 / 2.0);
        assert!((q - 0.5).abs() < 2e-3, "{q}");
        assert!((ln_gamma(10.0) - 362_880f64.ln()).abs() < 1e-12);
    }

    #[test]
    fn domains_round_trip() {
        let d = HalfVectorDomain::new([0.6, 0.0, 0.8], 0.3, 0.05, Pole::StretchedWi);
        let e = HalfVectorDomain::new([0.6, 0.0, 0.8], 0.3, 0.05, Pole::Normal);
        for &(u, v) in &[(0.1, 0.2), (0.5, 0.9), (0.95, 0.5), (0.01, 0.01), (0.7, 0.02)] {
            for dom in [&d as &dyn Domain, &e, &SphereDomain] {
                if dom.from_unit(u, v).1 == 0.0 {
                    continue;
                }
                let (w, _) = dom.from_unit(u, v);
                let (u2, v2) = dom.to_unit(w).unwrap();
                assert!((u - u2).abs() < 1e-9 && (v - v2).abs() < 1e-9, "{u} {v} -> {u2} {v2}");
            }
        }
    }

    #[test]
    fn uniform_sphere_integrates_to_one() {
        let grid = Grid { res_u: 8, res_v: 8, ..Grid::default() };
        let (p, _) = integrate_cells(&SphereDomain, &|_| 1.0 / (4.0 * PI), &grid, 1e6);
        assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        for pole in [Pole::StretchedWi, Pole::Normal] {
            let d = HalfVectorDomain::new([0.0, 0.6, 0.8], 0.5, 0.2, pole);
            let (p, _) = integrate_cells(&d, &|_| 1.0 / (4.0 * PI), &grid, 1e6);
            assert!((p.iter().sum::<f64>() - 1.0).abs() < 1e-5, "{pole:?}: {}", p.iter().sum::<f64>());
        }
    }
}
