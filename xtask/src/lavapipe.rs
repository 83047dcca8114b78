//! A second lavapipe beside the system's: Mesa 25.0.7 from Debian 12's backports, unpacked into
//! `target/lavapipe/` and loaded through `VK_ICD_FILENAMES` (the system's Mesa is left alone).
//!
//! Debian 12 ships Mesa 22.3.6, whose llvmpipe reads a storage buffer one lane at a time
//! (docs/reports/storage-bench.md); the backport, built against the same LLVM 15, reads it
//! 2-20x faster (docs/reports/storage-bench-mesa25.md).
//! `cargo xtask test` runs the CPU-vs-GPU comparisons on both, so a bit that differs on either
//! driver fails the run; `cargo xtask lavapipe` prints the environment that selects it.

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The package, pinned by version and SHA-256 (Debian's pool keeps the current backport only:
/// when it moves on, this download fails with its URL and the pin must be updated).
pub const MESA_VERSION: &str = "25.0.7-2~bpo12+1";
const MESA_DEB_URL: &str = "http://deb.debian.org/debian/pool/main/m/mesa/mesa-vulkan-drivers_25.0.7-2~bpo12%2B1_amd64.deb";
const MESA_DEB_SHA256: &str = "3899f1800424c60a05df5d6913076a526ca8fdbabec43672cd397563d1ca3263";
/// The LLVM the package links; Debian 12's own lavapipe (`libllvm15`) brings it.
const LLVM_LIB: &str = "/usr/lib/x86_64-linux-gnu/libLLVM-15.so.1";
/// What `HOST_ADAPTER` matches in the adapter's driver description (`runner::gpu::adapter_label`,
/// e.g. "Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)"); no spaces, so `env $(cargo xtask lavapipe)` works.
pub const ADAPTER_MATCH: &str = MESA_VERSION;

/// Can this machine load the backport? Debian 12 on x86-64 with LLVM 15 installed; the reason
/// when not.
pub fn unsupported_reason() -> Option<String> {
    let os = std::fs::read_to_string("/etc/os-release").unwrap_or_default();
    if !os.lines().any(|l| l.trim() == "VERSION_CODENAME=bookworm") {
        return Some("not Debian 12 (bookworm): the package is built for it".into());
    }
    if std::env::consts::ARCH != "x86_64" {
        return Some(format!("the package is amd64, this machine is {}", std::env::consts::ARCH));
    }
    if !Path::new(LLVM_LIB).exists() {
        return Some(format!("{LLVM_LIB} is missing (apt-get install -y libllvm15, or the system lavapipe)"));
    }
    None
}

/// Download (once), check and unpack the package under `target/lavapipe/`; returns the path of
/// the ICD manifest that names its driver by absolute path.
pub fn ensure(root: &Path) -> Result<PathBuf> {
    if let Some(why) = unsupported_reason() {
        bail!("Mesa {MESA_VERSION} lavapipe cannot run here: {why}");
    }
    let dir = root.join("target/lavapipe").join(format!("mesa-{}", MESA_VERSION.replace(['~', '+'], "_")));
    let driver = dir.join("root/usr/lib/x86_64-linux-gnu/libvulkan_lvp.so");
    let icd = dir.join("lvp_icd.json");
    if driver.exists() && icd.exists() {
        return Ok(icd);
    }
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let deb = dir.join("mesa-vulkan-drivers.deb");
    eprintln!("[lavapipe] downloading Mesa {MESA_VERSION} ({MESA_DEB_URL})");
    run(Command::new("curl").args(["-fsSL", "--retry", "3", "-o"]).arg(&deb).arg(MESA_DEB_URL), "curl")
        .with_context(|| format!("downloading {MESA_DEB_URL}; if Debian's backports moved on, update the pin in xtask/src/lavapipe.rs"))?;
    let sum = Command::new("sha256sum").arg(&deb).output().context("running sha256sum")?;
    let sum = String::from_utf8_lossy(&sum.stdout);
    let got = sum.split_whitespace().next().unwrap_or("");
    if got != MESA_DEB_SHA256 {
        bail!("{} has SHA-256 {got}, expected {MESA_DEB_SHA256}", deb.display());
    }
    run(Command::new("dpkg-deb").arg("-x").arg(&deb).arg(dir.join("root")), "dpkg-deb -x")?;
    if !driver.exists() {
        bail!("the package has no {}", driver.display());
    }
    let json = format!(
        "{{\n    \"ICD\": {{\n        \"api_version\": \"1.4.305\",\n        \"library_path\": \"{}\"\n    }},\n    \"file_format_version\": \"1.0.0\"\n}}\n",
        driver.display()
    );
    std::fs::write(&icd, json).with_context(|| format!("writing {}", icd.display()))?;
    std::fs::remove_file(&deb).ok();
    Ok(icd)
}

/// The environment that makes a program load this lavapipe and nothing else.
pub fn env(icd: &Path) -> [(&'static str, String); 2] {
    [("VK_ICD_FILENAMES", icd.display().to_string()), ("HOST_ADAPTER", ADAPTER_MATCH.to_string())]
}

/// The system's lavapipe manifest (Debian 12's `mesa-vulkan-drivers`, Mesa 22.3.6).
pub const SYSTEM_ICD: &str = "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json";

/// The environment that makes a program see both lavapipes, this one and the system's (selected
/// by driver name, e.g. `host bench ssr-passes --devices gpu:22.3.6,gpu:25.0.7`).
pub fn env_beside_system(icd: &Path) -> Result<[(&'static str, String); 1]> {
    if !Path::new(SYSTEM_ICD).exists() {
        bail!("no system lavapipe at {SYSTEM_ICD} (apt-get install -y mesa-vulkan-drivers)");
    }
    Ok([("VK_ICD_FILENAMES", format!("{}:{SYSTEM_ICD}", icd.display()))])
}

fn run(cmd: &mut Command, what: &str) -> Result<()> {
    let status = cmd.status().with_context(|| format!("running {what}"))?;
    if !status.success() {
        bail!("{what} failed ({status})");
    }
    Ok(())
}
