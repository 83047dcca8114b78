//! Statistical tests of the reflection samplers of `shader_core::vndf` (docs/vndf.md):
//!
//! * chi-square goodness of fit (`crosscheck::chi2`) of every sampler against its own pdf, over
//!   80 configurations (theta_i 0 .. 89.9 degrees and back-facing, alpha 1e-3 .. 2, anisotropy
//!   20:1 both ways, a generic azimuth, plus theta_i = 89.9 degrees in the xz plane), in the
//!   stretched half-vector parameterization (all configurations) and in Mitsuba's
//!   (cos theta, phi) parameterization of wo (min alpha >= 0.05, where a sphere grid resolves the
//!   lobe), at significance 0.01 Bonferroni-corrected over every chi-square test of this file;
//!   nothing is excluded. The expected counts integrate the pdf function adaptively; where its
//!   f32 evaluation is ill-conditioned (theta_i = 89.9 degrees with alpha = 1e-3: the rounding of
//!   wi alone moves the half vector by ~2 % of the lobe) they integrate the same formulas in f64;
//!   the f32 function is then checked against the samplers' returned pdfs only;
//! * the pdf integrates to 1 over the sphere, and its integral over the upper hemisphere matches
//!   the fraction of samples that land there;
//! * the pdf returned with a sample agrees with the pdf function at the sample;
//! * the suite rejects a perturbed pdf (pdf (1 + 0.1 cos theta_o) renormalized; the pdf of a 10 %
//!   larger alpha; the other family's pdf);
//! * the bounded method's cap contains every reflection above the horizon (its bound is
//!   conservative, anisotropic rule included).
//!
//! Samples are drawn on the CPU backend (the same kernel code as the GPU; tests/tests/vndf_crosscheck.rs
//! checks that both produce the same bits).

use crosscheck::chi2::{self, Domain, Grid, HalfVectorDomain, Pole, SphereDomain};
use host::Backend;
use shader_core::{vndf, Vec3};
use std::fmt::Write as _;

type PdfFn = fn(Vec3, Vec3, f32, f32) -> f32;

#[derive(Clone, Copy)]
struct Method {
    sampler: &'static str,
    pdf: PdfFn,
    /// The half-vector parameterization whose interior holds no jump of this density.
    pole: Pole,
}

const NDF: Method = Method { sampler: "sample_ndf", pdf: vndf::pdf_ndf, pole: Pole::StretchedWi };
const HEITZ: Method = Method { sampler: "sample_vndf_heitz", pdf: vndf::pdf_vndf_heitz, pole: Pole::Normal };
const CAPS: Method = Method { sampler: "sample_vndf_caps", pdf: vndf::pdf_vndf_caps, pole: Pole::Normal };
const BOUNDED: Method = Method { sampler: "sample_vndf_bounded", pdf: vndf::pdf_vndf_bounded, pole: Pole::Normal };
const METHODS: [Method; 4] = [NDF, HEITZ, CAPS, BOUNDED];

/// Samples per chi-square test.
const N: usize = 200_000;
/// Overall significance level, split over every chi-square test in this file (Bonferroni).
const SIGNIFICANCE: f64 = 0.01;

#[derive(Clone, Copy, Debug)]
struct Case {
    theta_deg: f64,
    phi_deg: f64,
    alpha_x: f32,
    alpha_y: f32,
}

impl Case {
    fn wi(&self) -> [f32; 3] {
        let (t, p) = (self.theta_deg.to_radians(), self.phi_deg.to_radians());
        [(t.sin() * p.cos()) as f32, (t.sin() * p.sin()) as f32, t.cos() as f32]
    }

