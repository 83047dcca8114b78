//! The fingerprint of the shader sources and the manifest committed beside the SPIR-V.
//!
//! `cargo xtask build-shaders` writes `runner/shaders/shader-kernels.json` with the hash of every file
//! that can change the SPIR-V (`shader-core` and `shader-kernels`: `Cargo.toml` and `src/**`). The
//! host's build script hashes the same files; at run time the host refuses a manifest whose hash
//! differs, so an edited kernel can never be silently compared against stale SPIR-V.

use std::path::{Path, PathBuf};

pub mod entry_point;
pub mod spec_constant;

/// Crates whose sources are compiled into the SPIR-V, relative to the workspace root.
pub const SHADER_CRATES: [&str; 2] = ["shader-core", "shader-kernels"];
/// Where the committed SPIR-V lives, relative to the workspace root.
pub const SPV_PATH: &str = "runner/shaders/shader-kernels.spv.gz";
/// Where the committed manifest lives, relative to the workspace root.
pub const MANIFEST_PATH: &str = "runner/shaders/shader-kernels.json";
/// The second module (only the kernels needing subgroup operations; `subgroup-module` feature).
pub const SUBGROUP_SPV_PATH: &str = "runner/shaders/shader-kernels-subgroup.spv.gz";
/// Its manifest.
pub const SUBGROUP_MANIFEST_PATH: &str = "runner/shaders/shader-kernels-subgroup.json";
/// The "native" variant of the main module (`native-div-sqrt` feature: `OpFDiv` / `Sqrt` instead
/// of `shader_core::ieee`'s corrected routines), loaded where the driver rounds them correctly
/// (`HOST_DIV_SQRT=auto`, see `runner::div_sqrt_probe`) or with `HOST_DIV_SQRT=native`.
pub const NATIVE_SPV_PATH: &str = "runner/shaders/shader-kernels-native.spv.gz";
/// Its manifest.
pub const NATIVE_MANIFEST_PATH: &str = "runner/shaders/shader-kernels-native.json";
/// The command that rebuilds all three (and the example module below).
pub const REBUILD_COMMAND: &str = "cargo xtask build-shaders";

/// The example shader crate built on `shader-core` (`examples/user-shader`): the crates whose
/// sources its SPIR-V is compiled from, relative to the workspace root.
pub const USER_SHADER_CRATES: [&str; 2] = ["shader-core", "examples/user-shader"];
/// The example's committed SPIR-V (gzip-compressed, as the project's own), relative to the
/// workspace root.
pub const USER_SHADER_SPV_PATH: &str = "examples/user-shader/user-shader.spv.gz";
/// Its manifest.
pub const USER_SHADER_MANIFEST_PATH: &str = "examples/user-shader/user-shader.json";
/// The command that rebuilds only the example.
pub const USER_SHADER_REBUILD_COMMAND: &str = "cargo xtask build-shaders --only user-shader";

/// Compress a SPIR-V module as stored in the repository (gzip, best compression, no timestamp:
/// the same module always gives the same bytes).
pub fn gzip(bytes: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut e = flate2::GzBuilder::new().mtime(0).write(Vec::new(), flate2::Compression::best());
    e.write_all(bytes).expect("writing to memory");
    e.finish().expect("writing to memory")
}

/// Decompress a stored module ([`gzip`]'s output); `path` names it in the error.
pub fn gunzip(bytes: &[u8], path: &str) -> Result<Vec<u8>, String> {
    use std::io::Read;
    let mut out = Vec::new();
    flate2::read::GzDecoder::new(bytes).read_to_end(&mut out).map_err(|e| format!("{path}: not a gzip-compressed SPIR-V module ({e})"))?;
    Ok(out)
}

/// Read a stored module from `root.join(rel)`: decompressed when `rel` ends in `.gz`; `None`
/// when the file does not exist.
pub fn read_module(root: &Path, rel: &str) -> Result<Option<Vec<u8>>, String> {
    let path = root.join(rel);
    match std::fs::read(&path) {
        Ok(b) if rel.ends_with(".gz") => gunzip(&b, rel).map(Some),
        Ok(b) => Ok(Some(b)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(format!("{}: {e}", path.display())),
    }
}

/// Write a module to `root.join(rel)`, gzip-compressed when `rel` ends in `.gz`.
pub fn write_module(root: &Path, rel: &str, spv: &[u8]) -> std::io::Result<()> {
    let path = root.join(rel);
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    if rel.ends_with(".gz") {
        std::fs::write(path, gzip(spv))
    } else {
        std::fs::write(path, spv)
    }
}

/// Every file of the shader crates that feeds the SPIR-V, as paths relative to `root`, sorted.
pub fn shader_source_files(root: &Path) -> std::io::Result<Vec<PathBuf>> {
    source_files_of(root, &SHADER_CRATES)
}

/// Every source file of `crates` (each crate's `Cargo.toml` and `src/**/*.rs`), as paths relative
/// to `root`, sorted.
pub fn source_files_of(root: &Path, crates: &[&str]) -> std::io::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for &krate in crates {
        files.push(PathBuf::from(krate).join("Cargo.toml"));
        collect_rs(root, &PathBuf::from(krate).join("src"), &mut files)?;
    }
    files.sort();
    Ok(files)
}

