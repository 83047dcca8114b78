//! Energy compensation (docs/energy.md): the precomputed tables against the independent f64
//! quadrature reference, the white furnace with and without compensation on the whole table
//! grid, published values, the Sobol third dimension, and argument checking.

use host::energy::{self, Compensation, FurnaceConfig, Sequence, TableSpec, Tables};
use host::energy_ref::{self, Quadrature};
use host::Backend;
use shader_core::energy as ce;
use std::sync::OnceLock;

const N: u32 = 32;

/// The reference tables on the 32x32 grid (shared by the tests of this binary).
fn reference() -> &'static (Vec<f64>, Vec<f64>, Vec<f64>) {
    static R: OnceLock<(Vec<f64>, Vec<f64>, Vec<f64>)> = OnceLock::new();
    R.get_or_init(|| energy_ref::tables(N as usize, N as usize, N as usize, &Quadrature::default()))
}

/// The default tables (32x32, 4096 Sobol samples, E_avg 16384) on the CPU backend.
fn tables() -> &'static Tables {
    static T: OnceLock<Tables> = OnceLock::new();
    T.get_or_init(|| energy::precompute(&Backend::Cpu, &TableSpec::default(), None).unwrap().0)
}

#[test]
fn reference_quadrature_converged() {
    let q = Quadrature::default();
    let mut worst: f64 = 0.0;
    for &mu in &[1e-4, 1.0 / 64.0, 0.1, 0.5, 0.99] {
        for &r in &[1.0 / 64.0, 0.1, 0.3, 0.6, 1.0] {
            let a = energy_ref::albedo(mu, r * r, &q);
            let b = energy_ref::albedo(mu, r * r, &q.doubled());
            let d = (a.0 - b.0).abs().max((a.1 - b.1).abs());
            worst = worst.max(d);
        }
    }
    let a = energy_ref::albedo_avg(1.0, &q);
    let b = energy_ref::albedo_avg(1.0, &q.doubled());
    eprintln!("reference: max change when doubling the nodes: E/E' {worst:.2e}, E_avg(alpha=1) {:.2e}", (a - b).abs());
    // Measured: 1.4e-6 at mu = 1e-4 (the grazing clamp), < 6e-8 at every other point.
    assert!(worst < 5e-6, "E/E' quadrature not converged: {worst:e}");
    assert!((a - b).abs() < 1e-7);
}

#[test]
fn tables_match_f64_reference() {
    let t = tables();
    let r = reference();
    let err = host::energy_bench::table_error(t, r);
    let mut worst = (0.0f64, 0usize);
    for (k, (a, b)) in t.e.iter().zip(&r.0).enumerate() {
        let d = (f64::from(*a) - b).abs();
        if d > worst.0 {
            worst = (d, k);
        }
    }
    eprintln!(
        "32x32, 4096 Sobol samples vs f64 reference: E max {:.2e} (cell mu {} r {}), RMS {:.2e}; E' max {:.2e}; E_avg max {:.2e}",
        err.e_max,
        worst.1 % 32,
        worst.1 / 32,
        err.e_rms,
        err.ep_max,
        err.avg_max
    );
    for j in [0usize, 8, 16, 31] {
        eprintln!("  r_{j}: E(mu_0) {:.5} ref {:.5}; E(mu_31) {:.5} ref {:.5}; E_avg {:.5} ref {:.5}", t.e[j * 32], r.0[j * 32], t.e[j * 32 + 31], r.0[j * 32 + 31], t.e_avg[j], r.2[j]);
    }
    // Measured: E 4.5e-4, E' 2.3e-4, E_avg 1.8e-4 (docs/energy.md).
    assert!(err.e_max < 1e-3 && err.ep_max < 1e-3 && err.avg_max < 5e-4, "{err:?}");
}


/// The F = 1 metal furnace on the 32x32 table grid (4096 Sobol samples per cell).
fn furnace_grid(lut: &[f32], mode: Compensation, metallic: f32, min_roughness: f32) -> Vec<f32> {
    let cfg = FurnaceConfig { mode, metallic, base: 1.0, samples: 4096, seq: Sequence::Sobol, seed: 7, min_roughness };
    energy::furnace_grid(&Backend::Cpu, lut, &cfg, N, N).unwrap()
}

fn worst_deviation(a: &[f32], want: impl Fn(usize) -> f64) -> (f64, usize) {
    a.iter().enumerate().map(|(k, v)| ((f64::from(*v) - want(k)).abs(), k)).fold((0.0, 0), |m, x| if x.0 > m.0 { x } else { m })
}