    /// wi in the xz plane (phi_i = 0). At grazing incidence the reflected lobe is narrow across
    /// the plane of incidence: 2 (wi.wm) alpha wide, 5e-6 rad at theta_i = 89.9 degrees with
    /// alpha = 1e-3. For a generic azimuth that direction mixes wo.x and wo.y, both near +-0.7,
    /// where f32 values are 6e-8 apart (~1 % of that width): only a coarse grid tests the
    /// sampler there rather than f32 ([`Case::half_grid`]). With wi in the xz plane that
    /// direction is y, where wo.y keeps full relative precision, so the same lobe gets the full
    /// grid (the phi_i = 0 cases of [`cases`]).
    fn in_xz_plane(&self) -> bool {
        self.phi_deg == 0.0
    }

    /// Whether the f32 pdf function gives the expected counts. Where the f32 rounding of wi and
    /// of the integration point moves h = wi + wo by more than 1e-2 of the lobe width
    /// (f32_resolution), the f32 density is off by a few percent (it integrates to 1.03 at
    /// theta_i = 89.9 degrees, alpha = 1e-3), and the f64 formulas of [`reference_pdf`] are used.
    fn f32_pdf_usable(&self) -> bool {
        self.f32_resolution() <= 1e-2
    }

    /// Whether Mitsuba's sphere grid can integrate method `m`'s density: the lobe must be wide
    /// enough (min alpha >= 0.05), and for NDF sampling the density's 1 / |wi + wo| singularity at
    /// wo = -wi must lie outside the lobe (it is 2 wi.z from the mirror direction: inside the
    /// lobe at 89.9 degrees, where the half-vector grid, whose Jacobian cancels it, is used alone).
    fn sphere_grid_resolves(&self, m: &Method) -> bool {
        self.alpha_x.min(self.alpha_y) >= 0.05 && (m.sampler != "sample_ndf" || self.wi()[2] >= 0.01)
    }

    /// Relative size of the f32 rounding of wo (~1.2e-7) measured in lobe widths, for a typical
    /// sample (half vector near the normal, |wi + wo| ~ 2 wi.z): the resolution below which a
    /// sampler that returns wo in f32 cannot follow its density.
    fn f32_resolution(&self) -> f64 {
        let wiz = self.wi()[2] as f64;
        if wiz <= 0.0 {
            return 0.0;
        }
        1.2e-7 / (2.0 * wiz * f64::from(self.alpha_x.min(self.alpha_y).min(1.0)))
    }

    /// The half-vector grid: 32 x 64, or 8 x 16 where the f32 rounding of wo moves a typical
    /// sample by more than 1e-3 of the lobe width (theta_i >= 89 degrees with alpha <= 0.01) at
    /// a generic azimuth: a fine grid there measures the precision of f32, not the sampler.
    fn half_grid(&self) -> Grid {
        if self.f32_resolution() > 1e-3 && !self.in_xz_plane() {
            Grid { res_u: 8, res_v: 16, ..Grid::default() }
        } else {
            Grid::default()
        }
    }

    /// The sphere grid, split at wo.z = -wi.z where the VNDF densities jump (half vector reaching
    /// the horizon).
    fn sphere_grid(&self) -> Grid {
        Grid { u_breaks: vec![(1.0 - f64::from(self.wi()[2])) * 0.5], ..Grid::default() }
    }

    fn label(&self) -> String {
        format!("theta {:>5.1} phi {:>4.0} alpha ({}, {})", self.theta_deg, self.phi_deg, self.alpha_x, self.alpha_y)
    }
}