fn collect_rs(root: &Path, rel: &Path, out: &mut Vec<PathBuf>) -> std::io::Result<()> {
    for entry in std::fs::read_dir(root.join(rel))? {
        let entry = entry?;
        let rel_child = rel.join(entry.file_name());
        if entry.file_type()?.is_dir() {
            collect_rs(root, &rel_child, out)?;
        } else if rel_child.extension().is_some_and(|e| e == "rs") {
            out.push(rel_child);
        }
    }
    Ok(())
}

/// FNV-1a (64 bit) over each file's relative path and bytes (CRLF normalized to LF), in sorted order.
/// Not cryptographic: it guards against forgetting to rebuild, not against tampering.
pub fn source_hash(root: &Path) -> std::io::Result<String> {
    source_hash_of(root, &SHADER_CRATES)
}

/// [`source_hash`] over the sources of `crates` ([`source_files_of`]).
pub fn source_hash_of(root: &Path, crates: &[&str]) -> std::io::Result<String> {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    for rel in source_files_of(root, crates)? {
        let text = std::fs::read(root.join(&rel))?;
        let text: Vec<u8> = normalize_newlines(&text);
        eat(rel.to_string_lossy().replace('\\', "/").as_bytes());
        eat(&[0]);
        eat(&(text.len() as u64).to_le_bytes());
        eat(&text);
    }
    Ok(format!("{h:016x}"))
}

fn normalize_newlines(bytes: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'\r' && bytes.get(i + 1) == Some(&b'\n') {
            i += 1;
            continue;
        }
        out.push(bytes[i]);
        i += 1;
    }
    out
}

/// What is stored beside the SPIR-V.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Manifest {
    pub source_hash: String,
    pub spv_bytes: u64,
    pub toolchain: String,
    pub spirv_builder: String,
    pub target: String,
    pub entry_points: Vec<String>,
}

