//! `host bench storage`: what reading a storage buffer costs the GPU backend's adapter, next to
//! the CPU reading the same values: the floor under every kernel that does little arithmetic per
//! value it reads (the SSR depth and colour pyramids, the specular pass, the neighbourhood
//! resolves; docs/ssr.md).
//!
//! Hand-written WGSL kernels (host/src/wgsl/storage.wgsl, compiled by naga), no project math:
//! invocation `i` sums K floats into `output[i]`, read from its own record of K (`input[i K + j]`,
//! as the SSR passes read G-buffer, ray and hit records) or K times from addresses every
//! invocation shares (`input[j]`, as the SSR passes read their parameter record while it was a
//! storage buffer), as K `f32` loads or K / 4 `vec4<f32>` loads, and the own-record reads also as
//! `textureLoad`s of an R32Float texture, one float per fetch, or of an Rgba32Float texture, four
//! per fetch (host/src/wgsl/storage_texture.wgsl: the way around the storage-buffer cost a kernel
//! could take); and 16 floats at per-invocation addresses of a 64 KiB
//! table, held in a storage buffer or in a uniform buffer (host/src/wgsl/storage_table.wgsl: the
//! energy LUT taps' pattern, and the other buffer such a table could live in). Every GPU result is checked
//! against the CPU's sums (exact: the inputs are multiples of 1/4), so a kernel that skipped its
//! reads would fail the run rather than look fast. GPU times are the timestamp queries around the
//! compute pass (uploads and readback excluded; the texture rows: the wall clock from submitting
//! the dispatch alone to its completion), CPU times the backend's thread pool over the same
//! reads; the fastest of `--repeats` runs after one warm-up, medians beside them.

use crate::backend::{Backend, DeviceChoice};
use crate::gpu::{groups_2d, GpuContext, OutputSpec};
use crate::report::{write_json, RunInfo};
use crate::timing::best_and_median;
use anyhow::{bail, Context, Result};
use rayon::prelude::*;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

/// The WGSL template (`ELEM`, `SUM` and the entry points' prefix are filled in per load width).
const WGSL_TEMPLATE: &str = include_str!("wgsl/storage.wgsl");

/// Options of `host bench storage`.
#[derive(clap::Args, Debug, Clone)]
pub struct StorageArgs {
    /// Invocations per dispatch (default 2^21, about the pixels of a 1920x1080 frame).
    #[arg(long, default_value_t = 1 << 21, value_parser = clap::value_parser!(u32).range(1024..=1 << 24))]
    pub invocations: u32,
    /// Timed runs per kernel and backend (after one warm-up); the fastest is reported.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=100))]
    pub repeats: u32,
    /// Markdown report; the JSON report is written beside it (same name, .json).
    #[arg(long, short, default_value = "out/storage-bench.md")]
    pub output: PathBuf,
}

/// One kernel: its entry point, floats it reads per invocation, load instructions per
/// invocation, whether every invocation reads the same addresses, the channels of the sampled
/// texture it reads them from instead of a storage buffer (0: a storage buffer), and whether it
/// reads a 64 KiB table at per-invocation addresses ([`TABLE_FLOATS`]; `storage_` / `uniform_`:
/// the buffer it is in).
struct Kernel {
    entry: &'static str,
    floats: usize,
    loads: usize,
    shared: bool,
    /// Channels of the texture rows' texels: 1 (R32Float, one `textureLoad` per float) or 4
    /// (Rgba32Float, one `textureLoad` per four floats); 0 for the storage-buffer rows.
    channels: u32,
    table: bool,
}

impl Kernel {
    /// Whether it reads a texture ([`Kernel::channels`] > 0) rather than a storage buffer.
    fn texture(&self) -> bool {
        self.channels > 0
    }
}

const KERNELS: [Kernel; 13] = [
    Kernel { entry: "f32_own_1", floats: 1, loads: 1, shared: false, channels: 0, table: false },
    Kernel { entry: "f32_own_4", floats: 4, loads: 4, shared: false, channels: 0, table: false },
    Kernel { entry: "f32_own_16", floats: 16, loads: 16, shared: false, channels: 0, table: false },
    Kernel { entry: "f32_shared_16", floats: 16, loads: 16, shared: true, channels: 0, table: false },
    Kernel { entry: "vec4_own_1", floats: 4, loads: 1, shared: false, channels: 0, table: false },
    Kernel { entry: "vec4_own_4", floats: 16, loads: 4, shared: false, channels: 0, table: false },
    Kernel { entry: "texel_own_1", floats: 1, loads: 1, shared: false, channels: 1, table: false },
    Kernel { entry: "texel_own_4", floats: 4, loads: 4, shared: false, channels: 1, table: false },
    Kernel { entry: "texel_own_16", floats: 16, loads: 16, shared: false, channels: 1, table: false },
    Kernel { entry: "texel4_own_1", floats: 4, loads: 1, shared: false, channels: 4, table: false },
    Kernel { entry: "texel4_own_4", floats: 16, loads: 4, shared: false, channels: 4, table: false },
    Kernel { entry: "storage_table_16", floats: 16, loads: 16, shared: false, channels: 0, table: true },
    Kernel { entry: "uniform_table_16", floats: 16, loads: 16, shared: false, channels: 0, table: true },
];