/// theta_i 0 .. 89.9 at a generic azimuth x 11 roughness pairs, 2 grazing cases in the xz plane,
/// and 12 back-facing cases.
fn cases() -> Vec<Case> {
    let alphas: [(f32, f32); 11] = [
        (1e-3, 1e-3),
        (0.01, 0.01),
        (0.05, 0.05),
        (0.2, 0.2),
        (0.5, 0.5),
        (1.0, 1.0),
        (2.0, 2.0),
        (0.05, 1.0),
        (1.0, 0.05),
        (0.01, 0.2),
        (0.3, 0.1),
    ];
    let mut v = Vec::new();
    for &theta_deg in &[0.0, 30.0, 60.0, 80.0, 89.0, 89.9] {
        for &(alpha_x, alpha_y) in &alphas {
            v.push(Case { theta_deg, phi_deg: 35.0, alpha_x, alpha_y });
        }
    }
    // Grazing, lowest roughness, wi in the xz plane: the lobe that f32 resolves only coarsely at
    // the generic azimuth (see Case::in_xz_plane), tested with the full grid.
    for &(alpha_x, alpha_y) in &[(1e-3f32, 1e-3f32), (1e-3, 0.01)] {
        v.push(Case { theta_deg: 89.9, phi_deg: 0.0, alpha_x, alpha_y });
    }
    for &theta_deg in &[100.0, 135.0, 170.0] {
        for &(alpha_x, alpha_y) in &[(0.2f32, 0.2f32), (0.5, 0.5), (1.0, 1.0), (0.05, 1.0)] {
            v.push(Case { theta_deg, phi_deg: 35.0, alpha_x, alpha_y });
        }
    }
    v
}

/// Every chi-square test of this file: the sampler runs (both domains) and the perturbed-pdf runs.
fn total_tests() -> usize {
    let c = cases();
    let runs: usize = METHODS
        .iter()
        .map(|m| c.len() + c.iter().filter(|c| c.sphere_grid_resolves(m)).count())
        .sum();
    runs + PERTURBED_TESTS
}

fn level() -> f64 {
    SIGNIFICANCE / total_tests() as f64
}

fn pdf64(pdf: PdfFn, wi: [f32; 3], ax: f32, ay: f32) -> impl Fn([f64; 3]) -> f64 + Sync {
    let wi = Vec3::new(wi[0], wi[1], wi[2]);
    move |w: [f64; 3]| f64::from(pdf(wi, Vec3::new(w[0] as f32, w[1] as f32, w[2] as f32), ax, ay))
}

/// GGX D (Walter et al. 2007 eq. 33, anisotropic) at the direction of `m` (any length), in f64.
fn ggx_d64(m: [f64; 3], ax: f64, ay: f64) -> f64 {
    if !(m[2] > 0.0) {
        return 0.0;
    }
    let l2 = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
    let q = (m[0] / ax).powi(2) + (m[1] / ay).powi(2) + m[2] * m[2];
    l2 * l2 / (std::f64::consts::PI * ax * ay * q * q)
}

/// The density of method `m` evaluated in f64 from the papers' formulas (docs/vndf.md), with wi
/// and wo normalized: the expected counts where the f32 pdf is ill-conditioned
/// ([`Case::f32_pdf_usable`]).
fn reference_pdf(m: &Method, wi: [f32; 3], ax: f32, ay: f32) -> impl Fn([f64; 3]) -> f64 + Sync {
    let l = wi.iter().map(|&x| f64::from(x) * f64::from(x)).sum::<f64>().sqrt();
    let i = wi.map(|x| f64::from(x) / l);
    let (ax, ay) = (f64::from(ax), f64::from(ay));
    let sampler = m.sampler;
    let len2 = (ax * i[0]).powi(2) + (ay * i[1]).powi(2);
    let t = (len2 + i[2] * i[2]).sqrt();
    // Eto & Tokuyoshi 2023 eq. 5 with alpha = min(alpha_x, alpha_y, 1).
    let a = ax.min(ay).min(1.0);
    let s = 1.0 + (i[0] * i[0] + i[1] * i[1]).sqrt();
    let k = (1.0 - a * a) * s * s / (s * s + a * a * i[2] * i[2]);
    let i_std = {
        let v = [ax * i[0], ay * i[1], i[2]];
        [v[0] / t, v[1] / t, v[2] / t]
    };
    move |w: [f64; 3]| {
        let lw = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
        let o = [w[0] / lw, w[1] / lw, w[2] / lw];
        let mut h = [i[0] + o[0], i[1] + o[1], i[2] + o[2]];
        let lh = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
        if !(lh > 0.0) {
            return 0.0;
        }
        match sampler {
            "sample_ndf" => {
                if h[2] < 0.0 {
                    h = h.map(|x| -x);
                }
                let hn = h.map(|x| x / lh);
                let ih = (i[0] * hn[0] + i[1] * hn[1] + i[2] * hn[2]).abs();
                ggx_d64(h, ax, ay) * hn[2] / (4.0 * ih)
            }
            "sample_vndf_bounded" if i[2] >= 0.0 => {
                // chi+(k i_std.z + o_std.z), o_std the reflection of i_std about h_std.
                let hs = [h[0] / ax, h[1] / ay, h[2]];
                let ls = (hs[0] * hs[0] + hs[1] * hs[1] + hs[2] * hs[2]).sqrt();
                let hs = hs.map(|x| x / ls);
                let d = i_std[0] * hs[0] + i_std[1] * hs[1] + i_std[2] * hs[2];
                if 2.0 * d * hs[2] - i_std[2] <= -k * i_std[2] {
                    return 0.0;
                }
                ggx_d64(h, ax, ay) / (2.0 * (k * i[2] + t))
            }
            _ => {
                let d = ggx_d64(h, ax, ay);
                if i[2] >= 0.0 {
                    d / (2.0 * (i[2] + t))
                } else {
                    d * (t - i[2]) / (2.0 * len2)
                }
            }
        }
    }
}

