//! The example shader crate `examples/user-shader` (a rust-gpu crate of one's own on
//! shader-core): its committed SPIR-V is fresh for the current sources and carries the
//! post-processing bit-exactness needs, and on the GPU its entry point returns the same bits as
//! the same function called natively.

use crosscheck::{assert_bits_equal, gpu_backend, inputs};
use host::gpu::{groups_2d, OutputSpec};
use shader_manifest::{Manifest, USER_SHADER_CRATES, USER_SHADER_MANIFEST_PATH, USER_SHADER_REBUILD_COMMAND, USER_SHADER_SPV_PATH};
use std::path::PathBuf;

fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).parent().expect("tests/ lives in the workspace").to_path_buf()
}

fn committed() -> (Vec<u32>, Manifest) {
    let root = workspace_root();
    let spv = shader_manifest::read_module(&root, USER_SHADER_SPV_PATH)
        .unwrap()
        .unwrap_or_else(|| panic!("{USER_SHADER_SPV_PATH} is missing; run `{USER_SHADER_REBUILD_COMMAND}`"));
    let json = std::fs::read_to_string(root.join(USER_SHADER_MANIFEST_PATH))
        .unwrap_or_else(|e| panic!("reading {USER_SHADER_MANIFEST_PATH}: {e}; run `{USER_SHADER_REBUILD_COMMAND}`"));
    let manifest = Manifest::from_json(&json).unwrap();
    assert_eq!(manifest.spv_bytes as usize, spv.len(), "{USER_SHADER_SPV_PATH} does not match its manifest");
    (shader_manifest::spirv_words(&spv), manifest)
}

#[test]
fn user_shader_spirv_is_fresh_and_post_processed() {
    let (words, manifest) = committed();
    let hash = shader_manifest::source_hash_of(&workspace_root(), &USER_SHADER_CRATES).unwrap();
    assert_eq!(
        manifest.source_hash, hash,
        "{USER_SHADER_SPV_PATH} was built from other sources (shader-core or examples/user-shader changed): run `{USER_SHADER_REBUILD_COMMAND}` and commit it"
    );
    assert_eq!(manifest.entry_points, [user_shader::ENTRY_POINT]);
    // Built by the same pinned toolchain and rust-gpu as the project's own kernels.
    let main = Manifest::from_json(runner_manifest()).unwrap();
    assert_eq!((&manifest.toolchain, &manifest.spirv_builder, &manifest.target), (&main.toolchain, &main.spirv_builder, &main.target));
    // The post-processing of `cargo xtask build-shaders`.
    let (total, covered) = shader_manifest::no_contraction_coverage(&words).unwrap();
    assert!(total > 100, "only {total} float arithmetic instructions: not the GGX lobe?");
    assert_eq!(covered, total, "float ops without NoContraction: run `{USER_SHADER_REBUILD_COMMAND}`");
    assert_eq!(shader_manifest::preserve_signed_zero_inf_nan(&words).unwrap(), words, "SignedZeroInfNanPreserve missing");
    let breaches = shader_manifest::seed_rule_breaches(&words).unwrap();
    assert!(breaches.is_empty(), "float instructions Vulkan does not require correctly rounded outside shader_core::ieee's seeds: {breaches:?}");
}

fn runner_manifest() -> &'static str {
    host::shaders::MANIFEST_JSON
}

/// Rows of `[wo, wi, alpha_x, alpha_y, f0]`: a grid of direction pairs over both hemispheres and
/// grazing angles times roughness pairs (isotropic, anisotropic, mirror, invalid), plus
/// degenerate, unnormalized, denormal and huge directions on either side.
fn rows() -> Vec<f32> {
    let dirs = inputs::directions(6, 4);
    let alphas: Vec<(f32, f32)> = inputs::alpha_pairs().into_iter().step_by(2).collect();
    let mut rows = Vec::new();
    let mut k = 0usize;
    let mut push = |wo: [f32; 3], wi: [f32; 3], (ax, ay): (f32, f32), rows: &mut Vec<f32>| {
        let f0 = if k.is_multiple_of(3) { 1.0 } else { 0.04 };
        k += 1;
        rows.extend_from_slice(&[wo[0], wo[1], wo[2], wi[0], wi[1], wi[2], ax, ay, f0]);
    };
    for &wo in &dirs {
        for &wi in &dirs {
            for &a in &alphas {
                push(wo, wi, a, &mut rows);
            }
        }
    }
    let fixed = [0.36f32, 0.48, 0.8];
    for d in inputs::adversarial_directions() {
        push(d, fixed, (0.3, 0.3), &mut rows);
        push(fixed, d, (0.2, 0.6), &mut rows);
    }
    rows
}

#[test]
fn user_shader_gpu_matches_native_bit_for_bit() {
    let Some(gpu) = gpu_backend() else { return };
    let Some(g) = gpu.gpu() else { panic!("gpu_backend() returned {}", gpu.describe()) };
    let (words, _) = committed();
    // The device's denormal mode, declared in the module as for the project's own kernels.
    let words = g.denorm_policy.apply(&words).unwrap();
    g.add_spirv("user-shader", &words, &[user_shader::ENTRY_POINT]).unwrap();

    let input = rows();
    let n = input.len() / user_shader::INPUTS;
    let mut cpu = vec![0.0f32; n];
    user_shader::ggx_specular_rows(&input, &mut cpu);

    let (gx, gy) = groups_2d((n as u32).div_ceil(user_shader::WORKGROUP_SIZE));
    let args: Vec<u8> = [n as u32, gx].iter().flat_map(|v| v.to_le_bytes()).collect();
    let bytes: Vec<u8> = input.iter().flat_map(|v| v.to_le_bytes()).collect();
    let (out, _) = g.dispatch(user_shader::ENTRY_POINT, &[&args, &bytes], &[OutputSpec::zeroed(n * 4)], (gx, gy, 1)).unwrap();
    let gpu_out: Vec<f32> = out[0].chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect();

    // The comparison must cover real lobe values, not only zeros and NaN.
    let positive = cpu.iter().filter(|v| v.is_finite() && **v > 0.0).count();
    let nan = cpu.iter().filter(|v| v.is_nan()).count();
    eprintln!("user-shader: {n} rows, {positive} positive finite values, {nan} NaN (invalid roughness or input)");
    assert!(n > 20_000 && positive > n / 4 && nan > 0, "input grid does not exercise the lobe");
    assert_bits_equal("user_shader::ggx_specular", 1, &cpu, &gpu_out);
}
