//! Hash the shader sources at build time so the host can refuse SPIR-V built from other sources.
use std::path::Path;

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let files = shader_manifest::shader_source_files(root).expect("listing shader sources");
    for f in &files {
        println!("cargo:rerun-if-changed={}", root.join(f).display());
    }
    for krate in shader_manifest::SHADER_CRATES {
        // New files in a source directory change the directory's mtime.
        println!("cargo:rerun-if-changed={}", root.join(krate).join("src").display());
    }
    println!("cargo:rerun-if-changed={}", root.join(shader_manifest::SPV_PATH).display());
    println!("cargo:rerun-if-changed={}", root.join(shader_manifest::MANIFEST_PATH).display());
    println!("cargo:rerun-if-changed={}", root.join(shader_manifest::SUBGROUP_SPV_PATH).display());
    println!("cargo:rerun-if-changed={}", root.join(shader_manifest::SUBGROUP_MANIFEST_PATH).display());
    println!("cargo:rerun-if-changed={}", root.join(shader_manifest::NATIVE_SPV_PATH).display());
    println!("cargo:rerun-if-changed={}", root.join(shader_manifest::NATIVE_MANIFEST_PATH).display());
    // Copy the committed SPIR-V (decompressed) and manifest into OUT_DIR (empty files when missing) so the
    // binary embeds them and a missing build is reported at run time, not as a compile error.
    let out = std::path::PathBuf::from(std::env::var("OUT_DIR").unwrap());
    for (src, dst) in [
        (shader_manifest::SPV_PATH, "shader-kernels.spv"),
        (shader_manifest::MANIFEST_PATH, "shader-kernels.json"),
        (shader_manifest::SUBGROUP_SPV_PATH, "shader-kernels-subgroup.spv"),
        (shader_manifest::SUBGROUP_MANIFEST_PATH, "shader-kernels-subgroup.json"),
        (shader_manifest::NATIVE_SPV_PATH, "shader-kernels-native.spv"),
        (shader_manifest::NATIVE_MANIFEST_PATH, "shader-kernels-native.json"),
    ] {
        let bytes = if src.ends_with(".gz") {
            shader_manifest::read_module(root, src).unwrap_or_else(|e| panic!("{e}")).unwrap_or_default()
        } else {
            std::fs::read(root.join(src)).unwrap_or_default()
        };
        std::fs::write(out.join(dst), bytes).unwrap();
    }
    let hash = shader_manifest::source_hash(root).expect("hashing shader sources");
    println!("cargo:rustc-env=SHADER_SOURCE_HASH={hash}");
}