/// Done-criterion 1: with Kulla-Conty or Turquin compensation and F = 1 the directional albedo
/// is 1 within 1 % at every (mu, roughness) of the table grid (threshold included); without
/// compensation it follows the loss curve E(mu) of the f64 reference; the dielectric (base 1,
/// diffuse scaled by 1 - E'') is 1 within 1 % too.
#[test]
fn furnace_albedo_is_one_with_compensation() {
    let lut = tables().lut_buffer();
    let r = reference();
    for mode in [Compensation::KullaConty, Compensation::Turquin] {
        for metallic in [1.0f32, 0.0] {
            let a = furnace_grid(&lut, mode, metallic, ce::COMPENSATION_MIN_ROUGHNESS);
            let (d, k) = worst_deviation(&a, |_| 1.0);
            eprintln!("{} metallic {metallic}: max |albedo - 1| = {d:.2e} at mu_{} r_{}", mode.label(), k % 32, k / 32);
            assert!(d < 0.01, "{} metallic {metallic}: albedo {} at cell {k}", mode.label(), a[k]);
        }
    }
    let a = furnace_grid(&lut, Compensation::None, 1.0, 0.0);
    let (d, k) = worst_deviation(&a, |k| r.0[k]);
    let loss = (0..a.len()).map(|k| 1.0 - r.0[k]).fold(0.0, f64::max);
    eprintln!("no compensation, metal: max |albedo - E_ref| = {d:.2e} at cell {k} (loss up to {loss:.3})");
    assert!(d < 3e-3, "uncompensated albedo does not follow the loss curve: {d}");
    assert!(loss > 0.5, "the loss curve should reach > 50 % at roughness 1");
}

/// The checks above can fail: a wrong E_avg (2 % low) breaks Kulla-Conty's conservation, and a
/// table built with E in place of E' is far from the reference.
#[test]
fn perturbed_formulas_fail() {
    let t = tables();
    let mut lut = t.lut_buffer();
    let off = ce::LUT_HEADER + 2 * t.e.len();
    for v in &mut lut[off..] {
        *v *= 0.98;
    }
    let a = furnace_grid(&lut, Compensation::KullaConty, 1.0, ce::COMPENSATION_MIN_ROUGHNESS);
    let (d, _) = worst_deviation(&a, |_| 1.0);
    eprintln!("Kulla-Conty with E_avg 2 % low: max |albedo - 1| = {d:.3}");
    assert!(d > 0.01);
    // The Monte-Carlo E_avg (the true integral) instead of the LUT-consistent one overshoots
    // at grazing mu for low roughness (why the LUT carries the consistent one).
    let mut lut = t.lut_buffer();
    lut[off..].copy_from_slice(&t.e_avg);
    let a = furnace_grid(&lut, Compensation::KullaConty, 1.0, ce::COMPENSATION_MIN_ROUGHNESS);
    let (d, k) = worst_deviation(&a, |_| 1.0);
    eprintln!("Kulla-Conty with the Monte-Carlo E_avg: max |albedo - 1| = {d:.4} at mu_{} r_{}", k % 32, k / 32);
    let gap = t.e_avg.iter().zip(t.lut_consistent_e_avg()).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
    eprintln!("max |E_avg (Monte Carlo) - E_avg (LUT-consistent)| = {gap:.2e}");
    let mut t = tables().clone();
    t.e_prime = t.e.clone();
    let err = host::energy_bench::table_error(&t, reference());
    assert!(err.ep_max > 0.1, "{err:?}");
}

/// Decode an IEEE binary16 (the published table's storage format).
fn half(bits: u16) -> f64 {
    let e = i32::from((bits >> 10) & 0x1f);
    let m = f64::from(bits & 0x3ff);
    let v = if e == 0 { m * 2f64.powi(-24) } else { (1.0 + m / 1024.0) * 2f64.powi(e - 15) };
    if bits & 0x8000 != 0 { -v } else { v }
}

/// Published split-sum table: three.js `src/nodes/functions/BSDF/DFGLUT.js` (mrdoob/three.js,
/// 16x16 RG16F, 4096 samples per texel, sampled at uv = (roughness, N.V), clamp to edge), whose
/// (scale, bias) are Filament's (DFG1, DFG2) = (E - E', E'). Texel (row, col) = (N.V, roughness)
/// cell centers. Values at documented points, against our f64 reference; tolerance 2e-3 (their
/// half-float rounding, 2.4e-4 near 0.5..1, plus their Monte-Carlo noise). Near grazing (N.V =
/// 1/32, row 0) the published E is up to 1.5 % lower than the reference (docs/energy.md).
#[test]
fn published_dfg_values() {
    const POINTS: [(u32, u32, u16, u16); 7] = [
        (1, 1, 0x364a, 0x38ce),
        (3, 12, 0x39be, 0x273c),
        (7, 7, 0x3ac2, 0x27b7),
        (8, 15, 0x3762, 0x19dd),
        (12, 4, 0x3bea, 0x1428),
        (15, 8, 0x3b1d, 0x05d4),
        (15, 15, 0x3586, 0x049f),
    ];
    let q = Quadrature::default();
    for (row, col, scale, bias) in POINTS {
        let mu = (f64::from(row) + 0.5) / 16.0;
        let r = (f64::from(col) + 0.5) / 16.0;
        let (e, ep) = energy_ref::albedo(mu, r * r, &q);
        let (pe, pep) = (half(scale) + half(bias), half(bias));
        eprintln!("N.V {mu:.4} r {r:.4}: published E {pe:.5} E' {pep:.5}; reference E {e:.5} E' {ep:.5}");
        assert!((pe - e).abs() < 2e-3 && (pep - ep).abs() < 2e-3, "N.V {mu} r {r}");
    }
}

