//! The GPU backend: headless wgpu on Vulkan, running the committed rust-gpu SPIR-V.
//!
//! The module is handed to the driver untouched (`PASSTHROUGH_SHADERS`) where the adapter allows,
//! so the arithmetic the driver sees is exactly what rust-gpu emitted; otherwise it goes through
//! naga's SPIR-V front end (which adds bounds checks). [`GpuContext::describe`] says which.

pub use crate::device::{groups_2d, ChainBuffer, ChainDispatch, ChainPass, GpuDevice, OutputSpec};
pub use crate::gpu_error::GpuError;
use crate::device::uniform_bindings;
use crate::kernel_module::KernelModule;
use crate::shaders::ShaderModule;
use std::collections::HashMap;
use std::sync::Mutex;

/// A headless GPU device with the kernels' module loaded: the [`GpuDevice`] (dispatch, pipelines;
/// reached through `Deref`) opened on the adapter chosen, with the float-controls policy and the
/// build of the main module chosen for it.
pub struct GpuContext {
    /// The device, its modules and pipelines.
    gpu: GpuDevice,
    /// fp32 denormal mode: declared in the loaded SPIR-V, or measured where the device can
    /// declare neither (crate::float_controls).
    pub denorm_policy: crate::float_controls::DenormPolicy,
    /// Which build of the main module is loaded (exact or native division / square root).
    pub div_sqrt: crate::shaders::DivSqrt,
    /// Why that build (the `HOST_DIV_SQRT` choice and, for `auto`, the driver and probe).
    pub div_sqrt_why: String,
}

impl std::ops::Deref for GpuContext {
    type Target = GpuDevice;

    fn deref(&self) -> &GpuDevice {
        &self.gpu
    }
}

fn adapter_rank(t: wgpu::DeviceType) -> u32 {
    match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    }
}

/// What `HOST_ADAPTER` is matched against (a substring, case-insensitive): the adapter's name,
/// then its driver and driver description, e.g. `llvmpipe (LLVM 15.0.6, 256 bits) llvmpipe Mesa
/// 22.3.6 (LLVM 15.0.6)`, so two lavapipes of different Mesa releases can be told apart.
pub fn adapter_label(info: &wgpu::AdapterInfo) -> String {
    format!("{} {} {}", info.name, info.driver, info.driver_info)
}

/// An adapter-matching error of a name that came from `HOST_ADAPTER`, said so.
fn from_env(e: GpuError) -> GpuError {
    match e {
        GpuError::NoMatchingAdapter(want, names) => GpuError::NoMatchingAdapter(format!("HOST_ADAPTER={want}"), names),
        e => e,
    }
}

impl GpuContext {
    /// Pick a Vulkan adapter (discrete > integrated > virtual > CPU; `HOST_ADAPTER=substring`
    /// selects by name or driver, see [`adapter_label`]), create a device and load the SPIR-V.
    pub fn new(shader: &ShaderModule) -> Result<Self, GpuError> {
        GpuContext::on_adapter(shader, std::env::var("HOST_ADAPTER").ok().as_deref()).map_err(from_env)
    }

