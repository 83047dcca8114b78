//! The GPU device the kernels run on: a wgpu device and queue with the kernels' modules loaded,
//! their pipelines, and dispatch (one pass, or a chain of passes on buffers that stay on the
//! device). [`crate::gpu::GpuContext`] opens it (adapter, float controls, the build of the main
//! module) and dereferences to it.

use crate::gpu_error::GpuError;
use crate::kernel_module::{spirv_module, validated, KernelModule};
use crate::timing::{Timing, TimingSource};
use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::Mutex;
use std::time::Instant;
use wgpu::util::DeviceExt;

/// A headless GPU device with the kernels' modules loaded: their pipelines and dispatch.
pub struct GpuDevice {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    pub passthrough: bool,
    pub timestamps: bool,
    pub limits: wgpu::Limits,
    /// The main module (handed to the driver one entry point at a time).
    pub(crate) main: KernelModule,
    /// The subgroup module, where the adapter has subgroup operations.
    pub(crate) subgroup_module: Option<KernelModule>,
    /// Modules added at run time (the benches' WGSL speed references) and their entry points.
    pub(crate) extra_modules: Mutex<Vec<(wgpu::ShaderModule, Vec<String>)>>,
    /// Pipelines by (entry point, specialization values it uses, read-only and read-write bindings).
    pub(crate) pipelines: Mutex<HashMap<(String, Vec<u32>, usize, usize), (wgpu::ComputePipeline, wgpu::BindGroupLayout)>>,
    /// Each SPIR-V entry point's uniform-buffer bindings (its parameter record, e.g. the SSR
    /// passes' `SsrParams`); every other binding is a storage buffer.
    pub(crate) uniforms: Mutex<HashMap<String, Vec<u32>>>,
    /// Seconds the driver took to create each entry point's pipeline (its compile), first use.
    pub(crate) compile_seconds: Mutex<HashMap<String, f64>>,
}

impl GpuDevice {
    /// Load a SPIR-V module of the caller's own (e.g. built by their rust-gpu shader crate with
    /// the post-processing of `cargo xtask build-shaders`) whose compute entry points `entries`
    /// (workgroup size 64 in x) then dispatch like the built-in ones. Handed to the driver
    /// unchanged where the adapter allows passthrough, else translated by naga.
    pub fn add_spirv(&self, label: &str, words: &[u32], entries: &[&str]) -> Result<(), GpuError> {
        let names: Vec<String> = entries.iter().map(|e| e.to_string()).collect();
        // SAFETY: the caller vouches for the module (as for the built-in one: a valid SPIR-V
        // compute module whose bindings are storage buffers in the order dispatched).
        let m = unsafe { spirv_module(&self.device, label, words, &names, self.passthrough)? };
        self.uniforms.lock().unwrap().extend(uniform_bindings(words)?);
        self.extra_modules.lock().unwrap().push((m, names));
        Ok(())
    }

    /// Compile a WGSL module (naga) whose entry points `entries` then dispatch like the SPIR-V
    /// ones: a caller's own kernels, or the benches' speed references. naga's translation is not
    /// bit-exact with the project's kernels (no NoContraction, the driver's own sqrt/division).
    pub fn add_wgsl(&self, label: &str, source: &str, entries: &[&str]) -> Result<(), GpuError> {
        self.add_wgsl_with_uniforms(label, source, entries, &[])
    }