/// The table rows' WGSL (`SPACE`: the table's address space, `PREFIX`: the entry point's prefix).
const WGSL_TABLE: &str = include_str!("wgsl/storage_table.wgsl");

/// Floats in the table rows' table: 64 KiB, the largest uniform buffer every Vulkan device binds.
const TABLE_FLOATS: usize = 16384;

/// The table module whose table lives in `space` ("storage" or "uniform").
fn table_module(space: &str) -> String {
    let decl = if space == "uniform" { "uniform" } else { "storage, read" };
    WGSL_TABLE.replace("SPACE", decl).replace("fn PREFIX_", &format!("fn {space}_"))
}

/// The table address invocation `i` reads `j`-th (the WGSL's formula).
fn table_address(i: usize, j: usize) -> usize {
    (i * 16 + j * 977) & (TABLE_FLOATS - 1)
}

/// The texture rows' WGSL (`textureLoad` of an R32Float texture).
const WGSL_TEXTURE: &str = include_str!("wgsl/storage_texture.wgsl");

/// Width in texels of the texture rows' input (rows of floats, as many as the input needs).
const TEXTURE_WIDTH: u32 = 4096;

/// One kernel's figures.
#[derive(Clone, Debug, Serialize)]
pub struct StorageRow {
    pub kernel: String,
    pub floats_per_invocation: usize,
    pub load_instructions_per_invocation: usize,
    pub shared_addresses: bool,
    /// Read from a sampled texture (`textureLoad`) rather than a storage buffer.
    pub texture: bool,
    /// The texture's channels: 1 (R32Float) or 4 (Rgba32Float); 0 for a storage buffer.
    pub texture_channels: u32,
    /// Reads a 64 KiB table at per-invocation addresses (the buffer it is in: the kernel's prefix).
    pub table: bool,
    /// How the GPU time was taken: "timestamp query" (the pass) or "wall clock" (the texture
    /// rows: submission to completion of the dispatch alone, uploads and readback excluded).
    pub gpu_timing: String,
    pub gpu_ns_per_invocation: f64,
    pub gpu_median_ns_per_invocation: f64,
    /// Storage load instructions per second (all lanes), from the fastest run.
    pub gpu_load_instructions_per_s: f64,
    pub cpu_ns_per_invocation: f64,
    pub cpu_median_ns_per_invocation: f64,
    /// gpu_ns_per_invocation / cpu_ns_per_invocation.
    pub gpu_over_cpu_time: f64,
}

/// The WGSL module of one load width: `f32` or `vec4` records, entry points prefixed by it.
fn wgsl_module(prefix: &str) -> String {
    let (elem, sum) = if prefix == "vec4" { ("vec4<f32>", "v.x + v.y + v.z + v.w") } else { ("f32", "v") };
    WGSL_TEMPLATE.replace("ELEM", elem).replace("SUM", sum).replace("fn own_", &format!("fn {prefix}_own_")).replace("fn shared_", &format!("fn {prefix}_shared_"))
}

/// The input of kernel `k`: multiples of 1/4 below 2, so every sum is exact in f32.
fn input_of(k: &Kernel, n: usize) -> Vec<f32> {
    let len = if k.table { TABLE_FLOATS } else if k.shared { k.floats } else { n * k.floats };
    (0..len).map(|j| (j % 7) as f32 * 0.25).collect()
}

/// The sums the kernel must produce, computed on the CPU backend's threads into `out`; returns
/// the seconds it took.
fn cpu_sums(k: &Kernel, input: &[f32], out: &mut [f32]) -> f64 {
    let t0 = Instant::now();
    let f = k.floats;
    if k.table {
        out.par_iter_mut().enumerate().for_each(|(i, o)| *o = (0..f).map(|j| input[table_address(i, j)]).sum());
    } else if k.shared {
        out.par_iter_mut().for_each(|o| *o = input[..f].iter().sum());
    } else {
        out.par_iter_mut().zip(input.par_chunks_exact(f)).for_each(|(o, r)| *o = r.iter().sum());
    }
    t0.elapsed().as_secs_f64()
}

