//! The guard against import circles: no source file of a workspace crate imports, directly or
//! through other files, a file that imports it.
//!
//! Every member of the root `Cargo.toml`'s `[workspace] members` is read; each crate root under
//! its `src/` (`lib.rs`, `main.rs`, `bin/*.rs`, `bin/*/main.rs`) is a crate of its own, whose
//! files are found by following `mod name;` declarations the way rustc does (`name.rs` or
//! `name/mod.rs`, `#[path = "..."]`). In each file, after comments, string and character literals
//! are skipped, every path that starts with `crate::`, `super::` or `self::` is an edge to the
//! file that holds its target: in `use` items, grouped ones expanded (`use crate::{a::b, c::{d,
//! e}}`), `pub use` included, and written inline in code (`crate::x::y`, `super::x`).
//!
//! A path that starts with the bare name of a child module the file declares (`pub use
//! child::X`, `child::f()`) is how a module presents the children it declares, like the `mod`
//! line itself: no edge (a `mod.rs` re-exporting its children while they import its shared
//! items is no circle). Written `self::child::X` or `crate::parent::child::X` it is one.
//!
//! A path `crate::a::b::c` goes to the file of its longest module prefix (`a/b.rs`, or `a.rs`
//! where `b` is an item or an inline module of it); where the next name is one that file imports
//! itself (a `use` at its top level, as the re-exports of a `lib.rs` or `mod.rs`), the path goes
//! on to that import's target, and an import from another crate ends it without an edge. A crate
//! root's `#[macro_export]` macros (`crate::m!`) go to the file defining them. A `mod child;`
//! declaration is not an edge, nor is a path from a file to itself (`use super::*` in an inline
//! `mod tests`).
//!
//! Every strongly connected component of more than one file is a circle, reported with its edges
//! and the names imported along them (`cargo xtask check-cycles`; the unit tests plant circles).

use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};
use std::path::{Path, PathBuf};

/// One file's imports from another file of the same crate.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Edge {
    /// Importing file, relative to the workspace root, `/`-separated.
    pub from: String,
    /// Imported file.
    pub to: String,
    /// The names imported (`*` for a glob, `mod x` for the module itself).
    pub names: BTreeSet<String>,
    /// 1-based line of the first import.
    pub line: usize,
}

/// Files of one crate that import each other in a circle, and the edges between them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Cycle {
    /// The crate: its member folder, with the root file where the folder holds several crates.
    pub krate: String,
    pub files: Vec<String>,
    pub edges: Vec<Edge>,
}

impl std::fmt::Display for Cycle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "{}: {} files import each other in a circle:", self.krate, self.files.len())?;
        for e in &self.edges {
            let names: Vec<&str> = e.names.iter().map(String::as_str).collect();
            writeln!(f, "  {}:{} -> {}: {}", e.from, e.line, e.to, names.join(", "))?;
        }
        Ok(())
    }
}

/// Every circle in every crate of the workspace at `root`.
pub fn scan_workspace(root: &Path) -> Result<Vec<Cycle>, String> {
    let mut cycles = Vec::new();
    for g in workspace_graphs(root)? {
        cycles.extend(g.cycles());
    }
    Ok(cycles)
}

/// The file graph of every crate of the workspace at `root`.
pub fn workspace_graphs(root: &Path) -> Result<Vec<Graph>, String> {
    let manifest = root.join("Cargo.toml");
    let text = std::fs::read_to_string(&manifest).map_err(|e| format!("reading {}: {e}", manifest.display()))?;
    let mut graphs = Vec::new();
    for member in workspace_members(root, &text)? {
        let src = root.join(&member).join("src");
        let mut roots: Vec<PathBuf> = ["lib.rs", "main.rs"].iter().map(|r| src.join(r)).filter(|p| p.is_file()).collect();
        if let Ok(entries) = std::fs::read_dir(src.join("bin")) {
            let mut bins: Vec<PathBuf> = entries.filter_map(|e| e.ok()).map(|e| e.path()).collect();
            bins.sort();
            for b in bins {
                if b.extension().is_some_and(|x| x == "rs") {
                    roots.push(b);
                } else if b.join("main.rs").is_file() {
                    roots.push(b.join("main.rs"));
                }
            }
        }
        let several = roots.len() > 1;
        for r in roots {
            let name = if several { format!("{member} ({})", relative(&root.join(&member), &r)) } else { member.clone() };
            graphs.push(Graph::build(root, &name, &r)?);
        }
    }
    Ok(graphs)
}

