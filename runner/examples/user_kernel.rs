//! Dispatch a kernel of your own with the runner alone (no CLI, plotting or image crates):
//! a WGSL compute shader that evaluates GGX D at normal incidence, 1 / (pi alpha^2), over a
//! buffer of roughness values, run on whatever Vulkan adapter there is and checked against the
//! CPU. (A rust-gpu module of your own goes through `GpuContext::add_spirv` the same way.)
//!
//! Run: `cargo run --release -p runner --example user_kernel`.

use runner::gpu::{groups_2d, GpuContext, GpuError, OutputSpec};

const SOURCE: &str = r#"
struct Args { rows: u32, groups_x: u32 }
@group(0) @binding(0) var<storage, read> args: Args;
@group(0) @binding(1) var<storage, read> alpha: array<f32>;
@group(0) @binding(2) var<storage, read_write> d: array<f32>;

@compute @workgroup_size(64)
fn ggx_d_normal(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x + id.y * args.groups_x * 64u;
    if (i < args.rows) {
        let a2 = alpha[i] * alpha[i];
        d[i] = 1.0 / (3.14159265 * a2);
    }
}
"#;

fn main() -> anyhow::Result<()> {
    // The adapter with the build of the built-in kernels HOST_DIV_SQRT chooses (auto: the native
    // division where the driver rounds it correctly, else the exact build).
    let gpu = match GpuContext::with_div_sqrt_choice() {
        Ok(g) => g,
        Err(GpuError::NoAdapter) => {
            eprintln!("no Vulkan adapter: install one (e.g. lavapipe: apt-get install -y mesa-vulkan-drivers libvulkan1)");
            return Ok(());
        }
        Err(e) => return Err(e.into()),
    };
    println!("{}", gpu.describe());
    gpu.add_wgsl("user kernel", SOURCE, &["ggx_d_normal"])?;
    let rows = 100_000usize;
    let alpha: Vec<f32> = (0..rows).map(|i| 0.01 + 0.99 * i as f32 / rows as f32).collect();
    let (gx, gy) = groups_2d(rows.div_ceil(64) as u32);
    let args = [rows as u32, gx];
    let (out, timing) = gpu.dispatch(
        "ggx_d_normal",
        &[bytemuck::cast_slice(&args), bytemuck::cast_slice(&alpha)],
        &[OutputSpec::zeroed(rows * 4)],
        (gx, gy, 1),
    )?;
    let d: Vec<f32> = bytemuck::pod_collect_to_vec(&out[0]);
    let worst = alpha
        .iter()
        .zip(&d)
        .map(|(a, d)| ((d - 1.0 / (std::f32::consts::PI * a * a)) * (std::f32::consts::PI * a * a)).abs())
        .fold(0.0f32, f32::max);
    println!("{rows} values in {:.3} ms ({}); max relative difference from the CPU: {worst:.2e}", timing.seconds * 1e3, timing.source);
    anyhow::ensure!(worst < 1e-5, "the GPU result differs from the CPU's by {worst}");
    Ok(())
}
