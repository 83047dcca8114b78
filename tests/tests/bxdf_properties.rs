//! Properties of `shader_core::fresnel` and `shader_core::bxdf`, checked against f64 closed forms and
//! f64 numerical integration (CPU only; the CPU-vs-GPU comparison is `bxdf_crosscheck.rs`).
//!
//! Run with `cargo test --release -p crosscheck --test bxdf_properties -- --nocapture` to see the
//! tables (white furnace, weak white furnace, Monte Carlo vs quadrature). docs/bxdf.md quotes them.
//!
//! Reference integration: albedo E(wo) = integral of f(wo, wi) |cos theta_i| dwi is computed in the
//! half-vector domain. wm runs over a midpoint grid in (u, v) mapped through the inverse CDF of the
//! isotropic GGX density D(wm) cos(theta_m) (tan^2 theta_m = alpha^2 u / (1 - u), phi = 2 pi v; in
//! f64), which adapts the grid to any roughness, and wi = reflect(wo, wm) (Jacobian 4 |wo.wm|) or
//! wi = refract(wo, wm) (Jacobian (wi.wm + wo.wm / eta')^2 / |wi.wm|). f itself is the f32 BxDF.
//! This grid is independent of the visible-normal sampler the BxDFs use, so Monte Carlo estimates
//! through `sample_f` are an independent second estimate.

use shader_core::bxdf::{
    self, BxDF, ConductorBxDF, DielectricBxDF, DiffuseBxDF, GltfMetalRoughBxDF, SpecularReflectionBxDF, TrowbridgeReitz,
    MODE_IMPORTANCE, MODE_RADIANCE, SAMPLE_ALL,
};
use shader_core::fresnel;
use shader_core::rng::Pcg32;
use shader_core::Vec3;
use std::f64::consts::PI;

// ------------------------------------------------------------------------------------------------
// f64 helpers
// ------------------------------------------------------------------------------------------------

type V = [f64; 3];

fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn scale(a: V, s: f64) -> V {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn add(a: V, b: V) -> V {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn norm(a: V) -> V {
    scale(a, 1.0 / dot(a, a).sqrt())
}
fn to32(a: V) -> Vec3 {
    Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32)
}
fn to64(a: Vec3) -> V {
    [a.x as f64, a.y as f64, a.z as f64]
}
/// Unit direction at polar angle theta (degrees from +z) and azimuth phi (degrees).
fn dir64(theta_deg: f64, phi_deg: f64) -> V {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    [t.sin() * p.cos(), t.sin() * p.sin(), t.cos()]
}
fn dir(theta_deg: f64, phi_deg: f64) -> Vec3 {
    to32(dir64(theta_deg, phi_deg))
}

/// Exact unpolarized dielectric Fresnel reflectance (f64; eta relative, cos < 0 = inside).
fn fr_dielectric64(cos_i: f64, eta: f64) -> f64 {
    let (mut c, mut e) = (cos_i.clamp(-1.0, 1.0), eta);
    if c < 0.0 {
        e = 1.0 / e;
        c = -c;
    }
    let s2t = (1.0 - c * c) / (e * e);
    if s2t >= 1.0 {
        return 1.0;
    }
    let ct = (1.0 - s2t).sqrt();
    let rs = (c - e * ct) / (c + e * ct);
    let rp = (e * c - ct) / (e * c + ct);
    (rs * rs + rp * rp) / 2.0
}

#[derive(Clone, Copy, Debug)]
struct C64 {
    re: f64,
    im: f64,
}
impl C64 {
    fn mul(self, o: C64) -> C64 {
        C64 { re: self.re * o.re - self.im * o.im, im: self.re * o.im + self.im * o.re }
    }
    fn div(self, o: C64) -> C64 {
        let d = o.re * o.re + o.im * o.im;
        C64 { re: (self.re * o.re + self.im * o.im) / d, im: (self.im * o.re - self.re * o.im) / d }
    }
    fn sub(self, o: C64) -> C64 {
        C64 { re: self.re - o.re, im: self.im - o.im }
    }
    fn add(self, o: C64) -> C64 {
        C64 { re: self.re + o.re, im: self.im + o.im }
    }
    fn sqrt(self) -> C64 {
        let r = self.re.hypot(self.im);
        let re = ((r + self.re) / 2.0).sqrt();
        let im = ((r - self.re) / 2.0).sqrt().copysign(self.im);
        C64 { re, im }
    }
    fn norm(self) -> f64 {
        self.re * self.re + self.im * self.im
    }
}

/// Exact conductor Fresnel reflectance (f64 complex arithmetic, the textbook formula).
fn fr_conductor64(cos_i: f64, eta: f64, k: f64) -> f64 {
    let c = cos_i.clamp(0.0, 1.0);
    let e = C64 { re: eta, im: k };
    let s2 = C64 { re: 1.0 - c * c, im: 0.0 };
    let ct = C64 { re: 1.0, im: 0.0 }.sub(s2.div(e.mul(e))).sqrt();
    let cc = C64 { re: c, im: 0.0 };
    let rp = e.mul(cc).sub(ct).div(e.mul(cc).add(ct));
    let rs = cc.sub(e.mul(ct)).div(cc.add(e.mul(ct)));
    (rp.norm() + rs.norm()) / 2.0
}

/// Isotropic GGX D in f64.
fn ggx_d64(wm: V, a: f64) -> f64 {
    if wm[2] <= 0.0 {
        return 0.0;
    }
    let c2 = wm[2] * wm[2];
    let t2 = (1.0 - c2) / c2;
    let e = 1.0 + t2 / (a * a);
    1.0 / (PI * a * a * c2 * c2 * e * e)
}

/// The grid point (i, j) of the reference quadrature: (wm, density of wm per unit grid area).
/// u = 1 - (1 - s)^4 with s on the midpoint grid concentrates points in the heavy GGX tail
/// (tan theta_m -> inf as u -> 1), so integrands growing like tan theta_m stay bounded in s.
fn grid_wm(i: usize, j: usize, nu: usize, nv: usize, a: f64) -> (V, f64) {
    let s = (i as f64 + 0.5) / nu as f64;
    let v = (j as f64 + 0.5) / nv as f64;
    let om = (1.0 - s).powi(4); // 1 - u
    let u = 1.0 - om;
    let du_ds = 4.0 * (1.0 - s).powi(3);
    let t2 = a * a * u / om;
    let c = 1.0 / (1.0 + t2).sqrt();
    let sn = (t2 / (1.0 + t2)).sqrt();
    let p = 2.0 * PI * v;
    let wm = [sn * p.cos(), sn * p.sin(), c];
    (wm, ggx_d64(wm, a) * c / du_ds)
}

/// f64 Snell refraction (PBRT-v4 convention): wi about n (n on wi's side or flipped), eta relative.
fn refract64(wi: V, n: V, eta: f64) -> Option<(V, f64)> {
    let (mut n, mut eta, mut ci) = (n, eta, dot(n, wi));
    if ci < 0.0 {
        eta = 1.0 / eta;
        ci = -ci;
        n = scale(n, -1.0);
    }
    let s2t = (1.0 - ci * ci).max(0.0) / (eta * eta);
    if s2t >= 1.0 {
        return None;
    }
    let ct = (1.0 - s2t).sqrt();
    Some((add(scale(wi, -1.0 / eta), scale(n, ci / eta - ct)), eta))
}

/// Per-channel albedo integrals over a wm grid: (reflection, transmission) of channel `ch`.
struct Albedo {
    r: [f64; 3],
    t: [f64; 3],
}

/// Reference albedo of a microfacet BxDF (f evaluated in f32), reflection and (if `eta` is Some)
/// transmission, for wo above the surface.
fn albedo_grid(f: &dyn Fn(Vec3, Vec3) -> Vec3, wo: V, alpha: f64, eta: Option<f64>, nu: usize, nv: usize) -> Albedo {
    let mut r = [0.0f64; 3];
    let mut t = [0.0f64; 3];
    let wo32 = to32(wo);
    for i in 0..nu {
        for j in 0..nv {
            let (wm, pm) = grid_wm(i, j, nu, nv, alpha);
            let d = dot(wo, wm);
            if d <= 0.0 || pm <= 0.0 {
                continue;
            }
            let wi = add(scale(wm, 2.0 * d), scale(wo, -1.0));
            if wi[2] > 0.0 {
                let fv = f(wo32, to32(wi));
                let w = wi[2] * 4.0 * d / pm;
                r[0] += fv.x as f64 * w;
                r[1] += fv.y as f64 * w;
                r[2] += fv.z as f64 * w;
            }
            if let Some(e) = eta {
                if let Some((wt, etap)) = refract64(wo, wm, e) {
                    if wt[2] < 0.0 {
                        let s = dot(wt, wm) + d / etap;
                        let jac = s * s / dot(wt, wm).abs();
                        let fv = f(wo32, to32(wt));
                        let w = -wt[2] * jac / pm;
                        t[0] += fv.x as f64 * w;
                        t[1] += fv.y as f64 * w;
                        t[2] += fv.z as f64 * w;
                    }
                }
            }
        }
    }
    let n = (nu * nv) as f64;
    Albedo { r: r.map(|x| x / n), t: t.map(|x| x / n) }
}

/// Isotropic GGX Smith Lambda in f64.
fn lambda64(w: V, a: f64) -> f64 {
    let t2 = (w[0] * w[0] + w[1] * w[1]) / (w[2] * w[2]);
    ((1.0 + a * a * t2).sqrt() - 1.0) / 2.0
}

/// Albedo of the f64 Torrance-Sparrow conductor model (isotropic GGX, height-correlated Smith,
/// exact complex Fresnel per channel), integrated on the same wm grid with the exact grid wm
/// (no f32 round trip of wi): the well-conditioned reference.
fn albedo_conductor_model(wo: V, a: f64, eta: [f64; 3], k: [f64; 3], nu: usize, nv: usize) -> [f64; 3] {
    let mut r = [0.0f64; 3];
    for i in 0..nu {
        for j in 0..nv {
            let (wm, pm) = grid_wm(i, j, nu, nv, a);
            let d = dot(wo, wm);
            if d <= 0.0 || pm <= 0.0 {
                continue;
            }
            let wi = add(scale(wm, 2.0 * d), scale(wo, -1.0));
            if wi[2] <= 0.0 {
                continue;
            }
            // f |cos_i| 4 d / pm = D G2 F / (4 cos_i cos_o) cos_i 4 d / (D cos_m / du_ds)
            let g2 = 1.0 / (1.0 + lambda64(wo, a) + lambda64(wi, a));
            let w = ggx_d64(wm, a) * g2 * d / (wo[2] * pm);
            for c in 0..3 {
                r[c] += fr_conductor64(d, eta[c], k[c]) * w;
            }
        }
    }
    r.map(|x| x / (nu * nv) as f64)
}

/// Monte Carlo albedo through `sample_f`: (mean, standard error) per channel of f |cos| / pdf.
fn albedo_mc(b: &dyn BxDF, wo: Vec3, mode: u32, n: usize, seed: u32) -> ([f64; 3], [f64; 3]) {
    let mut rng = Pcg32::new(seed, 7);
    let mut s = [0.0f64; 3];
    let mut s2 = [0.0f64; 3];
    for _ in 0..n {
        let (uc, u0, u1) = (rng.next_f32(), rng.next_f32(), rng.next_f32());
        let smp = b.sample_f(wo, uc, u0, u1, mode, SAMPLE_ALL);
        if !smp.is_valid() {
            continue;
        }
        let w = smp.wi.z.abs() as f64 / smp.pdf as f64;
        let v = [smp.f.x as f64 * w, smp.f.y as f64 * w, smp.f.z as f64 * w];
        for c in 0..3 {
            assert!(v[c].is_finite(), "f/pdf not finite: {smp:?} wo {wo:?}");
            s[c] += v[c];
            s2[c] += v[c] * v[c];
        }
    }
    let nf = n as f64;
    let mean = s.map(|x| x / nf);
    let mut se = [0.0; 3];
    for c in 0..3 {
        se[c] = ((s2[c] / nf - mean[c] * mean[c]).max(0.0) / nf).sqrt();
    }
    (mean, se)
}

fn rel(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        (a - b).abs() / a.abs().max(b.abs())
    }
}