    /// [`GpuDevice::add_wgsl`] for a module whose entry points read uniform buffers: `uniform`
    /// lists (entry point, binding) pairs declared `var<uniform>` (the SPIR-V modules' are found
    /// in their code; naga's WGSL is not inspected), bound as uniform buffers at dispatch.
    pub fn add_wgsl_with_uniforms(&self, label: &str, source: &str, entries: &[&str], uniform: &[(&str, u32)]) -> Result<(), GpuError> {
        let m = validated(&self.device, label, || {
            self.device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some(label), source: wgpu::ShaderSource::Wgsl(Cow::Borrowed(source)) })
        })?;
        let mut u = self.uniforms.lock().unwrap();
        for &(entry, binding) in uniform {
            u.entry(entry.to_string()).or_default().push(binding);
        }
        drop(u);
        self.extra_modules.lock().unwrap().push((m, entries.iter().map(|e| e.to_string()).collect()));
        Ok(())
    }

    /// Whether a loaded module has entry point `entry`.
    pub fn has_module_for(&self, entry: &str) -> bool {
        self.extra_modules.lock().unwrap().iter().any(|(_, names)| names.iter().any(|n| n == entry))
            || self.subgroup_module.as_ref().is_some_and(|m| m.has(entry))
            || self.main.has(entry)
    }

    /// The module holding `entry`, specialized with `spec` where it is one of the project's
    /// modules ([`crate::kernel_module`]; a module added at run time is used as it is), and
    /// whether `spec` changed it; or an error naming the entry points there are.
    fn module_for(&self, entry: &str, spec: &[u32]) -> Result<(wgpu::ShaderModule, bool), GpuError> {
        if let Some((m, _)) = self.extra_modules.lock().unwrap().iter().find(|(_, names)| names.iter().any(|n| n == entry)) {
            return Ok((m.clone(), false));
        }
        match &self.subgroup_module {
            Some(m) if m.has(entry) => return m.module(&self.device, entry, spec),
            _ => {}
        }
        if self.main.has(entry) {
            self.main.module(&self.device, entry, spec)
        } else {
            Err(GpuError::Shader(format!(
                "the SPIR-V module has no entry point {entry:?} (it has {}); rebuild it with `cargo xtask build-shaders`",
                self.main.entry_points().len()
            )))
        }
    }

    /// Create (once) and return the pipeline of `entry` specialized with `spec` (its
    /// specialization constants 0..; see [`ChainPass::spec`]) with `n_read` read-only then
    /// `n_write` read-write bindings: storage buffers, except those the entry point declares as
    /// uniform buffers (which must be among the read-only ones). The first creation's driver
    /// compile time is recorded ([`GpuDevice::compile_seconds`]).
    fn pipeline(&self, entry: &str, spec: &[u32], n_read: usize, n_write: usize) -> Result<(wgpu::ComputePipeline, wgpu::BindGroupLayout), GpuError> {
        let t0 = Instant::now();
        let (module, specialized) = self.module_for(entry, spec)?;
        // An entry point without specialization constants has one pipeline whatever `spec` is.
        let key = (entry.to_string(), if specialized { spec.to_vec() } else { Vec::new() }, n_read, n_write);
        if let Some(p) = self.pipelines.lock().unwrap().get(&key) {
            return Ok(p.clone());
        }
        let uniform = self.uniforms.lock().unwrap().get(entry).cloned().unwrap_or_default();
        if let Some(b) = uniform.iter().find(|&&b| b as usize >= n_read) {
            return Err(GpuError::Shader(format!(
                "{entry}: binding {b} is a uniform buffer but the dispatch binds only {n_read} read-only buffers before its read-write ones"
            )));
        }
        let entries: Vec<wgpu::BindGroupLayoutEntry> = (0..n_read + n_write)
            .map(|i| wgpu::BindGroupLayoutEntry {
                binding: i as u32,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: if uniform.contains(&(i as u32)) {
                        wgpu::BufferBindingType::Uniform
                    } else {
                        wgpu::BufferBindingType::Storage { read_only: i < n_read }
                    },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            })
            .collect();
        let bgl = self.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(entry),
            entries: &entries,
        });
        let layout = self.device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(entry),
            bind_group_layouts: &[Some(&bgl)],
            immediate_size: 0,
        });
        let pipeline = self.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: Some(&layout),
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        });
        self.compile_seconds.lock().unwrap().entry(entry.to_string()).or_insert(t0.elapsed().as_secs_f64());
        self.pipelines.lock().unwrap().insert(key, (pipeline.clone(), bgl.clone()));
        Ok((pipeline, bgl))
    }

    /// Create `entry`'s pipeline now (outside any timed region) and return the seconds its
    /// creation took: the driver's compile of that entry point, on first use.
    pub fn prepare(&self, entry: &str, n_read: usize, n_write: usize) -> Result<f64, GpuError> {
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        self.pipeline(entry, &[], n_read, n_write)?;
        if let Some(err) = pollster::block_on(scope.pop()) {
            return Err(GpuError::Shader(format!("{entry}: {err}")));
        }
        Ok(self.compile_seconds(entry).unwrap_or(0.0))
    }

    /// Seconds the first pipeline creation of `entry` took, if it was created.
    pub fn compile_seconds(&self, entry: &str) -> Option<f64> {
        self.compile_seconds.lock().unwrap().get(entry).copied()
    }

    /// Run entry point `entry` once over `groups` workgroups with bindings 0.. = `inputs`
    /// (read-only: storage, or uniform where the entry point declares one) followed by
    /// `outputs.len()` read-write storage buffers of the given byte sizes (zero-initialized, or
    /// copied from `init` where given), and read the outputs back: a one-pass
    /// [`GpuDevice::dispatch_chain`].
    pub fn dispatch(
        &self,
        entry: &str,
        inputs: &[&[u8]],
        outputs: &[OutputSpec<'_>],
        groups: (u32, u32, u32),
    ) -> Result<(Vec<Vec<u8>>, Timing), GpuError> {
        self.dispatch_specialized(entry, &[], inputs, outputs, groups)
    }

    /// [`GpuDevice::dispatch`] of `entry`'s pipeline specialized with `spec` ([`ChainPass::spec`]).
    pub fn dispatch_specialized(
        &self,
        entry: &str,
        spec: &[u32],
        inputs: &[&[u8]],
        outputs: &[OutputSpec<'_>],
        groups: (u32, u32, u32),
    ) -> Result<(Vec<Vec<u8>>, Timing), GpuError> {
        let mut buffers: Vec<ChainBuffer<'_>> = inputs.iter().map(|d| ChainBuffer::Input(d)).collect();
        buffers.extend(outputs.iter().map(|o| ChainBuffer::Output { size: o.size, init: o.init, read_back: true }));
        let pass = ChainPass {
            entry,
            spec,
            reads: (0..inputs.len()).collect(),
            writes: (inputs.len()..inputs.len() + outputs.len()).collect(),
            dispatch: ChainDispatch::Direct(groups.0, groups.1, groups.2),
        };
        let (out, times) = self.dispatch_chain(&buffers, &[pass])?;
        Ok((out.into_iter().skip(inputs.len()).map(|o| o.unwrap_or_default()).collect(), times[0]))
    }

    /// Run several passes in one command buffer, buffers staying on the device between them (no
    /// host round trip): each pass binds `reads` (read-only: storage or, where the entry point
    /// declares one, uniform; bindings 0..) then `writes` (read-write) from `buffers`, and is
    /// dispatched directly or indirectly from a buffer the earlier passes wrote. Returns the
    /// contents of the buffers marked `read_back` (None for the others) and each pass's time
    /// (timestamp queries where the adapter has them, else the whole chain's wall clock on every
    /// pass).
    pub fn dispatch_chain(&self, buffers: &[ChainBuffer<'_>], passes: &[ChainPass<'_>]) -> Result<(Vec<Option<Vec<u8>>>, Vec<Timing>), GpuError> {
        let names = passes.iter().map(|p| p.entry).collect::<Vec<_>>().join(" + ");
        // Pipelines first (an unknown entry point is an error before any GPU work is recorded).
        let pipelines = passes
            .iter()
            .map(|p| self.pipeline(p.entry, p.spec, p.reads.len(), p.writes.len()))
            .collect::<Result<Vec<_>, GpuError>>()?;
        let scope = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let t0 = Instant::now();
        let mut bufs = Vec::with_capacity(buffers.len());
        let mut readbacks: Vec<Option<(wgpu::Buffer, usize)>> = Vec::with_capacity(buffers.len());
        for (i, b) in buffers.iter().enumerate() {
            // UNIFORM too: a read may be an entry point's uniform binding (its parameter record).
            let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::INDIRECT;
            let label = format!("chain buffer {i}");
            let (buf, read_size) = match b {
                ChainBuffer::Input(data) => (
                    self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(&label), contents: &padded(data), usage }),
                    None,
                ),
                ChainBuffer::Output { size, init, read_back } => {
                    let buf = match init {
                        Some(init) => self.device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(&label), contents: &padded(init), usage }),
                        None => self.device.create_buffer(&wgpu::BufferDescriptor {
                            label: Some(&label),
                            size: (*size).max(4).next_multiple_of(4) as u64,
                            usage,
                            mapped_at_creation: false,
                        }),
                    };
                    (buf, read_back.then_some(*size))
                }
            };
            readbacks.push(read_size.map(|size| {
                let rb = self.device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(&format!("chain readback {i}")),
                    size: size.max(4).next_multiple_of(4) as u64,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                (rb, size)
            }));
            bufs.push(buf);
        }
        let n_q = 2 * passes.len() as u32;
        let query = self.timestamps.then(|| {
            let set = self.device.create_query_set(&wgpu::QuerySetDescriptor { label: Some("chain times"), ty: wgpu::QueryType::Timestamp, count: n_q });
            let resolve = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("chain timestamps"),
                size: 8 * n_q as u64,
                usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let read = self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("chain timestamps readback"),
                size: 8 * n_q as u64,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            (set, resolve, read)
        });
        let mut encoder = self.device.create_command_encoder(&Default::default());
        for (k, pass_spec) in passes.iter().enumerate() {
            let (pipeline, bgl) = &pipelines[k];
            let entries: Vec<wgpu::BindGroupEntry> = pass_spec
                .reads
                .iter()
                .chain(&pass_spec.writes)
                .enumerate()
                .map(|(binding, &b)| wgpu::BindGroupEntry { binding: binding as u32, resource: bufs[b].as_entire_binding() })
                .collect();
            let bind_group = self.device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(pass_spec.entry), layout: bgl, entries: &entries });
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(pass_spec.entry),
                timestamp_writes: query.as_ref().map(|(set, _, _)| wgpu::ComputePassTimestampWrites {
                    query_set: set,
                    beginning_of_pass_write_index: Some(2 * k as u32),
                    end_of_pass_write_index: Some(2 * k as u32 + 1),
                }),
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            match pass_spec.dispatch {
                ChainDispatch::Direct(x, y, z) => pass.dispatch_workgroups(x, y, z),
                ChainDispatch::Indirect { buffer, offset_bytes } => pass.dispatch_workgroups_indirect(&bufs[buffer], offset_bytes),
            }
        }
        for (i, rb) in readbacks.iter().enumerate() {
            if let Some((rb, _)) = rb {
                encoder.copy_buffer_to_buffer(&bufs[i], 0, rb, 0, rb.size());
            }
        }
        if let Some((set, resolve, read)) = &query {
            encoder.resolve_query_set(set, 0..n_q, resolve, 0);
            encoder.copy_buffer_to_buffer(resolve, 0, read, 0, 8 * n_q as u64);
        }
        self.queue.submit([encoder.finish()]);
        let mut maps: Vec<&wgpu::Buffer> = readbacks.iter().flatten().map(|(b, _)| b).collect();
        if let Some((_, _, read)) = &query {
            maps.push(read);
        }
        for b in &maps {
            b.map_async(wgpu::MapMode::Read, .., |r| r.expect("mapping a readback buffer"));
        }
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Runtime(names.clone(), e.to_string()))?;
        let wall = t0.elapsed().as_secs_f64();
        if let Some(err) = pollster::block_on(scope.pop()) {
            return Err(GpuError::Runtime(names, err.to_string()));
        }
        let mut out = Vec::with_capacity(buffers.len());
        for rb in &readbacks {
            out.push(match rb {
                Some((rb, size)) => {
                    let view = rb.get_mapped_range(..).map_err(|e| GpuError::Runtime(names.clone(), e.to_string()))?;
                    let v = view[..*size].to_vec();
                    drop(view);
                    rb.unmap();
                    Some(v)
                }
                None => None,
            });
        }
        let times = match &query {
            Some((_, _, read)) => {
                let view = read.get_mapped_range(..).map_err(|e| GpuError::Runtime(names.clone(), e.to_string()))?;
                let t: &[u64] = bytemuck::cast_slice(&view);
                let period = f64::from(self.queue.get_timestamp_period());
                let v = (0..passes.len())
                    .map(|k| Timing { seconds: t[2 * k + 1].saturating_sub(t[2 * k]) as f64 * period * 1e-9, source: TimingSource::TimestampQuery })
                    .collect();
                drop(view);
                read.unmap();
                v
            }
            None => vec![Timing { seconds: wall / passes.len().max(1) as f64, source: TimingSource::WallClock }; passes.len()],
        };
        Ok((out, times))
    }

    /// Whether the subgroup module (entry points under `ssr_subgroup::`) is loaded.
    pub fn has_subgroups(&self) -> bool {
        self.subgroup_module.is_some()
    }

    /// Largest storage binding, in bytes.
    pub fn max_binding_bytes(&self) -> usize {
        (self.limits.max_storage_buffer_binding_size as usize).min(1 << 30)
    }
}