fn half_domain(c: &Case, pole: Pole) -> HalfVectorDomain {
    let wi = c.wi();
    HalfVectorDomain::new([f64::from(wi[0]), f64::from(wi[1]), f64::from(wi[2])], f64::from(c.alpha_x), f64::from(c.alpha_y), pole)
}

fn seed(method: usize, case: usize) -> u32 {
    (method * 1000 + case) as u32
}

/// Condition of the density at a returned sample: the relative change of pdf(wi, wo) caused by
/// rounding wo to f32 (~1.2e-7 absolute), which moves the half vector h = wi + wo by 1.2e-7 / |h|
/// radians: D changes by up to 2 / alpha per radian, and NDF sampling's wm.z / |wi.wm| by
/// 1 / wm.z + 1 / |wi.wm|. Large where wo is near -wi (|h| -> 0) or the lobe is narrow.
fn pdf_condition(wi: [f32; 3], wo: [f32; 3], alpha_min: f32) -> f64 {
    let h = [0, 1, 2].map(|k| f64::from(wi[k]) + f64::from(wo[k]));
    let l = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
    let wih = (f64::from(wi[0]) * h[0] + f64::from(wi[1]) * h[1] + f64::from(wi[2]) * h[2]).abs() / l;
    1.2e-7 / l * (2.0 / f64::from(alpha_min.min(1.0)) + l / h[2].abs() + 1.0 / wih)
}