// ------------------------------------------------------------------------------------------------
// Fresnel
// ------------------------------------------------------------------------------------------------

#[test]
fn dielectric_fresnel_matches_closed_form_and_known_values() {
    // Glass at normal incidence: ((1.5 - 1) / (1.5 + 1))^2 = 0.04, from either side.
    assert!((fresnel::dielectric(1.0, 1.5) - 0.04).abs() < 1e-7);
    assert!((fresnel::dielectric(-1.0, 1.5) - 0.04).abs() < 1e-7);
    // Water 1.333: 0.02037.
    assert!((fresnel::dielectric(1.0, 1.333) as f64 - (0.333f64 / 2.333).powi(2)).abs() < 1e-7);
    // Index-matched: no reflection; grazing: total reflection.
    for c in [1e-6f32, 0.1, 0.5, 1.0, -0.5] {
        assert_eq!(fresnel::dielectric(c, 1.0), 0.0, "eta = 1, cos {c}");
    }
    assert_eq!(fresnel::dielectric(0.0, 1.5), 1.0);
    // Brewster angle (tan theta = eta): the parallel polarization vanishes, F = r_perp^2 / 2.
    let tb = 1.5f64.atan();
    let fb = fresnel::dielectric(tb.cos() as f32, 1.5) as f64;
    assert!((fb - fr_dielectric64(tb.cos(), 1.5)).abs() < 1e-6, "Brewster {fb}");
    // Total internal reflection inside glass beyond the critical angle asin(1 / 1.5) = 41.81 deg.
    let crit = (1.0f64 / 1.5).asin().to_degrees();
    for th in [crit + 1e-3, crit + 0.1, 45.0, 60.0, 89.0, 89.99] {
        assert_eq!(fresnel::dielectric(-(th.to_radians().cos() as f32), 1.5), 1.0, "TIR at {th} deg");
    }
    for th in [0.0, 20.0, 40.0, crit - 0.01] {
        assert!(fresnel::dielectric(-(th.to_radians().cos() as f32), 1.5) < 1.0, "no TIR at {th} deg");
    }
    // The same interface seen from both sides reflects the same fraction (Stokes relations):
    // F(cos_i, eta) = F(-cos_t, eta) with sin_t = sin_i / eta.
    // Near grazing outside (cos_i -> 0) the inside direction is near the critical angle where
    // dF/dcos_t is unbounded, so the f32 rounding of cos_t is amplified: checked separately.
    let (mut max_sym, mut max_sym_grazing) = (0.0f64, 0.0f64);
    for i in 0..=10000 {
        let ci = i as f64 / 10000.0;
        let st = (1.0 - ci * ci).sqrt() / 1.5;
        let ct = (1.0 - st * st).sqrt();
        let a = fresnel::dielectric(ci as f32, 1.5) as f64;
        let b = fresnel::dielectric(-ct as f32, 1.5) as f64;
        if ci >= 0.05 {
            max_sym = max_sym.max((a - b).abs());
        } else {
            max_sym_grazing = max_sym_grazing.max((a - b).abs());
        }
    }
    eprintln!("F(cos_i, 1.5) vs F(-cos_t, 1.5): max abs difference {max_sym:.2e} (cos_i >= 0.05), {max_sym_grazing:.2e} (cos_i < 0.05, near the inside critical angle)");
    assert!(max_sym < 2e-5, "two-sided symmetry {max_sym}");
    assert!(max_sym_grazing < 1e-2, "two-sided symmetry near grazing {max_sym_grazing}");
    // Against the f64 closed form over cos in [-1, 1] and eta in [1/3, 3].
    // The error allowed at each point is 1e-6 plus the change of the exact F under a relative
    // perturbation of 4 ulp of either input (F has an unbounded derivative at the critical angle,
    // so there any f32 evaluation is only backward-accurate).
    let mut max_err = 0.0f64;
    let mut max_ratio = 0.0f64;
    let mut worst = (0.0, 0.0);
    for ie in 0..=200 {
        let eta = 1.0 / 3.0 * (9.0f64).powf(ie as f64 / 200.0);
        for ic in 0..=2000 {
            let c = -1.0 + 2.0 * ic as f64 / 2000.0;
            let (c32, e32) = (c as f32, eta as f32);
            let got = fresnel::dielectric(c32, e32) as f64;
            let (cd, ed) = (c32 as f64, e32 as f64);
            let want = fr_dielectric64(cd, ed);
            let err = (got - want).abs();
            let h = 4.0 * f32::EPSILON as f64;
            let mut cond = 0.0f64;
            for (dc, de) in [(h, 0.0), (-h, 0.0), (0.0, h), (0.0, -h)] {
                cond = cond.max((fr_dielectric64(cd * (1.0 + dc), ed * (1.0 + de)) - want).abs());
            }
            max_err = max_err.max(err);
            let ratio = err / (1e-6 + cond);
            if ratio > max_ratio {
                max_ratio = ratio;
                worst = (c, eta);
            }
        }
    }
    eprintln!("fresnel::dielectric vs f64 closed form (402,201 points): max abs error {max_err:.3e}; max error / (1e-6 + 4-ulp input sensitivity) = {max_ratio:.3} at cos {:.4}, eta {:.4}", worst.0, worst.1);
    assert!(max_ratio <= 1.0, "dielectric Fresnel error beyond rounding at {worst:?}");
}