    /// [`GpuContext::new`] on the adapter whose [`adapter_label`] contains `want`
    /// (case-insensitive; `None`: the best-ranked adapter), whatever `HOST_ADAPTER` says.
    pub fn on_adapter(shader: &ShaderModule, want: Option<&str>) -> Result<Self, GpuError> {
        ensure_xdg_runtime_dir();
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = wgpu::Backends::VULKAN;
        let instance = wgpu::Instance::new(desc);
        let mut adapters = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::VULKAN));
        if adapters.is_empty() {
            return Err(GpuError::NoAdapter);
        }
        if let Some(want) = want {
            let names: Vec<String> = adapters.iter().map(|a| adapter_label(&a.get_info())).collect();
            adapters.retain(|a| adapter_label(&a.get_info()).to_lowercase().contains(&want.to_lowercase()));
            if adapters.is_empty() {
                return Err(GpuError::NoMatchingAdapter(format!("{want:?}"), names.join(", ")));
            }
        }
        adapters.sort_by_key(|a| adapter_rank(a.get_info().device_type));
        let adapter = adapters.remove(0);
        let info = adapter.get_info();
        let denorm_policy = crate::float_controls::DenormPolicy::for_adapter(&adapter);
        let words = denorm_policy.apply(&shader.words).map_err(GpuError::Shader)?;
        denorm_policy.apply_to_cpu();
        let features = adapter.features();
        let passthrough = features.contains(wgpu::Features::PASSTHROUGH_SHADERS)
            && std::env::var_os("HOST_NO_PASSTHROUGH").is_none();
        let timestamps = features.contains(wgpu::Features::TIMESTAMP_QUERY);
        let mut required = wgpu::Features::empty();
        if passthrough {
            required |= wgpu::Features::PASSTHROUGH_SHADERS;
        }
        if timestamps {
            required |= wgpu::Features::TIMESTAMP_QUERY;
        }
        // Subgroup kernels live in their own module (shader-kernels/src/lib.rs); it needs SPIR-V
        // passthrough (naga cannot read rust-gpu's modules) and the adapter's subgroup feature.
        let subgroups = passthrough
            && features.contains(wgpu::Features::SUBGROUP)
            && std::env::var_os("HOST_NO_SUBGROUPS").is_none();
        if subgroups {
            required |= wgpu::Features::SUBGROUP;
        }
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("host"),
            required_features: required,
            required_limits: limits.clone(),
            experimental_features: wgpu::ExperimentalFeatures::disabled(),
            memory_hints: wgpu::MemoryHints::Performance,
            trace: wgpu::Trace::Off,
        }))
        .map_err(|e| GpuError::Device(info.name.clone(), e.to_string()))?;

        // SAFETY: the module is the one rust-gpu produced (validated by spirv-val during the
        // build) and its manifest was checked against the sources; bindings are declared
        // explicitly in `pipeline()` to match the entry points' signatures.
        let mut uniforms = uniform_bindings(&words)?;
        let main = unsafe { KernelModule::new("shader-kernels", words, shader.manifest.entry_points.clone(), passthrough)? };
        let subgroup_module = if subgroups {
            let sg = crate::shaders::load_subgroup().map_err(GpuError::Shader)?;
            let sg_words = denorm_policy.apply(&sg.words).map_err(GpuError::Shader)?;
            // SAFETY: as for the main module (rust-gpu output, spirv-val'd, manifest checked).
            uniforms.extend(uniform_bindings(&sg_words)?);
            Some(unsafe { KernelModule::new("shader-kernels-subgroup", sg_words, sg.manifest.entry_points.clone(), true)? })
        } else {
            None
        };
        let mut g = GpuContext {
            gpu: GpuDevice {
                device,
                queue,
                info,
                passthrough,
                timestamps,
                limits,
                main,
                subgroup_module,
                extra_modules: Mutex::new(Vec::new()),
                pipelines: Mutex::new(HashMap::new()),
                uniforms: Mutex::new(uniforms),
                compile_seconds: Mutex::new(HashMap::new()),
            },
            denorm_policy,
            div_sqrt: shader.div_sqrt,
            div_sqrt_why: String::new(),
        };
        if g.denorm_policy == crate::float_controls::DenormPolicy::Unspecified {
            // Neither mode can be declared: measure what the driver does (float_controls::measure).
            match crate::float_controls::measure(&g)? {
                Ok(p) => {
                    g.denorm_policy = p;
                    p.apply_to_cpu();
                }
                Err(first) => log::warn!("warning: {}: fp32 denormals neither all kept nor all flushed on the probe rows: {first}", g.info.name),
            }
        }
        Ok(g)
    }

    /// [`GpuContext::new`] with the build of the main module `HOST_DIV_SQRT` chooses: `exact`
    /// and `native` as asked; `auto` (default) the native build where the driver is known to
    /// round `OpFDiv` and `Sqrt` correctly ([`crate::div_sqrt_probe::known_correctly_rounded`])
    /// and [`crate::div_sqrt_probe::run`] finds them so on this adapter, else the exact build.
    /// The description ([`GpuContext::describe`]) says which and why.
    pub fn with_div_sqrt_choice() -> Result<Self, GpuError> {
        GpuContext::with_div_sqrt_choice_on(std::env::var("HOST_ADAPTER").ok().as_deref()).map_err(from_env)
    }

    /// [`GpuContext::with_div_sqrt_choice`] on the adapter `want` names ([`GpuContext::on_adapter`]).
    pub fn with_div_sqrt_choice_on(want: Option<&str>) -> Result<Self, GpuError> {
        use crate::shaders::{load_variant, DivSqrt, DivSqrtChoice};
        let choice = DivSqrtChoice::from_env().map_err(GpuError::Shader)?;
        let first = if choice == DivSqrtChoice::Auto { DivSqrt::Native } else { choice.without_adapter() };
        let mut g = GpuContext::on_adapter(&load_variant(first).map_err(GpuError::Shader)?, want)?;
        match choice {
            DivSqrtChoice::Exact => g.div_sqrt_why = "HOST_DIV_SQRT=exact".into(),
            DivSqrtChoice::Native => g.div_sqrt_why = "HOST_DIV_SQRT=native: bit-exact with the CPU only where the driver rounds them correctly".into(),
            DivSqrtChoice::Auto => {
                let exact = |g: &mut GpuContext, why: String| -> Result<(), GpuError> {
                    g.set_main_module(&load_variant(DivSqrt::Exact).map_err(GpuError::Shader)?, why)
                };
                if !crate::div_sqrt_probe::known_correctly_rounded(&g.info) {
                    let why = format!("auto: driver {} is not known to round OpFDiv/Sqrt correctly", g.info.driver);
                    exact(&mut g, why)?;
                } else {
                    let p = crate::div_sqrt_probe::run(&g)?;
                    if p.passed() {
                        g.div_sqrt_why = format!(
                            "auto: {} rounds OpFDiv/Sqrt correctly, checked on {} probe rows; HOST_DIV_SQRT=exact for the corrected routines",
                            g.info.driver, p.rows
                        );
                    } else {
                        let why = format!(
                            "auto: {}'s OpFDiv/Sqrt differ from correctly rounded on {} of {} probe rows, first: {}",
                            g.info.driver,
                            p.differing,
                            p.rows,
                            p.first.unwrap_or_default()
                        );
                        log::warn!("warning: {why}; using the exact build");
                        exact(&mut g, why)?;
                    }
                }
            }
        }
        Ok(g)
    }

    /// One line naming the adapter, driver and how shaders and timings are handled.
    pub fn describe(&self) -> String {
        format!(
            "{} ({:?}, driver {} {}); SPIR-V {}, {}{}; {}; timings from {}; {}",
            self.info.name,
            self.info.device_type,
            self.info.driver,
            self.info.driver_info,
            if self.passthrough { "passed through unchanged" } else { "translated by naga" },
            self.main.describe(),
            if self.subgroup_module.is_some() { ", subgroup kernels loaded" } else { ", no subgroup kernels" },
            if self.div_sqrt_why.is_empty() { self.div_sqrt.describe().to_string() } else { format!("{} ({})", self.div_sqrt.describe(), self.div_sqrt_why) },
            if self.timestamps { "timestamp queries" } else { "wall clock" },
            self.denorm_policy.describe()
        )
    }

    /// Replace the main module by `shader` (the other build of the same kernels), with `why` for
    /// the description: its pipelines are created afresh on first use.
    pub fn set_main_module(&mut self, shader: &ShaderModule, why: String) -> Result<(), GpuError> {
        let words = self.denorm_policy.apply(&shader.words).map_err(GpuError::Shader)?;
        // SAFETY: as in `new` (rust-gpu output, spirv-val'd, manifest checked).
        self.uniforms.lock().unwrap().extend(uniform_bindings(&words)?);
        self.gpu.main = unsafe { KernelModule::new("shader-kernels", words, shader.manifest.entry_points.clone(), self.passthrough)? };
        self.div_sqrt = shader.div_sqrt;
        self.div_sqrt_why = why;
        self.pipelines.lock().unwrap().clear();
        self.compile_seconds.lock().unwrap().clear();
        Ok(())
    }
}

/// Give the Vulkan loader and Mesa a usable `XDG_RUNTIME_DIR` (lavapipe prints "error:
/// XDG_RUNTIME_DIR is invalid" otherwise): when it is unset, or not a directory owned by this
/// user with mode 0700, point it at `<temp dir>/host-runtime-<uid>`, created with mode 0700.
/// Call before creating a wgpu instance; does nothing after the first call.
pub fn ensure_xdg_runtime_dir() {
    use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let Ok(uid) = std::fs::metadata("/proc/self").map(|m| m.uid()) else { return };
        let usable = |p: &std::path::Path| {
            std::fs::metadata(p).is_ok_and(|m| m.is_dir() && m.uid() == uid && m.permissions().mode() & 0o777 == 0o700)
        };
        if std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| usable(std::path::Path::new(&d))) {
            return;
        }
        let dir = std::env::temp_dir().join(format!("host-runtime-{uid}"));
        let _ = std::fs::DirBuilder::new().mode(0o700).create(&dir);
        if usable(&dir) {
            // Called once, before the Vulkan loader starts reading the environment.
            std::env::set_var("XDG_RUNTIME_DIR", &dir);
        }
    });
}