/// Sobol dimension 3 (x^2 + x + 1, m = 1, 3): the first points of the unscrambled sequence
/// (index order; Gray-code order gives scipy's 0, .5, .25, .75, .625, ...).
#[test]
fn sobol_dim3_points() {
    let want = [0.0, 0.5, 0.75, 0.25, 0.375, 0.875, 0.625, 0.125];
    for (i, w) in want.iter().enumerate() {
        assert_eq!(ce::sobol_dim3(i as u32, 0), *w as f32, "point {i}");
    }
    // Every dyadic interval of length 1/64 holds exactly one of the first 64 points.
    let mut seen = [false; 64];
    for i in 0..64 {
        let k = (ce::sobol_dim3(i, 0) * 64.0) as usize;
        assert!(!seen[k]);
        seen[k] = true;
    }
}

#[test]
fn bad_arguments_are_rejected() {
    let ok = TableSpec::default();
    for bad in [
        TableSpec { n_mu: 0, ..ok },
        TableSpec { samples: 0, ..ok },
        TableSpec { chunk: 0, ..ok },
        TableSpec { n_avg: 5000, ..ok },
    ] {
        assert!(energy::precompute(&Backend::Cpu, &bad, None).is_err(), "{bad:?}");
    }
    let lut = tables().lut_buffer();
    let cfg = FurnaceConfig { mode: Compensation::KullaConty, metallic: f32::NAN, base: 1.0, samples: 4, seq: Sequence::Pcg, seed: 0, min_roughness: 0.0 };
    assert!(energy::furnace_grid(&Backend::Cpu, &lut, &cfg, 4, 4).is_err());
    assert!(energy::furnace_grid(&Backend::Cpu, &lut, &FurnaceConfig { samples: 0, metallic: 1.0, ..cfg }, 4, 4).is_err());
    assert!(Tables::from_words(&lut).is_err());
    // LUT lookups: NaN in, NaN out; out-of-range coordinates hold the value at the edge of the
    // domain (mu, r in [0, 1]; the outer half cells extrapolate, see energy::cell_taps).
    assert!(ce::lut_e(&lut, f32::NAN, 0.5).is_nan());
    assert_eq!(ce::lut_e(&lut, -3.0, 0.5), ce::lut_e(&lut, 0.0, 0.5));
    assert_eq!(ce::lut_e(&lut, 3.0, 0.5), ce::lut_e(&lut, 1.0, 0.5));
    assert_eq!(ce::lut_e(&lut, 0.5, 7.0), ce::lut_e(&lut, 0.5, 1.0));
    assert_eq!(ce::lut_e_avg(&lut, 7.0), ce::lut_e_avg(&lut, 1.0));
    assert_eq!(ce::lut_e_avg(&lut, -7.0), ce::lut_e_avg(&lut, 0.0));
    // At a cell centre the lookup is the stored value.
    let (n_mu, n_r, _) = ce::lut_dims(&lut);
    let (at, stored) = (ce::lut_e(&lut, ce::cell_center(5, n_mu), ce::cell_center(7, n_r)), tables().e[(7 * n_mu + 5) as usize]);
    assert!((at - stored).abs() <= 1e-6 * stored.abs(), "lookup at a cell centre {at}, stored {stored}");
    // The paired lookup (taps computed once) is bit for bit the two single lookups, inside the
    // domain, in the extrapolated half cells, outside it and for NaN.
    let mut coords: Vec<f32> = (0..=200).map(|k| k as f32 / 200.0).collect();
    coords.extend([-0.5, -1e-7, 1e-7, 0.5 / n_mu as f32, 0.5 / n_r as f32, 1.0 - 1e-7, 1.0 + 1e-7, 2.0, f32::NAN, f32::INFINITY]);
    for &mu in &coords {
        for &r in &coords {
            let (e, ep) = ce::lut_e_and_e_prime(&lut, mu, r);
            assert_eq!((e.to_bits(), ep.to_bits()), (ce::lut_e(&lut, mu, r).to_bits(), ce::lut_e_prime(&lut, mu, r).to_bits()), "mu {mu}, r {r}");
        }
    }
    // The binary form round-trips.
    let dir = std::env::temp_dir().join(format!("energy_lut_{}", std::process::id()));
    let path = dir.join("t.bin");
    tables().write_bin(&path).unwrap();
    assert_eq!(&Tables::read_bin(&path).unwrap(), tables());
    let _ = std::fs::remove_dir_all(dir);
}