#[test]
fn conductor_fresnel_matches_closed_form_and_dielectric_at_k_zero() {
    // k = 0: the conductor formula is the dielectric one (cos >= 0), TIR (eta < 1) included.
    let mut max_diff = 0.0f64;
    for &eta in &[0.2f32, 0.5, 0.9, 0.999, 1.001, 1.1, 1.33, 1.5, 2.4, 4.0] {
        for ic in 0..=2000 {
            let c = ic as f32 / 2000.0;
            let a = fresnel::conductor(c, eta, 0.0) as f64;
            let b = fresnel::dielectric(c, eta) as f64;
            max_diff = max_diff.max((a - b).abs());
        }
    }
    eprintln!("conductor(k = 0) vs dielectric: max abs difference {max_diff:.3e}");
    assert!(max_diff < 1e-5, "k = 0 conductor differs from dielectric by {max_diff:e}");
    // Normal incidence: F0 = ((n - 1)^2 + k^2) / ((n + 1)^2 + k^2) (gold and aluminium, Rakic, RGB).
    let gold = ([0.18836f32, 0.54836, 1.3319], [3.4034f32, 2.2309, 1.8693]);
    let alu = ([1.4303f32, 0.93878, 0.68603], [7.5081f32, 6.4195, 5.6351]);
    for (n, k) in [gold, alu] {
        for c in 0..3 {
            let (n, k) = (n[c] as f64, k[c] as f64);
            let f0 = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
            let got = fresnel::conductor(1.0, n as f32, k as f32) as f64;
            assert!(rel(got, f0) < 1e-6, "F0 {got} vs {f0} for n {n} k {k}");
        }
    }
    // Grazing incidence reflects everything; a perfect conductor (n = 0) reflects everything.
    assert_eq!(fresnel::conductor(0.0, 0.18836, 3.4034), 1.0);
    assert_eq!(fresnel::conductor(-0.5, 0.18836, 3.4034), 1.0);
    for ic in 0..=100 {
        let c = ic as f32 / 100.0;
        assert!((fresnel::conductor(c, 0.0, 1.0) - 1.0).abs() < 4e-7);
    }
    // Against f64 complex arithmetic over cos x n x k.
    let mut max_err = 0.0f64;
    let mut worst = (0.0, 0.0, 0.0);
    for &n in &[0.05f32, 0.18836, 0.5, 1.0, 1.4303, 2.0, 3.0, 10.0] {
        for &k in &[0.0f32, 1e-3, 0.1, 1.0, 1.8693, 3.4034, 7.5081, 20.0, 100.0] {
            for ic in 0..=1000 {
                let c = ic as f32 / 1000.0;
                let got = fresnel::conductor(c, n, k) as f64;
                let want = fr_conductor64(c as f64, n as f64, k as f64);
                let err = (got - want).abs();
                if err > max_err {
                    max_err = err;
                    worst = (c, n, k);
                }
            }
        }
    }
    eprintln!("fresnel::conductor vs f64 complex closed form: max abs error {max_err:.3e} at (cos, n, k) = {worst:?}");
    assert!(max_err < 1e-5, "conductor Fresnel error {max_err:e} at {worst:?}");
}

#[test]
fn schlick_endpoints_and_shape() {
    assert_eq!(fresnel::schlick(1.0, 0.04, 1.0), 0.04);
    assert_eq!(fresnel::schlick(0.0, 0.04, 1.0), 1.0);
    assert_eq!(fresnel::schlick(-1.0, 0.04, 1.0), 0.04);
    assert_eq!(fresnel::schlick(2.0, 0.04, 1.0), 0.04);
    assert_eq!(fresnel::schlick(0.5, 0.0, 1.0), 1.0 / 32.0);
    let v = fresnel::schlick_rgb(0.5, Vec3::new(0.0, 0.5, 1.0), Vec3::new(1.0, 1.0, 0.0));
    assert_eq!(v, Vec3::new(1.0 / 32.0, 0.5 + 0.5 / 32.0, 1.0 - 1.0 / 32.0));
    // Schlick vs exact glass: the approximation is within 0.036 everywhere (documented figure).
    let mut max_d = 0.0f64;
    for ic in 0..=1000 {
        let c = ic as f32 / 1000.0;
        let d = (fresnel::schlick(c, fresnel::f0_from_eta(1.5), 1.0) - fresnel::dielectric(c, 1.5)).abs() as f64;
        max_d = max_d.max(d);
    }
    eprintln!("Schlick(F0 = 0.04) vs exact dielectric (eta 1.5): max abs difference {max_d:.4}");
    assert!(max_d < 0.04);
}

#[test]
fn gulbrandsen_round_trip() {
    let mut max_f0 = 0.0f64;
    let mut max_r = 0.0f64;
    let mut max_g = 0.0f64;
    let mut worst_g = (0.0, 0.0);
    for ir in 0..=99 {
        let r = ir as f32 / 100.0;
        for ig in 0..=100 {
            let g = ig as f32 / 100.0;
            let nk = fresnel::gulbrandsen_nk(r, g);
            assert!(nk.re.is_finite() && nk.im.is_finite() && nk.re > 0.0 && nk.im >= 0.0, "{r} {g} -> {nk:?}");
            // F(0) of the resulting conductor is the requested reflectivity.
            let f0 = fresnel::conductor(1.0, nk.re, nk.im) as f64;
            max_f0 = max_f0.max((f0 - r as f64).abs());
            let back = fresnel::gulbrandsen_r_g(nk.re, nk.im);
            max_r = max_r.max((back.r as f64 - r as f64).abs());
            // g is ill-conditioned where n_max - n_min -> 0 (r -> 0): only compare for r >= 0.05.
            if r >= 0.05 {
                let e = (back.g as f64 - g as f64).abs();
                if e > max_g {
                    max_g = e;
                    worst_g = (r, g);
                }
            }
        }
    }
    eprintln!("Gulbrandsen (r, g) -> (n, k): max |F0 - r| {max_f0:.2e}; (n, k) -> (r, g): max |r' - r| {max_r:.2e}, max |g' - g| {max_g:.2e} (r >= 0.05) at {worst_g:?}");
    assert!(max_f0 < 2e-6, "F0 round trip {max_f0:e}");
    assert!(max_r < 2e-6, "r round trip {max_r:e}");
    assert!(max_g < 1e-4, "g round trip {max_g:e} at {worst_g:?}");
    // g = 0: n = n_max and k = 0 (a dielectric with F0 = r); g = 1: n = n_min = (1 - r) / (1 + r).
    let nk = fresnel::gulbrandsen_nk(0.5, 0.0);
    assert!(nk.im.abs() < 1e-3, "g = 0 gives k = 0: {nk:?}");
    let sr = 0.5f64.sqrt();
    assert!(rel(nk.re as f64, (1.0 + sr) / (1.0 - sr)) < 1e-6);
    let nk = fresnel::gulbrandsen_nk(0.5, 1.0);
    assert!(rel(nk.re as f64, 0.5 / 1.5) < 1e-6);
    // Clamping: r > 0.99 behaves as 0.99, g outside [0, 1] as the nearest end.
    assert_eq!(fresnel::gulbrandsen_nk(1.0, 0.3), fresnel::gulbrandsen_nk(0.99, 0.3));
    assert_eq!(fresnel::gulbrandsen_nk(0.7, 2.0), fresnel::gulbrandsen_nk(0.7, 1.0));
    assert_eq!(fresnel::gulbrandsen_nk(0.7, -1.0), fresnel::gulbrandsen_nk(0.7, 0.0));
}

