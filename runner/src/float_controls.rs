//! The adapter's fp32 denormal behaviour (`VkPhysicalDeviceFloatControlsProperties`, Vulkan 1.2)
//! and the policy the GPU backend applies to the SPIR-V it loads.
//!
//! Without a declared mode a Vulkan driver may flush denormal operands and results of any
//! instruction or keep them, so the CPU (which keeps them) and the GPU could differ on every value
//! below 2^-126. Policy, per adapter:
//! * `shaderDenormPreserveFloat32`: declare `DenormPreserve` (32-bit) on every entry point;
//!   results match the CPU bit for bit, denormals included.
//! * else `shaderDenormFlushToZeroFloat32`: declare `DenormFlushToZero` and set FTZ/DAZ in MXCSR
//!   on the CPU backend's rayon threads for the rest of the run, so both flush (the software
//!   `shader_core::ieee` routines then see flushed operands on both sides too).
//! * else: neither mode can be declared, so the backend measures what the driver does
//!   ([`measure`]: `a + b`, `a - b`, `a * b` on denormal operands and results): all kept, the
//!   CPU is left alone; all flushed exactly as FTZ/DAZ would (NVIDIA's driver flushes, seen on an
//!   H200), the CPU backend's threads flush too, as for a declared flush; anything else stays
//!   unspecified and the GPU may differ from the CPU wherever a denormal appears.

use shader_manifest::DenormMode;
use shader_core::ieee::flush_denormals_on_this_thread;

/// The fp32 fields of `VkPhysicalDeviceFloatControlsProperties`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FloatControls {
    pub denorm_preserve_f32: bool,
    pub denorm_flush_to_zero_f32: bool,
    pub signed_zero_inf_nan_preserve_f32: bool,
    /// `denormBehaviorIndependence`: "32-bit only", "all", or "none" (widths share one mode).
    pub denorm_independence: &'static str,
}

/// What the GPU backend does about denormals on one adapter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DenormPolicy {
    /// `DenormPreserve` declared: denormals kept on both backends.
    Preserve,
    /// `DenormFlushToZero` declared and the CPU backend flushes too (FTZ/DAZ).
    FlushToZero,
    /// Neither mode supported (or the properties could not be read): unspecified on the GPU,
    /// and the probe found neither behaviour throughout (or has not run).
    Unspecified,
    /// Neither mode supported; the probe found every denormal kept.
    MeasuredPreserve,
    /// Neither mode supported; the probe found every denormal operand and result flushed to a
    /// zero of its sign, so the CPU backend flushes too (FTZ/DAZ).
    MeasuredFlush,
}

/// Read the float-controls properties of a Vulkan adapter through wgpu's hal escape hatch;
/// `None` for a non-Vulkan adapter or a device older than Vulkan 1.2.
pub fn query(adapter: &wgpu::Adapter) -> Option<FloatControls> {
    // SAFETY: only read-only queries on the adapter's own instance and physical device, which
    // outlive this call (the guard keeps the hal adapter borrowed).
    unsafe {
        let hal = adapter.as_hal::<wgpu::hal::api::Vulkan>()?;
        let instance = hal.shared_instance().raw_instance();
        let phd = hal.raw_physical_device();
        if hal.physical_device_capabilities().properties().api_version < ash::vk::API_VERSION_1_2 {
            return None;
        }
        let mut fc = ash::vk::PhysicalDeviceFloatControlsProperties::default();
        let mut props = ash::vk::PhysicalDeviceProperties2::default().push_next(&mut fc);
        instance.get_physical_device_properties2(phd, &mut props);
        let independence = match fc.denorm_behavior_independence {
            ash::vk::ShaderFloatControlsIndependence::TYPE_32_ONLY => "32-bit only",
            ash::vk::ShaderFloatControlsIndependence::ALL => "all",
            _ => "none",
        };
        Some(FloatControls {
            denorm_preserve_f32: fc.shader_denorm_preserve_float32 != 0,
            denorm_flush_to_zero_f32: fc.shader_denorm_flush_to_zero_float32 != 0,
            signed_zero_inf_nan_preserve_f32: fc.shader_signed_zero_inf_nan_preserve_float32 != 0,
            denorm_independence: independence,
        })
    }
}

impl DenormPolicy {
    /// The policy for an adapter with these properties (see the module documentation).
    pub fn choose(fc: Option<&FloatControls>) -> Self {
        match fc {
            Some(f) if f.denorm_preserve_f32 => DenormPolicy::Preserve,
            Some(f) if f.denorm_flush_to_zero_f32 => DenormPolicy::FlushToZero,
            _ => DenormPolicy::Unspecified,
        }
    }

    /// The policy for `adapter`.
    pub fn for_adapter(adapter: &wgpu::Adapter) -> Self {
        Self::choose(query(adapter).as_ref())
    }