/// The member folders of the `[workspace]` table of a root manifest `text` (a trailing `*` in a
/// member's last component is expanded to the folders under `root` holding a `Cargo.toml`).
pub fn workspace_members(root: &Path, text: &str) -> Result<Vec<String>, String> {
    let mut in_workspace = false;
    let mut list = None;
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        let t = line.trim();
        if t.starts_with('[') {
            in_workspace = t == "[workspace]";
            continue;
        }
        if in_workspace && t.starts_with("members") && t[7..].trim_start().starts_with('=') {
            let mut value = t.split_once('=').map(|(_, v)| v.to_string()).unwrap_or_default();
            while !value.contains(']') {
                match lines.next() {
                    Some(l) => value.push_str(l.split('#').next().unwrap_or("")),
                    None => return Err("the workspace's members list has no closing `]`".into()),
                }
            }
            list = Some(value);
            break;
        }
    }
    let list = list.ok_or("the root Cargo.toml has no [workspace] members list")?;
    let mut members = Vec::new();
    for m in list.split('"').skip(1).step_by(2) {
        if let Some((dir, pattern)) = m.rsplit_once('/').filter(|(_, p)| p.contains('*')).or_else(|| m.contains('*').then_some(("", m))) {
            let (before, after) = pattern.split_once('*').unwrap_or((pattern, ""));
            let base = root.join(dir);
            let mut found: Vec<String> = std::fs::read_dir(&base)
                .map_err(|e| format!("expanding member {m:?}: {e}"))?
                .filter_map(|e| e.ok())
                .filter(|e| e.path().join("Cargo.toml").is_file())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.starts_with(before) && n.ends_with(after))
                .map(|n| if dir.is_empty() { n } else { format!("{dir}/{n}") })
                .collect();
            found.sort();
            members.extend(found);
        } else {
            members.push(m.to_string());
        }
    }
    Ok(members)
}

/// `path` relative to `root`, `/`-separated.
fn relative(root: &Path, path: &Path) -> String {
    let rel = path.strip_prefix(root).unwrap_or(path);
    rel.components().map(|c| c.as_os_str().to_string_lossy().into_owned()).collect::<Vec<_>>().join("/")
}

// ---------------------------------------------------------------------------------------------
// Tokens

#[derive(Debug, Clone, PartialEq, Eq)]
enum Tok {
    Ident(String),
    /// A string literal's text (escapes left as written).
    Str(String),
    /// `::`
    Sep,
    Punct(char),
    /// A number or character literal.
    Lit,
}

#[derive(Debug, Clone)]
struct Token {
    tok: Tok,
    line: usize,
}

fn ident_start(c: char) -> bool {
    c.is_alphabetic() || c == '_'
}

fn ident_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// Rust source as identifiers, `::`, punctuation and literals: comments (doc comments included)
/// are dropped, string literals (raw, byte and C strings too) become one token each, so nothing
/// written in them reads as a path.
fn lex(src: &str) -> Vec<Token> {
    let c: Vec<char> = src.chars().collect();
    let at = |i: usize| c.get(i).copied().unwrap_or('\0');
    let mut out = Vec::new();
    let (mut i, mut line) = (0, 1);
    // A quoted string from `i` (at its opening `"`): its text and the index after it.
    let quoted = |mut i: usize, line: &mut usize| -> (String, usize) {
        let start = i + 1;
        i += 1;
        while i < c.len() && c[i] != '"' {
            if c[i] == '\\' {
                i += 1;
            }
            if at(i) == '\n' {
                *line += 1;
            }
            i += 1;
        }
        (c[start..i.min(c.len())].iter().collect(), i + 1)
    };
    while i < c.len() {
        let ch = c[i];
        let start_line = line;
        if ch == '\n' {
            line += 1;
            i += 1;
        } else if ch.is_whitespace() {
            i += 1;
        } else if ch == '/' && at(i + 1) == '/' {
            while i < c.len() && c[i] != '\n' {
                i += 1;
            }
        } else if ch == '/' && at(i + 1) == '*' {
            let mut depth = 0;
            while i < c.len() {
                if c[i] == '/' && at(i + 1) == '*' {
                    depth += 1;
                    i += 2;
                } else if c[i] == '*' && at(i + 1) == '/' {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    if c[i] == '\n' {
                        line += 1;
                    }
                    i += 1;
                }
            }
        } else if ident_start(ch) {
            let s = i;
            while i < c.len() && ident_char(c[i]) {
                i += 1;
            }
            let word: String = c[s..i].iter().collect();
            let raw_prefix = matches!(word.as_str(), "r" | "br" | "cr");
            if raw_prefix && (at(i) == '"' || (at(i) == '#' && (at(i + 1) == '#' || at(i + 1) == '"'))) {
                let mut hashes = 0;
                while at(i) == '#' {
                    hashes += 1;
                    i += 1;
                }
                i += 1;
                let body = i;
                loop {
                    if i >= c.len() {
                        break;
                    }
                    if c[i] == '"' && (0..hashes).all(|k| at(i + 1 + k) == '#') {
                        break;
                    }
                    if c[i] == '\n' {
                        line += 1;
                    }
                    i += 1;
                }
                out.push(Token { tok: Tok::Str(c[body..i.min(c.len())].iter().collect()), line: start_line });
                i += 1 + hashes;
            } else if matches!(word.as_str(), "b" | "c") && at(i) == '"' {
                let (text, next) = quoted(i, &mut line);
                out.push(Token { tok: Tok::Str(text), line: start_line });
                i = next;
            } else if word == "b" && at(i) == '\'' {
                i = char_literal_end(&c, i);
                out.push(Token { tok: Tok::Lit, line: start_line });
            } else if word == "r" && at(i) == '#' && ident_start(at(i + 1)) {
                let s = i + 1;
                i += 1;
                while i < c.len() && ident_char(c[i]) {
                    i += 1;
                }
                out.push(Token { tok: Tok::Ident(c[s..i].iter().collect()), line: start_line });
            } else {
                out.push(Token { tok: Tok::Ident(word), line: start_line });
            }
        } else if ch.is_ascii_digit() {
            while i < c.len() && ident_char(c[i]) {
                i += 1;
            }
            out.push(Token { tok: Tok::Lit, line: start_line });
        } else if ch == '"' {
            let (text, next) = quoted(i, &mut line);
            out.push(Token { tok: Tok::Str(text), line: start_line });
            i = next;
        } else if ch == '\'' {
            if at(i + 1) == '\\' || (at(i + 2) == '\'' && at(i + 1) != '\n') {
                i = char_literal_end(&c, i);
                out.push(Token { tok: Tok::Lit, line: start_line });
            } else {
                // A lifetime or a label: its name follows as an identifier.
                out.push(Token { tok: Tok::Punct('\''), line: start_line });
                i += 1;
            }
        } else if ch == ':' && at(i + 1) == ':' {
            out.push(Token { tok: Tok::Sep, line: start_line });
            i += 2;
        } else {
            out.push(Token { tok: Tok::Punct(ch), line: start_line });
            i += 1;
        }
    }
    out
}