#[test]
fn refract_follows_snell() {
    let mut max_snell = 0.0f64;
    let mut max_len = 0.0f64;
    let mut max_rt = 0.0f64;
    let mut max_rt_grazing = 0.0f64;
    let mut tir = 0;
    for &eta in &[1.0f32, 1.0 + 1e-6, 1.33, 1.5, 2.4, 1.0 / 1.5] {
        for it in 0..=180 {
            for ip in 0..8 {
                let th = it as f64 * 1.0 - if it == 180 { 1e-4 } else { 0.0 };
                let wi = dir(th, ip as f64 * 45.0 + 10.0);
                let r = fresnel::refract(wi, Vec3::Z, eta);
                let inside = wi.z < 0.0;
                let etap = if inside { 1.0 / eta as f64 } else { eta as f64 };
                assert!((r.etap as f64 - etap).abs() < 1e-6 * etap);
                let sin_i = (wi.x as f64).hypot(wi.y as f64);
                if etap < 1.0 && sin_i / etap > 1.0 + 1e-6 {
                    assert_eq!(r.valid, 0, "TIR expected, wi {wi:?} eta {eta}");
                    tir += 1;
                    continue;
                }
                if r.valid == 0 {
                    // Only within rounding of the critical angle, and never when eta' >= 1.
                    assert!(etap < 1.0 && (sin_i / etap - 1.0).abs() < 1e-6, "unexpected TIR {wi:?} eta {eta}");
                    continue;
                }
                let wt = to64(r.wt);
                max_len = max_len.max((dot(wt, wt).sqrt() - 1.0).abs());
                // Snell: sin_t * eta' = sin_i, opposite side, same plane (azimuth opposite).
                let sin_t = wt[0].hypot(wt[1]);
                max_snell = max_snell.max((sin_t * etap - sin_i).abs());
                assert!(wt[2] * wi.z as f64 <= 0.0, "same side: {wi:?} -> {wt:?}");
                assert!(wt[0] * wi.x as f64 + wt[1] * wi.y as f64 <= 1e-7);
                // Reversibility: refracting back gives wi.
                let back = fresnel::refract(r.wt, Vec3::Z, eta);
                if back.valid == 0 {
                    // wt leaves at (rounding from) the critical angle on the way back.
                    assert!((sin_t * etap - 1.0).abs() < 1e-6, "no way back for {wi:?} eta {eta}");
                    continue;
                }
                let d = add(to64(back.wt), scale(to64(wi), -1.0));
                // A (nearly) grazing wi refracts to the critical angle, where the way back has
                // cos_t = sqrt(rounding) ~ sqrt(eps): only backward-accurate there.
                if (wi.z as f64).abs() > 1e-2 {
                    max_rt = max_rt.max(dot(d, d).sqrt());
                } else {
                    max_rt_grazing = max_rt_grazing.max(dot(d, d).sqrt());
                }
            }
        }
    }
    eprintln!("refract: max |sin_t eta' - sin_i| {max_snell:.2e}, max ||wt| - 1| {max_len:.2e}, max |refract(refract(wi)) - wi| {max_rt:.2e} (|wi.z| > 0.01), {max_rt_grazing:.2e} (|wi.z| <= 0.01), {tir} TIR cases");
    assert!(max_snell < 1e-6 && max_len < 1e-6 && max_rt < 1e-5);
    assert!(max_rt_grazing < 2e-3);
    assert!(tir > 0);
    // reflect is the PBRT one: both directions point away from the surface.
    let wo = dir(30.0, 20.0);
    let wr = fresnel::reflect(wo, Vec3::Z);
    assert_eq!(wr, Vec3::new(-wo.x, -wo.y, wo.z));
}

// ------------------------------------------------------------------------------------------------
// BxDFs: reciprocity
// ------------------------------------------------------------------------------------------------

fn random_dir(rng: &mut Pcg32) -> Vec3 {
    let z = 2.0 * rng.next_f32() as f64 - 1.0;
    let p = 2.0 * PI * rng.next_f32() as f64;
    let s = (1.0 - z * z).max(0.0).sqrt();
    to32([s * p.cos(), s * p.sin(), z])
}

fn gold() -> (Vec3, Vec3) {
    (Vec3::new(0.18836, 0.54836, 1.3319), Vec3::new(3.4034, 2.2309, 1.8693))
}

#[test]
fn reflection_bxdfs_are_reciprocal() {
    let (eta, k) = gold();
    let mut rng = Pcg32::new(1, 2);
    let mut report = Vec::new();
    let alphas = [(1e-3f32, 1e-3f32), (0.01, 0.01), (0.1, 0.1), (0.5, 0.5), (1.0, 1.0), (0.05, 0.4), (0.8, 0.1), (2.0, 2.0)];
    let mut worst_all = 0.0f64;
    for &(ax, ay) in &alphas {
        let cond = ConductorBxDF::new(TrowbridgeReitz::new(ax, ay), eta, k);
        let gl = GltfMetalRoughBxDF::new(Vec3::new(0.8, 0.5, 0.2), 0.5, ax.sqrt());
        let mut worst = [0.0f64; 2];
        let mut nonzero = 0usize;
        for _ in 0..50_000 {
            let wo = random_dir(&mut rng);
            let mut wi = random_dir(&mut rng);
            if wi.z * wo.z < 0.0 {
                wi.z = -wi.z;
            }
            for (bi, b) in [&cond as &dyn BxDF, &gl as &dyn BxDF].into_iter().enumerate() {
                let w = &mut worst[bi];
                let a = b.f(wo, wi, MODE_RADIANCE);
                let c = b.f(wi, wo, MODE_RADIANCE);
                for (x, y) in [(a.x, c.x), (a.y, c.y), (a.z, c.z)] {
                    // Relative difference, ignoring values below 1e-30 (underflow territory).
                    if x.abs() > 1e-30 || y.abs() > 1e-30 {
                        nonzero += 1;
                        *w = w.max(rel(x as f64, y as f64));
                    } else {
                        assert_eq!(x, y);
                    }
                }
            }
        }
        worst_all = worst_all.max(worst[0]).max(worst[1]);
        report.push(format!("  alpha ({ax}, {ay}): max rel |f(wo,wi) - f(wi,wo)| conductor {:.2e}, glTF {:.2e} ({nonzero} nonzero values)", worst[0], worst[1]));
    }
    // Lambert is exactly symmetric.
    let lam = DiffuseBxDF::new(Vec3::new(0.3, 0.6, 0.9));
    for _ in 0..10_000 {
        let (wo, wi) = (random_dir(&mut rng), random_dir(&mut rng));
        assert_eq!(lam.f(wo, wi, MODE_RADIANCE), lam.f(wi, wo, MODE_RADIANCE));
    }
    eprintln!("reciprocity f(wo, wi) = f(wi, wo), 50,000 random pairs per roughness:\n{}", report.join("\n"));
    // f32 rounding: F is evaluated at |wo.wm| one way and |wi.wm| the other (equal in exact
    // arithmetic), plus ~30 roundings in D, G and the normalizations.
    assert!(worst_all < 1e-4, "reciprocity violated by {worst_all:e}");
}