pub fn run(a: &StorageArgs) -> Result<()> {
    crate::io::prepare_output(&a.output)?;
    let backend = Backend::select(DeviceChoice::Gpu).context("host bench storage times the GPU backend's adapter")?;
    let Some(g) = backend.gpu() else { bail!("host bench storage needs the GPU backend") };
    eprintln!("{}", backend.describe());
    let info = RunInfo::start(Some(g.describe()));
    for prefix in ["f32", "vec4"] {
        let names: Vec<&str> = KERNELS.iter().filter(|k| !k.texture()).map(|k| k.entry).filter(|e| e.starts_with(prefix)).collect();
        g.add_wgsl(&format!("storage bench ({prefix})"), &wgsl_module(prefix), &names)?;
    }
    g.add_wgsl("storage bench (table in a storage buffer)", &table_module("storage"), &["storage_table_16"])?;
    g.add_wgsl_with_uniforms("storage bench (table in a uniform buffer)", &table_module("uniform"), &["uniform_table_16"], &[("uniform_table_16", 1)])?;
    let n = a.invocations as usize;
    let mut rows = Vec::new();
    let mut expected = vec![0.0f32; n];
    for k in &KERNELS {
        let input = input_of(k, n);
        let mut cpu = Vec::new();
        cpu_sums(k, &input, &mut expected);
        for _ in 0..a.repeats {
            cpu.push(cpu_sums(k, &input, &mut expected));
        }
        let mut gpu = Vec::new();
        let texture = if k.texture() { Some(TextureKernel::new(g, k, &input, n)?) } else { None };
        for run in 0..=a.repeats {
            let (sums, secs) = match &texture {
                Some(t) => t.run(g)?,
                None => gpu_sums(g, k.entry, &input, n)?,
            };
            if let Some(i) = (0..n).find(|&i| sums[i].to_bits() != expected[i].to_bits()) {
                bail!("{}: invocation {i} wrote {} where its reads sum to {}", k.entry, sums[i], expected[i]);
            }
            if run > 0 {
                gpu.push(secs);
            }
        }
        let (gb, gm) = best_and_median(gpu);
        let (cb, cm) = best_and_median(cpu);
        let per = |s: f64| s * 1e9 / n as f64;
        let row = StorageRow {
            kernel: k.entry.into(),
            floats_per_invocation: k.floats,
            load_instructions_per_invocation: k.loads,
            shared_addresses: k.shared,
            texture: k.texture(),
            texture_channels: k.channels,
            table: k.table,
            gpu_timing: if k.texture() { "wall clock" } else { "timestamp query" }.into(),
            gpu_ns_per_invocation: per(gb),
            gpu_median_ns_per_invocation: per(gm),
            gpu_load_instructions_per_s: (n * k.loads) as f64 / gb,
            cpu_ns_per_invocation: per(cb),
            cpu_median_ns_per_invocation: per(cm),
            gpu_over_cpu_time: gb / cb,
        };
        eprintln!("{:<14} GPU {:>7.2} ns  CPU {:>6.2} ns per invocation", row.kernel, row.gpu_ns_per_invocation, row.cpu_ns_per_invocation);
        rows.push(row);
    }
    let md = markdown(&info, a, &rows);
    crate::io::write_file(&a.output, md)?;
    let json = write_json(&a.output, info, &rows)?;
    println!("wrote {}", a.output.display());
    println!("wrote {}", json.display());
    Ok(())
}

/// One GPU dispatch of `entry` over `n` invocations: the sums and the pass's seconds.
fn gpu_sums(g: &GpuContext, entry: &str, input: &[f32], n: usize) -> Result<(Vec<f32>, f64)> {
    let (gx, gy) = groups_2d((n as u32).div_ceil(shader_kernels::WORKGROUP_SIZE));
    let args = [n as u32, gx];
    let (out, t) = g
        .dispatch(entry, &[bytemuck::cast_slice(&args), bytemuck::cast_slice(input)], &[OutputSpec::zeroed(n * 4)], (gx, gy, 1))
        .with_context(|| format!("dispatching {entry}"))?;
    Ok((bytemuck::cast_slice(&out[0]).to_vec(), t.seconds))
}

