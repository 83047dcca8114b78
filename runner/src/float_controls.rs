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
//! * else: neither mode can be declared; denormal behaviour is unspecified and the GPU may differ
//!   from the CPU wherever a denormal appears.

use shader_manifest::DenormMode;

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
    /// Neither mode supported (or the properties could not be read): unspecified on the GPU.
    Unspecified,
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
            DenormPolicy::Unspecified => Ok(words.to_vec()),
        }
    }

    /// Make the CPU backend follow the policy: for `FlushToZero`, set FTZ and DAZ on every
    /// thread of rayon's global pool (which runs the CPU kernels) for the rest of the process.
    pub fn apply_to_cpu(self) {
        if self == DenormPolicy::FlushToZero {
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
            DenormPolicy::choose(Some(&f)).describe()
        ),
        None => format!("float controls unavailable (not Vulkan 1.2) -> {}", DenormPolicy::Unspecified.describe()),
    }
}

/// Set MXCSR.FTZ (bit 15) and MXCSR.DAZ (bit 6) on the calling thread.
fn flush_denormals_on_this_thread() {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: ldmxcsr/stmxcsr only change this thread's SSE rounding/denormal controls.
    unsafe {
        let mut csr: u32 = 0;
        core::arch::asm!("stmxcsr [{}]", in(reg) &mut csr, options(nostack));
        csr |= (1 << 15) | (1 << 6);
        core::arch::asm!("ldmxcsr [{}]", in(reg) &csr, options(nostack));
    }
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