/// The chi-square runs, integrals and pdf agreement of one method over every case.
fn check_method(mi: usize) {
    let m = METHODS[mi];
    let alpha = level();
    let mut failures = Vec::new();
    let mut log = String::new();
    let t0 = std::time::Instant::now();
    let _ = writeln!(log, "{}: {} cases, {} samples each, per-test level {:.2e}", m.sampler, cases().len(), N, alpha);
    for (ci, c) in cases().iter().enumerate() {
        let wi = c.wi();
        let samples = chi2::draw(&Backend::Cpu, m.sampler, wi, c.alpha_x, c.alpha_y, N, seed(mi, ci));
        let dirs: Vec<[f32; 3]> = samples.iter().map(|s| s.0).collect();
        let pdf: Box<dyn Fn([f64; 3]) -> f64 + Sync> = if c.f32_pdf_usable() {
            Box::new(pdf64(m.pdf, wi, c.alpha_x, c.alpha_y))
        } else {
            let _ = writeln!(log, "  {} expected counts from the f64 formulas (f32 resolution {:.3} lobe widths)", c.label(), c.f32_resolution());
            Box::new(reference_pdf(&m, wi, c.alpha_x, c.alpha_y))
        };

        // Goodness of fit, stretched half-vector parameterization.
        let hd = half_domain(c, m.pole);
        let hgrid = c.half_grid();
        let r = chi2::test(&hd, &dirs, &pdf, &hgrid);
        let _ = writeln!(log, "  {} half-vector {}x{}: {}", c.label(), hgrid.res_u, hgrid.res_v, r.summary());
        if !r.passes(alpha) {
            failures.push(format!("{} half-vector domain: {}", c.label(), r.summary()));
        }
        if (r.integral - 1.0).abs() > 2e-3 {
            failures.push(format!("{} pdf integrates to {} over the sphere", c.label(), r.integral));
        }
        // Mitsuba's (cos theta, phi) grid over wo, where it resolves the lobe; its rows u >= 1/2
        // are the upper hemisphere, so the same cells give the upper-hemisphere integral.
        let kept = dirs.iter().filter(|d| d[2] > 0.0).count() as f64 / N as f64;
        let upper = if c.sphere_grid_resolves(&m) {
            let sgrid = c.sphere_grid();
            let (obs, invalid, outside) = chi2::histogram(&SphereDomain, &dirs, &sgrid);
            let (cells, evals) = chi2::integrate_cells(&SphereDomain, &pdf, &sgrid, N as f64);
            let r = chi2::pearson(&obs, &cells, N, invalid, outside, sgrid.min_expected, evals);
            let _ = writeln!(log, "  {} sphere:         {}", c.label(), r.summary());
            if !r.passes(alpha) {
                failures.push(format!("{} sphere domain: {}", c.label(), r.summary()));
            }
            if (r.integral - 1.0).abs() > 2e-3 {
                failures.push(format!("{} pdf integrates to {} over the sphere (sphere grid)", c.label(), r.integral));
            }
            cells[sgrid.res_u / 2 * sgrid.res_v..].iter().sum()
        } else {
            let hgrid = c.half_grid();
            chi2::integrate_masked(&hd, &pdf, &|w| w[2] > 0.0, &hgrid, N as f64)
        };
        // Upper-hemisphere mass vs the fraction of samples kept.
        let sigma = (kept * (1.0 - kept) / N as f64).sqrt();
        let _ = writeln!(log, "    kept {kept:.5}, upper-hemisphere integral {upper:.5}");
        if (upper - kept).abs() > 5.0 * sigma + 1e-3 {
            failures.push(format!("{}: kept fraction {kept} but the pdf's upper-hemisphere integral is {upper}", c.label()));
        }

        // The pdf returned with a sample agrees with the pdf function there, to within what the
        // rounding of wo to f32 allows (pdf_condition); the bounded cap's edge may flip a few.
        let (mut worst, mut violations, mut ill, mut off_support) = (0.0f64, 0usize, 0usize, 0usize);
        let wi_v = Vec3::new(wi[0], wi[1], wi[2]);
        let amin = c.alpha_x.min(c.alpha_y);
        for (wo, p) in &samples {
            let q = (m.pdf)(wi_v, Vec3::new(wo[0], wo[1], wo[2]), c.alpha_x, c.alpha_y);
            if *p == 0.0 && q == 0.0 {
                continue;
            }
            off_support += (*p > 0.0 && q == 0.0) as usize;
            let rel = (f64::from(*p) - f64::from(q)).abs() / f64::from(p.max(q));
            let cond = pdf_condition(wi, *wo, amin);
            ill += (cond > 1e-4) as usize;
            if rel > 1e-4 + 10.0 * cond {
                violations += 1;
            } else {
                worst = worst.max(rel);
            }
        }
        let _ = writeln!(
            log,
            "    pdf agreement: {violations} beyond 1e-4 + 10 x condition, worst within {worst:.2e}, {ill} samples with condition > 1e-4, {off_support} where the pdf function is 0"
        );
        if violations as f64 > 2e-5 * N as f64 {
            failures.push(format!("{}: sample pdf vs pdf function: {violations} samples beyond 1e-4 + 10 x condition", c.label()));
        }
    }
    let _ = writeln!(log, "{}: {:.1} s", m.sampler, t0.elapsed().as_secs_f64());
    eprintln!("{log}");
    assert!(failures.is_empty(), "{} failed:\n{}", m.sampler, failures.join("\n"));
}

