//! `cargo xtask check-deps`: the feature crates below the CLI stay libraries. None of them may
//! depend (normal dependencies, at any depth) on a CLI, plotting, progress-bar or image crate,
//! and each must carry a doc example in its crate documentation (run by `cargo test --doc`).

use anyhow::{bail, Context, Result};
use std::path::Path;
use std::process::Command;

/// The crates a Rust user may depend on without the `host` CLI's dependencies.
pub const FEATURE_CRATES: &[&str] = &["fileio", "scene", "render", "ssr", "energy", "eval", "runner"];

/// Crates that belong to the CLI, never below it.
pub const CLI_ONLY: &[&str] = &["clap", "plotters", "indicatif", "image"];

/// The CLI-only crates named in `cargo tree --prefix none` output, sorted and deduplicated.
pub fn cli_only_in(tree: &str) -> Vec<String> {
    let mut found: Vec<String> = tree
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .filter(|name| CLI_ONLY.contains(name))
        .map(str::to_string)
        .collect();
    found.sort();
    found.dedup();
    found
}

/// Whether a crate root's inner doc comment holds a code example.
pub fn has_doc_example(lib_rs: &str) -> bool {
    lib_rs.lines().map(str::trim_start).take_while(|l| l.starts_with("//!") || l.is_empty()).any(|l| l.starts_with("//! ```"))
}

pub fn check(root: &Path) -> Result<()> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut faults = Vec::new();
    for krate in FEATURE_CRATES {
        let out = Command::new(&cargo)
            .current_dir(root)
            .args(["tree", "-e", "normal", "--prefix", "none", "-p", krate])
            .output()
            .with_context(|| format!("running cargo tree -p {krate}"))?;
        if !out.status.success() {
            bail!("cargo tree -p {krate} failed: {}", String::from_utf8_lossy(&out.stderr));
        }
        let bad = cli_only_in(&String::from_utf8_lossy(&out.stdout));
        if !bad.is_empty() {
            faults.push(format!("{krate} depends on {} (see `cargo tree -e normal -i {} -p {krate}`)", bad.join(", "), bad[0]));
        }
        let lib = root.join(krate).join("src/lib.rs");
        let text = std::fs::read_to_string(&lib).with_context(|| format!("reading {}", lib.display()))?;
        if !has_doc_example(&text) {
            faults.push(format!("{} has no doc example in its crate documentation", lib.display()));
        }
    }
    if !faults.is_empty() {
        bail!("[check-deps] {}", faults.join("\n[check-deps] "));
    }
    println!("[check-deps] {} feature crates: no {} below the CLI, a doc example in each", FEATURE_CRATES.len(), CLI_ONLY.join("/"));
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cli_crate_anywhere_in_the_tree_is_found() {
        let tree = "ssr v0.1.0 (/w/ssr)\nanyhow v1.0.100\nclap v4.5.1\nclap_builder v4.5.1\nimage v0.25.10\nclap v4.5.1\n";
        assert_eq!(cli_only_in(tree), ["clap", "image"]);
        assert!(cli_only_in("scene v0.1.0\npng v0.18.1\nimage-webp v0.2\n").is_empty(), "a prefix is not the crate");
    }

    #[test]
    fn doc_examples_are_found_in_the_crate_documentation_only() {
        assert!(has_doc_example("//! What it is.\n//!\n//! ```\n//! let x = 1;\n//! ```\n\npub mod a;\n"));
        assert!(!has_doc_example("//! What it is.\n\n/// ```\n/// item example\n/// ```\nfn f() {}\n"));
    }
}
