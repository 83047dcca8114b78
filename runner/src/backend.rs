//! Backend selection (`--device auto|cpu|gpu`) and the operations every backend offers.

use crate::gpu::{groups_2d, GpuContext, GpuError, OutputSpec};
use crate::timing::Timing;
use anyhow::{bail, Context, Result};
use shader_kernels::eval::{EvalArgs, FunctionInfo};
use shader_kernels::launch::{Bindings, BlockFns, ItemFn, Kernel, ListFn, SerialFn};
use rayon::prelude::*;
use std::time::Instant;

/// What the user asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum DeviceChoice {
    /// A hardware GPU (discrete, integrated or virtual Vulkan adapter) when there is one, else
    /// the native CPU backend; a software Vulkan adapter (lavapipe) only with `gpu`, because it
    /// runs on the same CPU cores and is not faster overall (the path tracer about 20x slower,
    /// eval functions and SSR passes either way, the energy precompute faster: docs/kernels.md,
    /// docs/render.md). Says on one line which
    /// it chose and why. With HOST_ADAPTER set, the adapter it names. Benchmarks, which always
    /// time the CPU backend, take any Vulkan adapter (lavapipe included) for their GPU column.
    Auto,
    /// The native CPU backend (same kernel code, all cores).
    Cpu,
    /// A Vulkan adapter (real GPU or lavapipe); an error if none exists.
    Gpu,
}

/// A backend ready to run kernels.
pub enum Backend {
    Cpu,
    Gpu(Box<GpuContext>),
}

impl From<Box<GpuContext>> for Backend {
    fn from(g: Box<GpuContext>) -> Backend {
        Backend::Gpu(g)
    }
}

impl Backend {
    /// The GPU backend on the adapter whose name or driver contains `name` (as `HOST_ADAPTER`
    /// would select it, whatever that variable says), with the build `HOST_DIV_SQRT` chooses.
    pub fn gpu_named(name: &str) -> Result<Backend> {
        Ok(Backend::Gpu(Box::new(GpuContext::with_div_sqrt_choice_on(Some(name))?)))
    }

    /// Create the backend the user chose (see [`DeviceChoice`]); why `auto` chose what it
    /// did goes to the `log` facade at info level (the `host` CLI prints it). The GPU backend refuses SPIR-V
    /// that is stale relative to the shader sources this binary was built from, and loads the
    /// build of the main module `HOST_DIV_SQRT` chooses ([`crate::shaders::DivSqrtChoice`]).
    pub fn select(choice: DeviceChoice) -> Result<Backend> {
        let gpu = || -> Result<Backend> { Ok(Backend::Gpu(Box::new(GpuContext::with_div_sqrt_choice()?))) };
        match choice {
            DeviceChoice::Cpu => Ok(Backend::Cpu),
            DeviceChoice::Gpu => gpu(),
            DeviceChoice::Auto => {
                if let Ok(name) = std::env::var("HOST_ADAPTER") {
                    log::info!("--device auto: GPU backend, because HOST_ADAPTER={name:?} names an adapter");
                    return gpu();
                }
                crate::gpu::ensure_xdg_runtime_dir();
                let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
                desc.backends = wgpu::Backends::VULKAN;
                let adapters = pollster::block_on(wgpu::Instance::new(desc).enumerate_adapters(wgpu::Backends::VULKAN));
                let hardware = |t: wgpu::DeviceType| {
                    matches!(t, wgpu::DeviceType::DiscreteGpu | wgpu::DeviceType::IntegratedGpu | wgpu::DeviceType::VirtualGpu)
                };
                if let Some(a) = adapters.iter().map(|a| a.get_info()).find(|i| hardware(i.device_type)) {
                    log::info!("--device auto: GPU backend, hardware adapter {} ({:?})", a.name, a.device_type);
                    return gpu();
                }
                let why = if adapters.is_empty() {
                    "no Vulkan adapter (install one, e.g. Mesa lavapipe: apt-get install -y mesa-vulkan-drivers libvulkan1)".to_string()
                } else {
                    let names: Vec<String> = adapters.iter().map(|a| a.get_info().name).collect();
                    format!("no hardware GPU, only the software adapter(s) {} (it runs on the same CPU cores and is not faster overall; --device gpu uses it)", names.join(", "))
                };
                log::info!("--device auto: CPU backend ({} threads): {why}", crate::cpu::threads());
                Ok(Backend::Cpu)
            }
        }
    }

