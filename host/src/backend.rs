//! Backend selection (`--device auto|cpu|gpu`) and the operations every backend offers.

use crate::gpu::{groups_2d, GpuContext, GpuError, OutputSpec};
use crate::timing::{Timing, TimingSource};
use anyhow::{bail, Context, Result};
use shader_kernels::eval::{EvalArgs, FunctionInfo};
use std::time::Instant;

/// What the user asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum DeviceChoice {
    /// The GPU if a Vulkan adapter exists, else the CPU backend (with a one-line notice).
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

impl Backend {
    /// Create the backend the user chose. The GPU backend refuses SPIR-V that is stale relative
    /// to the shader sources this binary was built from.
    pub fn select(choice: DeviceChoice) -> Result<Backend> {
        match choice {
            DeviceChoice::Cpu => Ok(Backend::Cpu),
            DeviceChoice::Gpu | DeviceChoice::Auto => {
                let shader = crate::shaders::load().map_err(anyhow::Error::msg)?;
                match GpuContext::new(&shader) {
                    Ok(ctx) => Ok(Backend::Gpu(Box::new(ctx))),
                    Err(GpuError::NoAdapter) if choice == DeviceChoice::Auto => {
                        eprintln!(
                            "notice: no Vulkan adapter found, running on the CPU backend \
                             ({} threads); install lavapipe for the GPU path: \
                             apt-get install -y mesa-vulkan-drivers libvulkan1",
                            crate::cpu::threads()
                        );
                        Ok(Backend::Cpu)
                    }
                    Err(e) => Err(e.into()),
                }
            }
        }
    }

    /// The GPU backend for a benchmark's GPU columns: `None` for `--device cpu` and for `auto`
    /// without an adapter, an error for `--device gpu` without one.
    pub fn gpu_column(choice: DeviceChoice) -> Result<Option<Backend>> {
        match choice {
            DeviceChoice::Cpu => Ok(None),
            DeviceChoice::Gpu | DeviceChoice::Auto => match Backend::select(choice)? {
                b @ Backend::Gpu(_) => Ok(Some(b)),
                Backend::Cpu => Ok(None),
            },
        }
    }

    /// The backends a benchmark times: the CPU backend and [`Backend::gpu_column`], each
    /// described on standard error.
    pub fn bench_pair(choice: DeviceChoice) -> Result<(Backend, Option<Backend>)> {
        let gpu = Backend::gpu_column(choice)?;
        let cpu = Backend::Cpu;
        eprintln!("{}", cpu.describe());
        match &gpu {
            Some(g) => eprintln!("{}", g.describe()),
            None => eprintln!("no GPU backend: GPU columns left empty"),
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

    pub fn is_gpu(&self) -> bool {
        matches!(self, Backend::Gpu(_))
    }

    /// Evaluate `f` over `rows` rows of its input columns (`input` holds `rows * f.inputs.len()`
    /// values, row-major), returning `rows * f.outputs.len()` outputs and the time taken. The GPU
    /// runs `f`'s own entry point; the CPU runs its batch loop on all cores.
    pub fn eval_table(&self, f: &FunctionInfo, input: &[f32], rows: usize) -> Result<(Vec<f32>, Timing)> {
        let (in_stride, out_stride) = (f.inputs.len(), f.outputs.len());
        if input.len() != rows * in_stride {
            bail!("{}: input has {} values, expected {rows} rows x {in_stride} columns", f.name, input.len());
        }
        match self {
            Backend::Cpu => {
                let t0 = Instant::now();
                let out = crate::cpu::eval_table(f, input, rows);
                Ok((out, Timing { seconds: t0.elapsed().as_secs_f64(), source: TimingSource::WallClock }))
            }
            Backend::Gpu(g) => {
                if rows == 0 {
                    return Ok((Vec::new(), Timing { seconds: 0.0, source: TimingSource::WallClock }));
                }
                let wg = shader_kernels::WORKGROUP_SIZE as usize;
                let max_bytes = g.max_binding_bytes();
                let per_row = 4 * in_stride.max(out_stride).max(1);
                let chunk_rows = (max_bytes / per_row).min(65535 * 65535 * wg).max(wg);
                let mut out = Vec::with_capacity(rows * out_stride);
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
                    total = Some(match total { Some(a) => a.add(t), None => t });
                    start += n;
                }
                Ok((out, total.expect("at least one dispatch")))
            }
        }
    }
}