#[test]
fn dielectric_reciprocity_under_the_radiance_convention() {
    // Reflection: f(wo, wi) = f(wi, wo). Transmission (radiance mode divides by eta'^2):
    // f_rad(wo, wi) / eta_o^2 = f_rad(wi, wo) / eta_i^2 (eta of the side each direction is on:
    // 1 above, eta below), equivalently f_rad(wo, wi) = f_imp(wi, wo).
    //
    // Conditioning: when a direction is nearly grazing to the microfacet (|w.wm| small) the
    // partner direction is near the critical angle, where dF/dcos is unbounded; f32 rounding of the
    // two dot products then gives different 1 - F. Pairs with min(|wo.wm|, |wi.wm|) < 0.02 or
    // |cos^2 theta_t| < 4e-4 are reported separately with an absolute bound.
    let mut rng = Pcg32::new(3, 4);
    let mut lines = Vec::new();
    let mut grazing_pairs = Vec::new();
    for &eta in &[1.5f32, 1.0 / 1.5, 1.33, 2.4, 1.01] {
        // [reflection, transmission eta relation, transmission adjoint] x [well-conditioned, grazing]
        let mut worst = [[0.0f64; 3]; 2];
        let mut worst_abs_grazing = 0.0f64;
        let mut worst_pair = (Vec3::ZERO, Vec3::ZERO, 0.0, 0.0, 0.0, 0.0);
        let mut counts = [[0usize; 2]; 2];
        for &(ax, ay) in &[(0.01f32, 0.01f32), (0.1, 0.1), (0.3, 0.3), (0.7, 0.7), (0.2, 0.05), (1.0, 1.0)] {
            let b = DielectricBxDF::new(TrowbridgeReitz::new(ax, ay), eta);
            for _ in 0..20_000 {
                let wo = random_dir(&mut rng);
                let wi = random_dir(&mut rng);
                let f_oi = b.f(wo, wi, MODE_RADIANCE).x as f64;
                let f_io = b.f(wi, wo, MODE_RADIANCE).x as f64;
                let imp_io = b.f(wi, wo, MODE_IMPORTANCE).x as f64;
                if f_oi < 1e-30 && f_io < 1e-30 {
                    continue;
                }
                let (o, i) = (to64(wo), to64(wi));
                let refl = wo.z * wi.z > 0.0;
                let etap = if refl { 1.0 } else if wo.z > 0.0 { eta as f64 } else { 1.0 / eta as f64 };
                let wm = norm(add(scale(i, etap), o));
                let cm = dot(o, wm).abs().min(dot(i, wm).abs());
                // cos^2 of the transmitted angle for wo at this microfacet: near 0 = critical angle.
                let e_o = if wo.z > 0.0 { eta as f64 } else { 1.0 / eta as f64 };
                let co = dot(o, wm).abs();
                let ct2 = 1.0 - (1.0 - co * co) / (e_o * e_o);
                let c = if cm < 0.02 || ct2.abs() < 4e-4 { 1 } else { 0 };
                let (k, lhs, rhs) = if refl {
                    (0, f_oi, f_io)
                } else {
                    let eta_side = |w: Vec3| if w.z > 0.0 { 1.0 } else { eta as f64 };
                    (1, f_oi / eta_side(wo).powi(2), f_io / eta_side(wi).powi(2))
                };
                counts[c][k] += 1;
                worst[c][k] = worst[c][k].max(rel(lhs, rhs));
                if !refl {
                    worst[c][2] = worst[c][2].max(rel(f_oi, imp_io));
                }
                // Near-critical pairs: |lhs - rhs| <= 1e-2 max(lhs, rhs) + 1e-3 (ratio <= 1).
                let ratio = (lhs - rhs).abs() / (1e-2 * lhs.abs().max(rhs.abs()) + 1e-3);
                if c == 1 && ratio > worst_abs_grazing {
                    worst_abs_grazing = ratio;
                    worst_pair = (wo, wi, lhs, rhs, cm, ct2);
                }
            }
        }
        lines.push(format!(
            "  {eta:>6.4} {:>8} {:>9.2e} {:>8} {:>9.2e} {:>9.2e} | {:>6} {:>6} {:>9.2e} {:>9.2e}",
            counts[0][0], worst[0][0], counts[0][1], worst[0][1], worst[0][2], counts[1][0], counts[1][1], worst[1][0].max(worst[1][1]), worst_abs_grazing
        ));
        // (eta = 1.01 transmits into a narrow cone around -wo: few random pairs land in it.)
        assert!(counts[0][0] > 10_000 && counts[0][1] > 200, "{counts:?}");
        // eta -> 1 makes the generalized half vector eta wi + wo a difference of nearly opposite
        // vectors and (wi.wm + wo.wm / eta)^2 a squared cancellation: looser bound there.
        // Transmission computes wm as eta' wi + wo one way and wo / eta' + wi the other; at
        // alpha = 0.01 D changes by ~4 / alpha per radian of wm, so the rounding of wm shows.
        let tol = if (eta - 1.0).abs() < 0.05 { 2e-2 } else { 5e-3 };
        assert!(worst[0][0] < 1e-3 && worst[0][1] < tol && worst[0][2] < tol, "eta {eta}: {worst:?}");
        grazing_pairs.push(format!("  eta {eta}: largest near-critical difference (wo, wi, lhs, rhs, min|w.wm|, cos^2 t) = {worst_pair:?}"));
        assert!(worst_abs_grazing <= 1.0, "eta {eta}: near-critical ratio {worst_abs_grazing}");
    }
    eprintln!(
        "dielectric reciprocity, radiance convention (120,000 random pairs per eta; rel = max relative difference):\n  {:>6} {:>8} {:>9} {:>8} {:>9} {:>9} | {:>6} {:>6} {:>9} {:>9}\n{}",
        "eta", "refl", "rel", "trans", "rel eta^2", "rel adj", "g.refl", "g.tr", "g.rel", "g.ratio", lines.join("\n")
    );
    eprintln!("{}", grazing_pairs.join("\n"));
    eprintln!("  (rel eta^2: f_rad(wo,wi)/eta_o^2 vs f_rad(wi,wo)/eta_i^2; rel adj: f_rad(wo,wi) vs f_imp(wi,wo); g.*: pairs with min(|wo.wm|, |wi.wm|) < 0.02 or |cos^2 theta_t| < 4e-4, i.e. near the critical angle, where dF/dcos is unbounded; g.ratio = max |lhs - rhs| / (1e-2 max(lhs, rhs) + 1e-3), must be <= 1)");
}

// ------------------------------------------------------------------------------------------------
// Energy: white furnace and weak white furnace
// ------------------------------------------------------------------------------------------------

const ALPHAS: [f64; 9] = [1e-3, 3e-3, 0.01, 0.03, 0.1, 0.3, 0.5, 0.7, 1.0];
const THETAS: [f64; 8] = [0.0, 30.0, 60.0, 75.0, 85.0, 89.0, 89.5, 89.9];
const NU: usize = 1024;
const NV: usize = 512;

fn table_header() -> String {
    let mut s = format!("  {:>7}", "alpha");
    for t in THETAS {
        s += &format!(" {:>10}", format!("{t}deg"));
    }
    s
}