    /// The GPU backend for a benchmark's GPU columns: `None` for `--device cpu` and for `auto`
    /// without any Vulkan adapter, an error for `--device gpu` without one. Unlike
    /// [`Backend::select`], `auto` takes a software adapter (lavapipe) here: a benchmark always
    /// times the CPU backend too, and its GPU column is what CPU = GPU bits are checked against.
    pub fn gpu_column(choice: DeviceChoice) -> Result<Option<Backend>> {
        match choice {
            DeviceChoice::Cpu => Ok(None),
            DeviceChoice::Gpu => Backend::select(choice).map(Some),
            DeviceChoice::Auto => match Backend::select(DeviceChoice::Gpu) {
                Ok(b) => Ok(Some(b)),
                Err(e) if matches!(e.downcast_ref::<GpuError>(), Some(GpuError::NoAdapter)) => {
                    log::info!("notice: no Vulkan adapter: timing the CPU backend only");
                    Ok(None)
                }
                Err(e) => Err(e),
            },
        }
    }

    /// The backends a benchmark times: the CPU backend and [`Backend::gpu_column`], each
    /// described on standard error.
    pub fn bench_pair(choice: DeviceChoice) -> Result<(Backend, Option<Backend>)> {
        let gpu = Backend::gpu_column(choice)?;
        let cpu = Backend::Cpu;
        log::info!("{}", cpu.describe());
        match &gpu {
            Some(g) => log::info!("{}", g.describe()),
            None => log::info!("no GPU backend: GPU columns left empty"),
        }
        Ok((cpu, gpu))
    }

    /// A one-line description of the backend.
    pub fn describe(&self) -> String {
        match self {
            Backend::Cpu => format!("CPU backend (native, {} threads)", crate::cpu::threads()),
            Backend::Gpu(g) => format!("GPU backend: {}", g.describe()),
        }
    }

    /// The GPU context, owned (the CPU backend: `None`).
    pub fn into_gpu(self) -> Option<Box<GpuContext>> {
        match self {
            Backend::Cpu => None,
            Backend::Gpu(g) => Some(g),
        }
    }

    pub fn is_gpu(&self) -> bool {
        matches!(self, Backend::Gpu(_))
    }

    /// Evaluate `f` over `rows` rows of its input columns (`input` holds `rows * f.inputs.len()`
    /// values, row-major), returning `rows * f.outputs.len()` outputs and the time taken. The GPU
    /// runs `f`'s own entry point; the CPU runs its batch loop on all cores.
    pub fn eval_table(&self, f: &FunctionInfo, input: &[f32], rows: usize) -> Result<(Vec<f32>, Timing)> {
        let mut out = Vec::new();
        let t = self.eval_table_into(f, input, rows, &mut out)?;
        Ok((out, t))
    }

