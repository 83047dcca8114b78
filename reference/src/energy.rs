//! Independent f64 quadrature reference for the energy tables (`shader_core::energy`): E(mu,
//! alpha), E'(mu, alpha) and E_avg(alpha) of GGX with height-correlated Smith G2 and F = 1.
//!
//! E = int f cos dwi is written over the half vector wm with the NDF-sampling measure D(wm) cos
//! theta_m dwm = du dphi / (2 pi), u = tan^2 / (alpha^2 + tan^2) (Walter et al. 2007 eq. 35):
//! E(mu) = (1 / pi) int_0^pi dphi int_0^{u_cut(phi)} G2(wo, wi) (wo.wm) / (mu cos theta_m) du,
//! with wi = reflect(wo, wm) and the exact horizon cut: wi.z = s sin 2theta cos phi + mu cos
//! 2theta > 0  <=>  theta < theta_cut = (pi/2 + atan2(s cos phi, mu)) / 2. Inside the cut the
//! integrand is smooth (G2 goes linearly to 0 at the cut), so composite Gauss-Legendre converges
//! fast; the u panels are graded geometrically toward the cut (where small alpha puts all the
//! structure in a sliver of u) and the phi panels are uniform. E' carries (1 - wo.wm)^5. E_avg =
//! 2 int E mu dmu by Gauss-Legendre over mu, graded toward mu = 0.
//!
//! Nothing here shares code with the kernels (no f32, no sampling); `tests/tests/energy_properties.rs`
//! checks its convergence by doubling the node counts.

use rayon::prelude::*;
use std::f64::consts::PI;

/// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n from the Chebyshev guesses).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let k = k as f64;
                let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            let p = if n == 0 { 1.0 } else { p1 };
            let pm1 = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (x * p - pm1) / (x * x - 1.0);
            let dx = p / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        out.push((x, 2.0 / ((1.0 - x * x) * dp * dp)));
    }
    out
}

/// Quadrature resolution: Gauss-Legendre order per panel, panels in phi, graded panels in u,
/// graded panels in mu (E_avg).
#[derive(Clone, Copy, Debug)]
pub struct Quadrature {
    pub order: usize,
    pub phi_panels: usize,
    pub u_panels: usize,
    pub mu_panels: usize,
}

impl Default for Quadrature {
    fn default() -> Self {
        Quadrature { order: 8, phi_panels: 16, u_panels: 30, mu_panels: 14 }
    }
}

impl Quadrature {
    /// Every node count doubled (the convergence check).
    pub fn doubled(self) -> Quadrature {
        Quadrature { order: self.order, phi_panels: 2 * self.phi_panels, u_panels: 2 * self.u_panels, mu_panels: 2 * self.mu_panels }
    }
}

/// Smith Lambda of GGX for a direction with cos theta = c (isotropic alpha): (sqrt(1 + a^2 tan^2) - 1) / 2.
fn lambda(c: f64, alpha: f64) -> f64 {
    let c2 = c * c;
    let a2t2 = alpha * alpha * (1.0 - c2) / c2;
    a2t2 / (2.0 * (1.0 + (1.0 + a2t2).sqrt()))
}

/// Panels [lo, hi] of (0, len] graded geometrically toward 0 by halving: the last `k` panels are
/// [len 2^-(k+1), len 2^-k], plus [0, len 2^-count].
fn graded_panels(len: f64, count: usize) -> Vec<(f64, f64)> {
    let mut v = Vec::with_capacity(count + 1);
    let mut hi = len;
    for _ in 0..count {
        let lo = hi * 0.5;
        v.push((lo, hi));
        hi = lo;
    }
    v.push((0.0, hi));
    v
}