    /// The SPIR-V with this policy's execution mode declared (unchanged for `Unspecified`).
    pub fn apply(self, words: &[u32]) -> Result<Vec<u32>, String> {
        match self {
            DenormPolicy::Preserve => shader_manifest::declare_denorm_mode(words, DenormMode::Preserve),
            DenormPolicy::FlushToZero => shader_manifest::declare_denorm_mode(words, DenormMode::FlushToZero),
            DenormPolicy::Unspecified | DenormPolicy::MeasuredPreserve | DenormPolicy::MeasuredFlush => Ok(words.to_vec()),
        }
    }

    /// Make the CPU backend follow the policy: for `FlushToZero`, set FTZ and DAZ on every
    /// thread of rayon's global pool (which runs the CPU kernels) for the rest of the process.
    pub fn apply_to_cpu(self) {
        if matches!(self, DenormPolicy::FlushToZero | DenormPolicy::MeasuredFlush) {
            rayon::broadcast(|_| flush_denormals_on_this_thread());
        }
    }

    /// One line for `host info` and the backend description.
    pub fn describe(self) -> &'static str {
        match self {
            DenormPolicy::Preserve => "fp32 denormals preserved (DenormPreserve declared; CPU = GPU bit for bit)",
            DenormPolicy::FlushToZero => {
                "fp32 denormals flushed (DenormFlushToZero declared; the CPU backend flushes too: FTZ/DAZ)"
            }
            DenormPolicy::Unspecified => {
                "fp32 denormal behaviour unspecified (device supports neither DenormPreserve nor DenormFlushToZero)"
            }
            DenormPolicy::MeasuredPreserve => {
                "fp32 denormals preserved (measured: the device supports neither mode, the probe found every denormal kept)"
            }
            DenormPolicy::MeasuredFlush => {
                "fp32 denormals flushed (measured: the device supports neither mode, the probe found every denormal flushed; the CPU backend flushes too: FTZ/DAZ)"
            }
        }
    }
}

/// One line describing an adapter's float controls and the policy chosen for it.
pub fn describe_adapter(adapter: &wgpu::Adapter) -> String {
    match query(adapter) {
        Some(f) => format!(
            "float controls: denormPreserve32 {}, denormFlushToZero32 {}, signedZeroInfNanPreserve32 {}, denorm independence {} -> {}",
            f.denorm_preserve_f32,
            f.denorm_flush_to_zero_f32,
            f.signed_zero_inf_nan_preserve_f32,
            f.denorm_independence,
            match DenormPolicy::choose(Some(&f)) {
                DenormPolicy::Unspecified => "no mode can be declared; the GPU backend measures what the driver does at start-up (its description says)",
                p => p.describe(),
            }
        ),
        None => format!("float controls unavailable (not Vulkan 1.2) -> {}", DenormPolicy::Unspecified.describe()),
    }
}

/// The (a, b) pairs of the denormal probe, flattened: denormal operands (with a zero, with each
/// other, with a normal), sums and products that land well inside the denormal range, and one
/// normal row. No result sits near the smallest normal, where FTZ's tininess rule would matter.
pub fn denormal_rows() -> Vec<f32> {
    let tiny = f32::MIN_POSITIVE; // 2^-126
    vec![
        f32::from_bits(1), 0.0, // 1e-45 + 0
        -1e-40, 0.0,
        1e-38, 1e-38, // two denormals whose sum is normal
        5e-39, -2e-39,
        1.5 * tiny, -tiny, // normal operands, denormal sum
        0.75 * tiny, 3.0,
        2f32.powi(-63), 2f32.powi(-64), // normal operands, product 2^-127
        -(2f32.powi(-70)), 2f32.powi(-60), // product -2^-130
        1.0, 2.0,
    ]
}

/// Zero of `x`'s sign where `x` is denormal.
fn flushed(x: f32) -> f32 {
    if x.is_subnormal() { 0f32.copysign(x) } else { x }
}

