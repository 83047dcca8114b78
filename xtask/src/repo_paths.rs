//! The guard that keeps a fresh clone standing alone: no source, test, script, manifest or doc
//! of the repository names a path outside it.
//!
//! Two rules, applied to every text file of the tree (build outputs, `.git` and `out/` aside):
//! - a *needle*, the forms the development machines' neighbouring folders take (the `shared`
//!   folder reached upwards, its `scenes` or `seeds` subfolders, an absolute path into the
//!   machines' work folder; [`needles`] builds them), is refused wherever it appears;
//! - every relative path with `../` is resolved against the folder it is relative to and refused
//!   when it climbs above the repository root. That folder is the crate's for Rust string
//!   literals (`concat!(env!("CARGO_MANIFEST_DIR"), "/../x")`, and tests run in the crate's
//!   folder), the file's own for `include_str!`/`include_bytes!`, `Cargo.toml` and Markdown links,
//!   and the repository root for commands in Markdown, scripts and everything else (the README's
//!   commands and `.ci/run` run there); a path glued to a variable (`$here/../x`) is taken from
//!   the file's folder.
//!
//! The unit tests run it on the tree and on planted paths (`cargo test -p xtask`).

use std::path::{Path, PathBuf};

/// One path that leaves the repository: where it is written and why it is refused.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Finding {
    /// File, relative to the repository root, with `/` separators.
    pub file: String,
    /// 1-based line.
    pub line: usize,
    /// The path as written.
    pub path: String,
    pub why: &'static str,
}

impl std::fmt::Display for Finding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}: `{}` {}", self.file, self.line, self.path, self.why)
    }
}

/// Folders never scanned: build outputs, VCS data and generated local output.
const SKIP_DIRS: [&str; 6] = [".git", "target", "out", ".gpu-bundle", ".gl", "node_modules"];

/// Every text file under `root` (recursively, [`SKIP_DIRS`] aside; files that are not UTF-8 or
/// hold a NUL byte are binary and skipped) with the paths in it that leave the repository.
pub fn scan_tree(root: &Path) -> std::io::Result<Vec<Finding>> {
    let mut found = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        let mut entries: Vec<_> = std::fs::read_dir(&dir)?.collect::<Result<_, _>>()?;
        entries.sort_by_key(|e| e.file_name());
        for e in entries {
            let path = e.path();
            let kind = e.file_type()?;
            if kind.is_dir() {
                if !SKIP_DIRS.iter().any(|s| e.file_name() == *s) {
                    stack.push(path);
                }
            } else if kind.is_file() && e.file_name() != ".git" {
                // (A worktree's `.git` is a file naming its main repository's folder.)
                let bytes = std::fs::read(&path)?;
                let Ok(text) = String::from_utf8(bytes) else { continue };
                if text.contains('\0') {
                    continue;
                }
                let rel = relative(root, &path);
                let crate_dir = crate_dir(root, &path);
                found.extend(scan_text(&rel, &crate_dir, &text));
            }
        }
    }
    Ok(found)
}

/// `path` relative to `root`, `/`-separated.
fn relative(root: &Path, path: &Path) -> String {
    let rel = path.strip_prefix(root).unwrap_or(path);
    rel.components().map(|c| c.as_os_str().to_string_lossy().into_owned()).collect::<Vec<_>>().join("/")
}

/// The folder (relative to `root`, `/`-separated, "" for the root) of the nearest `Cargo.toml` at
/// or above `file`'s folder; the root when there is none.
fn crate_dir(root: &Path, file: &Path) -> String {
    let mut dir: Option<PathBuf> = file.parent().map(Path::to_path_buf);
    while let Some(d) = dir {
        if !d.starts_with(root) {
            break;
        }
        if d.join("Cargo.toml").is_file() {
            return relative(root, &d);
        }
        dir = d.parent().map(Path::to_path_buf);
    }
    String::new()
}

/// The needles refused wherever they appear. Built from pieces so this file does not name them.
fn needles() -> [String; 4] {
    let up = "..";
    let shared = "shared";
    [format!("{up}/{shared}"), format!("{shared}/scenes"), format!("{shared}/seeds"), format!("/{}/", "work")]
}

/// Characters a written path is made of.
fn path_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || matches!(c, '.' | '/' | '_' | '-' | '*' | '+')
}

/// The findings in one file's text. `file` is its path relative to the root and `crate_dir` the
/// folder of its crate (both `/`-separated; "" is the root).
pub fn scan_text(file: &str, crate_dir: &str, text: &str) -> Vec<Finding> {
    let file_dir = file.rsplit_once('/').map(|(d, _)| d).unwrap_or("");
    let name = file.rsplit('/').next().unwrap_or(file);
    let is_rust = name.ends_with(".rs");
    let is_markdown = name.ends_with(".md");
    let needles = needles();
    let mut found = Vec::new();
    for (i, line) in text.lines().enumerate() {
        for n in &needles {
            if let Some(at) = line.find(n.as_str()) {
                found.push(Finding { file: file.into(), line: i + 1, path: token_at(line, at), why: "names a folder outside the repository" });
            }
        }
        let mut from = 0;
        while let Some(off) = line[from..].find("../") {
            let at = from + off;
            let (start, token) = token_around(line, at);
            from = start + token.len().max(1);
            let glued = start > 0 && !line[..start].ends_with(|c: char| c.is_whitespace() || matches!(c, '"' | '\'' | '(' | '=' | '`' | '[' | '<' | ',' | ':'));
            let base = if is_rust {
                if line.contains("include_str!") || line.contains("include_bytes!") {
                    file_dir
                } else {
                    crate_dir
                }
            } else if name == "Cargo.toml" || glued || (is_markdown && line[..start].ends_with("](")) {
                file_dir
            } else {
                ""
            };
            // `concat!(env!("CARGO_MANIFEST_DIR"), "/../x")`: the literal's leading `/` joins it
            // to the crate folder.
            let rel = token.trim_start_matches('/');
            if escapes(base, rel) {
                found.push(Finding { file: file.into(), line: i + 1, path: token.to_string(), why: "climbs above the repository root" });
            }
        }
    }
    found
}