/// A texture row's pipeline and resources, created once (the input uploaded, the driver's
/// compile done) so that [`TextureKernel::run`] times the dispatch alone.
struct TextureKernel {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    output: wgpu::Buffer,
    readback: wgpu::Buffer,
    groups: (u32, u32),
    n: usize,
}

impl TextureKernel {
    fn new(g: &GpuContext, k: &Kernel, input: &[f32], n: usize) -> Result<TextureKernel> {
        let entry = k.entry;
        let device = &g.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let channels = k.channels;
        let height = (input.len() as u32).div_ceil(TEXTURE_WIDTH * channels);
        let max = g.limits.max_texture_dimension_2d;
        if height > max {
            bail!("{entry}: {} floats need a texture {TEXTURE_WIDTH} x {height} of {channels}-channel texels, over the adapter's {max} texels; use fewer --invocations", input.len());
        }
        let size = wgpu::Extent3d { width: TEXTURE_WIDTH, height, depth_or_array_layers: 1 };
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(entry),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: if channels == 4 { wgpu::TextureFormat::Rgba32Float } else { wgpu::TextureFormat::R32Float },
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let mut texels = input.to_vec();
        texels.resize((TEXTURE_WIDTH * channels * height) as usize, 0.0);
        g.queue.write_texture(
            wgpu::TexelCopyTextureInfo { texture: &texture, mip_level: 0, origin: wgpu::Origin3d::ZERO, aspect: wgpu::TextureAspect::All },
            bytemuck::cast_slice(&texels),
            wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(TEXTURE_WIDTH * channels * 4), rows_per_image: Some(height) },
            size,
        );
        let groups = groups_2d((n as u32).div_ceil(shader_kernels::WORKGROUP_SIZE));
        let args = [n as u32, groups.0, TEXTURE_WIDTH, 0];
        use wgpu::util::DeviceExt;
        let args = device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some("texture bench args"), contents: bytemuck::cast_slice(&args), usage: wgpu::BufferUsages::STORAGE });
        let output = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("texture bench output"),
            size: (n * 4) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("texture bench readback"),
            size: (n * 4) as u64,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let buffer = |binding: u32, read_only: bool| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Storage { read_only }, has_dynamic_offset: false, min_binding_size: None },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some(entry),
            entries: &[
                buffer(0, true),
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                buffer(2, false),
            ],
        });
        let view = texture.create_view(&Default::default());
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(entry),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: args.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&view) },
                wgpu::BindGroupEntry { binding: 2, resource: output.as_entire_binding() },
            ],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some("storage bench (texture)"), source: wgpu::ShaderSource::Wgsl(WGSL_TEXTURE.into()) });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor { label: Some(entry), bind_group_layouts: &[Some(&layout)], immediate_size: 0 });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some(entry),
            compilation_options: Default::default(),
            cache: None,
        });
        device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| anyhow::anyhow!("{entry}: {e}"))?;
        if let Some(err) = pollster::block_on(scope.pop()) {
            bail!("{entry}: {err}");
        }
        Ok(TextureKernel { pipeline, bind_group, output, readback, groups, n })
    }

    /// One dispatch, timed from its submission to its completion, then the sums read back.
    fn run(&self, g: &GpuContext) -> Result<(Vec<f32>, f64)> {
        let mut encoder = g.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.dispatch_workgroups(self.groups.0, self.groups.1, 1);
        }
        let t0 = Instant::now();
        g.queue.submit([encoder.finish()]);
        g.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| anyhow::anyhow!("texture bench: {e}"))?;
        let secs = t0.elapsed().as_secs_f64();
        let mut encoder = g.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&self.output, 0, &self.readback, 0, (self.n * 4) as u64);
        g.queue.submit([encoder.finish()]);
        self.readback.map_async(wgpu::MapMode::Read, .., |r| r.expect("mapping the texture bench's readback"));
        g.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| anyhow::anyhow!("texture bench: {e}"))?;
        let sums = {
            let view = self.readback.get_mapped_range(..).map_err(|e| anyhow::anyhow!("texture bench: {e}"))?;
            bytemuck::cast_slice::<u8, f32>(&view).to_vec()
        };
        self.readback.unmap();
        Ok((sums, secs))
    }
}