/// White furnace: a perfect conductor (eta = 0, k = 1: F = 1 to 1.2e-7) with the real
/// height-correlated G2. E(wo) must not exceed 1; the shortfall is the single-scattering loss.
#[test]
fn white_furnace_conductor_albedo_at_most_one() {
    let mut lines = vec![table_header()];
    let mut lines_m = vec![table_header()];
    let mut max_e = 0.0f64;
    let mut min_e = 1.0f64;
    let mut max_diff = (0.0f64, 0.0, 0.0);
    for &a in &ALPHAS {
        let b = ConductorBxDF::new(TrowbridgeReitz::new(a as f32, a as f32), bxdf::splat(0.0), bxdf::splat(1.0));
        let mut line = format!("  {a:>7}");
        let mut line_m = format!("  {a:>7}");
        for &t in &THETAS {
            let wo = dir64(t, 0.0);
            let e = albedo_grid(&|o, i| b.f(o, i, MODE_RADIANCE), wo, a, None, NU, NV).r[0];
            let em = albedo_conductor_model(wo, a, [0.0; 3], [1.0; 3], NU, NV)[0];
            max_e = max_e.max(e).max(em);
            min_e = min_e.min(e);
            if (e - em).abs() > max_diff.0 {
                max_diff = ((e - em).abs(), a, t);
            }
            line += &format!(" {e:>10.6}");
            line_m += &format!(" {em:>10.6}");
        }
        lines.push(line);
        lines_m.push(line_m);
    }
    eprintln!("white furnace, E(wo) = int f |cos_i| dwi, F = 1, height-correlated G2 ({NU}x{NV} f64 quadrature over wm of the f32 BxDF):\n{}", lines.join("\n"));
    eprintln!("same, f64 model (exact grid wm, f64 D, Lambda, Fresnel):\n{}", lines_m.join("\n"));
    eprintln!(
        "max |E(f32 BxDF) - E(f64 model)| = {:.2e} at alpha {}, theta {} deg (f32 f recomputes wm from the rounded wi: ill-conditioned at grazing with tiny alpha)",
        max_diff.0, max_diff.1, max_diff.2
    );
    assert!(max_diff.0 < 5e-3, "f32 BxDF albedo departs from the f64 model by {max_diff:?}");
    // Quadrature error of this grid is below 2e-5 (see the convergence test); F is 1 + 1.2e-7.
    assert!(max_e <= 1.0 + 2e-5, "albedo {max_e} exceeds 1");
    assert!(min_e > 0.3, "implausible energy loss {min_e}");
}

/// Weak white furnace (Heitz 2014, eq. 18/21): with G2 replaced by G1(wo) and integrating over the
/// whole sphere of wi, int D(wm) G1(wo) / (4 |cos_o|) dwi = 1 for every wo and alpha. Evaluated
/// with the f32 D and G1 of shader-core.
#[test]
fn weak_white_furnace_is_one() {
    let mut lines = vec![table_header()];
    let mut max_dev = 0.0f64;
    for &a in &ALPHAS {
        let td = TrowbridgeReitz::new(a as f32, a as f32);
        let mut line = format!("  {a:>7}");
        for &t in &THETAS {
            let wo = dir64(t, 0.0);
            let wo32 = to32(wo);
            let g1 = td.g1(wo32) as f64;
            let mut sum = 0.0f64;
            for i in 0..NU {
                for j in 0..NV {
                    let (wm, pm) = grid_wm(i, j, NU, NV, a);
                    let d = dot(wo, wm);
                    if d <= 0.0 || pm <= 0.0 {
                        continue;
                    }
                    // f_weak |cos_i| dwi = D G1(wo) / (4 |cos_o|) * 4 (wo.wm) dwm
                    sum += td.d(to32(wm)) as f64 * g1 * d / wo[2] / pm;
                }
            }
            let w = sum / (NU * NV) as f64;
            max_dev = max_dev.max((w - 1.0).abs());
            line += &format!(" {w:>10.6}");
        }
        lines.push(line);
    }
    eprintln!("weak white furnace, int D(wm) G1(wo) / (4 cos_o) dwi over the sphere ({NU}x{NV} f64 quadrature over wm):\n{}", lines.join("\n"));
    assert!(max_dev < 1e-3, "weak white furnace deviates by {max_dev}");
}

/// The quadrature behind the furnace tables converges: doubling the grid changes E by < 2e-5.
#[test]
fn furnace_quadrature_converges() {
    let mut worst = 0.0f64;
    for &a in &[1e-3, 0.1, 1.0] {
        let b = ConductorBxDF::new(TrowbridgeReitz::new(a as f32, a as f32), bxdf::splat(0.0), bxdf::splat(1.0));
        for &t in &[0.0, 60.0, 89.9] {
            let wo = dir64(t, 0.0);
            let e1 = albedo_grid(&|o, i| b.f(o, i, MODE_RADIANCE), wo, a, None, NU, NV).r[0];
            let e2 = albedo_grid(&|o, i| b.f(o, i, MODE_RADIANCE), wo, a, None, 2 * NU, 2 * NV).r[0];
            eprintln!("  alpha {a:<6} theta {t:>5}: E({NU}x{NV}) = {e1:.7}, E({}x{}) = {e2:.7}, diff {:.1e}", 2 * NU, 2 * NV, (e1 - e2).abs());
            worst = worst.max((e1 - e2).abs());
        }
    }
    assert!(worst < 2e-5, "quadrature not converged: {worst:e}");
}

/// Rough dielectric, wo outside and inside: reflection + transmission (importance mode, i.e.
/// energy) <= 1 with the real G2; with G2 -> G1(wo) it is 1 minus the energy whose reflected or
/// refracted direction lands on the wrong side of the macrosurface (computed independently).
#[test]
fn rough_dielectric_energy() {
    let mut lines = vec![format!(
        "  {:>5} {:>6} {:>6} {:>9} {:>9} {:>9} {:>9} {:>10}",
        "eta", "alpha", "theta", "R", "T", "R+T", "weak R+T", "weak+lost"
    )];
    let mut worst_weak = 0.0f64;
    let mut max_rt = 0.0f64;
    for &eta in &[1.5f64, 1.0 / 1.5, 1.33] {
        for &a in &[0.01f64, 0.1, 0.3, 0.7] {
            for &t in &[0.0f64, 45.0, 80.0, 89.0] {
                let b = DielectricBxDF::new(TrowbridgeReitz::new(a as f32, a as f32), eta as f32);
                let td = b.distrib;
                let wo = dir64(t, 0.0);
                let full = albedo_grid(&|o, i| b.f(o, i, MODE_IMPORTANCE), wo, a, Some(eta), NU, NV);
                // Weak: scale f by G1(wo) / G2(wo, wi).
                let weak_f = |o: Vec3, i: Vec3| {
                    let g2 = td.g(o, i);
                    if g2 > 0.0 {
                        b.f(o, i, MODE_IMPORTANCE) * (td.g1(o) / g2)
                    } else {
                        Vec3::ZERO
                    }
                };
                let weak = albedo_grid(&weak_f, wo, a, Some(eta), NU, NV);
                // Energy the microfacet model sends to the wrong side: D_wo(wm) F [reflect below] +
                // D_wo(wm) (1 - F) [refract above], integrated over wm (f64 Fresnel).
                let g1 = td.g1(to32(wo)) as f64;
                let mut lost = 0.0;
                for i in 0..NU {
                    for j in 0..NV {
                        let (wm, pm) = grid_wm(i, j, NU, NV, a);
                        let d = dot(wo, wm);
                        if d <= 0.0 || pm <= 0.0 {
                            continue;
                        }
                        let dw = ggx_d64(wm, a) * g1 * d / wo[2];
                        let fr = fr_dielectric64(d, eta);
                        let wr = add(scale(wm, 2.0 * d), scale(wo, -1.0));
                        if wr[2] <= 0.0 {
                            lost += dw * fr / pm;
                        }
                        if let Some((wt, _)) = refract64(wo, wm, eta) {
                            if wt[2] >= 0.0 {
                                lost += dw * (1.0 - fr) / pm;
                            }
                        }
                    }
                }
                lost /= (NU * NV) as f64;
                let rt = full.r[0] + full.t[0];
                let wrt = weak.r[0] + weak.t[0];
                max_rt = max_rt.max(rt);
                worst_weak = worst_weak.max((wrt + lost - 1.0).abs());
                lines.push(format!(
                    "  {eta:>5.3} {a:>6} {t:>6} {:>9.6} {:>9.6} {rt:>9.6} {wrt:>9.6} {:>10.6}",
                    full.r[0],
                    full.t[0],
                    wrt + lost
                ));
            }
        }
    }
    eprintln!("rough dielectric energy (importance mode), wo above the surface ({NU}x{NV} quadrature over wm):\n{}", lines.join("\n"));
    assert!(max_rt <= 1.0 + 2e-5, "dielectric R + T = {max_rt} > 1");
    assert!(worst_weak < 1e-3, "weak furnace + lost energy deviates from 1 by {worst_weak}");
}

