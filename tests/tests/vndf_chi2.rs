//! Statistical tests of the reflection samplers of `shader_core::vndf` (docs/vndf.md):
//!
//! * chi-square goodness of fit (`crosscheck::chi2`) of every sampler against its own pdf, over
//!   78 configurations (theta_i 0 .. 89.9 degrees and back-facing, alpha 1e-3 .. 2, anisotropy
//!   20:1 both ways, a generic azimuth), in the stretched half-vector parameterization (all
//!   configurations) and in Mitsuba's (cos theta, phi) parameterization of wo (min alpha >= 0.05,
//!   where a sphere grid resolves the lobe), at significance 0.01 Bonferroni-corrected over every
//!   chi-square test of this file;
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

    /// Mitsuba's sphere grid resolves the lobe.
    fn sphere_grid_resolves(&self) -> bool {
        self.alpha_x.min(self.alpha_y) >= 0.05
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
    /// sample by more than 1e-3 of the lobe width (theta_i >= 89 degrees with alpha <= 0.01): a
    /// fine grid there measures the precision of f32, not the sampler.
    fn half_grid(&self) -> Grid {
        if self.f32_resolution() > 1e-3 {
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

/// theta_i 0 .. 89.9 at a generic azimuth x 11 roughness pairs, plus 12 back-facing cases.
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
    let per_method = c.len() + c.iter().filter(|c| c.sphere_grid_resolves()).count();
    METHODS.len() * per_method + PERTURBED_TESTS
}

fn level() -> f64 {
    SIGNIFICANCE / total_tests() as f64
}

fn pdf64(pdf: PdfFn, wi: [f32; 3], ax: f32, ay: f32) -> impl Fn([f64; 3]) -> f64 + Sync {
    let wi = Vec3::new(wi[0], wi[1], wi[2]);
    move |w: [f64; 3]| f64::from(pdf(wi, Vec3::new(w[0] as f32, w[1] as f32, w[2] as f32), ax, ay))
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
        let pdf = pdf64(m.pdf, wi, c.alpha_x, c.alpha_y);

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
        // Mitsuba's (cos theta, phi) grid over wo, where it resolves the lobe.
        let sgrid = c.sphere_grid();
        if c.sphere_grid_resolves() {
            let r = chi2::test(&SphereDomain, &dirs, &pdf, &sgrid);
            let _ = writeln!(log, "  {} sphere:         {}", c.label(), r.summary());
            if !r.passes(alpha) {
                failures.push(format!("{} sphere domain: {}", c.label(), r.summary()));
            }
            if (r.integral - 1.0).abs() > 2e-3 {
                failures.push(format!("{} pdf integrates to {} over the sphere (sphere grid)", c.label(), r.integral));
            }
        }

        // Upper-hemisphere mass vs the fraction of samples kept. The horizon is a row edge of the
        // sphere grid; for narrower lobes the half-vector grid refines along it.
        let kept = dirs.iter().filter(|d| d[2] > 0.0).count() as f64 / N as f64;
        let upper = if c.sphere_grid_resolves() {
            chi2::integrate_masked(&SphereDomain, &pdf, &|w| w[2] > 0.0, &sgrid, N as f64)
        } else {
            chi2::integrate_masked(&hd, &pdf, &|w| w[2] > 0.0, &hgrid, N as f64)
        };
        let sigma = (kept * (1.0 - kept) / N as f64).sqrt();
        let _ = writeln!(log, "    kept {kept:.5}, upper-hemisphere integral {upper:.5}");
        if (upper - kept).abs() > 5.0 * sigma + 1e-3 {
            failures.push(format!("{}: kept fraction {kept} but the pdf's upper-hemisphere integral is {upper}", c.label()));
        }

        // The pdf returned with a sample agrees with the pdf function there, to within what the
        // rounding of wo to f32 allows (pdf_condition); the bounded cap's edge may flip a few.
        let (mut worst, mut violations, mut ill) = (0.0f64, 0usize, 0usize);
        let wi_v = Vec3::new(wi[0], wi[1], wi[2]);
        let amin = c.alpha_x.min(c.alpha_y);
        for (wo, p) in &samples {
            let q = (m.pdf)(wi_v, Vec3::new(wo[0], wo[1], wo[2]), c.alpha_x, c.alpha_y);
            if *p == 0.0 && q == 0.0 {
                continue;
            }
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
            "    pdf agreement: {violations} beyond 1e-4 + 10 x condition, worst within {worst:.2e}, {ill} samples with condition > 1e-4"
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

/// Number of chi-square runs in [`suite_rejects_perturbed_pdfs`] (part of the Bonferroni count).
const PERTURBED_TESTS: usize = 12;

/// The suite must reject a density that is slightly wrong: samples of each VNDF method against
/// (a) its pdf times (1 + 0.1 cos theta_o), renormalized, (b) its pdf with alpha 10 % larger,
/// (c) for bounded vs caps, the other method's pdf; NDF sampling against (a) and (b).
#[test]
fn suite_rejects_perturbed_pdfs() {
    let alpha = level();
    let configs = [
        (HEITZ, Case { theta_deg: 60.0, phi_deg: 35.0, alpha_x: 0.3, alpha_y: 0.1 }),
        (CAPS, Case { theta_deg: 89.0, phi_deg: 35.0, alpha_x: 0.05, alpha_y: 1.0 }),
        (BOUNDED, Case { theta_deg: 80.0, phi_deg: 35.0, alpha_x: 0.5, alpha_y: 0.5 }),
        (NDF, Case { theta_deg: 30.0, phi_deg: 35.0, alpha_x: 0.2, alpha_y: 0.2 }),
    ];
    let mut runs = 0;
    let mut report = String::new();
    let mut accepted = Vec::new();
    for (k, (m, c)) in configs.iter().enumerate() {
        let wi = c.wi();
        let dirs: Vec<[f32; 3]> =
            chi2::draw(&Backend::Cpu, m.sampler, wi, c.alpha_x, c.alpha_y, N, 90_000 + k as u32).iter().map(|s| s.0).collect();
        let hd = half_domain(c, m.pole);
        let (domain, grid): (&dyn Domain, Grid) =
            if c.sphere_grid_resolves() { (&SphereDomain, c.sphere_grid()) } else { (&hd, c.half_grid()) };
        let base = pdf64(m.pdf, wi, c.alpha_x, c.alpha_y);
        // The unperturbed pdf passes (sanity of the setup).
        let ok = chi2::test(domain, &dirs, &base, &grid);
        assert!(ok.passes(alpha), "{} {}: the true pdf fails: {}", m.sampler, c.label(), ok.summary());

        // (a) pdf (1 + 0.1 cos theta_o) / normalization.
        let tilt = |w: [f64; 3]| base(w) * (1.0 + 0.1 * w[2] / (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt());
        let norm = chi2::integrate_masked(domain, &tilt, &|_| true, &grid, N as f64);
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