/// The index after the character literal whose opening `'` is at `i`.
fn char_literal_end(c: &[char], mut i: usize) -> usize {
    i += 1;
    if c.get(i) == Some(&'\\') {
        i += 2;
    } else {
        i += 1;
    }
    while i < c.len() && c[i] != '\'' && c[i] != '\n' {
        i += 1;
    }
    i + 1
}

fn is_ident(t: Option<&Token>, word: &str) -> bool {
    matches!(t, Some(Token { tok: Tok::Ident(w), .. }) if w == word)
}

fn is_punct(t: Option<&Token>, ch: char) -> bool {
    matches!(t, Some(Token { tok: Tok::Punct(p), .. }) if *p == ch)
}

fn ident(t: Option<&Token>) -> Option<&str> {
    match t {
        Some(Token { tok: Tok::Ident(w), .. }) => Some(w),
        _ => None,
    }
}

// ---------------------------------------------------------------------------------------------
// Use trees

/// One path a `use` item brings in: its segments as written (a trailing `self` dropped) and the
/// name it binds (the alias, the last segment, or `*` for a glob).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UsePath {
    pub segments: Vec<String>,
    pub name: String,
}

/// The paths of the use tree starting at token `i` (after `use`), and the index after its `;`.
fn parse_use(toks: &[Token], i: usize) -> (Vec<UsePath>, usize) {
    let mut out = Vec::new();
    let end = use_tree(toks, i, &[], &mut out);
    let mut j = end;
    while j < toks.len() && !is_punct(toks.get(j), ';') {
        j += 1;
    }
    (out, j + 1)
}