// ------------------------------------------------------------------------------------------------
// Sampling: sample_f vs f / pdf, Monte Carlo vs quadrature
// ------------------------------------------------------------------------------------------------

struct Consistency {
    samples: usize,
    valid: usize,
    specular: usize,
    max_pdf_rel: f64,
    max_f_rel: f64,
    /// max over samples of rel / cond, cond = eps (|a| + |b|) / (alpha_min |a + b|): the rounding
    /// amplification of recomputing wm from (wo, wi) (see [`check_consistency`]).
    max_rel_per_cond: f64,
    /// max over samples of rel / (TOL + C cond): must be <= 1.
    max_excess: f64,
}

/// Allowed relative difference between what `sample_f` returns and `f(wo, wi)` / `pdf(wo, wi)`:
/// TOL + C cond. sample_f evaluates at the sampled wm; f and pdf recompute wm = normalize(a + b)
/// (a = wo, b = wi for reflection; a = wo, b = eta' wi for transmission) from the rounded f32 wi,
/// an error of about eps (|a| + |b|) / |a + b| radians, which D (slope ~2 / alpha per radian at
/// theta_m ~ alpha) turns into a relative error ~ 2 eps (|a| + |b|) / (alpha |a + b|). Grazing wo
/// (|wo + wi| = 2 |wo.wm| -> 0) and tiny alpha are where this is large.
const CONSISTENCY_TOL: f64 = 2e-3;
const CONSISTENCY_C: f64 = 8.0;

fn check_consistency(b: &dyn BxDF, mode: u32, n: usize, seed: u32, thetas: &[f64], alpha_min: f64, eta: f64) -> Consistency {
    let mut c = Consistency { samples: 0, valid: 0, specular: 0, max_pdf_rel: 0.0, max_f_rel: 0.0, max_rel_per_cond: 0.0, max_excess: 0.0 };
    let mut rng = Pcg32::new(seed, 11);
    let eps = f32::EPSILON as f64;
    for &t in thetas {
        for k in 0..n {
            let wo = dir(t, 360.0 * k as f64 / n as f64);
            let (uc, u0, u1) = (rng.next_f32(), rng.next_f32(), rng.next_f32());
            let s = b.sample_f(wo, uc, u0, u1, mode, SAMPLE_ALL);
            c.samples += 1;
            if !s.is_valid() {
                assert!(s.pdf == 0.0 && s.f == Vec3::ZERO, "invalid sample must be zero: {s:?}");
                continue;
            }
            c.valid += 1;
            assert!(s.pdf > 0.0 && s.pdf.is_finite() && s.f.is_finite(), "wo {wo:?} -> {s:?}");
            let w = s.wi.z.abs() / s.pdf;
            assert!((s.f * w).is_finite(), "f/pdf not finite: {s:?}");
            if s.flags & bxdf::SPECULAR != 0 {
                // A delta lobe has no density: pdf(wo, wi) holds only the other lobes' density
                // (0 for a pure mirror, the diffuse part for glTF).
                c.specular += 1;
                assert!(b.pdf(wo, s.wi, mode, SAMPLE_ALL).is_finite());
                continue;
            }
            let p = b.pdf(wo, s.wi, mode, SAMPLE_ALL) as f64;
            let pr = rel(p, s.pdf as f64);
            let fv = b.f(wo, s.wi, mode);
            let fr = rel(fv.x as f64, s.f.x as f64).max(rel(fv.y as f64, s.f.y as f64)).max(rel(fv.z as f64, s.f.z as f64));
            let (o, i) = (to64(wo), to64(s.wi));
            let etap = if wo.z * s.wi.z > 0.0 { 1.0 } else if wo.z > 0.0 { eta } else { 1.0 / eta };
            let h = add(o, scale(i, etap));
            let cond = eps * (1.0 + etap) / (alpha_min * dot(h, h).sqrt());
            let r = pr.max(fr);
            c.max_pdf_rel = c.max_pdf_rel.max(pr);
            c.max_f_rel = c.max_f_rel.max(fr);
            c.max_rel_per_cond = c.max_rel_per_cond.max(r / cond);
            c.max_excess = c.max_excess.max(r / (CONSISTENCY_TOL + CONSISTENCY_C * cond));
        }
    }
    c
}