impl Manifest {
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("manifest serializes") + "\n"
    }

    /// Parse a manifest; the error names what is wrong.
    pub fn from_json(text: &str) -> Result<Self, String> {
        serde_json::from_str(text).map_err(|e| format!("malformed shader manifest {MANIFEST_PATH}: {e}"))
    }

    /// Refuse SPIR-V built from other sources than `current_hash`.
    pub fn check_fresh(&self, current_hash: &str) -> Result<(), String> {
        if self.source_hash == current_hash {
            Ok(())
        } else {
            Err(format!(
                "the committed SPIR-V ({SPV_PATH}) was built from shader sources with hash {}, \
                 but shader-core/shader-kernels now hash to {current_hash}: the GPU would run stale code. \
                 Run `{REBUILD_COMMAND}` and commit {SPV_PATH} and {MANIFEST_PATH}.",
                self.source_hash
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn manifest_round_trips() {
        let m = Manifest {
            source_hash: "0123456789abcdef".into(),
            spv_bytes: 1234,
            toolchain: "nightly-2026-08-15".into(),
            spirv_builder: "0.11.0".into(),
            target: "spirv-unknown-vulkan1.2".into(),
            entry_points: vec!["a".into(), "b".into()],
        };
        assert_eq!(Manifest::from_json(&m.to_json()).unwrap(), m);
        assert!(m.check_fresh("0123456789abcdef").is_ok());
        let err = m.check_fresh("fedcba9876543210").unwrap_err();
        assert!(err.contains(REBUILD_COMMAND), "{err}");
    }

    #[test]
    fn missing_field_is_named() {
        let err = Manifest::from_json("{\"spv_bytes\": 3}").unwrap_err();
        assert!(err.contains("source_hash"), "{err}");
    }

    #[test]
    fn newline_style_does_not_change_hash_input() {
        assert_eq!(normalize_newlines(b"a\r\nb\n"), b"a\nb\n".to_vec());
    }
}

/// SPIR-V opcodes of floating-point arithmetic that a driver could contract (fuse into an FMA)
/// or rewrite with inexact algebra: OpFNegate, OpFAdd, OpFSub, OpFMul, OpFDiv, OpFRem, OpFMod,
/// OpVectorTimesScalar, OpMatrixTimesScalar, OpVectorTimesMatrix, OpMatrixTimesVector,
/// OpMatrixTimesMatrix, OpDot.
pub const FLOAT_ARITHMETIC_OPCODES: [u32; 13] = [127, 129, 131, 133, 136, 140, 141, 142, 143, 144, 145, 146, 148];
const OP_DECORATE: u32 = 71;
const DECORATION_NO_CONTRACTION: u32 = 42;
/// Opcodes of the annotation section (OpDecorate ... OpMemberDecorateString).
const ANNOTATION_OPCODES: [u32; 8] = [71, 72, 73, 74, 75, 332, 5632, 5633];
/// Opcodes with a result type and result id whose first operands are (type, id).
const HEADER_WORDS: usize = 5;

/// Split a module into (opcode, word range) instructions; errors on a malformed stream.
fn instructions(words: &[u32]) -> Result<Vec<(u32, std::ops::Range<usize>)>, String> {
    if words.len() < HEADER_WORDS || words[0] != 0x0723_0203 {
        return Err("not a SPIR-V module (bad magic number or header)".into());
    }
    let mut out = Vec::new();
    let mut i = HEADER_WORDS;
    while i < words.len() {
        let count = (words[i] >> 16) as usize;
        if count == 0 || i + count > words.len() {
            return Err(format!("malformed SPIR-V instruction at word {i}"));
        }
        out.push((words[i] & 0xffff, i..i + count));
        i += count;
    }
    Ok(out)
}

/// Decorate the result of every floating-point arithmetic instruction with `NoContraction`.
///
/// rust-gpu emits none, and without it a Vulkan driver may fuse `a * b + c` into an FMA or apply
/// inexact algebra (Mesa's NIR rewrites `(1 + x) - 1` to `x`), which breaks bit-exactness with
/// the CPU. With it, NIR marks those instructions exact. Idempotent.
pub fn decorate_no_contraction(words: &[u32]) -> Result<Vec<u32>, String> {
    let insts = instructions(words)?;
    let mut already = std::collections::HashSet::new();
    let mut targets = Vec::new();
    let mut last_annotation = None;
    let mut first_type = None;
    for (op, r) in &insts {
        if ANNOTATION_OPCODES.contains(op) {
            last_annotation = Some(r.end);
            if *op == OP_DECORATE && r.len() >= 3 && words[r.start + 2] == DECORATION_NO_CONTRACTION {
                already.insert(words[r.start + 1]);
            }
        }
        // Types, constants and global variables start at OpTypeVoid (19) .. OpTypeForwardPointer (39),
        // constants 41..52, OpVariable 59 at module scope: the annotation section ends before them.
        if first_type.is_none() && ((19..=52).contains(op)) {
            first_type = Some(r.start);
        }
        if FLOAT_ARITHMETIC_OPCODES.contains(op) && r.len() >= 3 {
            targets.push(words[r.start + 2]);
        }
    }
    let at = last_annotation
        .or(first_type)
        .ok_or("SPIR-V module has neither annotations nor types")?;
    let mut out = Vec::with_capacity(words.len() + 3 * targets.len());
    out.extend_from_slice(&words[..at]);
    for id in targets {
        if already.insert(id) {
            out.extend_from_slice(&[(3 << 16) | OP_DECORATE, id, DECORATION_NO_CONTRACTION]);
        }
    }
    out.extend_from_slice(&words[at..]);
    Ok(out)
}

const OP_CAPABILITY: u32 = 17;
const OP_ENTRY_POINT: u32 = 15;
const OP_EXECUTION_MODE: u32 = 16;
const CAPABILITY_SIGNED_ZERO_INF_NAN_PRESERVE: u32 = 4466;
const MODE_SIGNED_ZERO_INF_NAN_PRESERVE: u32 = 4461;

/// Declare `SignedZeroInfNanPreserve` (SPIR-V 1.4 float controls) for 32-bit floats on every
/// entry point, so the driver may not fold away the sign of zero or assume no NaN/Inf (e.g.
/// rewrite `0 * x` or `x + 0`), as the CPU's IEEE arithmetic does not. Idempotent.
pub fn preserve_signed_zero_inf_nan(words: &[u32]) -> Result<Vec<u32>, String> {
    declare_fp32_mode(words, CAPABILITY_SIGNED_ZERO_INF_NAN_PRESERVE, MODE_SIGNED_ZERO_INF_NAN_PRESERVE)
}

const CAPABILITY_DENORM_PRESERVE: u32 = 4464;
const CAPABILITY_DENORM_FLUSH_TO_ZERO: u32 = 4465;
const MODE_DENORM_PRESERVE: u32 = 4459;
const MODE_DENORM_FLUSH_TO_ZERO: u32 = 4460;

/// The 32-bit denormal mode a module declares (SPIR-V 1.4 float controls).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DenormMode {
    /// `DenormPreserve`: denormal operands and results kept (as on the CPU).
    Preserve,
    /// `DenormFlushToZero`: denormal operands and results flushed to zero.
    FlushToZero,
}

/// Declare `mode` for 32-bit floats on every entry point, with its capability. The host does
/// this at module-load time where the device supports the mode (`host::float_controls`); the
/// committed module declares neither. Idempotent; a module declaring the other mode is refused.
pub fn declare_denorm_mode(words: &[u32], mode: DenormMode) -> Result<Vec<u32>, String> {
    let (cap, m, other) = match mode {
        DenormMode::Preserve => (CAPABILITY_DENORM_PRESERVE, MODE_DENORM_PRESERVE, MODE_DENORM_FLUSH_TO_ZERO),
        DenormMode::FlushToZero => (CAPABILITY_DENORM_FLUSH_TO_ZERO, MODE_DENORM_FLUSH_TO_ZERO, MODE_DENORM_PRESERVE),
    };
    for (op, r) in instructions(words)? {
        if op == OP_EXECUTION_MODE && r.len() >= 4 && words[r.start + 2] == other && words[r.start + 3] == 32 {
            return Err(format!("SPIR-V module already declares the other denormal mode than {mode:?}"));
        }
    }
    declare_fp32_mode(words, cap, m)
}

/// Add `OpCapability cap` (once) and `OpExecutionMode %entry mode 32` to every entry point that
/// lacks it. Idempotent.
fn declare_fp32_mode(words: &[u32], capability: u32, mode: u32) -> Result<Vec<u32>, String> {
    let insts = instructions(words)?;
    let mut last_capability = None;
    let mut has_capability = false;
    let mut entry_ids = Vec::new();
    let mut has_mode = std::collections::HashSet::new();
    let mut mode_at = None;
    for (op, r) in &insts {
        match *op {
            OP_CAPABILITY => {
                last_capability = Some(r.end);
                has_capability |= words[r.start + 1] == capability;
            }
            OP_ENTRY_POINT => {
                entry_ids.push(words[r.start + 2]);
                mode_at = Some(r.end);
            }
            OP_EXECUTION_MODE => {
                if words[r.start + 2] == mode {
                    has_mode.insert(words[r.start + 1]);
                }
                mode_at = Some(r.end);
            }
            _ => {}
        }
    }
    let cap_at = last_capability.ok_or("SPIR-V module declares no capabilities")?;
    let mode_at = mode_at.ok_or("SPIR-V module has no entry points")?;
    let mut out = Vec::with_capacity(words.len() + 2 + 4 * entry_ids.len());
    out.extend_from_slice(&words[..cap_at]);
    if !has_capability {
        out.extend_from_slice(&[(2 << 16) | OP_CAPABILITY, capability]);
    }
    out.extend_from_slice(&words[cap_at..mode_at]);
    for id in entry_ids {
        if has_mode.insert(id) {
            out.extend_from_slice(&[(4 << 16) | OP_EXECUTION_MODE, id, mode, 32]);
        }
    }
    out.extend_from_slice(&words[mode_at..]);
    Ok(out)
}

/// (float arithmetic instructions, how many of them carry NoContraction).
pub fn no_contraction_coverage(words: &[u32]) -> Result<(usize, usize), String> {
    let insts = instructions(words)?;
    let mut decorated = std::collections::HashSet::new();
    for (op, r) in &insts {
        if *op == OP_DECORATE && r.len() >= 3 && words[r.start + 2] == DECORATION_NO_CONTRACTION {
            decorated.insert(words[r.start + 1]);
        }
    }
    let mut total = 0;
    let mut covered = 0;
    for (op, r) in &insts {
        if FLOAT_ARITHMETIC_OPCODES.contains(op) && r.len() >= 3 {
            total += 1;
            covered += decorated.contains(&words[r.start + 2]) as usize;
        }
    }
    Ok((total, covered))
}

const OP_EXT_INST_IMPORT: u32 = 11;
const OP_EXT_INST: u32 = 12;

/// GLSL.std.450 instruction names, indexed by instruction number (1..=81).
const GLSL_STD_450_NAMES: [&str; 82] = [
    "?", "Round", "RoundEven", "Trunc", "FAbs", "SAbs", "FSign", "SSign", "Floor", "Ceil", "Fract",
    "Radians", "Degrees", "Sin", "Cos", "Tan", "Asin", "Acos", "Atan", "Sinh", "Cosh", "Tanh",
    "Asinh", "Acosh", "Atanh", "Atan2", "Pow", "Exp", "Log", "Exp2", "Log2", "Sqrt", "InverseSqrt",
    "Determinant", "MatrixInverse", "Modf", "ModfStruct", "FMin", "UMin", "SMin", "FMax", "UMax",
    "SMax", "FClamp", "UClamp", "SClamp", "FMix", "IMix", "Step", "SmoothStep", "Fma", "Frexp",
    "FrexpStruct", "Ldexp", "PackSnorm4x8", "PackUnorm4x8", "PackSnorm2x16", "PackUnorm2x16",
    "PackHalf2x16", "PackDouble2x32", "UnpackSnorm2x16", "UnpackUnorm2x16", "UnpackHalf2x16",
    "UnpackSnorm4x8", "UnpackUnorm4x8", "UnpackDouble2x32", "Length", "Distance", "Cross",
    "Normalize", "FaceForward", "Reflect", "Refract", "FindILsb", "FindSMsb", "FindUMsb",
    "InterpolateAtCentroid", "InterpolateAtSample", "InterpolateAtOffset", "NMin", "NMax", "NClamp",
];

/// GLSL.std.450 instructions whose result the Vulkan spec fixes exactly: the table "Precision
/// and Operation of SPIR-V Instructions" (Vulkan 1.3, chapter "Floating-Point Computation")
/// lists them as exact or correctly rounded (rounding/truncation to integers, abs, sign, min, max,
/// clamp, step, frexp, ldexp, modf and fract = x - floor(x) inherited from OpFSub), plus the
/// integer-only ones (SAbs, SSign, U/S min/max/clamp, FindILsb/FindSMsb/FindUMsb).
/// Everything else in the set (Sqrt, InverseSqrt, Fma, FMix, the transcendentals, Length,
/// Normalize, Refract, ...) may be approximate, fused or evaluated in an unspecified order.
pub const EXACT_GLSL_STD_450: [u32; 30] = [
    1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 35, 36, 37, 38, 39, 40, 41, 42, 43, 44, 45, 48, 51, 52, 53, 73, 74,
    75, 79, 80,
];

/// Core SPIR-V float instructions that the same Vulkan table does not require correctly rounded:
/// OpFDiv (2.5 ULP), OpFRem and OpFMod (inherited from the division), and the compound products
/// whose summation order and contraction are unspecified (OpVectorTimesMatrix,
/// OpMatrixTimesVector, OpMatrixTimesMatrix, OpOuterProduct, OpDot). Required correctly rounded
/// (and therefore allowed): OpFAdd, OpFSub, OpFMul, OpFNegate, OpVectorTimesScalar,
/// OpMatrixTimesScalar, the conversions, comparisons and bit casts.
pub const INEXACT_CORE_FLOAT_OPCODES: [(u32, &str); 8] = [
    (136, "OpFDiv"),
    (140, "OpFRem"),
    (141, "OpFMod"),
    (144, "OpVectorTimesMatrix"),
    (145, "OpMatrixTimesVector"),
    (146, "OpMatrixTimesMatrix"),
    (147, "OpOuterProduct"),
    (148, "OpDot"),
];

/// Every instruction of the module whose float result a conformant Vulkan driver may compute
/// inexactly (see [`INEXACT_CORE_FLOAT_OPCODES`], [`EXACT_GLSL_STD_450`]; any other extended
/// instruction set except `NonSemantic.*` counts as inexact), as (name, count) sorted by name.
/// Empty for a module whose float arithmetic is bit-exact on every conformant device.
pub fn inexact_float_instructions(words: &[u32]) -> Result<Vec<(String, usize)>, String> {
    let insts = instructions(words)?;
    let mut sets = std::collections::HashMap::new();
    for (op, r) in &insts {
        if *op == OP_EXT_INST_IMPORT && r.len() >= 3 {
            sets.insert(words[r.start + 1], spirv_string(&words[r.start + 2..r.end]));
        }
    }
    let mut counts = std::collections::BTreeMap::<String, usize>::new();
    for (op, r) in &insts {
        if let Some(name) = inexact_name(words, &sets, *op, r) {
            *counts.entry(name).or_default() += 1;
        }
    }
    Ok(counts.into_iter().collect())
}

/// The name of instruction `op` at `r` if a conformant driver may compute its float result
/// inexactly (see [`inexact_float_instructions`]), else `None`. `sets`: the module's extended
/// instruction set imports by id.
fn inexact_name(words: &[u32], sets: &std::collections::HashMap<u32, String>, op: u32, r: &std::ops::Range<usize>) -> Option<String> {
    if let Some((_, name)) = INEXACT_CORE_FLOAT_OPCODES.iter().find(|(o, _)| *o == op) {
        return Some((*name).to_string());
    }
    if op != OP_EXT_INST || r.len() < 5 {
        return None;
    }
    let (set, inst) = (words[r.start + 3], words[r.start + 4]);
    let set_name = sets.get(&set).map_or("?", |s| s.as_str());
    if set_name == "GLSL.std.450" {
        if EXACT_GLSL_STD_450.contains(&inst) {
            return None;
        }
        return Some(format!("GLSL.std.450 {}", GLSL_STD_450_NAMES.get(inst as usize).unwrap_or(&"?")));
    }
    if set_name.starts_with("NonSemantic.") {
        return None;
    }
    Some(format!("{set_name} #{inst}"))
}

const OP_NAME: u32 = 5;
const OP_FUNCTION: u32 = 54;
const OP_FUNCTION_PARAMETER: u32 = 55;
const OP_FUNCTION_END: u32 = 56;
const OP_FUNCTION_CALL: u32 = 57;
const OP_LABEL: u32 = 248;
const OP_RETURN_VALUE: u32 = 254;

/// The exact build's rule for the instructions [`inexact_float_instructions`] lists (the seeds
/// of `shader_core::ieee`): each must sit alone in a function of its own whose `OpName` contains
/// `seed` (parameters, one label, the instruction, the return of its result: nothing else), and
/// every call of such a function must sit in a function whose `OpName` contains `ieee` (the
/// correction that reads the seed). Returns the breaches, each a sentence naming the
/// instruction or the function; empty for a module that keeps the rule. A module without names
/// (built without function names) breaches it wherever it holds an inexact instruction.
pub fn seed_rule_breaches(words: &[u32]) -> Result<Vec<String>, String> {
    let insts = instructions(words)?;
    let mut sets = std::collections::HashMap::new();
    let mut names = std::collections::HashMap::new();
    for (op, r) in &insts {
        if *op == OP_EXT_INST_IMPORT && r.len() >= 3 {
            sets.insert(words[r.start + 1], spirv_string(&words[r.start + 2..r.end]));
        } else if *op == OP_NAME && r.len() >= 3 {
            names.insert(words[r.start + 1], spirv_string(&words[r.start + 2..r.end]));
        }
    }
    // Each function: its id, name and instructions (the OpFunction line excluded).
    let mut functions: Vec<(u32, String, Vec<(u32, std::ops::Range<usize>)>)> = Vec::new();
    for (op, r) in &insts {
        if *op == OP_FUNCTION && r.len() >= 5 {
            let id = words[r.start + 2];
            functions.push((id, names.get(&id).cloned().unwrap_or_default(), Vec::new()));
        } else if let Some(f) = functions.last_mut() {
            if *op != OP_FUNCTION_END {
                f.2.push((*op, r.clone()));
            }
        }
    }
    let mut breaches = Vec::new();
    let mut seeds = std::collections::HashSet::new();
    for (id, name, body) in &functions {
        let inexact: Vec<(String, u32)> = body.iter().filter_map(|(op, r)| inexact_name(words, &sets, *op, r).map(|n| (n, words[r.start + 2]))).collect();
        if inexact.is_empty() {
            continue;
        }
        let shown = if name.is_empty() { format!("function %{id} (no name)") } else { format!("function `{name}`") };
        if !name.contains("seed") {
            for (n, _) in &inexact {
                breaches.push(format!("{n} in {shown}, not a seed function"));
            }
            continue;
        }
        // Alone: parameters, a label, the one inexact instruction and the return of its result.
        let rest: Vec<u32> = body.iter().map(|(op, _)| *op).filter(|op| ![OP_FUNCTION_PARAMETER, OP_LABEL].contains(op)).collect();
        let returns_it = body.iter().any(|(op, r)| *op == OP_RETURN_VALUE && r.len() >= 2 && words[r.start + 1] == inexact[0].1);
        if inexact.len() != 1 || rest.len() != 2 || !returns_it {
            breaches.push(format!("{shown} does more than return one seed instruction ({} inexact, {} other instructions)", inexact.len(), rest.len() - inexact.len().min(rest.len())));
        }
        seeds.insert(*id);
    }
    for (_, name, body) in &functions {
        for (op, r) in body {
            if *op == OP_FUNCTION_CALL && r.len() >= 4 && seeds.contains(&words[r.start + 3]) && !name.contains("ieee") {
                let callee = names.get(&words[r.start + 3]).cloned().unwrap_or_default();
                let caller = if name.is_empty() { "a function without a name".to_string() } else { format!("`{name}`") };
                breaches.push(format!("seed function `{callee}` called from {caller}, not from the correction in `ieee`"));
            }
        }
    }
    Ok(breaches)
}

/// Every named function of the module with the number of instructions in its body (from its
/// OpFunction to its OpFunctionEnd, both counted), in module order: what the exact build's
/// routines cost in instructions (`host info` prints those of `shader_core::ieee`).
pub fn function_sizes(words: &[u32]) -> Result<Vec<(String, usize)>, String> {
    let insts = instructions(words)?;
    let names: std::collections::HashMap<u32, String> =
        insts.iter().filter(|(op, r)| *op == OP_NAME && r.len() >= 3).map(|(_, r)| (words[r.start + 1], spirv_string(&words[r.start + 2..r.end]))).collect();
    let mut out = Vec::new();
    let mut current: Option<(String, usize)> = None;
    for (op, r) in &insts {
        if *op == OP_FUNCTION && r.len() >= 5 {
            current = names.get(&words[r.start + 2]).map(|n| (n.clone(), 0));
        }
        if let Some(c) = current.as_mut() {
            c.1 += 1;
        }
        if *op == OP_FUNCTION_END {
            out.extend(current.take());
        }
    }
    Ok(out)
}

/// OpNames of functions kept by [`strip_debug_info`]: the seeds and the corrections that call
/// them ([`seed_rule_breaches`] reads them).
pub fn is_kept_function_name(name: &str) -> bool {
    name.contains("ieee")
}

const OP_STRING: u32 = 7;
const OP_LINE: u32 = 8;
const OP_NO_LINE: u32 = 317;
const OP_SOURCE: u32 = 3;
const OP_SOURCE_CONTINUED: u32 = 2;
const OP_SOURCE_EXTENSION: u32 = 4;
const OP_MEMBER_NAME: u32 = 6;
const OP_MODULE_PROCESSED: u32 = 330;

/// The module without its debug information (OpLine, OpNoLine, OpString, OpSource*,
/// OpModuleProcessed, OpMemberName, and every OpName but those of functions whose name
/// `keep` accepts): the shader build asks rust-gpu for full names so the seed functions can be
/// found, then keeps only those.
pub fn strip_debug_info(words: &[u32], keep: impl Fn(&str) -> bool) -> Result<Vec<u32>, String> {
    let insts = instructions(words)?;
    let functions: std::collections::HashSet<u32> = insts.iter().filter(|(op, r)| *op == OP_FUNCTION && r.len() >= 5).map(|(_, r)| words[r.start + 2]).collect();
    let mut out = words[..HEADER_WORDS].to_vec();
    for (op, r) in &insts {
        let drop = match *op {
            OP_LINE | OP_NO_LINE | OP_STRING | OP_SOURCE | OP_SOURCE_CONTINUED | OP_SOURCE_EXTENSION | OP_MODULE_PROCESSED | OP_MEMBER_NAME => true,
            OP_NAME => !(r.len() >= 3 && functions.contains(&words[r.start + 1]) && keep(&spirv_string(&words[r.start + 2..r.end]))),
            _ => false,
        };
        if !drop {
            out.extend_from_slice(&words[r.clone()]);
        }
    }
    Ok(out)
}

const OP_VARIABLE: u32 = 59;
const DECORATION_BINDING: u32 = 33;
const STORAGE_CLASS_UNIFORM: u32 = 2;

/// The bindings of each entry point that are uniform buffers (`Uniform` storage class: a
/// `#[spirv(uniform)]` parameter), as (entry point name, sorted binding numbers); every other
/// binding of the project's kernels is a storage buffer. Needs SPIR-V 1.4 or later, whose entry
/// points list every global variable they use (rust-gpu's `vulkan1.2` target emits 1.5).
pub fn uniform_bindings(words: &[u32]) -> Result<Vec<(String, Vec<u32>)>, String> {
    let insts = instructions(words)?;
    let mut binding = std::collections::HashMap::new();
    let mut uniform = std::collections::HashSet::new();
    for (op, r) in &insts {
        if *op == OP_DECORATE && r.len() >= 4 && words[r.start + 2] == DECORATION_BINDING {
            binding.insert(words[r.start + 1], words[r.start + 3]);
        } else if *op == OP_VARIABLE && r.len() >= 4 && words[r.start + 3] == STORAGE_CLASS_UNIFORM {
            uniform.insert(words[r.start + 2]);
        }
    }
    let mut out = Vec::new();
    for (op, r) in &insts {
        if *op != OP_ENTRY_POINT || r.len() < 4 {
            continue;
        }
        let name_words = &words[r.start + 3..r.end];
        // The name's words end with the one holding its nul byte; the interface ids follow.
        let name_len = name_words.iter().position(|w| w.to_le_bytes().contains(&0)).map_or(name_words.len(), |k| k + 1);
        let mut bindings: Vec<u32> =
            name_words[name_len..].iter().filter(|id| uniform.contains(id)).filter_map(|id| binding.get(id).copied()).collect();
        bindings.sort_unstable();
        out.push((spirv_string(name_words), bindings));
    }
    Ok(out)
}

/// A nul-terminated SPIR-V literal string.
fn spirv_string(words: &[u32]) -> String {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).take_while(|&b| b != 0).collect();
    String::from_utf8_lossy(&bytes).into_owned()
}

/// Little-endian bytes to SPIR-V words.
pub fn spirv_words(bytes: &[u8]) -> Vec<u32> {
    bytes.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
}

#[cfg(test)]
mod spirv_tests {
    use super::*;

    #[test]
    fn decorates_every_float_op_once() {
        // header, OpDecorate %1 Binding 0, OpTypeFloat %2 32, OpFAdd %2 %3 %4 %5, OpFMul %2 %6 %3 %3
        let words = vec![
            0x0723_0203, 0x0001_0500, 0, 10, 0,
            (3 << 16) | 71, 1, 33,
            (3 << 16) | 22, 2, 32,
            (5 << 16) | 129, 2, 3, 4, 5,
            (5 << 16) | 133, 2, 6, 3, 3,
        ];
        assert_eq!(no_contraction_coverage(&words).unwrap(), (2, 0));
        let out = decorate_no_contraction(&words).unwrap();
        assert_eq!(no_contraction_coverage(&out).unwrap(), (2, 2));
        assert_eq!(out.len(), words.len() + 6);
        // Decorations go right after the existing annotation.
        assert_eq!(&out[8..14], &[(3 << 16) | 71, 3, 42, (3 << 16) | 71, 6, 42]);
        assert_eq!(decorate_no_contraction(&out).unwrap(), out, "idempotent");
        assert!(decorate_no_contraction(&[1, 2, 3]).is_err());
    }

    #[test]
    fn finds_each_entry_points_uniform_bindings() {
        // OpEntryPoint GLCompute %5 "abcd" %7 %8; OpEntryPoint GLCompute %6 "b" %9;
        // OpDecorate %7 Binding 1, %8 Binding 0, %9 Binding 1; %7 Uniform, %8 and %9 StorageBuffer (12).
        let words = vec![
            0x0723_0203, 0x0001_0500, 0, 10, 0,
            (7 << 16) | 15, 5, 5, u32::from_le_bytes(*b"abcd"), 0, 7, 8,
            (5 << 16) | 15, 5, 6, u32::from_le_bytes(*b"b\0\0\0"), 9,
            (4 << 16) | 71, 7, 33, 1,
            (4 << 16) | 71, 8, 33, 0,
            (4 << 16) | 71, 9, 33, 1,
            (4 << 16) | 59, 3, 7, 2,
            (4 << 16) | 59, 4, 8, 12,
            (4 << 16) | 59, 4, 9, 12,
        ];
        assert_eq!(uniform_bindings(&words).unwrap(), vec![("abcd".to_string(), vec![1]), ("b".to_string(), vec![])]);
        assert!(uniform_bindings(&[0x0723_0203]).is_err());
    }

    #[test]
    fn declares_denorm_mode_on_every_entry_point() {
        // header, OpCapability Shader, OpEntryPoint GLCompute %5 "a", OpEntryPoint GLCompute %6 "b"
        let words = vec![
            0x0723_0203, 0x0001_0500, 0, 10, 0,
            (2 << 16) | 17, 1,
            (4 << 16) | 15, 5, 5, u32::from_le_bytes(*b"a\0\0\0"),
            (4 << 16) | 15, 5, 6, u32::from_le_bytes(*b"b\0\0\0"),
        ];
        let out = declare_denorm_mode(&words, DenormMode::Preserve).unwrap();
        assert_eq!(&out[5..9], &[(2 << 16) | 17, 1, (2 << 16) | 17, 4464]);
        assert_eq!(&out[out.len() - 8..], &[(4 << 16) | 16, 5, 4459, 32, (4 << 16) | 16, 6, 4459, 32]);
        assert_eq!(declare_denorm_mode(&out, DenormMode::Preserve).unwrap(), out, "idempotent");
        assert!(declare_denorm_mode(&out, DenormMode::FlushToZero).is_err());
        let ftz = declare_denorm_mode(&words, DenormMode::FlushToZero).unwrap();
        assert!(ftz.windows(4).any(|w| w == [(4 << 16) | 16, 5, 4460, 32]));
    }

    /// A module with a seed `ieee::div_seed` (%10: OpFDiv of its two parameters), the correction
    /// `ieee::div_exact` (%20) calling it, and a kernel (%30) calling the correction; `kernel_body`
    /// and `seed_extra` are spliced into the kernel's and the seed's bodies.
    fn seeded_module(kernel_body: &[u32], seed_extra: &[u32]) -> Vec<u32> {
        let name = |id: u32, s: &str| {
            let mut b = s.as_bytes().to_vec();
            b.push(0);
            while !b.len().is_multiple_of(4) {
                b.push(0);
            }
            let mut w = vec![((2 + b.len() as u32 / 4) << 16) | 5, id];
            w.extend(b.chunks(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])));
            w
        };
        let mut w = vec![0x0723_0203, 0x0001_0500, 0, 100, 0];
        w.extend(name(10, "shader_core::ieee::div_seed"));
        w.extend(name(20, "shader_core::ieee::div_exact"));
        w.extend(name(30, "kernel"));
        w.extend([(3 << 16) | 22, 2, 32, (5 << 16) | 33, 3, 2, 2, 2]);
        // seed
        w.extend([(5 << 16) | 54, 2, 10, 0, 3, (3 << 16) | 55, 2, 11, (3 << 16) | 55, 2, 12, (2 << 16) | 248, 13]);
        w.extend_from_slice(seed_extra);
        w.extend([(5 << 16) | 136, 2, 14, 11, 12, (2 << 16) | 254, 14, (1 << 16) | 56]);
        // correction
        w.extend([(5 << 16) | 54, 2, 20, 0, 3, (3 << 16) | 55, 2, 21, (3 << 16) | 55, 2, 22, (2 << 16) | 248, 23]);
        w.extend([(6 << 16) | 57, 2, 24, 10, 21, 22, (2 << 16) | 254, 24, (1 << 16) | 56]);
        // kernel
        w.extend([(5 << 16) | 54, 2, 30, 0, 3, (3 << 16) | 55, 2, 31, (3 << 16) | 55, 2, 32, (2 << 16) | 248, 33]);
        w.extend([(6 << 16) | 57, 2, 34, 20, 31, 32]);
        w.extend_from_slice(kernel_body);
        w.extend([(2 << 16) | 254, 34, (1 << 16) | 56]);
        w
    }

    #[test]
    fn seed_rule_holds_only_for_lone_seeds_called_by_the_correction() {
        assert_eq!(seed_rule_breaches(&seeded_module(&[], &[])).unwrap(), Vec::<String>::new());
        assert_eq!(inexact_float_instructions(&seeded_module(&[], &[])).unwrap(), vec![("OpFDiv".to_string(), 1)]);
        // A division in the kernel itself.
        let b = seed_rule_breaches(&seeded_module(&[(5 << 16) | 136, 2, 40, 31, 32], &[])).unwrap();
        assert_eq!(b.len(), 1, "{b:?}");
        assert!(b[0].contains("OpFDiv in function `kernel`"), "{b:?}");
        // The kernel calls the seed directly.
        let b = seed_rule_breaches(&seeded_module(&[(6 << 16) | 57, 2, 41, 10, 31, 32], &[])).unwrap();
        assert!(b.len() == 1 && b[0].contains("called from `kernel`"), "{b:?}");
        // The seed does other work (an OpFMul) beside its division.
        let b = seed_rule_breaches(&seeded_module(&[], &[(5 << 16) | 133, 2, 15, 11, 12])).unwrap();
        assert!(b.len() == 1 && b[0].contains("does more than return one seed instruction"), "{b:?}");
        // Names stripped: nothing can be a seed.
        let stripped = strip_debug_info(&seeded_module(&[], &[]), |_| false).unwrap();
        assert!(seed_rule_breaches(&stripped).unwrap()[0].contains("no name"));
        // Stripping keeps the names asked for and nothing else.
        let kept = strip_debug_info(&seeded_module(&[], &[]), is_kept_function_name).unwrap();
        assert_eq!(seed_rule_breaches(&kept).unwrap(), Vec::<String>::new());
        assert_eq!(kept.len(), seeded_module(&[], &[]).len() - 4, "the kernel's OpName (4 words) removed");
        assert_eq!(
            function_sizes(&kept).unwrap(),
            vec![("shader_core::ieee::div_seed".to_string(), 7), ("shader_core::ieee::div_exact".to_string(), 7)]
        );
    }

    #[test]
    fn lists_inexact_float_instructions_with_counts() {
        // "GLSL.std.450" as a nul-terminated literal (12 chars + nul = 4 words).
        let glsl = [u32::from_le_bytes(*b"GLSL"), u32::from_le_bytes(*b".std"), u32::from_le_bytes(*b".450"), 0];
        let mut words = vec![0x0723_0203, 0x0001_0500, 0, 20, 0, (6 << 16) | 11, 1];
        words.extend_from_slice(&glsl);
        words.extend_from_slice(&[
            (3 << 16) | 22, 2, 32,
            (5 << 16) | 129, 2, 3, 4, 5, // OpFAdd: fine
            (5 << 16) | 136, 2, 6, 3, 3, // OpFDiv
            (5 << 16) | 136, 2, 7, 3, 3, // OpFDiv
            (6 << 16) | 12, 2, 8, 1, 31, 3, // Sqrt
            (6 << 16) | 12, 2, 9, 1, 4, 3, // FAbs: fine
            (6 << 16) | 12, 2, 10, 1, 75, 3, // FindUMsb: fine
        ]);
        let got = inexact_float_instructions(&words).unwrap();
        assert_eq!(got, vec![("GLSL.std.450 Sqrt".to_string(), 1), ("OpFDiv".to_string(), 2)]);
        assert!(inexact_float_instructions(&[1, 2]).is_err());
    }
}
