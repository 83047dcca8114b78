//! Checks an adapter's division and square root against correct rounding (IEEE 754-2019 §5.4.1) on the inputs where an approximate one shows: the guard of `HOST_DIV_SQRT=auto`.
//!
//! The probe runs the evaluable function `arith_probe` (`a + b`, `a - b`, `a * b`,
//! `shader_core::ieee::{div, sqrt, rsqrt}`) of the loaded main module over [`probe_rows`] and
//! compares every result with the CPU's own `a / b`, `a.sqrt()`, `1 / a.sqrt()` (x86-64 `divss`,
//! `sqrtss`, correctly rounded): bits must be equal, NaNs must be NaN. In the native build the
//! kernel's division and square root are the driver's `OpFDiv` and GLSL.std.450 `Sqrt`, which
//! Vulkan allows to be 2.5 ULP and ~2 ULP off, so the probe is how `auto` refuses a driver whose
//! division is a reciprocal times a Newton step, flushes denormals or breaks ties the wrong way.
//! A probe cannot prove correct rounding for every input: `auto` takes the native build only on a
//! driver also known to lower these instructions to the CPU's IEEE instructions (llvmpipe), and
//! the cross-check suite, which CI runs with both builds, is the proof there.

use crate::device::{groups_2d, GpuDevice, OutputSpec};
use crate::gpu_error::GpuError;
use shader_kernels::eval::EvalArgs;

/// Where the adapter and the CPU differ.
#[derive(Clone, Debug, Default)]
pub struct ProbeReport {
    /// Rows compared.
    pub rows: usize,
    /// Rows whose quotient, square root or reciprocal square root (or sum, difference, product)
    /// differ from the CPU's.
    pub differing: usize,
    /// The first differing row, described.
    pub first: Option<String>,
}

impl ProbeReport {
    pub fn passed(&self) -> bool {
        self.differing == 0 && self.rows > 0
    }
}

/// The (a, b) pairs, flattened: special values against each other; operands next to 1 and to
/// powers of two, also scaled towards both ends of the exponent range; denormal operands and
/// quotients; quotients and square roots within an ULP of a rounding midpoint (where a
/// division that is not correctly rounded goes wrong first); and random bit patterns.
pub fn probe_rows() -> Vec<f32> {
    let mut rows: Vec<f32> = Vec::new();
    let mut push = |a: f32, b: f32| rows.extend_from_slice(&[a, b]);
    let specials = [
        0.0, -0.0, 1.0, -1.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, f32::from_bits(1),
        f32::from_bits(0x807f_ffff), f32::MIN_POSITIVE, f32::MAX, -f32::MAX, 3.0, 1e-40, 7e37, 0.1,
    ];
    for &a in &specials {
        for &b in &specials {
            push(a, b);
        }
    }
    let p2 = |k: i32| f32::from_bits(((k + 127) as u32) << 23);
    for i in 0..512u32 {
        for j in 0..32u32 {
            let a = f32::from_bits(0x3f80_0000 - 256 + i);
            let b = f32::from_bits(0x3f80_0000 - 16 + j);
            push(a, b);
            push(b, a);
            push(a * p2(-100), b * p2(30));
            push(a * p2(100), b * p2(-30));
        }
    }
    // xorshift64*: deterministic, so a failure names the same rows on every run.
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        (state.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 32) as u32
    };
    for _ in 0..8192 {
        // Denormal operands, and normal operands whose quotient is denormal.
        let d = f32::from_bits(next() & 0x807f_ffff);
        let n = f32::from_bits((next() & 0x807f_ffff) | 0x3f80_0000);
        push(d, n);
        push(n, d);
        push(d, f32::from_bits(next() & 0x007f_ffff | 0x0080_0000));
        push(f32::from_bits((next() & 0x007f_ffff) | 0x0100_0000), f32::from_bits((next() & 0x007f_ffff) | 0x4c00_0000));
    }
    for _ in 0..32768 {
        // a = RN(b (q + ulp(q) / 2)): a / b lies within about an ULP of the midpoint above q.
        let b = f32::from_bits((next() & 0x007f_ffff) | 0x3f80_0000);
        let q = f32::from_bits((next() & 0x007f_ffff) | 0x3f80_0000);
        let mid = q as f64 + (f32::from_bits(q.to_bits() + 1) as f64 - q as f64) / 2.0;
        push((mid * b as f64) as f32, b);
        // a = RN((s + ulp(s) / 2)^2): sqrt(a) lies next to the midpoint above s.
        let s = f32::from_bits((next() & 0x007f_ffff) | 0x3f80_0000);
        let mid = s as f64 + (f32::from_bits(s.to_bits() + 1) as f64 - s as f64) / 2.0;
        push((mid * mid) as f32, 1.0);
    }
    for _ in 0..65536 {
        push(f32::from_bits(next()), f32::from_bits(next()));
    }
    rows
}