    /// [`Backend::eval_table`] into `out`, which is resized to `rows * f.outputs.len()` values;
    /// the CPU backend writes into it in place, so evaluating repeatedly with one `out` allocates
    /// (and page-faults) its memory once, not on every call. Returns the time taken (the CPU: the
    /// evaluation's wall clock, buffer resizing excluded).
    pub fn eval_table_into(&self, f: &FunctionInfo, input: &[f32], rows: usize, out: &mut Vec<f32>) -> Result<Timing> {
        let (in_stride, out_stride) = (f.inputs.len(), f.outputs.len());
        if input.len() != rows * in_stride {
            bail!("{}: input has {} values, expected {rows} rows x {in_stride} columns", f.name, input.len());
        }
        match self {
            Backend::Cpu => {
                if out.len() != rows * out_stride {
                    // A fresh zeroed allocation (lazily zeroed pages), not a memset on this thread
                    // before the batch loops overwrite every value anyway.
                    *out = vec![0.0; rows * out_stride];
                }
                let t0 = Instant::now();
                crate::cpu::eval_table_into(f, input, rows, out);
                Ok(Timing::since(t0))
            }
            Backend::Gpu(g) => {
                out.clear();
                if rows == 0 {
                    return Ok(Timing::zero());
                }
                let wg = shader_kernels::WORKGROUP_SIZE as usize;
                let max_bytes = g.max_binding_bytes();
                let per_row = 4 * in_stride.max(out_stride).max(1);
                let chunk_rows = (max_bytes / per_row).min(65535 * 65535 * wg).max(wg);
                out.reserve(rows * out_stride);
                let mut total: Option<Timing> = None;
                let mut start = 0;
                while start < rows {
                    let n = (rows - start).min(chunk_rows);
                    let (gx, gy) = groups_2d(n.div_ceil(wg) as u32);
                    let args = EvalArgs { rows: n as u32, groups_x: gx };
                    let chunk = &input[start * in_stride..(start + n) * in_stride];
                    let (res, t) = g
                        .dispatch(
                            f.entry,
                            &[bytemuck::bytes_of(&args), bytemuck::cast_slice(chunk)],
                            &[OutputSpec::zeroed(n * out_stride * 4)],
                            (gx, gy, 1),
                        )
                        .with_context(|| format!("{}: rows {start}..{}", f.name, start + n))?;
                    out.extend_from_slice(&bytemuck::pod_collect_to_vec::<u8, f32>(&res[0]));
                    total = Some(match total { Some(a) => a + t, None => t });
                    start += n;
                }
                Ok(total.expect("at least one dispatch"))
            }
        }
    }

    /// The GPU context, for what only a GPU has (its adapter, pipeline compile times, command
    /// chains, WGSL comparison kernels); `None` on the CPU backend.
    pub fn gpu(&self) -> Option<&GpuContext> {
        match self {
            Backend::Cpu => None,
            Backend::Gpu(g) => Some(g),
        }
    }

    /// Seconds the driver took to compile `kernel`'s pipeline on first use (`None` on the CPU
    /// backend, or before its first launch).
    pub fn compile_seconds<F>(&self, kernel: &Kernel<F>) -> Option<f64> {
        self.gpu().and_then(|g| g.compile_seconds(kernel.entry))
    }

    /// Run `kernel` over invocations `0..count`, each writing its `stride` values of the output:
    /// the GPU dispatches its entry point (bindings: the argument record, `launch.inputs`, the
    /// output), the CPU calls its [`ItemFn`] for every invocation on all cores. A launch whose
    /// output exceeds the adapter's binding limit is split when the record has a
    /// first-invocation field ([`LaunchArgs::SPLITS`]); the launch fields are filled in here.
    /// Returns the output and the time (the CPU: its loop, the output's allocation excluded).
    pub fn run<A: LaunchArgs>(&self, kernel: &Kernel<ItemFn<A>>, launch: Launch<'_, A>, count: usize, stride: usize) -> Result<(Vec<f32>, Timing)> {
        if count == 0 {
            return Ok((Vec::new(), Timing::zero()));
        }
        let wg = shader_kernels::WORKGROUP_SIZE as usize;
        match self {
            Backend::Cpu => {
                let mut out = crate::cpu::touched_zeros(count * stride);
                let a = cpu_args(&launch, count);
                let b = Bindings(launch.inputs);
                let t0 = Instant::now();
                crate::cpu::on_backend_threads(|| out.par_chunks_mut(stride.max(1)).enumerate().for_each(|(i, o)| (kernel.cpu)(&a, &b, i as u32, o)));
                Ok((out, Timing::since(t0)))
            }
            Backend::Gpu(g) => {
                let per = if A::SPLITS { (g.max_binding_bytes() / (4 * stride.max(1))).min(65535 * 65535 * wg).max(wg) } else { count };
                let mut out = vec![0.0f32; count * stride];
                let mut total: Option<Timing> = None;
                let mut start = 0;
                while start < count {
                    let n = (count - start).min(per);
                    let (res, t) = self
                        .dispatch(kernel.entry, &launch, start, n, &[OutputSpec::zeroed(n * stride * 4)])
                        .with_context(|| format!("{}: invocations {start}..{}", kernel.entry, start + n))?;
                    out[start * stride..(start + n) * stride].copy_from_slice(&bytemuck::pod_collect_to_vec::<u8, f32>(&res[0]));
                    total = Some(match total { Some(x) => x + t, None => t });
                    start += n;
                }
                Ok((out, total.expect("at least one dispatch")))
            }
        }
    }