#[test]
fn chi2_sample_ndf() {
    check_method(0);
}

#[test]
fn chi2_sample_vndf_heitz() {
    check_method(1);
}

#[test]
fn chi2_sample_vndf_caps() {
    check_method(2);
}

#[test]
fn chi2_sample_vndf_bounded() {
    check_method(3);
}

/// Samples per run of [`suite_rejects_perturbed_pdfs`]: a 10 % tilt changes the density of a
/// lobe by a few percent, which the 2048-cell grid detects reliably from about 1M samples.
const N_PERTURBED: usize = 1_000_000;

/// Number of chi-square runs in [`suite_rejects_perturbed_pdfs`] (part of the Bonferroni count).
const PERTURBED_TESTS: usize = 12;

/// The suite must reject a density that is slightly wrong: samples of each VNDF method against
/// (a) its pdf times (1 + 0.1 cos theta_o), renormalized, (b) its pdf with alpha 10 % larger,
/// (c) for bounded vs caps, the other method's pdf; NDF sampling against (a) and (b).
#[test]
fn suite_rejects_perturbed_pdfs() {
    let alpha = level();
    // Where the perturbations matter: cos theta_o varies over the lobe (not at grazing, where
    // every reflection is near the horizon), and caps and bounded differ (rough, oblique).
    let configs = [
        (HEITZ, Case { theta_deg: 30.0, phi_deg: 35.0, alpha_x: 0.3, alpha_y: 0.1 }),
        (CAPS, Case { theta_deg: 70.0, phi_deg: 35.0, alpha_x: 0.5, alpha_y: 1.0 }),
        (BOUNDED, Case { theta_deg: 45.0, phi_deg: 35.0, alpha_x: 0.5, alpha_y: 0.5 }),
        (NDF, Case { theta_deg: 30.0, phi_deg: 35.0, alpha_x: 0.2, alpha_y: 0.2 }),
    ];
    let mut runs = 0;
    let mut report = String::new();
    let mut accepted = Vec::new();
    for (k, (m, c)) in configs.iter().enumerate() {
        let wi = c.wi();
        let dirs: Vec<[f32; 3]> =
            chi2::draw(&Backend::Cpu, m.sampler, wi, c.alpha_x, c.alpha_y, N_PERTURBED, 90_000 + k as u32).iter().map(|s| s.0).collect();
        let hd = half_domain(c, m.pole);
        let (domain, grid): (&dyn Domain, Grid) =
            if c.sphere_grid_resolves(m) { (&SphereDomain, c.sphere_grid()) } else { (&hd, c.half_grid()) };
        let base = pdf64(m.pdf, wi, c.alpha_x, c.alpha_y);
        // The unperturbed pdf passes (sanity of the setup).
        let ok = chi2::test(domain, &dirs, &base, &grid);
        assert!(ok.passes(alpha), "{} {}: the true pdf fails: {}", m.sampler, c.label(), ok.summary());

        // (a) pdf (1 + 0.1 cos theta_o) / normalization.
        let tilt = |w: [f64; 3]| base(w) * (1.0 + 0.1 * w[2] / (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt());
        let norm = chi2::integrate_masked(domain, &tilt, &|_| true, &grid, N_PERTURBED as f64);
        let tilted = |w: [f64; 3]| tilt(w) / norm;
        let r = chi2::test(domain, &dirs, &tilted, &grid);
        runs += 1;
        let _ = writeln!(report, "{} {} tilted (norm {norm:.4}): {}", m.sampler, c.label(), r.summary());
        if r.passes(alpha) {
            accepted.push(format!("{} {} tilted", m.sampler, c.label()));
        }
        // (b) the pdf of a 10 % larger alpha.
        let wider = pdf64(m.pdf, wi, c.alpha_x * 1.1, c.alpha_y * 1.1);
        let r = chi2::test(domain, &dirs, &wider, &grid);
        runs += 1;
        let _ = writeln!(report, "{} {} alpha x 1.1: {}", m.sampler, c.label(), r.summary());
        if r.passes(alpha) {
            accepted.push(format!("{} {} alpha x 1.1", m.sampler, c.label()));
        }
        // (c) the other family's pdf.
        let other: Option<PdfFn> = match m.sampler {
            "sample_vndf_bounded" => Some(vndf::pdf_vndf_caps),
            "sample_vndf_caps" | "sample_vndf_heitz" => Some(vndf::pdf_vndf_bounded),
            _ => Some(vndf::pdf_vndf_heitz),
        };
        if let Some(o) = other {
            let r = chi2::test(domain, &dirs, &pdf64(o, wi, c.alpha_x, c.alpha_y), &grid);
            runs += 1;
            let _ = writeln!(report, "{} {} other family's pdf: {}", m.sampler, c.label(), r.summary());
            if r.passes(alpha) {
                accepted.push(format!("{} {} other family's pdf", m.sampler, c.label()));
            }
        }
    }
    eprintln!("{report}");
    assert_eq!(runs, PERTURBED_TESTS, "update PERTURBED_TESTS");
    assert!(accepted.is_empty(), "perturbed pdfs accepted: {accepted:?}\n{report}");
}

/// Eto & Tokuyoshi's cap must contain the stretched reflection of every direction above the
/// horizon (with the anisotropic rule alpha = min(alpha_x, alpha_y, 1)); otherwise the bounded
/// sampler could never produce it and would be biased. Dense grid of wi, wo and alphas.
#[test]
fn bounded_cap_contains_the_upper_hemisphere() {
    let alphas = [1e-3f32, 0.01, 0.05, 0.1, 0.3, 0.6, 0.9, 1.0, 1.5, 3.0];
    let mut checked = 0u64;
    let mut outside = Vec::new();
    for &ax in &alphas {
        for &ay in &alphas {
            for it in 0..24 {
                let ti = (it as f64 + 0.5) / 24.0 * 89.95f64.to_radians();
                for ip in 0..8 {
                    let pi = ip as f64 / 8.0 * std::f64::consts::TAU + 0.1;
                    let wi = Vec3::new((ti.sin() * pi.cos()) as f32, (ti.sin() * pi.sin()) as f32, ti.cos() as f32);
                    let (k, one_minus_k) = vndf::bounded_vndf_k_pair(wi, ax, ay);
                    for ot in 0..48 {
                        // Up to 1e-3 degrees above the horizon, the cap's tight edge.
                        let to = (ot as f64 / 47.0) * (90.0f64 - 1e-3).to_radians();
                        for op in 0..64 {
                            let po = op as f64 / 64.0 * std::f64::consts::TAU;
                            let wo = Vec3::new((to.sin() * po.cos()) as f32, (to.sin() * po.sin()) as f32, to.cos() as f32);
                            let h = wi + wo;
                            if shader_core::ndf::ggx_d(h, ax, ay) == 0.0 {
                                continue;
                            }
                            checked += 1;
                            if !vndf::bounded_cap_contains(wi, h, ax, ay, one_minus_k) && outside.len() < 10 {
                                outside.push((wi, wo, ax, ay, k));
                            }
                        }
                    }
                }
            }
        }
    }
    eprintln!("checked {checked} (wi, wo, alpha) triples");
    assert!(outside.is_empty(), "reflections above the horizon outside the bounded cap: {outside:?}");
}
