//! The fingerprint of the shader sources and the manifest committed beside the SPIR-V.
//!
//! `cargo xtask build-shaders` writes `host/shaders/shader-kernels.json` with the hash of every file
//! that can change the SPIR-V (`shader-core` and `shader-kernels`: `Cargo.toml` and `src/**`). The
//! host's build script hashes the same files; at run time the host refuses a manifest whose hash
//! differs, so an edited kernel can never be silently compared against stale SPIR-V.

use std::path::{Path, PathBuf};

/// Crates whose sources are compiled into the SPIR-V, relative to the workspace root.
pub const SHADER_CRATES: [&str; 2] = ["shader-core", "shader-kernels"];
/// Where the committed SPIR-V lives, relative to the workspace root.
pub const SPV_PATH: &str = "host/shaders/shader-kernels.spv";
/// Where the committed manifest lives, relative to the workspace root.
pub const MANIFEST_PATH: &str = "host/shaders/shader-kernels.json";
/// The command that rebuilds both.
pub const REBUILD_COMMAND: &str = "cargo xtask build-shaders";

/// Every file of the shader crates that feeds the SPIR-V, as paths relative to `root`, sorted.
pub fn shader_source_files(root: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for krate in SHADER_CRATES {
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
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    for rel in shader_source_files(root)? {
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