/// The CPU's results for one row, in `arith_probe`'s output order.
fn expected(a: f32, b: f32) -> [f32; 6] {
    use std::hint::black_box;
    let (a, b) = (black_box(a), black_box(b));
    [a + b, a - b, a * b, a / b, a.sqrt(), 1.0 / a.sqrt()]
}

/// Run the probe on `gpu`'s loaded main module.
pub fn run(gpu: &GpuDevice) -> Result<ProbeReport, GpuError> {
    let input = probe_rows();
    let got = run_rows(gpu, &input)?;
    Ok(compare(&input, &got))
}

/// `arith_probe`'s six outputs per row for the (a, b) pairs `input` (flattened), on `gpu`.
pub fn run_rows(gpu: &GpuDevice, input: &[f32]) -> Result<Vec<f32>, GpuError> {
    let f = shader_kernels::eval::find("arith_probe").expect("arith_probe is registered");
    let rows = input.len() / 2;
    let wg = shader_kernels::WORKGROUP_SIZE as usize;
    let (gx, gy) = groups_2d(rows.div_ceil(wg) as u32);
    let args = EvalArgs { rows: rows as u32, groups_x: gx };
    let (out, _) = gpu.dispatch(f.entry, &[bytemuck::bytes_of(&args), bytemuck::cast_slice(input)], &[OutputSpec::zeroed(rows * 6 * 4)], (gx, gy, 1))?;
    Ok(bytemuck::pod_collect_to_vec(&out[0]))
}

/// Compare `got` (`arith_probe`'s six outputs per row) with the CPU's results for `input`,
/// computed on the CPU backend's threads ([`crate::cpu::on_backend_threads`]): where the GPU
/// backend made them flush denormals (`float_controls`: a device that flushes), the expectation
/// is the flushed one.
pub fn compare(input: &[f32], got: &[f32]) -> ProbeReport {
    use rayon::prelude::*;
    let names = ["a + b", "a - b", "a * b", "a / b", "sqrt(a)", "1 / sqrt(a)"];
    let rows = input.len() / 2;
    let expected: Vec<[f32; 6]> = crate::cpu::on_backend_threads(|| input.par_chunks_exact(2).map(|p| expected(p[0], p[1])).collect());
    let mut report = ProbeReport { rows, ..Default::default() };
    if got.len() != rows * 6 {
        report.differing = rows;
        report.first = Some(format!("the adapter returned {} values for {rows} rows x 6 outputs", got.len()));
        return report;
    }
    for (r, (pair, want)) in input.chunks_exact(2).zip(&expected).enumerate() {
        let have = &got[r * 6..r * 6 + 6];
        let bad = (0..6).find(|&k| if want[k].is_nan() { !have[k].is_nan() } else { have[k].to_bits() != want[k].to_bits() });
        if let Some(k) = bad {
            report.differing += 1;
            if report.first.is_none() {
                report.first = Some(format!(
                    "{} with a = {:e} ({:#010x}), b = {:e} ({:#010x}): adapter {:e} ({:#010x}), correctly rounded {:e} ({:#010x})",
                    names[k], pair[0], pair[0].to_bits(), pair[1], pair[1].to_bits(), have[k], have[k].to_bits(), want[k], want[k].to_bits()
                ));
            }
        }
    }
    report
}