    /// Run `kernel` over the `count` entries of a compacted list, each writing a record of
    /// `stride` values at the slot it names of an output of `slots` zeroed records: the GPU
    /// dispatches its entry point, the CPU calls its [`ListFn`] on all cores and stores each
    /// record at its slot (two entries naming one slot, or a slot past the end, are an error:
    /// `cpu::scatter_records`).
    pub fn run_list<A: LaunchArgs>(&self, kernel: &Kernel<ListFn<A>>, launch: Launch<'_, A>, count: usize, slots: usize, stride: usize) -> Result<(Vec<f32>, Timing)> {
        match self {
            Backend::Cpu => {
                let mut out = crate::cpu::touched_zeros(slots * stride);
                let a = cpu_args(&launch, count);
                let b = Bindings(launch.inputs);
                let t0 = Instant::now();
                crate::cpu::on_backend_threads(|| crate::cpu::scatter_records(count, stride, &mut out, |k, o| (kernel.cpu)(&a, &b, k, o) as usize))
                    .with_context(|| format!("CPU launch of {}", kernel.entry))?;
                Ok((out, Timing::since(t0)))
            }
            Backend::Gpu(_) => {
                let (res, t) = self.dispatch(kernel.entry, &launch, 0, count, &[OutputSpec::zeroed(slots * stride * 4)])?;
                Ok((bytemuck::pod_collect_to_vec(&res[0]), t))
            }
        }
    }

    /// Run `kernel` over `count` blocks of `buf`, updated in place: every invocation reads the
    /// buffer as it was and writes its block ([`BlockFns`]). Returns the updated buffer.
    pub fn run_in_place<A: LaunchArgs, W: Send>(&self, kernel: &Kernel<BlockFns<A, W>>, launch: Launch<'_, A>, count: usize, mut buf: Vec<f32>) -> Result<(Vec<f32>, Timing)> {
        match self {
            Backend::Cpu => {
                let a = cpu_args(&launch, count);
                let b = Bindings(launch.inputs);
                let t0 = Instant::now();
                crate::cpu::on_backend_threads(|| crate::cpu::update_in_place(&mut buf, count, |src, i| (kernel.cpu.block)(&a, &b, src, i), |w, dst| (kernel.cpu.store)(w, dst)));
                Ok((buf, Timing::since(t0)))
            }
            Backend::Gpu(_) => {
                let init = OutputSpec { size: buf.len() * 4, init: Some(bytemuck::cast_slice(&buf)) };
                let (res, t) = self.dispatch(kernel.entry, &launch, 0, count, &[init])?;
                Ok((bytemuck::pod_collect_to_vec(&res[0]), t))
            }
        }
    }

    /// Run `kernel` over invocations `0..count` writing disjoint parts of zeroed outputs of
    /// `lens` values each, at places they compute ([`SerialFn`]); the CPU runs the invocations
    /// in order on one thread of the backend's pool.
    pub fn run_serial<A: LaunchArgs>(&self, kernel: &Kernel<SerialFn<A>>, launch: Launch<'_, A>, count: usize, lens: &[usize]) -> Result<(Vec<Vec<f32>>, Timing)> {
        match self {
            Backend::Cpu => {
                let mut outs: Vec<Vec<f32>> = lens.iter().map(|&n| crate::cpu::touched_zeros(n)).collect();
                let a = cpu_args(&launch, count);
                let b = Bindings(launch.inputs);
                let t0 = Instant::now();
                crate::cpu::on_backend_threads(|| {
                    let mut views: Vec<&mut [f32]> = outs.iter_mut().map(|o| o.as_mut_slice()).collect();
                    for i in 0..count as u32 {
                        (kernel.cpu)(&a, &b, i, &mut views);
                    }
                });
                Ok((outs, Timing::since(t0)))
            }
            Backend::Gpu(_) => {
                let specs: Vec<OutputSpec<'_>> = lens.iter().map(|&n| OutputSpec::zeroed(n * 4)).collect();
                let (res, t) = self.dispatch(kernel.entry, &launch, 0, count, &specs)?;
                Ok((res.iter().map(|r| bytemuck::pod_collect_to_vec(r)).collect(), t))
            }
        }
    }

