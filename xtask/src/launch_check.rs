//! `cargo xtask check-launch`: one way to launch a kernel. Outside the launch mechanism
//! (`runner`) and the kernel declarations (`shader-kernels`, where each entry point's `Kernel`
//! constant names it), no library or binary source (a workspace crate's `src/`) may
//! - write an entry-point name in a string literal (`"ssr::sssr_trace"`): it launches the
//!   declared constant instead (`backend.run(&kern::SSSR_TRACE, ..)`);
//! - branch on the backend's variant (`Backend::Gpu(..)`, `Backend::Cpu =>`,
//!   `matches!(b, Backend::Cpu)`, `let Backend::Cpu = ..`): the launchers hold that branch once;
//!   what only a GPU has (its adapter, compile times, command chains) is reached through
//!   `backend.gpu()`.
//!
//! Tests (`tests/` folders and the `tests` crate) may name entry points, e.g. to check the
//! launcher's error for an unknown one; `xtask` holds this check's own patterns.

use std::path::{Path, PathBuf};

/// Crates exempt from the check: the launch mechanism, the kernel declarations, the tests crate
/// and this tool.
pub const EXEMPT: &[&str] = &["runner", "shader-kernels", "tests", "xtask"];

/// The shader modules whose entry points the kernels declare (`module::function`).
const MODULES: &[&str] = &["eval::", "render::", "energy::", "ssr::", "ssr_subgroup::"];

/// `line` without its `//` comment (a `//` inside a string literal is kept).
fn code_of(line: &str) -> &str {
    let b = line.as_bytes();
    let mut in_str = false;
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'\\' if in_str => i += 1,
            b'"' => in_str = !in_str,
            b'/' if !in_str && b.get(i + 1) == Some(&b'/') => return &line[..i],
            _ => {}
        }
        i += 1;
    }
    line
}

/// The contents of the string literals of a line of code (escapes left as written).
fn literals(code: &str) -> Vec<&str> {
    let b = code.as_bytes();
    let mut out = Vec::new();
    let mut start = None;
    let mut i = 0;
    while i < b.len() {
        match (b[i], start) {
            (b'\\', Some(_)) => i += 1,
            (b'"', None) => start = Some(i + 1),
            (b'"', Some(s)) => {
                out.push(&code[s..i]);
                start = None;
            }
            _ => {}
        }
        i += 1;
    }
    out
}

/// Whether a literal is an entry-point name.
fn is_entry(lit: &str) -> bool {
    MODULES.iter().any(|m| lit.starts_with(m)) && lit.len() > 2 && lit.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == ':')
}

/// Whether `code` branches on the backend's variant.
fn branches_on_backend(code: &str) -> bool {
    if code.contains("Backend::Gpu") {
        return true;
    }
    code.match_indices("Backend::Cpu").any(|(i, m)| {
        let after = code[i + m.len()..].trim_start();
        let before = code[..i].trim_end();
        after.starts_with("=>") || after.starts_with('|') || before.ends_with("let") || (after.starts_with(')') && code[..i].contains("matches!("))
    })
}

/// The faults of one file's text, as `file:line: what`.
pub fn faults(file: &str, text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let code = code_of(line);
        for lit in literals(code).into_iter().filter(|l| is_entry(l)) {
            out.push(format!("{file}:{}: entry point \"{lit}\" written out: launch its Kernel constant (shader-kernels) instead", n + 1));
        }
        if branches_on_backend(code) {
            out.push(format!("{file}:{}: branches on the backend's variant: launch through runner::Backend::run*, reach GPU-only things through backend.gpu()", n + 1));
        }
    }
    out
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok()).map(|e| e.path()).collect();
    paths.sort();
    for p in paths {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// Every fault in the `src/` trees of the workspace's crates outside [`EXEMPT`].
pub fn scan_workspace(root: &Path) -> Result<Vec<String>, String> {
    let manifest = root.join("Cargo.toml");
    let text = std::fs::read_to_string(&manifest).map_err(|e| format!("reading {}: {e}", manifest.display()))?;
    let mut out = Vec::new();
    for member in crate::import_cycles::workspace_members(root, &text)? {
        if EXEMPT.contains(&member.as_str()) {
            continue;
        }
        let mut files = Vec::new();
        rust_files(&root.join(&member).join("src"), &mut files);
        for f in files {
            let text = std::fs::read_to_string(&f).map_err(|e| format!("reading {}: {e}", f.display()))?;
            let name = f.strip_prefix(root).unwrap_or(&f).display().to_string();
            out.extend(faults(&name, &text));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entry_literals_and_backend_branches_are_found() {
        let planted = "\
            let (out, t) = g.dispatch(\"ssr::sssr_trace\", &bufs, &outs, groups)?;\n\
            match backend { Backend::Cpu => cpu(), Backend::Gpu(g) => gpu(g) }\n\
            if matches!(b, Backend::Cpu) { }\n\
            let Backend::Cpu = b else { return };\n\
            x(\"ssr_subgroup::sssr_scan_subgroup\");\n";
        let f = faults("x.rs", planted);
        assert_eq!(f.len(), 5, "{f:#?}");
        assert!(f[0].starts_with("x.rs:1: entry point \"ssr::sssr_trace\""), "{}", f[0]);
        assert!(f[1].starts_with("x.rs:2: branches"), "{}", f[1]);
        assert!(f[2].starts_with("x.rs:3: branches") && f[3].starts_with("x.rs:4: branches"));
        assert!(f[4].contains("ssr_subgroup::sssr_scan_subgroup"));
    }

    #[test]
    fn declarations_queries_comments_and_prose_pass() {
        let fine = "\
            backend.run(&kern::SSSR_TRACE, launch, n, RAY_STRIDE)?;\n\
            let cpu = Backend::Cpu;\n\
            run_config(&Backend::Cpu, &sc)?;\n\
            if let Some(g) = backend.gpu() { g.compile_seconds(PT_RENDER.entry); }\n\
            // dispatches \"ssr::sssr_trace\" on Backend::Gpu(g)\n\
            bail!(\"ssr: the G-buffer has {} values\", n);\n\
            let url = \"https://x//y\"; // Backend::Gpu\n";
        assert_eq!(faults("y.rs", fine), Vec::<String>::new());
    }

    /// The tree itself passes.
    #[test]
    fn the_workspace_launches_kernels_one_way() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
        let f = scan_workspace(root).unwrap();
        assert!(f.is_empty(), "{}", f.join("\n"));
    }
}