/// (E, E') at cos theta_o = mu, GGX roughness alpha (> 0), F = 1, height-correlated G2.
pub fn albedo(mu: f64, alpha: f64, q: &Quadrature) -> (f64, f64) {
    let gl = gauss_legendre(q.order);
    let s = (1.0 - mu * mu).max(0.0).sqrt();
    let lambda_o = lambda(mu, alpha);
    let (mut e, mut ep) = (0.0, 0.0);
    let dphi = PI / q.phi_panels as f64;
    for pp in 0..q.phi_panels {
        for &(xp, wp) in &gl {
            let phi = dphi * (pp as f64 + 0.5 + 0.5 * xp);
            let wphi = wp * 0.5 * dphi;
            let (sp, cp) = phi.sin_cos();
            let theta_cut = 0.5 * (0.5 * PI + (s * cp).atan2(mu));
            let t_cut = theta_cut.tan() / alpha; // tan(theta_cut) / alpha
            // u = t^2 / (1 + t^2); v = 1 - u; distance d = u_cut - u = v - v_cut.
            let v_cut = 1.0 / (1.0 + t_cut * t_cut);
            let u_cut = t_cut * t_cut / (1.0 + t_cut * t_cut);
            let (mut ie, mut iep) = (0.0, 0.0);
            for (lo, hi) in graded_panels(u_cut, q.u_panels) {
                for &(xu, wu) in &gl {
                    let d = lo + (hi - lo) * 0.5 * (1.0 + xu);
                    let w = wu * 0.5 * (hi - lo);
                    let v = v_cut + d;
                    let u = u_cut - d;
                    // tan theta_m = alpha sqrt(u / v); cos, sin from it.
                    let tan_m = alpha * (u / v).sqrt();
                    let cos_m = 1.0 / (1.0 + tan_m * tan_m).sqrt();
                    let sin_m = tan_m * cos_m;
                    let wm = [sin_m * cp, sin_m * sp, cos_m];
                    let vh = s * wm[0] + mu * wm[2];
                    let wi_z = 2.0 * vh * wm[2] - mu;
                    if wi_z <= 0.0 || vh <= 0.0 {
                        continue;
                    }
                    let g2 = 1.0 / (1.0 + lambda_o + lambda(wi_z, alpha));
                    let g = g2 * vh / (mu * cos_m);
                    ie += w * g;
                    iep += w * g * (1.0 - vh).powi(5);
                }
            }
            e += wphi * ie;
            ep += wphi * iep;
        }
    }
    (e / PI, ep / PI)
}

/// E_avg(alpha) = 2 int_0^1 E(mu) mu dmu.
pub fn albedo_avg(alpha: f64, q: &Quadrature) -> f64 {
    let gl = gauss_legendre(q.order);
    let mut sum = 0.0;
    for (lo, hi) in graded_panels(1.0, q.mu_panels) {
        for &(x, w) in &gl {
            let mu = lo + (hi - lo) * 0.5 * (1.0 + x);
            sum += w * 0.5 * (hi - lo) * 2.0 * mu * albedo(mu, alpha, q).0;
        }
    }
    sum
}

/// Reference tables on the kernels' grid (cell centers, mu clamped to >= 1e-4, alpha = r^2):
/// (E, E') roughness-major (n_mu x n_r) and E_avg (n_avg), in parallel over cells.
pub fn tables(n_mu: usize, n_r: usize, n_avg: usize, q: &Quadrature) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let cells: Vec<(f64, f64)> = (0..n_mu * n_r)
        .into_par_iter()
        .map(|c| {
            let (i, j) = (c % n_mu, c / n_mu);
            let mu = ((i as f64 + 0.5) / n_mu as f64).max(1e-4);
            let r = (j as f64 + 0.5) / n_r as f64;
            albedo(mu, r * r, q)
        })
        .collect();
    let avg: Vec<f64> = (0..n_avg)
        .into_par_iter()
        .map(|j| {
            let r = (j as f64 + 0.5) / n_avg as f64;
            albedo_avg(r * r, q)
        })
        .collect();
    (cells.iter().map(|c| c.0).collect(), cells.iter().map(|c| c.1).collect(), avg)
}
