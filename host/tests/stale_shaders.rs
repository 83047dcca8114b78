//! The GPU backend must refuse SPIR-V that was not built from the current shader sources.

use host::shaders::{load_checked, MANIFEST_JSON, NATIVE_SPV_BYTES, SOURCE_HASH, SPV_BYTES, SUBGROUP_MANIFEST_JSON, SUBGROUP_SPV_BYTES};
use std::path::{Path, PathBuf};

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

fn copy_shader_sources(to: &Path) {
    let root = workspace_root();
    for rel in shader_manifest::shader_source_files(&root).unwrap() {
        let dst = to.join(&rel);
        std::fs::create_dir_all(dst.parent().unwrap()).unwrap();
        std::fs::copy(root.join(&rel), dst).unwrap();
    }
}

#[test]
fn committed_spirv_matches_the_sources_this_binary_was_built_from() {
    // Fails when a shader-core/shader-kernels edit was committed without `cargo xtask build-shaders`.
    let m = load_checked(SPV_BYTES, MANIFEST_JSON, SOURCE_HASH);
    assert!(m.is_ok(), "{}", m.unwrap_err());
    // The subgroup module is built by the same command from the same sources.
    let sg = load_checked(SUBGROUP_SPV_BYTES, SUBGROUP_MANIFEST_JSON, SOURCE_HASH);
    assert!(sg.is_ok(), "subgroup module: {}", sg.unwrap_err());
    let sg = sg.unwrap();
    assert_eq!(sg.manifest.entry_points, ["ssr_subgroup::sssr_scan_subgroup"]);
    assert!(!m.unwrap().manifest.entry_points.iter().any(|e| e.starts_with("ssr_subgroup::")), "subgroup kernels leaked into the main module");
}

#[test]
fn editing_a_shader_core_function_without_rebuilding_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    copy_shader_sources(dir.path());
    // The copy hashes like the tree the binary was built from...
    assert_eq!(shader_manifest::source_hash(dir.path()).unwrap(), SOURCE_HASH);
    // ...until a shader-core function changes.
    let ndf = dir.path().join("shader-core/src/ndf.rs");
    let text = std::fs::read_to_string(&ndf).unwrap();
    // Change the body of `ggx_d`: scale its result by 2 right after the signature's opening brace.
    let at = text.find("pub fn ggx_d(").expect("ndf.rs defines ggx_d");
    let brace = at + text[at..].find('{').unwrap() + 1;
    let edited = format!("{}\n    if wm.z > 0.0 {{ return 2.0; }}{}", &text[..brace], &text[brace..]);
    assert_ne!(text, edited, "the edit must apply");
    std::fs::write(&ndf, edited).unwrap();
    let new_hash = shader_manifest::source_hash(dir.path()).unwrap();
    assert_ne!(new_hash, SOURCE_HASH);
    let err = load_checked(SPV_BYTES, MANIFEST_JSON, &new_hash).unwrap_err();
    assert!(err.contains("cargo xtask build-shaders"), "{err}");
    assert!(err.contains("stale"), "{err}");
}

#[test]
fn a_new_shader_source_file_changes_the_hash() {
    let dir = tempfile::tempdir().unwrap();
    copy_shader_sources(dir.path());
    std::fs::write(dir.path().join("shader-core/src/extra.rs"), "pub fn f() {}\n").unwrap();
    assert_ne!(shader_manifest::source_hash(dir.path()).unwrap(), SOURCE_HASH);
}

#[test]
fn missing_or_malformed_spirv_is_refused_with_a_clear_message() {
    let err = load_checked(&[], MANIFEST_JSON, SOURCE_HASH).unwrap_err();
    assert!(err.contains("cargo xtask build-shaders"), "{err}");
    let err = load_checked(SPV_BYTES, "{ not json", SOURCE_HASH).unwrap_err();
    assert!(err.contains("malformed shader manifest"), "{err}");
    let err = load_checked(&SPV_BYTES[..SPV_BYTES.len() - 2], MANIFEST_JSON, SOURCE_HASH).unwrap_err();
    assert!(err.contains("whole number of 32-bit words"), "{err}");
    let mut bad = SPV_BYTES.to_vec();
    bad[0] ^= 0xff;
    let err = load_checked(&bad, MANIFEST_JSON, SOURCE_HASH).unwrap_err();
    assert!(err.contains("magic"), "{err}");
}

#[test]
fn committed_spirv_forbids_contraction_and_keeps_signed_zeros() {
    let words = shader_manifest::spirv_words(SPV_BYTES);
    let (total, covered) = shader_manifest::no_contraction_coverage(&words).unwrap();
    assert!(total > 0);
    assert_eq!(covered, total, "float ops without NoContraction: rerun `cargo xtask build-shaders`");
    assert_eq!(
        shader_manifest::preserve_signed_zero_inf_nan(&words).unwrap(),
        words,
        "SignedZeroInfNanPreserve missing: rerun `cargo xtask build-shaders`"
    );
}

/// Vulkan requires only add/sub/mul, conversions and a few exact GLSL.std.450 instructions to be
/// correctly rounded ("Precision and Operation of SPIR-V Instructions"); division, square root,
/// FMA and transcendentals may differ between conformant drivers. `shader_core::ieee` replaces
/// them, so the committed modules must contain none.
#[test]
fn committed_spirv_uses_only_correctly_rounded_float_instructions() {
    for (name, bytes) in [("shader-kernels.spv", SPV_BYTES), ("shader-kernels-subgroup.spv", SUBGROUP_SPV_BYTES)] {
        let words = shader_manifest::spirv_words(bytes);
        let breaches = shader_manifest::seed_rule_breaches(&words).unwrap();
        assert!(
            breaches.is_empty(),
            "{name} holds float instructions Vulkan does not require correctly rounded outside the \
             seeds of shader_core::ieee: {}; use shader_core::ieee::{{div, sqrt}} and rerun `cargo xtask build-shaders`",
            breaches.join("; ")
        );
        // The seeds themselves: one division and one square root at most.
        for (inst, count) in shader_manifest::inexact_float_instructions(&words).unwrap() {
            assert!(["OpFDiv", "GLSL.std.450 Sqrt"].contains(&inst.as_str()) && count == 1, "{name}: {inst} x{count}");
        }
    }
    // The check can fail on a real module: the native build divides in every kernel.
    let native = shader_manifest::seed_rule_breaches(&shader_manifest::spirv_words(NATIVE_SPV_BYTES)).unwrap();
    assert!(native.len() > 1000 && native.iter().any(|b| b.starts_with("OpFDiv in function")), "{} breaches: {:?}", native.len(), native.first());
}
