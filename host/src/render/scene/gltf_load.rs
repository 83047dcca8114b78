//! glTF 2.0 loading (Khronos glTF 2.0 specification) through the `gltf` crate.

use super::Scene;
use std::path::Path;

/// Loads `path` (.gltf or .glb).
pub fn load(path: &Path) -> anyhow::Result<Scene> {
    anyhow::bail!("{}: the glTF loader is not written yet", path.display())
}
