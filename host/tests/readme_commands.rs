//! Every `host` command the README shows leaves `git status` as it was: each path it writes (the
//! ones its arguments name and its options' default outputs) is ignored by git, and the cheap
//! ones, run here as written, change nothing git tracks.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().to_path_buf()
}

/// The argument lists of every `cargo run --release -p host -- ...` in the README (code blocks
/// and table cells; optional `[...]` parts dropped).
fn readme_commands() -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(root().join("README.md")).expect("reading README.md");
    let marker = "cargo run --release -p host -- ";
    let mut out = Vec::new();
    for (at, _) in text.match_indices(marker) {
        let rest = &text[at + marker.len()..];
        let end = rest.find(['`', '\n']).unwrap_or(rest.len());
        let mut cmd = rest[..end].to_string();
        while let Some(open) = cmd.find('[') {
            let close = cmd[open..].find(']').map(|c| open + c + 1).unwrap_or(cmd.len());
            cmd.replace_range(open..close, "");
        }
        out.push(cmd.split_whitespace().map(str::to_string).collect());
    }
    out
}

/// Options whose value is a path the command writes.
const OUTPUT_OPTIONS: &[&str] = &["-o", "--output", "--report", "--plot", "--gbuffer", "--save-gbuffer", "--scene-dir"];

fn host(args: &[String]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_host")).args(args).current_dir(root()).output().expect("running host")
}

fn ignored(path: &str) -> bool {
    Command::new("git").args(["check-ignore", "-q", path]).current_dir(root()).status().expect("running git check-ignore").success()
}

fn git_status() -> String {
    let o = Command::new("git").args(["status", "--porcelain", "--untracked-files=all"]).current_dir(root()).output().expect("running git status");
    assert!(o.status.success(), "git status failed: {}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn readme_commands_write_only_ignored_paths() {
    let cmds = readme_commands();
    assert!(cmds.len() >= 15, "found only {} host commands in the README", cmds.len());
    for cmd in &cmds {
        let shown = cmd.join(" ");
        // the paths its arguments name
        let mut written: Vec<String> = cmd.windows(2).filter(|w| OUTPUT_OPTIONS.contains(&w[0].as_str())).map(|w| w[1].clone()).collect();
        // and the defaults of its output options, from its --help
        let mut help_args = cmd.clone();
        help_args.push("--help".into());
        let h = host(&help_args);
        assert!(h.status.success(), "`host {shown} --help` failed: {}", String::from_utf8_lossy(&h.stderr));
        let help = String::from_utf8_lossy(&h.stdout);
        for d in help.split("[default: ").skip(1).filter_map(|s| s.split(']').next()) {
            // a path, not a description such as "the report's path with extension .png"
            if d.contains(char::is_whitespace) {
                continue;
            }
            if d.contains('/') || [".md", ".json", ".png", ".exr", ".csv", ".npy", ".bin"].iter().any(|e| d.ends_with(e)) {
                written.push(d.to_string());
            }
        }
        for p in written {
            assert!(!Path::new(&p).is_absolute(), "`host {shown}` writes {p}, outside the checkout");
            assert!(ignored(&p), "`host {shown}` writes {p}, which git does not ignore: `git status` would not stay clean");
        }
    }
}

/// The README's quick commands, run as written: `git status` is the same after them.
#[test]
fn quick_readme_commands_leave_git_status_unchanged() {
    let before = git_status();
    let quick: Vec<Vec<String>> = readme_commands().into_iter().filter(|c| matches!(c.first().map(String::as_str), Some("info" | "grid")) || c.starts_with(&["eval".into(), "--list".into()])).collect();
    assert!(quick.len() >= 3, "{quick:?}");
    for cmd in &quick {
        let o = host(cmd);
        assert!(o.status.success(), "`host {}` failed: {}", cmd.join(" "), String::from_utf8_lossy(&o.stderr));
    }
    assert_eq!(git_status(), before, "README commands changed what git sees");
}