/// Parse one use tree at `i` under `prefix`, pushing its paths; returns the index after it.
fn use_tree(toks: &[Token], mut i: usize, prefix: &[String], out: &mut Vec<UsePath>) -> usize {
    let mut segs = prefix.to_vec();
    loop {
        match toks.get(i).map(|t| &t.tok) {
            Some(Tok::Sep) => i += 1,
            Some(Tok::Punct('{')) => {
                i += 1;
                loop {
                    match toks.get(i).map(|t| &t.tok) {
                        None => return i,
                        Some(Tok::Punct('}')) => return i + 1,
                        Some(Tok::Punct(',')) => i += 1,
                        _ => {
                            let next = use_tree(toks, i, &segs, out);
                            if next == i {
                                return i;
                            }
                            i = next;
                        }
                    }
                }
            }
            Some(Tok::Punct('*')) => {
                out.push(UsePath { segments: segs, name: "*".into() });
                return i + 1;
            }
            Some(Tok::Ident(w)) => {
                segs.push(w.clone());
                i += 1;
                if matches!(toks.get(i).map(|t| &t.tok), Some(Tok::Sep)) {
                    continue;
                }
                let mut name = w.clone();
                if is_ident(toks.get(i), "as") {
                    if let Some(alias) = ident(toks.get(i + 1)) {
                        name = alias.to_string();
                    }
                    i += 2;
                }
                if segs.last().is_some_and(|s| s == "self") && segs.len() > 1 {
                    segs.pop();
                    if name == "self" {
                        name = segs.last().cloned().unwrap_or_default();
                    }
                }
                out.push(UsePath { segments: segs, name });
                return i;
            }
            _ => return i,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Files and modules

/// A `mod name;` declaration: the inline modules around it, its name, its `#[path]`.
struct ModDecl {
    inline: Vec<String>,
    name: String,
    path_attr: Option<String>,
}

/// What one pass over a file's tokens finds.
#[derive(Default)]
struct Outline {
    mod_decls: Vec<ModDecl>,
    /// Inline modules (`mod tests { ... }`), as paths below the file's module.
    inline_mods: Vec<Vec<String>>,
    /// `#[macro_export] macro_rules! name`.
    exported_macros: Vec<String>,
}

fn outline(toks: &[Token]) -> Outline {
    let mut o = Outline::default();
    let mut depth = 0usize;
    let mut stack: Vec<(String, usize)> = Vec::new();
    for (i, t) in toks.iter().enumerate() {
        match &t.tok {
            Tok::Punct('{') => depth += 1,
            Tok::Punct('}') => {
                depth = depth.saturating_sub(1);
                while stack.last().is_some_and(|(_, d)| *d > depth) {
                    stack.pop();
                }
            }
            Tok::Ident(w) if w == "mod" && !is_punct(i.checked_sub(1).and_then(|p| toks.get(p)), '$') => {
                let Some(name) = ident(toks.get(i + 1)) else { continue };
                let inline: Vec<String> = stack.iter().map(|(n, _)| n.clone()).collect();
                if is_punct(toks.get(i + 2), ';') {
                    o.mod_decls.push(ModDecl { inline, name: name.to_string(), path_attr: path_attribute(toks, i) });
                } else if is_punct(toks.get(i + 2), '{') {
                    let mut p = inline;
                    p.push(name.to_string());
                    o.inline_mods.push(p);
                    stack.push((name.to_string(), depth + 1));
                }
            }
            Tok::Ident(w) if w == "macro_rules" && is_punct(toks.get(i + 1), '!') && stack.is_empty() && depth == 0 => {
                if let Some(name) = ident(toks.get(i + 2)) {
                    if attributes_before(toks, i).iter().any(|a| a.first().is_some_and(|t| is_ident(Some(t), "macro_export"))) {
                        o.exported_macros.push(name.to_string());
                    }
                }
            }
            _ => {}
        }
    }
    o
}

/// The attributes (`#[...]`, their inner tokens) directly before the item whose first keyword
/// is token `i`, skipping visibility (`pub`, `pub(crate)`, ...).
fn attributes_before(toks: &[Token], i: usize) -> Vec<&[Token]> {
    let mut attrs = Vec::new();
    let mut j = i;
    while j > 0 {
        let t = &toks[j - 1];
        match &t.tok {
            Tok::Ident(w) if matches!(w.as_str(), "pub" | "crate" | "self" | "super" | "in") => j -= 1,
            Tok::Punct('(') | Tok::Punct(')') | Tok::Sep => j -= 1,
            Tok::Punct(']') => {
                let close = j - 1;
                let mut k = close;
                let mut level = 0;
                loop {
                    match toks[k].tok {
                        Tok::Punct(']') => level += 1,
                        Tok::Punct('[') => level -= 1,
                        _ => {}
                    }
                    if level == 0 || k == 0 {
                        break;
                    }
                    k -= 1;
                }
                if k == 0 || !is_punct(toks.get(k - 1), '#') {
                    break;
                }
                attrs.push(&toks[k + 1..close]);
                j = k - 1;
            }
            _ => break,
        }
    }
    attrs
}

/// The `#[path = "..."]` of the `mod` at token `i`, if any.
fn path_attribute(toks: &[Token], i: usize) -> Option<String> {
    attributes_before(toks, i).into_iter().find_map(|a| match a {
        [Token { tok: Tok::Ident(p), .. }, Token { tok: Tok::Punct('='), .. }, Token { tok: Tok::Str(s), .. }] if p == "path" => Some(s.clone()),
        _ => None,
    })
}

/// One source file of a crate.
pub struct SourceFile {
    /// Relative to the workspace root, `/`-separated.
    pub rel: String,
    /// Its module path below the crate root (empty for the root).
    pub module: Vec<String>,
    toks: Vec<Token>,
}

/// Where a name a module imports comes from: a path in the crate (absolute module path and
/// item), or another crate.
#[derive(Debug, Clone)]
enum Origin {
    Internal(Vec<String>),
    External,
}

/// A path into the crate written in a file.
struct Reference {
    /// Absolute path (below the crate root).
    path: Vec<String>,
    /// A glob import (`use super::*`).
    glob: bool,
    /// Written from a child module's bare name (`child::x`): no edge.
    bare: bool,
    line: usize,
}

/// The files of one crate and the imports between them.
pub struct Graph {
    pub krate: String,
    pub files: Vec<SourceFile>,
    /// Module path -> index into `files`, for modules that are files.
    file_of: HashMap<Vec<String>, usize>,
    /// Every module path, inline modules included.
    modules: HashSet<Vec<String>>,
    /// Exported macro name -> defining file.
    macros: HashMap<String, usize>,
    /// Per module (file or inline), the names its top-level `use` items bind.
    imports: HashMap<Vec<String>, HashMap<String, Origin>>,
    /// (from, to) -> names and first line.
    pub edges: BTreeMap<(usize, usize), (BTreeSet<String>, usize)>,
}

impl Graph {
    /// The graph of the crate whose root file is `root_file` (`krate` names it in reports).
    pub fn build(ws_root: &Path, krate: &str, root_file: &Path) -> Result<Graph, String> {
        let mut g = Graph {
            krate: krate.to_string(),
            files: Vec::new(),
            file_of: HashMap::new(),
            modules: HashSet::new(),
            macros: HashMap::new(),
            imports: HashMap::new(),
            edges: BTreeMap::new(),
        };
        g.modules.insert(Vec::new());
        let mut seen = HashSet::new();
        // (file, module path, whether its child modules sit in its own folder, as for mod.rs)
        let mut stack = vec![(root_file.to_path_buf(), Vec::<String>::new(), true)];
        while let Some((path, module, mod_rs)) = stack.pop() {
            if !seen.insert(path.clone()) {
                continue;
            }
            let text = std::fs::read_to_string(&path).map_err(|e| format!("reading {}: {e}", path.display()))?;
            let toks = lex(&text);
            let o = outline(&toks);
            let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
            let own_dir = if mod_rs { dir.clone() } else { dir.join(path.file_stem().unwrap_or_default()) };
            for m in &o.inline_mods {
                g.modules.insert([module.clone(), m.clone()].concat());
            }
            for d in o.mod_decls.iter().rev() {
                let child: Vec<String> = [module.clone(), d.inline.clone(), vec![d.name.clone()]].concat();
                g.modules.insert(child.clone());
                let found = match &d.path_attr {
                    Some(p) if d.inline.is_empty() => Some((dir.join(p), true)),
                    Some(p) => Some((d.inline.iter().fold(own_dir.clone(), |a, s| a.join(s)).join(p), true)),
                    None => {
                        let base = d.inline.iter().fold(own_dir.clone(), |a, s| a.join(s));
                        let flat = base.join(format!("{}.rs", d.name));
                        let nested = base.join(&d.name).join("mod.rs");
                        if flat.is_file() {
                            Some((flat, false))
                        } else if nested.is_file() {
                            Some((nested, true))
                        } else {
                            None
                        }
                    }
                };
                // A declaration without a file is compiled out (`#[cfg]`) or an error rustc reports.
                if let Some((file, child_mod_rs)) = found.filter(|(f, _)| f.is_file()) {
                    stack.push((file, child, child_mod_rs));
                }
            }
            let idx = g.files.len();
            for m in &o.exported_macros {
                g.macros.insert(m.clone(), idx);
            }
            g.file_of.insert(module.clone(), idx);
            g.files.push(SourceFile { rel: relative(ws_root, &path), module, toks });
        }
        let refs: Vec<Vec<(Reference, String)>> = (0..g.files.len()).map(|f| g.references(f)).collect();
        for (f, list) in refs.into_iter().enumerate() {
            for (r, written) in list {
                if r.bare {
                    continue;
                }
                let Some((to, name)) = g.target(&r.path, 0) else { continue };
                if to == f {
                    continue;
                }
                let name = if r.glob { "*".to_string() } else { name.unwrap_or_else(|| format!("mod {}", written.rsplit("::").next().unwrap_or(&written))) };
                let e = g.edges.entry((f, to)).or_insert_with(|| (BTreeSet::new(), r.line));
                e.0.insert(name);
                e.1 = e.1.min(r.line);
            }
        }
        Ok(g)
    }

    /// The absolute path of `segs` written in module `module`; `None` for a path that does not
    /// start in this crate (another crate, a name in scope). A first segment that names a child
    /// module of `module` starts there, as `self::` would.
    fn absolute(&self, module: &[String], segs: &[String]) -> Option<Vec<String>> {
        let first = segs.first()?;
        let (mut abs, rest) = match first.as_str() {
            "crate" => (Vec::new(), &segs[1..]),
            "self" => (module.to_vec(), &segs[1..]),
            "super" => {
                let mut m = module.to_vec();
                let mut k = 0;
                while segs.get(k).is_some_and(|s| s == "super") {
                    m.pop()?;
                    k += 1;
                }
                (m, &segs[k..])
            }
            name => {
                let mut child = module.to_vec();
                child.push(name.to_string());
                if !self.modules.contains(&child) {
                    return None;
                }
                (module.to_vec(), segs)
            }
        };
        abs.extend(rest.iter().filter(|s| *s != "self").cloned());
        Some(abs)
    }

    /// The file an absolute path leads to, following the imports of the file it first reaches,
    /// and the name imported there (`None`: the path is a module that is a file).
    fn target(&self, abs: &[String], hops: usize) -> Option<(usize, Option<String>)> {
        let k = (0..=abs.len()).rev().find(|&k| self.file_of.contains_key(&abs[..k]))?;
        let file = self.file_of[&abs[..k]];
        let Some(next) = abs.get(k) else { return Some((file, None)) };
        if hops < 16 {
            match self.imports.get(&abs[..k]).and_then(|m| m.get(next)) {
                Some(Origin::External) => return None,
                Some(Origin::Internal(src)) => {
                    let mut p = src.clone();
                    p.extend(abs[k + 1..].iter().cloned());
                    if let Some((to, name)) = self.target(&p, hops + 1) {
                        return Some((to, Some(name.unwrap_or_else(|| next.clone()))));
                    }
                    return None;
                }
                None => {}
            }
        }
        if k == 0 {
            if let Some(&m) = self.macros.get(next) {
                return Some((m, Some(next.clone())));
            }
        }
        Some((file, Some(next.clone())))
    }

    /// Every path into the crate written in file `f` (with the path as written, for the report);
    /// records the names its top-level `use` items bind in `self.imports` on the way.
    fn references(&mut self, f: usize) -> Vec<(Reference, String)> {
        let module = self.files[f].module.clone();
        let toks = std::mem::take(&mut self.files[f].toks);
        let mut refs = Vec::new();
        let mut depth = 0usize;
        let mut stack: Vec<(String, usize)> = Vec::new();
        let mut i = 0;
        let here = |stack: &Vec<(String, usize)>| -> Vec<String> { [module.clone(), stack.iter().map(|(n, _)| n.clone()).collect()].concat() };
        while i < toks.len() {
            let prev = i.checked_sub(1).and_then(|p| toks.get(p));
            match &toks[i].tok {
                Tok::Punct('{') => depth += 1,
                Tok::Punct('}') => {
                    depth = depth.saturating_sub(1);
                    while stack.last().is_some_and(|(_, d)| *d > depth) {
                        stack.pop();
                    }
                }
                Tok::Ident(w) if w == "mod" && is_punct(toks.get(i + 2), '{') => {
                    if let Some(name) = ident(toks.get(i + 1)) {
                        stack.push((name.to_string(), depth + 1));
                        depth += 1;
                        i += 3;
                        continue;
                    }
                }
                Tok::Ident(w) if w == "use" && !matches!(prev.map(|t| &t.tok), Some(Tok::Sep) | Some(Tok::Punct('$'))) => {
                    let line = toks[i].line;
                    let (paths, next) = parse_use(&toks, i + 1);
                    let m = here(&stack);
                    let top_level = depth == stack.last().map_or(0, |(_, d)| *d);
                    for p in paths {
                        let abs = self.absolute(&m, &p.segments);
                        if top_level && p.name != "*" && p.name != "_" {
                            let origin = match &abs {
                                Some(a) => Origin::Internal(a.clone()),
                                None => Origin::External,
                            };
                            self.imports.entry(m.clone()).or_default().insert(p.name.clone(), origin);
                        }
                        if let Some(abs) = abs {
                            let bare = !matches!(p.segments[0].as_str(), "crate" | "self" | "super");
                            refs.push((Reference { path: abs, glob: p.name == "*", bare, line }, p.segments.join("::")));
                        }
                    }
                    i = next;
                    continue;
                }
                Tok::Ident(w)
                    if matches!(toks.get(i + 1).map(|t| &t.tok), Some(Tok::Sep))
                        && !matches!(prev.map(|t| &t.tok), Some(Tok::Sep) | Some(Tok::Punct('$')) | Some(Tok::Punct('.')) | Some(Tok::Punct('\'')))
                        && !(is_ident(prev, "in") && is_punct(i.checked_sub(2).and_then(|p| toks.get(p)), '(')) =>
                {
                    // A path in code: collect its segments up to a turbofish, group or glob.
                    let line = toks[i].line;
                    let mut segs = vec![w.clone()];
                    let mut j = i + 1;
                    while matches!(toks.get(j).map(|t| &t.tok), Some(Tok::Sep)) {
                        match ident(toks.get(j + 1)) {
                            Some(s) => {
                                segs.push(s.to_string());
                                j += 2;
                            }
                            None => break,
                        }
                    }
                    let m = here(&stack);
                    if let Some(abs) = self.absolute(&m, &segs) {
                        let bare = !matches!(w.as_str(), "crate" | "self" | "super");
                        refs.push((Reference { path: abs, glob: false, bare, line }, segs.join("::")));
                    }
                    i = j;
                    continue;
                }
                _ => {}
            }
            i += 1;
        }
        self.files[f].toks = toks;
        refs
    }

    /// The strongly connected components of more than one file.
    pub fn cycles(&self) -> Vec<Cycle> {
        let n = self.files.len();
        let mut adj = vec![Vec::new(); n];
        for &(a, b) in self.edges.keys() {
            adj[a].push(b);
        }
        let comps = tarjan(&adj);
        let mut out = Vec::new();
        for comp in comps.into_iter().filter(|c| c.len() > 1) {
            let set: HashSet<usize> = comp.iter().copied().collect();
            let mut files: Vec<String> = comp.iter().map(|&f| self.files[f].rel.clone()).collect();
            files.sort();
            let mut edges: Vec<Edge> = self
                .edges
                .iter()
                .filter(|((a, b), _)| set.contains(a) && set.contains(b))
                .map(|((a, b), (names, line))| Edge { from: self.files[*a].rel.clone(), to: self.files[*b].rel.clone(), names: names.clone(), line: *line })
                .collect();
            edges.sort_by(|x, y| (&x.from, &x.to).cmp(&(&y.from, &y.to)));
            out.push(Cycle { krate: self.krate.clone(), files, edges });
        }
        out.sort_by(|a, b| a.files.cmp(&b.files));
        out
    }

    /// Every edge, as (from, to, names), file paths relative to the workspace root, sorted.
    #[cfg(test)]
    pub fn edge_list(&self) -> Vec<(String, String, Vec<String>)> {
        let mut list: Vec<_> = self
            .edges
            .iter()
            .map(|((a, b), (names, _))| (self.files[*a].rel.clone(), self.files[*b].rel.clone(), names.iter().cloned().collect()))
            .collect();
        list.sort();
        list
    }
}

/// Tarjan's strongly connected components of the graph `adj` (iterative).
fn tarjan(adj: &[Vec<usize>]) -> Vec<Vec<usize>> {
    let n = adj.len();
    let mut index = vec![usize::MAX; n];
    let mut low = vec![0; n];
    let mut on_stack = vec![false; n];
    let mut stack = Vec::new();
    let mut comps = Vec::new();
    let mut next = 0;
    for s in 0..n {
        if index[s] != usize::MAX {
            continue;
        }
        // (node, next neighbour to visit)
        let mut call = vec![(s, 0usize)];
        index[s] = next;
        low[s] = next;
        next += 1;
        stack.push(s);
        on_stack[s] = true;
        while let Some(&mut (v, ref mut k)) = call.last_mut() {
            if let Some(&w) = adj[v].get(*k) {
                *k += 1;
                if index[w] == usize::MAX {
                    index[w] = next;
                    low[w] = next;
                    next += 1;
                    stack.push(w);
                    on_stack[w] = true;
                    call.push((w, 0));
                } else if on_stack[w] {
                    low[v] = low[v].min(index[w]);
                }
            } else {
                call.pop();
                if let Some(&(u, _)) = call.last() {
                    low[u] = low[u].min(low[v]);
                }
                if low[v] == index[v] {
                    let mut comp = Vec::new();
                    loop {
                        let w = stack.pop().expect("on the stack");
                        on_stack[w] = false;
                        comp.push(w);
                        if w == v {
                            break;
                        }
                    }
                    comps.push(comp);
                }
            }
        }
    }
    comps
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A workspace of one crate `a` in a fresh temporary folder: `files` are (path under
    /// `a/src`, text).
    fn tree(name: &str, files: &[(&str, &str)]) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("import-cycles-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("a/src")).unwrap();
        std::fs::write(dir.join("Cargo.toml"), "[workspace]\nresolver = \"2\"\nmembers = [\n    \"a\", # the crate\n]\n").unwrap();
        std::fs::write(dir.join("a/Cargo.toml"), "[package]\nname = \"a\"\n").unwrap();
        for (path, text) in files {
            let p = dir.join("a/src").join(path);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, text).unwrap();
        }
        dir
    }

    /// The edges of crate `a` in `dir`, as "from -> to: names" with paths under `a/src/`.
    fn edges(dir: &Path) -> Vec<String> {
        let graphs = workspace_graphs(dir).unwrap();
        let short = |p: &str| p.trim_start_matches("a/src/").to_string();
        graphs[0].edge_list().into_iter().map(|(a, b, n)| format!("{} -> {}: {}", short(&a), short(&b), n.join(", "))).collect()
    }

    const LIB: &str = "//! The crate.\npub mod b;\npub mod c;\npub use b::B;\n";
    const B: &str = "//! B, which reads `crate::c::C` (in a doc comment: no edge).\nuse crate::c::{C, D as E};\n\
        pub struct B(pub C, pub E);\n\
        pub fn f() -> &'static str { \"crate::c::x is a string\" }\n\
        /* crate::c::C in a block /* nested */ comment */\n\
        pub fn g() -> char { '\"' }\n\
        pub fn h(x: &str) -> &str { let _ = r#\"super::c\"#; x }\n";
    const C: &str = "//! C.\npub struct C;\npub struct D;\n#[cfg(test)]\nmod tests {\n    use super::*;\n    #[test]\n    fn t() { let _ = C; }\n}\n";

    #[test]
    fn a_tree_without_a_cycle_passes() {
        let dir = tree("acyclic", &[("lib.rs", LIB), ("b.rs", B), ("c.rs", C)]);
        let e = edges(&dir);
        let cycles = scan_workspace(&dir).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        // lib.rs's `pub use b::B` presents its child: no edge.
        assert_eq!(e, vec!["b.rs -> c.rs: C, D".to_string()]);
        assert_eq!(cycles, vec![]);
    }

    #[test]
    fn a_planted_cycle_fails_and_names_both_files() {
        // c -> b through an inline path in code, b -> c through its `use`.
        let c = C.replace("pub struct D;", "pub struct D;\npub fn make() -> crate::b::B { crate::b::B(C, D) }");
        let dir = tree("planted", &[("lib.rs", LIB), ("b.rs", B), ("c.rs", &c)]);
        let cycles = scan_workspace(&dir).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        assert_eq!(cycles.len(), 1, "{cycles:?}");
        assert_eq!(cycles[0].files, vec!["a/src/b.rs".to_string(), "a/src/c.rs".to_string()]);
        let shown = cycles[0].to_string();
        assert!(shown.contains("a/src/b.rs:2 -> a/src/c.rs: C, D"), "{shown}");
        assert!(shown.contains("a/src/c.rs:4 -> a/src/b.rs: B"), "{shown}");
    }

    #[test]
    fn grouped_use_is_expanded() {
        let toks = lex("pub use crate::{a::b, c::{d, e as f, self}, g::*, ::std::x};");
        assert!(is_ident(toks.get(1), "use"));
        let (paths, next) = parse_use(&toks, 2);
        assert_eq!(next, toks.len());
        let got: Vec<(String, String)> = paths.into_iter().map(|p| (p.segments.join("::"), p.name)).collect();
        let want = [("crate::a::b", "b"), ("crate::c::d", "d"), ("crate::c::e", "f"), ("crate::c", "c"), ("crate::g", "*"), ("crate::std::x", "x")];
        assert_eq!(got, want.iter().map(|(a, b)| (a.to_string(), b.to_string())).collect::<Vec<_>>());
    }

    #[test]
    fn super_resolves_to_the_parent_file() {
        // p.rs declares p/q.rs and p/q/r.rs below it; r reads p through `super::super`, q reads
        // r through `self::r`, p's own `mod tests` reads p (no edge), and `mod q;` is no edge.
        let files = [
            ("lib.rs", "mod p;\n"),
            ("p.rs", "mod q;\npub struct P;\n#[cfg(test)]\nmod tests {\n    use super::*;\n    use super::super::p::P as Q;\n}\n"),
            ("p/q/mod.rs", "mod r;\npub fn q() -> self::r::R { r::R }\n"),
            ("p/q/r.rs", "pub struct R(super::super::P);\n"),
        ];
        let dir = tree("super", &files);
        let e = edges(&dir);
        let cycles = scan_workspace(&dir).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        assert_eq!(e, vec!["p/q/mod.rs -> p/q/r.rs: R".to_string(), "p/q/r.rs -> p.rs: P".to_string()]);
        assert_eq!(cycles, vec![]);
        // One `use super::q` in r closes a circle q -> r -> q.
        let mut planted = files;
        planted[3].1 = "use super::q;\npub struct R(super::super::P);\n";
        let dir = tree("super-cycle", &planted);
        let cycles = scan_workspace(&dir).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        assert_eq!(cycles.len(), 1, "{cycles:?}");
        assert_eq!(cycles[0].files, vec!["a/src/p/q/mod.rs".to_string(), "a/src/p/q/r.rs".to_string()]);
    }

    #[test]
    fn reexports_lead_to_the_defining_file_and_other_crates_end_the_path() {
        // `crate::B` in d is lib.rs's re-export of b::B: d -> b, not d -> lib. `crate::Ext` comes
        // from another crate: no edge. `crate::m!` is c's exported macro: b -> c. The `#[path]`
        // module of b reads b through `super`.
        let lib = "pub mod b;\npub mod c;\nmod d;\npub use self::b::B;\npub use std::string::String as Ext;\n";
        let b = "pub struct B;\npub fn g() { crate::m!(); }\n#[path = \"extra_b.rs\"]\nmod extra;\n";
        let c = "pub struct C;\n#[macro_export]\nmacro_rules! m { () => { $crate::c::C } }\npub fn f(_: crate::Ext) {}\n";
        let d = "pub fn h(_: crate::B) {}\n";
        let dir = tree("reexport", &[("lib.rs", lib), ("b.rs", b), ("c.rs", c), ("d.rs", d), ("extra_b.rs", "pub fn e() -> super::B { super::B }\n")]);
        let e = edges(&dir);
        let cycles = scan_workspace(&dir).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        let want = ["b.rs -> c.rs: m", "d.rs -> b.rs: B", "extra_b.rs -> b.rs: B", "lib.rs -> b.rs: B"];
        assert_eq!(e, want.iter().map(|s| s.to_string()).collect::<Vec<_>>());
        assert_eq!(cycles, vec![]);
    }

    #[test]
    fn comments_strings_and_char_literals_are_skipped() {
        let src = "/// crate::a\n//! crate::b\n/* crate::c /* crate::d */ crate::e */\nlet s = \"crate::f \\\" crate::g\";\n\
                   let r = br##\"crate::h \"# crate::i\"##; let q = '\\''; let l: &'static str = crate::j::K;\nlet c = '\"'; crate::l::M";
        let idents: Vec<String> = lex(src).into_iter().filter_map(|t| match t.tok { Tok::Ident(w) if w.len() == 1 => Some(format!("{w}@{}", t.line)), _ => None }).collect();
        assert_eq!(idents, vec!["s@4", "r@5", "q@5", "l@5", "j@5", "K@5", "c@6", "l@6", "M@6"]);
    }

    /// The workspace's own sources, copied: a circle planted between two files of one of its
    /// crates (an `use` back along an existing edge) is reported and fails the check.
    #[test]
    fn a_cycle_planted_in_a_copy_of_the_workspace_fails_the_check() {
        let root = crate::workspace_root();
        let copy = std::env::temp_dir().join(format!("import-cycles-workspace-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&copy);
        let text = std::fs::read_to_string(root.join("Cargo.toml")).unwrap();
        std::fs::create_dir_all(&copy).unwrap();
        std::fs::write(copy.join("Cargo.toml"), &text).unwrap();
        for m in workspace_members(&root, &text).unwrap() {
            copy_rs(&root.join(&m).join("src"), &copy.join(&m).join("src"));
        }
        let before = scan_workspace(&root).unwrap();
        assert_eq!(scan_workspace(&copy).unwrap(), before, "the copy reads as the tree");
        // An edge a -> b of a non-root file a that no circle holds; plant b -> a.
        let graphs = workspace_graphs(&copy).unwrap();
        let in_cycle: HashSet<String> = before.iter().flat_map(|c| c.files.clone()).collect();
        let (g, a, b) = graphs
            .iter()
            .find_map(|g| {
                g.edges.keys().find(|(a, b)| !g.files[*a].module.is_empty() && !in_cycle.contains(&g.files[*a].rel) && !in_cycle.contains(&g.files[*b].rel)).map(|&(a, b)| (g, a, b))
            })
            .expect("an edge outside every circle");
        let (a_rel, b_rel) = (g.files[a].rel.clone(), g.files[b].rel.clone());
        let planted = format!("\n#[allow(unused_imports)]\nuse crate::{}::*;\n", g.files[a].module.join("::"));
        let b_path = copy.join(&b_rel);
        let mut b_text = std::fs::read_to_string(&b_path).unwrap();
        b_text.push_str(&planted);
        std::fs::write(&b_path, b_text).unwrap();
        let after = scan_workspace(&copy).unwrap();
        std::fs::remove_dir_all(&copy).ok();
        assert_eq!(after.len(), before.len() + 1, "{after:?}");
        let new = after.iter().find(|c| c.files.contains(&a_rel) && c.files.contains(&b_rel)).expect("the planted circle is reported");
        assert!(new.edges.iter().any(|e| e.from == b_rel && e.to == a_rel && e.names.contains("*")), "{new}");
    }

    /// Copy the `.rs` files under `from` to `to`.
    fn copy_rs(from: &Path, to: &Path) {
        for e in std::fs::read_dir(from).unwrap() {
            let e = e.unwrap();
            let p = e.path();
            if p.is_dir() {
                copy_rs(&p, &to.join(e.file_name()));
            } else if p.extension().is_some_and(|x| x == "rs") {
                std::fs::create_dir_all(to).unwrap();
                std::fs::copy(&p, to.join(e.file_name())).unwrap();
            }
        }
    }
}