/// What the adapter did with the probe's rows: `got` holds `arith_probe`'s six outputs per row
/// (only the sum, difference and product are compared: the division and square root of the
/// native build are the driver's and have their own probe).
pub fn classify(input: &[f32], got: &[f32]) -> Result<DenormPolicy, String> {
    use std::hint::black_box;
    let rows = input.len() / 2;
    if got.len() != rows * 6 {
        return Err(format!("the adapter returned {} values for {rows} rows x 6 outputs", got.len()));
    }
    let (mut kept, mut flush) = (true, true);
    let mut first = None;
    for (r, pair) in input.chunks_exact(2).enumerate() {
        let (a, b) = (black_box(pair[0]), black_box(pair[1]));
        let preserve = [a + b, a - b, a * b];
        let (fa, fb) = (flushed(a), flushed(b));
        let flush_to_zero = [flushed(fa + fb), flushed(fa - fb), flushed(fa * fb)];
        for k in 0..3 {
            let have = got[r * 6 + k].to_bits();
            let (is_kept, is_flushed) = (have == preserve[k].to_bits(), have == flush_to_zero[k].to_bits());
            kept &= is_kept;
            flush &= is_flushed;
            if !is_kept && !is_flushed && first.is_none() {
                first = Some(format!(
                    "{} with a = {a:e}, b = {b:e}: adapter {:e} ({have:#010x}), kept {:e}, flushed {:e}",
                    ["a + b", "a - b", "a * b"][k],
                    f32::from_bits(have),
                    preserve[k],
                    flush_to_zero[k]
                ));
            }
        }
    }
    match (kept, flush) {
        (true, _) => Ok(DenormPolicy::MeasuredPreserve),
        (false, true) => Ok(DenormPolicy::MeasuredFlush),
        _ => Err(first.unwrap_or_else(|| "some denormals kept, others flushed".into())),
    }
}

/// Run the denormal probe (`arith_probe` of the loaded main module over [`denormal_rows`]) and
/// say what the adapter does; an error describes the first row that fits neither behaviour.
pub fn measure(gpu: &crate::device::GpuDevice) -> Result<Result<DenormPolicy, String>, crate::gpu_error::GpuError> {
    let input = denormal_rows();
    let got = crate::div_sqrt_probe::run_rows(gpu, &input)?;
    Ok(classify(&input, &got))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn policy_prefers_preserve_then_flush() {
        let f = |p, z| FloatControls {
            denorm_preserve_f32: p,
            denorm_flush_to_zero_f32: z,
            signed_zero_inf_nan_preserve_f32: true,
            denorm_independence: "all",
        };
        assert_eq!(DenormPolicy::choose(Some(&f(true, true))), DenormPolicy::Preserve);
        assert_eq!(DenormPolicy::choose(Some(&f(false, true))), DenormPolicy::FlushToZero);
        assert_eq!(DenormPolicy::choose(Some(&f(false, false))), DenormPolicy::Unspecified);
        assert_eq!(DenormPolicy::choose(None), DenormPolicy::Unspecified);
    }

    /// `arith_probe`'s outputs for `rows` computed with `op` applied to each (a, b).
    fn outputs(rows: &[f32], op: impl Fn(f32, f32) -> [f32; 3]) -> Vec<f32> {
        rows.chunks_exact(2).flat_map(|p| {
            let [s, d, m] = op(p[0], p[1]);
            [s, d, m, 0.0, 0.0, 0.0]
        }).collect()
    }

    #[test]
    fn probe_tells_kept_from_flushed_from_mixed() {
        let rows = denormal_rows();
        assert!(rows.chunks_exact(2).filter(|p| p[0].is_subnormal() || p[1].is_subnormal()).count() >= 4);
        assert!(rows.chunks_exact(2).filter(|p| (p[0] + p[1]).is_subnormal() || (p[0] * p[1]).is_subnormal()).count() >= 4);
        let kept = outputs(&rows, |a, b| [a + b, a - b, a * b]);
        assert_eq!(classify(&rows, &kept), Ok(DenormPolicy::MeasuredPreserve));
        let ftz_daz = outputs(&rows, |a, b| {
            let (a, b) = (flushed(a), flushed(b));
            [flushed(a + b), flushed(a - b), flushed(a * b)]
        });
        assert_eq!(classify(&rows, &ftz_daz), Ok(DenormPolicy::MeasuredFlush));
        // Flushing results but not operands (FTZ without DAZ) is neither.
        let ftz_only = outputs(&rows, |a, b| [flushed(a + b), flushed(a - b), flushed(a * b)]);
        assert!(classify(&rows, &ftz_only).is_err());
        // Flushing to +0 whatever the sign is neither either.
        let unsigned = outputs(&rows, |a, b| {
            let f = |x: f32| if x.is_subnormal() { 0.0 } else { x };
            let (a, b) = (f(a), f(b));
            [f(a + b), f(a - b), f(a * b)]
        });
        assert!(classify(&rows, &unsigned).is_err());
        assert!(classify(&rows, &kept[..6]).is_err());
    }

    #[test]
    fn flush_sets_ftz_and_daz_on_this_thread_only() {
        std::thread::spawn(|| {
            let tiny = std::hint::black_box(f32::from_bits(1));
            assert_ne!(tiny * 1.0, 0.0);
            flush_denormals_on_this_thread();
            assert_eq!(std::hint::black_box(tiny) * 1.0, 0.0);
        })
        .join()
        .unwrap();
        assert_ne!(std::hint::black_box(f32::from_bits(1)) * 1.0, 0.0);
    }
}