fn markdown(info: &RunInfo, a: &StorageArgs, rows: &[StorageRow]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Storage-buffer reads: GPU backend against CPU\n");
    let _ = writeln!(s, "Command: `{}`  ", info.command);
    let _ = writeln!(s, "CPU: {} ({} threads); load average at start {:?}  ", info.cpu, info.cpu_threads, info.load_average_start.unwrap_or_default());
    let _ = writeln!(s, "Adapter: {}  ", info.adapter.as_deref().unwrap_or("-"));
    let _ = writeln!(s, "{} invocations per dispatch, fastest of {} runs after a warm-up (median in brackets); every GPU sum checked against the CPU's.\n", a.invocations, a.repeats);
    let _ = writeln!(s, "Storage rows are timed by timestamp queries around the pass, texture rows (`textureLoad` of an R32Float or, `texel4_`, an Rgba32Float texture {TEXTURE_WIDTH} texels wide) by the wall clock from submitting the dispatch alone to its completion.\n");
    let _ = writeln!(s, "| kernel | floats read per invocation | load instructions | addresses | GPU ns / invocation | GPU load instructions / s | CPU ns / invocation | GPU time / CPU time |");
    let _ = writeln!(s, "| --- | ---: | ---: | --- | ---: | ---: | ---: | ---: |");
    for r in rows {
        let _ = writeln!(
            s,
            "| `{}` | {} | {} | {} | {:.2} ({:.2}) | {:.0} M | {:.2} ({:.2}) | {:.1} |",
            r.kernel,
            r.floats_per_invocation,
            r.load_instructions_per_invocation,
            match (r.table, r.texture, r.shared_addresses) {
                (true, ..) if r.kernel.starts_with("uniform") => "64 KiB table, uniform buffer",
                (true, ..) => "64 KiB table, storage buffer",
                (false, true, _) if r.texture_channels == 4 => "own record, RGBA texture",
                (false, true, _) => "own record, texture",
                (false, false, true) => "shared by all",
                (false, false, false) => "own record",
            },
            r.gpu_ns_per_invocation,
            r.gpu_median_ns_per_invocation,
            r.gpu_load_instructions_per_s / 1e6,
            r.cpu_ns_per_invocation,
            r.cpu_median_ns_per_invocation,
            r.gpu_over_cpu_time
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modules_name_their_entry_points_and_load_width() {
        let f = wgsl_module("f32");
        assert!(f.contains("array<f32>") && f.contains("fn f32_own_16") && f.contains("fn f32_shared_16") && !f.contains("ELEM"));
        let v = wgsl_module("vec4");
        assert!(v.contains("array<vec4<f32>>") && v.contains("fn vec4_own_4") && v.contains("v.x + v.y + v.z + v.w"));
        // Every storage kernel's entry point is in the module of its prefix, every texture
        // kernel's in the texture module.
        for k in KERNELS.iter().filter(|k| k.texture()) {
            assert!(WGSL_TEXTURE.contains(&format!("fn {}(", k.entry)), "{}", k.entry);
        }
        for k in KERNELS.iter().filter(|k| !k.texture() && !k.table) {
            let prefix = k.entry.split('_').next().unwrap();
            assert!(wgsl_module(prefix).contains(&format!("fn {}(", k.entry)), "{}", k.entry);
        }
        let u = table_module("uniform");
        assert!(u.contains("var<uniform> table") && u.contains("fn uniform_table_16(") && !u.contains("SPACE"));
        let st = table_module("storage");
        assert!(st.contains("var<storage, read> table") && st.contains("fn storage_table_16("));
        assert!(KERNELS.iter().filter(|k| k.table).all(|k| table_module(k.entry.split('_').next().unwrap()).contains(&format!("fn {}(", k.entry))));
    }

    #[test]
    fn table_sums_read_the_wgsl_addresses() {
        let k = KERNELS.iter().find(|k| k.entry == "uniform_table_16").unwrap();
        let input = input_of(k, 2);
        assert_eq!(input.len(), TABLE_FLOATS);
        let mut out = vec![0.0; 2];
        cpu_sums(k, &input, &mut out);
        // Invocation 1 reads 16 + 977 j: the WGSL's (i * 16 + j * 977) & 16383.
        let want: f32 = (0..16).map(|j| ((16 + 977 * j) % 7) as f32 * 0.25).sum();
        assert_eq!(out[1], want);
        assert_eq!(table_address(16383, 15), (16383 * 16 + 15 * 977) % 16384);
    }

    #[test]
    fn cpu_sums_read_each_invocations_record() {
        let k = &KERNELS[1];
        let input = input_of(k, 3);
        let mut out = vec![0.0; 3];
        cpu_sums(k, &input, &mut out);
        assert_eq!(out, vec![0.0 + 0.25 + 0.5 + 0.75, 1.0 + 1.25 + 1.5 + 0.0, 0.25 + 0.5 + 0.75 + 1.0]);
    }
}