    /// One GPU dispatch of invocations `first..first + n` of `entry`.
    fn dispatch<A: LaunchArgs>(&self, entry: &str, launch: &Launch<'_, A>, first: usize, n: usize, outputs: &[OutputSpec<'_>]) -> Result<(Vec<Vec<u8>>, Timing)> {
        let Backend::Gpu(g) = self else { bail!("{entry}: a GPU dispatch on the CPU backend") };
        let (gx, gy) = groups_2d(n.div_ceil(shader_kernels::WORKGROUP_SIZE as usize) as u32);
        let mut a = launch.args;
        a.set_launch(n as u32, gx, first as u32);
        let mut bufs: Vec<&[u8]> = vec![bytemuck::bytes_of(&a)];
        bufs.extend_from_slice(launch.inputs);
        g.dispatch_specialized(entry, launch.spec, &bufs, outputs, (gx, gy, 1)).with_context(|| format!("GPU launch of {entry}"))
    }
}

/// The argument record the CPU backend hands a kernel's function: the launch fields of one
/// launch of `count` invocations.
fn cpu_args<A: LaunchArgs>(launch: &Launch<'_, A>, count: usize) -> A {
    let mut a = launch.args;
    a.set_launch(count as u32, groups_2d(count.div_ceil(shader_kernels::WORKGROUP_SIZE as usize) as u32).0, 0);
    a
}

/// What one launch of a [`Kernel`] binds: its argument record (binding 0), the buffers after it
/// (as bytes, in the entry point's order: [`Bindings`]) and the values of its specialization
/// constants (GPU only; `&[]`: the module's defaults).
#[derive(Clone, Copy, Debug)]
pub struct Launch<'a, A> {
    pub args: A,
    pub inputs: &'a [&'a [u8]],
    pub spec: &'a [u32],
}

impl<'a, A> Launch<'a, A> {
    /// A launch with argument record `args` and bindings `inputs`, no specialization.
    pub fn new(args: A, inputs: &'a [&'a [u8]]) -> Self {
        Launch { args, inputs, spec: &[] }
    }

    /// The same launch with specialization constants `spec`.
    pub fn with_spec(self, spec: &'a [u32]) -> Self {
        Launch { spec, ..self }
    }
}

/// The launch fields of a kernel's argument record, filled by the launchers ([`Backend::run`]): the number of
/// invocations of one dispatch, its workgroups in x, and the index of its first invocation (the
/// kernel's invocation `i` is overall invocation `first + i`).
pub trait LaunchArgs: bytemuck::Pod + Send + Sync {
    /// Whether the record has a first-invocation field, so that a launch may be split in
    /// several dispatches.
    const SPLITS: bool = true;
    /// Set the launch fields.
    fn set_launch(&mut self, invocations: u32, groups_x: u32, first: u32);
}

/// An SSR pass's record has no first-invocation field: its launches are never split.
impl LaunchArgs for shader_kernels::ssr::PassArgs {
    const SPLITS: bool = false;
    fn set_launch(&mut self, invocations: u32, groups_x: u32, _first: u32) {
        self.invocations = invocations;
        self.groups_x = groups_x;
    }
}

/// `LaunchArgs` for records whose launch fields are `invocations`, `groups_x` and the named
/// first-invocation field.
macro_rules! launch_args {
    ($first:ident: $($t:ty),*) => {$(
        impl LaunchArgs for $t {
            fn set_launch(&mut self, invocations: u32, groups_x: u32, first: u32) {
                self.invocations = invocations;
                self.groups_x = groups_x;
                self.$first = first;
            }
        }
    )*};
}
launch_args!(first_pixel: shader_kernels::render::RenderArgs, shader_kernels::render::GBufferArgs);
launch_args!(first: shader_kernels::energy::AlbedoTableArgs, shader_kernels::energy::AlbedoAvgArgs, shader_kernels::energy::FurnaceArgs);