/// The path token that contains byte `at` of `line`, with its start.
fn token_around(line: &str, at: usize) -> (usize, &str) {
    let start = line[..at].rfind(|c: char| !path_char(c)).map(|p| p + line[p..].chars().next().map_or(1, char::len_utf8)).unwrap_or(0);
    let end = line[at..].find(|c: char| !path_char(c)).map(|p| at + p).unwrap_or(line.len());
    (start, &line[start..end])
}

fn token_at(line: &str, at: usize) -> String {
    token_around(line, at).1.to_string()
}

/// Whether `rel`, taken from folder `base` (relative to the root), leaves the root.
fn escapes(base: &str, rel: &str) -> bool {
    let mut depth: i64 = base.split('/').filter(|s| !s.is_empty()).count() as i64;
    for part in rel.split('/') {
        match part {
            "" | "." => {}
            ".." => {
                depth -= 1;
                if depth < 0 {
                    return true;
                }
            }
            _ => depth += 1,
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    fn root() -> PathBuf {
        crate::workspace_root()
    }

    #[test]
    fn the_tree_names_no_path_outside_the_repository() {
        let found = scan_tree(&root()).expect("reading the tree");
        let listed: Vec<String> = found.iter().map(ToString::to_string).collect();
        assert!(found.is_empty(), "paths outside the repository (a fresh clone has nothing beside it):\n{}", listed.join("\n"));
    }

    #[test]
    fn a_planted_shared_path_is_found_in_a_test_file() {
        let (up, shared) = ("..", "shared");
        let line = format!("const CORNELL: &str = concat!(env!(\"CARGO_MANIFEST_DIR\"), \"/{up}/{up}/{shared}/scenes/cornell_box/cornell_box.gltf\");");
        let found = scan_text("host/tests/render_cli.rs", "host", &line);
        assert!(found.iter().any(|f| f.why.contains("outside")), "{found:?}");
        assert!(found.iter().any(|f| f.why.contains("climbs")), "{found:?}");
    }

    #[test]
    fn a_planted_path_is_found_by_the_tree_scan() {
        let dir = std::env::temp_dir().join(format!("repo-paths-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("host/src")).unwrap();
        std::fs::write(dir.join("host/Cargo.toml"), "[package]\nname = \"host\"\n").unwrap();
        std::fs::write(dir.join("host/src/lib.rs"), "pub const OK: &str = include_str!(\"../Cargo.toml\");\n").unwrap();
        assert_eq!(scan_tree(&dir).unwrap(), vec![]);
        let (up, shared) = ("..", "shared");
        std::fs::write(dir.join("README.md"), format!("Run:\n\n    host render {up}/{shared}/scenes/cornell_box/cornell_box.gltf\n")).unwrap();
        let found = scan_tree(&dir).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        assert_eq!(found.len(), 3, "{found:?}");
        assert!(found.iter().all(|f| f.file == "README.md" && f.line == 3), "{found:?}");
    }

    #[test]
    fn relative_paths_are_resolved_from_their_base() {
        // Written with `{up}` for `..`, so this file names no such path itself.
        let up = "..";
        let n = |file: &str, krate: &str, line: String| scan_text(file, krate, &line).len();
        // A README command runs at the root: any `../` leaves it.
        assert_eq!(n("README.md", "", format!("cargo run -- render {up}/scene.gltf")), 1);
        // A Markdown link is relative to its document.
        assert_eq!(n("docs/render.md", "", format!("see [the README]({up}/README.md)")), 0);
        assert_eq!(n("docs/render.md", "", format!("see [x]({up}/{up}/x.md)")), 1);
        // Rust: include_* from the file's folder, other literals from the crate's.
        assert_eq!(n("host/src/ssr/legend.rs", "host", format!("include_bytes!(\"{up}/{up}/assets/DejaVuSans.ttf\")")), 0);
        assert_eq!(n("host/src/ssr/legend.rs", "host", format!("include_bytes!(\"{up}/{up}/{up}/{up}/x.ttf\")")), 1);
        assert_eq!(n("tests/tests/a.rs", "tests", format!("concat!(env!(\"CARGO_MANIFEST_DIR\"), \"/{up}/scenes/x.gltf\")")), 0);
        assert_eq!(n("tests/tests/a.rs", "tests", format!("concat!(env!(\"CARGO_MANIFEST_DIR\"), \"/{up}/{up}/x.gltf\")")), 1);
        // Manifests: from their folder.
        assert_eq!(n("tests/Cargo.toml", "tests", format!("host = {{ path = \"{up}/host\" }}")), 0);
        assert_eq!(n("tests/Cargo.toml", "tests", format!("x = {{ path = \"{up}/{up}/x\" }}")), 1);
        // Scripts: a path glued to a variable is the script folder's.
        assert_eq!(n(".ci/run", "", format!("cd \"$(dirname \"$0\")/{up}\"")), 0);
        assert_eq!(n(".ci/run", "", format!("cd \"$(dirname \"$0\")/{up}/{up}\"")), 1);
        // Absolute paths into the development machines' folders.
        assert_eq!(scan_text("docs/x.md", "", &format!("read /{}/main/x", "work")).len(), 1);
    }
}