/// Each entry point's uniform-buffer bindings in a SPIR-V module
/// ([`shader_manifest::uniform_bindings`]).
pub(crate) fn uniform_bindings(words: &[u32]) -> Result<HashMap<String, Vec<u32>>, GpuError> {
    Ok(shader_manifest::uniform_bindings(words).map_err(GpuError::Shader)?.into_iter().collect())
}

/// A buffer of [`GpuDevice::dispatch_chain`]: uploaded input, or a device buffer the passes
/// write (zeroed or initialized), optionally read back after the chain.
#[derive(Clone, Copy, Debug)]
pub enum ChainBuffer<'a> {
    Input(&'a [u8]),
    Output { size: usize, init: Option<&'a [u8]>, read_back: bool },
}

/// How a chain pass is dispatched: fixed workgroup counts, or (x, y, z) u32 counts read from a
/// chain buffer at a byte offset (written by an earlier pass).
#[derive(Clone, Copy, Debug)]
pub enum ChainDispatch {
    Direct(u32, u32, u32),
    Indirect { buffer: usize, offset_bytes: u64 },
}

/// One pass of a chain: entry point and its specialization, read-only buffers, read-write
/// buffers (indices into the chain's buffers, bound in that order), dispatch.
#[derive(Clone, Debug)]
pub struct ChainPass<'a> {
    pub entry: &'a str,
    /// Values of the entry point's specialization constants 0.. (`&[]`: none set, each keeps the
    /// default its module declares); the pipeline is compiled with them as constants
    /// ([`shader_manifest::spec_constant`]). Ignored by an entry point that declares none and
    /// by modules added at run time.
    pub spec: &'a [u32],
    pub reads: Vec<usize>,
    pub writes: Vec<usize>,
    pub dispatch: ChainDispatch,
}

/// A read-write buffer of `dispatch`: its size in bytes and optional initial contents.
#[derive(Clone, Copy, Debug)]
pub struct OutputSpec<'a> {
    pub size: usize,
    pub init: Option<&'a [u8]>,
}

impl OutputSpec<'_> {
    pub fn zeroed(size: usize) -> Self {
        OutputSpec { size, init: None }
    }
}

fn padded(data: &[u8]) -> Cow<'_, [u8]> {
    if data.len() >= 4 && data.len().is_multiple_of(4) {
        Cow::Borrowed(data)
    } else {
        let mut v = data.to_vec();
        v.resize(data.len().max(4).next_multiple_of(4), 0);
        Cow::Owned(v)
    }
}

/// Split `groups` workgroups into a 2D grid within the 65535-per-dimension limit.
/// (`shader_core::dispatch::groups_2d`, with at least one row: a launch of nothing still
/// dispatches one workgroup, whose invocations return at once.)
pub fn groups_2d(groups: u32) -> (u32, u32) {
    shader_core::dispatch::groups_2d(groups.max(1))
}
