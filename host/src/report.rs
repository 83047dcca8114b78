//! What every benchmark records beside its Markdown report: a JSON file with the machine, the
//! adapter, the load average before and after the run and the per-row figures, so runs can be
//! compared by script (`<report>.json`, written by [`write_json`]).

use anyhow::Result;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The machine a benchmark ran on and how busy it was.
#[derive(Clone, Debug, Serialize)]
pub struct RunInfo {
    /// The command line (`host ...`).
    pub command: String,
    /// CPU model (`/proc/cpuinfo`), or "unknown".
    pub cpu: String,
    /// Threads of the CPU backend.
    pub cpu_threads: usize,
    /// The GPU backend's adapter (its description), or `None` when only the CPU backend ran.
    pub adapter: Option<String>,
    /// 1-, 5- and 15-minute load averages (`/proc/loadavg`) when the run started and ended.
    pub load_average_start: Option<[f64; 3]>,
    pub load_average_end: Option<[f64; 3]>,
    /// Seconds since the Unix epoch when the run ended.
    pub finished_unix_s: u64,
}

/// The 1-, 5- and 15-minute load averages, where the system reports them.
pub fn load_average() -> Option<[f64; 3]> {
    let s = std::fs::read_to_string("/proc/loadavg").ok()?;
    let mut it = s.split_whitespace().map(|v| v.parse::<f64>().ok());
    Some([it.next()??, it.next()??, it.next()??])
}

fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("model name")).and_then(|l| l.split_once(':')).map(|(_, v)| v.trim().to_string()))
        .unwrap_or_else(|| "unknown".into())
}

/// The variables that change which adapter, driver or kernel build a run uses; [`command_line`]
/// shows the ones that are set, so a report's command reruns the same configuration.
pub const ADAPTER_ENV: [&str; 6] = ["VK_ICD_FILENAMES", "VK_DRIVER_FILES", "HOST_ADAPTER", "HOST_DIV_SQRT", "HOST_NO_SUBGROUPS", "HOST_NO_PASSTHROUGH"];

/// The [`ADAPTER_ENV`] variables that are set, as `K=V ` words (empty when none is). Paths
/// under the current directory (the ICD files of `cargo xtask lavapipe`, under `target/`) are
/// shown relative to it, so a report names no folder of the machine it ran on.
pub fn adapter_env() -> String {
    let cwd = std::env::current_dir().ok();
    let shown = |v: String| -> String {
        let Some(cwd) = &cwd else { return v };
        v.split(':')
            .map(|part| std::path::Path::new(part).strip_prefix(cwd).map_or_else(|_| part.to_string(), |rel| rel.display().to_string()))
            .collect::<Vec<_>>()
            .join(":")
    };
    ADAPTER_ENV.iter().filter_map(|k| std::env::var(k).ok().filter(|v| !v.is_empty()).map(|v| format!("{k}={} ", shown(v)))).collect()
}

/// This process's command line after [`adapter_env`]
/// (`HOST_ADAPTER=25.0.7-2~bpo12+1 host bench storage ...`), each argument quoted for a POSIX
/// shell where it needs it ([`shell_word`]), so the line reruns as it is.
pub fn command_line() -> String {
    format!("{}{}", adapter_env(), std::env::args().map(|a| shell_word(&a)).collect::<Vec<_>>().join(" "))
}

/// `word` as a POSIX shell reads it back: unchanged when it holds only characters no shell
/// treats specially, else in single quotes (a `'` inside written `'\''`).
pub fn shell_word(word: &str) -> String {
    let plain = !word.is_empty() && word.chars().all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c));
    if plain {
        word.to_string()
    } else {
        format!("'{}'", word.replace('\'', "'\\''"))
    }
}

impl RunInfo {
    /// Start recording: the command line ([`command_line`]), the machine and the current load average.
    pub fn start(adapter: Option<String>) -> RunInfo {
        RunInfo {
            command: command_line(),
            cpu: cpu_model(),
            cpu_threads: crate::cpu::threads(),
            adapter,
            load_average_start: load_average(),
            load_average_end: None,
            finished_unix_s: 0,
        }
    }
}

/// `report` with the extension `.json`.
pub fn json_path(report: &Path) -> PathBuf {
    report.with_extension("json")
}

/// Finish `info` (load average and time now) and write `{"run": info, "rows": rows}` beside the
/// Markdown `report`; returns the JSON file's path. Non-finite figures (nothing measured) are
/// written as `null`.
pub fn write_json<R: Serialize>(report: &Path, mut info: RunInfo, rows: &[R]) -> Result<PathBuf> {
    info.load_average_end = load_average();
    info.finished_unix_s = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_secs()).unwrap_or(0);
    #[derive(Serialize)]
    struct Doc<'a, R> {
        run: RunInfo,
        rows: &'a [R],
    }
    let path = json_path(report);
    let text = serde_json::to_string_pretty(&Doc { run: info, rows })?;
    crate::io::write_file(&path, text + "\n")?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    #[test]
    fn shell_words_quote_what_a_shell_would_split_or_expand() {
        use super::shell_word;
        assert_eq!(shell_word("--width"), "--width");
        assert_eq!(shell_word("out/a.md"), "out/a.md");
        assert_eq!(shell_word("gpu:22.3.6,cpu"), "gpu:22.3.6,cpu");
        assert_eq!(shell_word("--scene floor --pipeline sssr"), "'--scene floor --pipeline sssr'");
        assert_eq!(shell_word("it's"), "'it'\\''s'");
        assert_eq!(shell_word("$HOME"), "'$HOME'");
        assert_eq!(shell_word(""), "''");
    }
}
