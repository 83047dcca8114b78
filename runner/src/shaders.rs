//! The committed SPIR-V of `shader-kernels`, embedded at build time, and its freshness check.

use shader_manifest::{Manifest, MANIFEST_PATH, REBUILD_COMMAND, SPV_PATH};

/// The SPIR-V module (little-endian words), as committed in `runner/shaders/`.
pub const SPV_BYTES: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/shader-kernels.spv"));
/// Its manifest.
pub const MANIFEST_JSON: &str = include_str!(concat!(env!("OUT_DIR"), "/shader-kernels.json"));
/// The subgroup module (kernels that need subgroup operations) and its manifest.
pub const SUBGROUP_SPV_BYTES: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/shader-kernels-subgroup.spv"));
pub const SUBGROUP_MANIFEST_JSON: &str = include_str!(concat!(env!("OUT_DIR"), "/shader-kernels-subgroup.json"));
/// The "native" variant of the main module (native `OpFDiv` / `Sqrt`) and its manifest.
pub const NATIVE_SPV_BYTES: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/shader-kernels-native.spv"));
pub const NATIVE_MANIFEST_JSON: &str = include_str!(concat!(env!("OUT_DIR"), "/shader-kernels-native.json"));
/// Hash of the shader sources this binary was compiled from (see `shader-manifest`).
pub const SOURCE_HASH: &str = env!("SHADER_SOURCE_HASH");

/// The embedded SPIR-V, checked: present, well formed, and built from the same shader sources
/// as the CPU backend in this binary.
#[derive(Debug, Clone)]
pub struct ShaderModule {
    pub words: Vec<u32>,
    pub manifest: Manifest,
    /// How its kernels divide and take square roots.
    pub div_sqrt: DivSqrt,
}

/// The two builds of the main module, from the same sources (`shader_core::ieee::EXACT`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DivSqrt {
    /// `shader_core::ieee`'s correctly rounded routines (the device's instruction as a seed, corrected exactly): the same bits as the CPU on
    /// any conformant Vulkan device.
    Exact,
    /// The native `OpFDiv` / GLSL.std.450 `Sqrt`: faster, correctly rounded on lavapipe, up to
    /// 2.5 ULP off on other drivers ([`DivSqrtChoice`] says when it is loaded).
    Native,
}

impl DivSqrt {
    /// One phrase for reports.
    pub fn describe(self) -> &'static str {
        match self {
            DivSqrt::Exact => "div/sqrt exact (shader_core::ieee seed and correction)",
            DivSqrt::Native => "div/sqrt native (OpFDiv/Sqrt)",
        }
    }
}

/// What `HOST_DIV_SQRT` asks for: which build of the main module the GPU backend loads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DivSqrtChoice {
    /// Unset, empty or `auto` (the default): the native build on a driver known to round
    /// `OpFDiv` and `Sqrt` correctly (Mesa llvmpipe/lavapipe, whose whole cross-check suite CI
    /// runs with both builds) once [`crate::div_sqrt_probe`] has found its division and square
    /// root correctly rounded on the adapter; the exact build everywhere else.
    Auto,
    /// `exact`: the corrected routines on every adapter.
    Exact,
    /// `native`: the driver's division and square root on every adapter, checked or not (bit
    /// exactness with the CPU then holds only where the driver rounds them correctly).
    Native,
}

impl DivSqrtChoice {
    /// Parse `HOST_DIV_SQRT`; anything but unset, empty, `auto`, `exact` or `native` is an error
    /// naming the allowed values.
    pub fn from_env() -> Result<DivSqrtChoice, String> {
        match std::env::var("HOST_DIV_SQRT").as_deref() {
            Err(_) | Ok("") | Ok("auto") => Ok(DivSqrtChoice::Auto),
            Ok("exact") => Ok(DivSqrtChoice::Exact),
            Ok("native") => Ok(DivSqrtChoice::Native),
            Ok(other) => Err(format!(
                "HOST_DIV_SQRT={other:?} is not a division/square-root choice: use auto (default), exact or native"
            )),
        }
    }

    /// The build to load before the adapter is known: [`DivSqrt::Native`] for `native`, else
    /// [`DivSqrt::Exact`] (correct on every conformant device; `auto` switches to the native
    /// build only after checking the adapter, in [`crate::gpu::GpuContext::with_div_sqrt_choice`]).
    pub fn without_adapter(self) -> DivSqrt {
        match self {
            DivSqrtChoice::Native => DivSqrt::Native,
            DivSqrtChoice::Auto | DivSqrtChoice::Exact => DivSqrt::Exact,
        }
    }
}

/// Load and check the embedded main module `HOST_DIV_SQRT` selects without an adapter
/// ([`DivSqrtChoice::without_adapter`]: the exact build unless `native` is asked for).
pub fn load() -> Result<ShaderModule, String> {
    load_variant(DivSqrtChoice::from_env()?.without_adapter())
}

/// Load and check the embedded main module of variant `v` against [`SOURCE_HASH`].
pub fn load_variant(v: DivSqrt) -> Result<ShaderModule, String> {
    let mut m = match v {
        DivSqrt::Exact => load_checked(SPV_BYTES, MANIFEST_JSON, SOURCE_HASH)?,
        DivSqrt::Native => load_checked(NATIVE_SPV_BYTES, NATIVE_MANIFEST_JSON, SOURCE_HASH).map_err(|e| format!("native module: {e}"))?,
    };
    m.div_sqrt = v;
    Ok(m)
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
    if !spv.len().is_multiple_of(4) {
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
    Ok(ShaderModule { words, manifest, div_sqrt: DivSqrt::Exact })
}
