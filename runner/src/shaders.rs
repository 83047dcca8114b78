//! The committed SPIR-V of `shader-kernels`, embedded at build time, and its freshness check.

use shader_manifest::{Manifest, MANIFEST_PATH, REBUILD_COMMAND, SPV_PATH};

/// The SPIR-V module (little-endian words), as committed in `runner/shaders/`.
pub const SPV_BYTES: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/shader-kernels.spv"));
/// Its manifest.
pub const MANIFEST_JSON: &str = include_str!(concat!(env!("OUT_DIR"), "/shader-kernels.json"));
/// The subgroup module (kernels that need subgroup operations) and its manifest.
pub const SUBGROUP_SPV_BYTES: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/shader-kernels-subgroup.spv"));
pub const SUBGROUP_MANIFEST_JSON: &str = include_str!(concat!(env!("OUT_DIR"), "/shader-kernels-subgroup.json"));
/// Hash of the shader sources this binary was compiled from (see `shader-manifest`).
pub const SOURCE_HASH: &str = env!("SHADER_SOURCE_HASH");

/// The embedded SPIR-V, checked: present, well formed, and built from the same shader sources
/// as the CPU backend in this binary.
#[derive(Debug, Clone)]
pub struct ShaderModule {
    pub words: Vec<u32>,
    pub manifest: Manifest,
}

/// Load and check the embedded module against [`SOURCE_HASH`].
pub fn load() -> Result<ShaderModule, String> {
    load_checked(SPV_BYTES, MANIFEST_JSON, SOURCE_HASH)
}

/// Load and check the embedded subgroup module against [`SOURCE_HASH`].
pub fn load_subgroup() -> Result<ShaderModule, String> {
    load_checked(SUBGROUP_SPV_BYTES, SUBGROUP_MANIFEST_JSON, SOURCE_HASH).map_err(|e| format!("subgroup module: {e}"))
}

/// Load `spv` with `manifest_json`, refusing it unless it was built from sources hashing to `source_hash`.
pub fn load_checked(spv: &[u8], manifest_json: &str, source_hash: &str) -> Result<ShaderModule, String> {
    if spv.is_empty() || manifest_json.trim().is_empty() {
        return Err(format!(
            "no SPIR-V found at {SPV_PATH} / {MANIFEST_PATH}: run `{REBUILD_COMMAND}` first"
        ));
    }
    let manifest = Manifest::from_json(manifest_json)?;
    manifest.check_fresh(source_hash)?;
    if spv.len() % 4 != 0 {
        return Err(format!("{SPV_PATH} is {} bytes, not a whole number of 32-bit words", spv.len()));
    }
    if spv.len() as u64 != manifest.spv_bytes {
        return Err(format!(
            "{SPV_PATH} is {} bytes but its manifest says {}: rerun `{REBUILD_COMMAND}`",
            spv.len(),
            manifest.spv_bytes
        ));
    }
    let words: Vec<u32> = spv
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    if words[0] != 0x0723_0203 {
        return Err(format!("{SPV_PATH} does not start with the SPIR-V magic number"));
    }
    Ok(ShaderModule { words, manifest })
}