/// Drivers known to lower `OpFDiv` and GLSL.std.450 `Sqrt` to the CPU's correctly rounded
/// instructions: Mesa llvmpipe (lavapipe) emits LLVM `fdiv` and `llvm.sqrt`, which LLVM turns
/// into `divps`/`sqrtps` (x86-64) or `fdiv`/`fsqrt` (AArch64) without fast-math flags.
pub fn known_correctly_rounded(info: &wgpu::AdapterInfo) -> bool {
    info.driver == "llvmpipe" && info.device_type == wgpu::DeviceType::Cpu
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_hold_the_hard_cases() {
        let rows = probe_rows();
        assert_eq!(rows.len() % 2, 0);
        let pairs: Vec<(f32, f32)> = rows.chunks_exact(2).map(|p| (p[0], p[1])).collect();
        assert!(pairs.len() > 150_000, "{} rows", pairs.len());
        // Denormal quotients, denormal operands, NaN and infinite operands are all there.
        assert!(pairs.iter().any(|&(a, b)| { let q = a / b; q != 0.0 && q.abs() < f32::MIN_POSITIVE }));
        assert!(pairs.iter().any(|&(a, _)| a != 0.0 && a.abs() < f32::MIN_POSITIVE));
        assert!(pairs.iter().any(|&(a, b)| a.is_nan() || b.is_nan()));
        assert!(pairs.iter().any(|&(_, b)| b.is_infinite()));
        // Near-midpoint quotients: a / b in f64 within 1.5 ULP of a midpoint of the f32 grid.
        let near_mid = pairs
            .iter()
            .filter(|&&(a, b)| {
                let q = a as f64 / b as f64;
                if !(q.is_finite() && q > 0.5 && q < 2.0) {
                    return false;
                }
                let f = q as f32;
                let ulp = f32::from_bits(f.to_bits() + 1) as f64 - f as f64;
                let frac = ((q - f as f64) / ulp).abs();
                (frac - 0.5).abs() < 1e-3
            })
            .count();
        assert!(near_mid > 1000, "{near_mid} quotients next to a midpoint");
    }

    fn cpu_outputs(rows: &[f32], div: impl Fn(f32, f32) -> f32, sqrt: impl Fn(f32) -> f32) -> Vec<f32> {
        rows.chunks_exact(2)
            .flat_map(|p| {
                let (a, b) = (std::hint::black_box(p[0]), std::hint::black_box(p[1]));
                [a + b, a - b, a * b, div(a, b), sqrt(a), div(1.0, sqrt(a))]
            })
            .collect()
    }

    /// The correctly rounded operations pass; a division that is a reciprocal times the
    /// dividend (what a driver may do under the 2.5 ULP rule), one that flushes denormal
    /// results, and a square root one ULP off at the midpoints are each refused on many rows.
    #[test]
    fn approximate_operations_fail_the_probe() {
        let rows = probe_rows();
        let exact = compare(&rows, &cpu_outputs(&rows, |a, b| a / b, f32::sqrt));
        assert!(exact.passed(), "{:?}", exact.first);
        let recip = compare(&rows, &cpu_outputs(&rows, |a, b| a * (1.0 / b), f32::sqrt));
        assert!(recip.differing > 10_000, "reciprocal-times-dividend differs on only {} rows", recip.differing);
        assert!(recip.first.as_deref().unwrap().starts_with("a / b"), "{:?}", recip.first);
        let ftz = |a: f32, b: f32| { let q = a / b; if q != 0.0 && q.abs() < f32::MIN_POSITIVE { 0.0 * q } else { q } };
        let flushed = compare(&rows, &cpu_outputs(&rows, ftz, f32::sqrt));
        assert!(flushed.differing > 1000, "flushing denormal quotients differs on only {} rows", flushed.differing);
        // sqrt computed as x * rsqrt(x) in f32 (two roundings).
        let two_step = |x: f32| x * (1.0 / x.sqrt());
        let sq = compare(&rows, &cpu_outputs(&rows, |a, b| a / b, two_step));
        assert!(sq.differing > 1000, "a two-rounding square root differs on only {} rows", sq.differing);
        let short = compare(&rows, &[]);
        assert!(!short.passed());
    }
}
