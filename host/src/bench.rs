//! `host bench <feature>`: the one tree of benchmarks (cost, accuracy and speed reports of
//! every feature); each subcommand's module writes its report.

use anyhow::Result;

/// `host bench ...`.
#[derive(clap::Args, Debug)]
pub struct BenchCli {
    #[command(subcommand)]
    pub what: BenchWhat,
}

/// The benchmarks.
#[derive(clap::Subcommand, Debug)]
pub enum BenchWhat {
    /// Error (vs f64 references) and evaluations/s (CPU and GPU backends) of the visibility
    /// approximations, the GGX D forms (fp32 and emulated fp16) and the Beckmann Lambda (exact vs
    /// Walter). Writes a markdown table and a PNG scatter plot (error vs evaluations/s).
    Microfacet(crate::bench_microfacet::MicrofacetArgs),
    /// GGX reflection samplers (NDF, ellipsoid VNDF, spherical caps, bounded VNDF): fraction of
    /// samples below the horizon, samples/s (CPU and GPU backends), variance of a one-sample
    /// albedo estimator and its error at equal time. Writes out/vndf-bench.md and .png.
    Vndf(crate::bench_vndf::VndfArgs),
    /// Evaluations/s of every evaluable function on the CPU backend (all threads and one
    /// thread) and the GPU backend, the driver compile time of each entry point, and the
    /// rust-gpu / hand-written WGSL rate ratio for ggx_d and sample_vndf_heitz. Writes
    /// out/kernel-rates.md and .json.
    Kernels(crate::bench_kernels::KernelsArgs),
    /// What reading a storage buffer costs the GPU backend's adapter against the CPU reading
    /// the same values, and the same reads as texture fetches (hand-written WGSL kernels, no
    /// shading math): the floor under the kernels that do little arithmetic per value read.
    /// Needs a Vulkan adapter. Writes out/storage-bench.md and .json.
    Storage(crate::bench_storage::StorageArgs),
    /// Rays per second of the path tracer (CPU backend on all threads and one, GPU backend, with
    /// bit-identical images checked), cost against scene size (1k / 30k / 300k triangles), time
    /// to a given error at 512x512, and memory. Writes out/render-bench.md and .json.
    Render(crate::render::bench::RenderBenchArgs),
    /// Error of the precomputed energy tables (E, E', E_avg) against the f64 quadrature for
    /// several resolutions and sample counts, and the precompute time on the CPU and GPU
    /// backends. Writes Markdown + PNG + JSON (default out/energy-bench.md).
    Energy(crate::energy_bench::BenchArgs),
    /// SSR: every configuration on every built-in scene: errors against the path-traced
    /// reference, times, skipped work; writes a Markdown report, its figures as JSON and a PNG
    /// of error against time (default: out/).
    Ssr(crate::ssr::bench::BenchArgs),
    /// SSR: the stochastic pipeline with its parts switched off one at a time (non-mirror error
    /// per roughness band), to locate its error; prints a Markdown table.
    SsrAblate(crate::ssr::bench::AblateArgs),
    /// SSR: GPU wall-clock time of one stochastic frame: every pass submitted and read back on
    /// its own against the whole frame in one command buffer (indirect trace); prints a
    /// Markdown table.
    SsrWall(crate::ssr::bench::WallArgs),
    /// SSR: per-pass frame times of several configurations on several backends in one process
    /// (e.g. the CPU backend and two lavapipes), alternated, fastest of some rounds; checks that
    /// every backend's reflection and specular term are bit-identical; Markdown + JSON.
    SsrPasses(crate::ssr::passes::PassesArgs),
}

impl BenchCli {
    pub fn run(self) -> Result<()> {
        match self.what {
            BenchWhat::Microfacet(a) => crate::bench_microfacet::run(&a),
            BenchWhat::Vndf(a) => crate::bench_vndf::run(&a),
            BenchWhat::Kernels(a) => crate::bench_kernels::run(&a),
            BenchWhat::Storage(a) => crate::bench_storage::run(&a),
            BenchWhat::Render(a) => crate::render::bench::run(&a),
            BenchWhat::Energy(a) => crate::energy_bench::run(&a),
            BenchWhat::Ssr(a) => crate::ssr::bench::run(&a),
            BenchWhat::SsrAblate(a) => crate::ssr::bench::run_ablate(&a),
            BenchWhat::SsrWall(a) => crate::ssr::bench::run_wall(&a),
            BenchWhat::SsrPasses(a) => crate::ssr::passes::run(&a),
        }
    }
}