#[test]
fn sample_f_agrees_with_f_and_pdf() {
    let (eta, k) = gold();
    let thetas = [0.0, 10.0, 30.0, 50.0, 70.0, 85.0, 89.0, 89.9, 100.0, 150.0, 179.0];
    let mut lines = Vec::new();
    let mut failures = Vec::new();
    let mut run = |name: String, b: &dyn BxDF, mode: u32, alpha_min: f64, eta: f64| {
        let c = check_consistency(b, mode, 20_000, 5, &thetas, alpha_min, eta);
        lines.push(format!(
            "  {name:<46} {:>7} {:>7} {:>6} {:>10.2e} {:>10.2e} {:>9.2e} {:>7.3}",
            c.samples, c.valid, c.specular, c.max_pdf_rel, c.max_f_rel, c.max_rel_per_cond, c.max_excess
        ));
        if c.valid <= c.samples / 3 {
            failures.push(format!("{name}: too few valid samples"));
        }
        if !(c.max_excess <= 1.0) {
            failures.push(format!("{name}: pdf rel {:e}, f rel {:e}, excess {}", c.max_pdf_rel, c.max_f_rel, c.max_excess));
        }
    };
    run("lambert".into(), &DiffuseBxDF::new(Vec3::new(0.2, 0.5, 0.8)), MODE_RADIANCE, f64::INFINITY, 1.0);
    for &(ax, ay) in &[(1e-4f32, 1e-4f32), (1e-3, 1e-3), (0.01, 0.01), (0.1, 0.1), (0.5, 0.5), (1.0, 1.0), (0.05, 0.5), (3.0, 3.0)] {
        let am = ax.min(ay) as f64;
        run(format!("conductor gold alpha ({ax}, {ay})"), &ConductorBxDF::new(TrowbridgeReitz::new(ax, ay), eta, k), MODE_RADIANCE, am, 1.0);
        for &e in &[1.5f32, 1.0 / 1.5] {
            for mode in [MODE_RADIANCE, MODE_IMPORTANCE] {
                run(format!("dielectric eta {e:.3} alpha ({ax}, {ay}) mode {mode}"), &DielectricBxDF::new(TrowbridgeReitz::new(ax, ay), e), mode, am, e as f64);
            }
        }
    }
    for &r in &[0.0f32, 0.02, 0.1, 0.3, 0.6, 1.0] {
        for &m in &[0.0f32, 0.5, 1.0] {
            let am = (r as f64 * r as f64).max(1e-3);
            run(format!("gltf roughness {r} metallic {m}"), &GltfMetalRoughBxDF::new(Vec3::new(0.9, 0.6, 0.3), m, r), MODE_RADIANCE, am, 1.0);
        }
    }
    run("specular reflection".into(), &SpecularReflectionBxDF::new(Vec3::new(1.0, 0.5, 0.25)), MODE_RADIANCE, f64::INFINITY, 1.0);
    eprintln!(
        "sample_f consistency (pdf and f returned by sample_f vs pdf(wo, wi), f(wo, wi)); wo at theta {thetas:?} deg x 20,000 azimuths;\n  rel/cond = max rel / (eps (1 + eta') / (alpha |wo + eta' wi|)); excess = max rel / ({CONSISTENCY_TOL} + {CONSISTENCY_C} cond), must be <= 1:\n  {:<46} {:>7} {:>7} {:>6} {:>10} {:>10} {:>9} {:>7}\n{}",
        "bxdf", "samples", "valid", "spec", "max rel p", "max rel f", "rel/cond", "excess",
        lines.join("\n")
    );
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn monte_carlo_albedo_matches_quadrature() {
    let (eta, k) = gold();
    let n_mc = 1 << 18;
    let mut lines = vec![format!("  {:<36} {:>6} {:>10} {:>10} {:>9} {:>7}", "bxdf", "theta", "quadrature", "MC", "MC s.e.", "|z|")];
    let mut worst_z = 0.0f64;
    let mut check = |name: String, t: f64, quad: f64, mc: f64, se: f64| {
        let z = (mc - quad).abs() / (se + 2e-5);
        worst_z = worst_z.max(z);
        lines.push(format!("  {name:<36} {t:>6} {quad:>10.6} {mc:>10.6} {se:>9.2e} {z:>7.2}"));
    };
    for &a in &[1e-3f64, 0.05, 0.3, 1.0] {
        let b = ConductorBxDF::new(TrowbridgeReitz::new(a as f32, a as f32), eta, k);
        for &t in &[0.0, 60.0, 85.0, 89.9] {
            // Reference: the f64 model (the f32 f at grazing with alpha = 1e-3 is ill-conditioned,
            // see the white furnace test); the MC uses the sampled wm, which is well-conditioned.
            let ef = [eta.x as f64, eta.y as f64, eta.z as f64];
            let kf = [k.x as f64, k.y as f64, k.z as f64];
            let q = albedo_conductor_model(dir64(t, 0.0), a, ef, kf, NU, NV);
            let (m, se) = albedo_mc(&b, to32(dir64(t, 0.0)), MODE_RADIANCE, n_mc, 9);
            for c in 0..3 {
                check(format!("conductor gold a={a} ch{c}"), t, q[c], m[c], se[c]);
            }
        }
    }
    for &eta_d in &[1.5f64, 1.0 / 1.5] {
        for &a in &[0.01f64, 0.3, 0.8] {
            let b = DielectricBxDF::new(TrowbridgeReitz::new(a as f32, a as f32), eta_d as f32);
            for &t in &[0.0, 60.0, 89.0] {
                for mode in [MODE_RADIANCE, MODE_IMPORTANCE] {
                    let q = albedo_grid(&|o, i| b.f(o, i, mode), dir64(t, 0.0), a, Some(eta_d), NU, NV);
                    let (m, se) = albedo_mc(&b, to32(dir64(t, 0.0)), mode, n_mc, 13);
                    check(format!("dielectric eta={eta_d:.3} a={a} mode={mode}"), t, q.r[0] + q.t[0], m[0], se[0]);
                }
            }
        }
    }
    // glTF: the reference combines a cosine-hemisphere grid and the wm grid with the balance
    // heuristic (deterministic multi-sample MIS); smooth roughness adds the delta lobe exactly.
    for &r in &[0.0f64, 0.2, 0.5, 1.0] {
        for &m in &[0.0f32, 0.5, 1.0] {
            let base = Vec3::new(0.9, 0.6, 0.3);
            let b = GltfMetalRoughBxDF::new(base, m, r as f32);
            let a = (r * r).max(1e-3);
            for &t in &[0.0, 60.0, 89.0] {
                let wo = dir64(t, 0.0);
                let q = gltf_albedo_reference(&b, wo, a);
                let (mc, se) = albedo_mc(&b, to32(wo), MODE_RADIANCE, n_mc, 17);
                for c in 0..3 {
                    check(format!("gltf r={r} m={m} ch{c}"), t, q[c], mc[c], se[c]);
                }
            }
        }
    }
    // Lambert: E = R exactly, zero variance with cosine sampling.
    let lam = DiffuseBxDF::new(Vec3::new(0.25, 0.5, 0.75));
    let (m, se) = albedo_mc(&lam, dir(40.0, 0.0), MODE_RADIANCE, 1 << 12, 1);
    for c in 0..3 {
        check(format!("lambert ch{c}"), 40.0, [0.25, 0.5, 0.75][c], m[c], se[c]);
    }
    eprintln!("albedo: f64 quadrature vs Monte Carlo through sample_f ({n_mc} samples; z = |diff| / (s.e. + 2e-5)):\n{}", lines.join("\n"));
    assert!(worst_z < 5.0, "Monte Carlo disagrees with quadrature: z = {worst_z}");
}

fn gltf_albedo_reference(b: &GltfMetalRoughBxDF, wo: V, alpha: f64) -> [f64; 3] {
    let wo32 = to32(wo);
    let smooth = b.distrib.effectively_smooth();
    let mut acc = [0.0f64; 3];
    let p_m = |wi: V| -> f64 {
        if smooth {
            return 0.0;
        }
        let wm = norm(add(wo, wi));
        let d = dot(wo, wm);
        if d <= 0.0 {
            return 0.0;
        }
        // Density of the wm grid (see grid_wm): D cos / (du/ds), du/ds = 4 (1 - u)^(3/4).
        let t2 = (1.0 - wm[2] * wm[2]) / (wm[2] * wm[2]);
        let om = alpha * alpha / (alpha * alpha + t2); // 1 - u
        ggx_d64(wm, alpha) * wm[2] / (4.0 * om.powf(0.75)) / (4.0 * d)
    };
    let n = (NU * NV) as f64;
    // Cosine-hemisphere grid: cos theta = sqrt(1 - u), pdf cos / pi.
    for i in 0..NU {
        for j in 0..NV {
            let u = (i as f64 + 0.5) / NU as f64;
            let v = (j as f64 + 0.5) / NV as f64;
            let c = (1.0 - u).sqrt();
            let s = u.sqrt();
            let p = 2.0 * PI * v;
            let wi = [s * p.cos(), s * p.sin(), c];
            let fv = b.f(wo32, to32(wi), MODE_RADIANCE);
            let w = c / (c / PI + p_m(wi)) / n;
            acc[0] += fv.x as f64 * w;
            acc[1] += fv.y as f64 * w;
            acc[2] += fv.z as f64 * w;
        }
    }
    if !smooth {
        for i in 0..NU {
            for j in 0..NV {
                let (wm, pm) = grid_wm(i, j, NU, NV, alpha);
                let d = dot(wo, wm);
                if d <= 0.0 || pm <= 0.0 {
                    continue;
                }
                let wi = add(scale(wm, 2.0 * d), scale(wo, -1.0));
                if wi[2] <= 0.0 {
                    continue;
                }
                let fv = b.f(wo32, to32(wi), MODE_RADIANCE);
                let w = wi[2] / (wi[2] / PI + pm / (4.0 * d)) / n;
                acc[0] += fv.x as f64 * w;
                acc[1] += fv.y as f64 * w;
                acc[2] += fv.z as f64 * w;
            }
        }
    } else {
        // Delta lobe: ((1 - m) F_d(cos_o) + m F_m(cos_o)), Schlick at cos_o.
        let c = wo[2];
        let w5 = (1.0 - c).powi(5);
        let f0 = fresnel::f0_from_eta(1.5) as f64;
        let m = b.metallic as f64;
        let base = [b.base.x as f64, b.base.y as f64, b.base.z as f64];
        for ch in 0..3 {
            acc[ch] += (1.0 - m) * (f0 + (1.0 - f0) * w5) + m * (base[ch] + (1.0 - base[ch]) * w5);
        }
    }
    acc
}
