//! `host bench ssr-passes`: the per-pass times of SSR frames on several backends in one process, the
//! table docs/ssr.md quotes for lavapipe against the CPU backend. Every configuration (the options
//! of one `host ssr` run) runs on every backend once per round, in turn, after one untimed warm-up
//! round (llvmpipe compiles shader variants during the first command buffers, Mesa's disk cache
//! serves later runs); each pass's fastest round is reported. Each backend's reflection and
//! specular term are compared bit for bit with the first backend's. Markdown + JSON.

use super::cli::{load_input, run_frame, steps_limit, Input, RunArgs};
use crate::report::{write_json, RunInfo};
use crate::Backend;
use anyhow::{bail, Context, Result};
use clap::{CommandFactory, FromArgMatches};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;

/// The configurations docs/ssr.md's per-pass tables time on the built-in floor (cornell's
/// G-buffer is added with `--config "--input ..."`, see docs/ssr.md).
const DEFAULT_CONFIGS: [&str; 3] = ["--scene floor --pipeline sssr", "--scene floor --pipeline hdrp", "--scene floor --pipeline hdrp --resolve 3x3"];

#[derive(Clone, Debug, clap::Args)]
pub struct PassesArgs {
    /// One configuration: the options of a `host ssr` run (scene or `--input` G-buffer, pipeline,
    /// resolve, ...), quoted; repeat for several. `--width`/`--height` below and
    /// `--reference-samples 0` are added (a G-buffer input keeps its own size).
    #[arg(long = "config", allow_hyphen_values = true, default_values_t = DEFAULT_CONFIGS.map(String::from))]
    pub configs: Vec<String>,
    /// Frame width of the built-in scenes.
    #[arg(long, default_value_t = 1920, value_parser = crate::cli_args::pixels)]
    pub width: usize,
    /// Frame height of the built-in scenes.
    #[arg(long, default_value_t = 1080, value_parser = crate::cli_args::pixels)]
    pub height: usize,
    /// Backends, comma-separated, in the order of the table's cells: `cpu`, `gpu` (the adapter
    /// `--device gpu` takes) or `gpu:NAME` (the adapter whose name or driver contains NAME, as
    /// HOST_ADAPTER matches). With VK_ICD_FILENAMES listing the manifests of both the system's
    /// lavapipe and the one `cargo xtask lavapipe` fetches, `gpu:22.3.6,gpu:25.0.7,cpu` compares
    /// the two drivers and the CPU backend (docs/ssr.md gives the command).
    #[arg(long, default_value = "gpu,cpu")]
    pub devices: String,
    /// Timed rounds after the warm-up round (at least 1).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..))]
    pub rounds: u32,
    /// Markdown report; the JSON (every round of every pass) is written beside it.
    #[arg(long, default_value = "out/ssr-passes.md")]
    pub report: PathBuf,
    /// The JSON of an earlier run (e.g. of the binary before a change): the report adds a table
    /// of this run's fastest times over that run's, per pass, configuration and backend (matched
    /// by their labels; "-" where the earlier run has no such cell).
    #[arg(long)]
    pub baseline: Option<PathBuf>,
}

/// (configuration, backend, pass) -> fastest ms of an earlier run's JSON.
type Baseline = BTreeMap<(String, String, String), f64>;

fn load_baseline(path: &std::path::Path) -> Result<Baseline> {
    let text = std::fs::read_to_string(path).with_context(|| format!("--baseline {}", path.display()))?;
    let doc: serde_json::Value = serde_json::from_str(&text).with_context(|| format!("--baseline {}: not JSON", path.display()))?;
    let rows = doc["rows"].as_array().with_context(|| format!("--baseline {}: no \"rows\" array (not a `host bench ssr-passes` JSON)", path.display()))?;
    let mut out = Baseline::new();
    for (i, r) in rows.iter().enumerate() {
        let field = |k: &str| r[k].as_str().map(String::from).with_context(|| format!("--baseline {}: row {i} has no {k:?} (not a `host bench ssr-passes` JSON)", path.display()));
        let key = (field("config")?, field("device")?, field("pass")?);
        let ms = r["fastest_ms"].as_f64().filter(|v| v.is_finite() && *v > 0.0);
        let ms = ms.with_context(|| format!("--baseline {}: row {i}: \"fastest_ms\" is not a positive number", path.display()))?;
        out.insert(key, ms);
    }
    if out.is_empty() {
        bail!("--baseline {}: no rows", path.display());
    }
    Ok(out)
}

/// A `host ssr` command line of its own, to parse one configuration.
#[derive(clap::Parser)]
#[command(no_binary_name = true, name = "--config")]
struct ConfigLine {
    #[command(flatten)]
    run: RunArgs,
}

/// One configuration, parsed and checked as `host ssr` would.
struct Config {
    label: String,
    args: RunArgs,
    input: Input,
    /// Its energy tables (`--lut`, or the default tables computed on the CPU backend: bit-identical
    /// on every backend), one set for every backend of the table.
    lut: Vec<f32>,
}

fn parse_config(line: &str, width: usize, height: usize) -> Result<Config> {
    let mut words: Vec<String> = line.split_whitespace().map(String::from).collect();
    if words.iter().any(|w| w == "--width" || w == "--height" || w == "--reference-samples" || w == "--device") {
        bail!("--config {line:?}: --width, --height, --reference-samples and --device are set by `host bench ssr-passes` (its --width/--height/--devices)");
    }
    words.extend(["--width".into(), width.to_string(), "--height".into(), height.to_string(), "--reference-samples".into(), "0".into()]);
    let matches = ConfigLine::command().try_get_matches_from(&words).with_context(|| format!("--config {line:?}"))?;
    let args = ConfigLine::from_arg_matches(&matches).with_context(|| format!("--config {line:?}"))?.run;
    args.validate(&|id| matches.value_source(id) == Some(clap::parser::ValueSource::CommandLine)).with_context(|| format!("--config {line:?}"))?;
    let input = load_input(&args).with_context(|| format!("--config {line:?}"))?;
    steps_limit(&args, input.gbuffer.width, input.gbuffer.height).with_context(|| format!("--config {line:?}"))?;
    let lut = crate::energy::tables_cached(&Backend::Cpu, &args.lut).with_context(|| format!("--config {line:?}"))?.lut_buffer();
    Ok(Config { label: line.trim().to_string(), args, input, lut })
}

/// The fastest of some rounds.
fn fastest(rounds: &[f64]) -> f64 {
    rounds.iter().copied().fold(f64::INFINITY, f64::min)
}

/// One backend of the table.
struct Device {
    label: String,
    backend: Backend,
}

fn parse_devices(list: &str) -> Result<Vec<Device>> {
    let mut out = Vec::new();
    for word in list.split(',').map(str::trim) {
        let backend = match word {
            "cpu" => Backend::Cpu,
            "gpu" => Backend::select(crate::DeviceChoice::Gpu)?,
            _ => match word.strip_prefix("gpu:") {
                Some(name) if !name.is_empty() => Backend::gpu_named(name).with_context(|| format!("--devices: {word}"))?,
                _ => bail!("--devices: {word:?} is not cpu, gpu or gpu:NAME"),
            },
        };
        out.push(Device { label: word.to_string(), backend });
    }
    if out.is_empty() {
        bail!("--devices names no backend");
    }
    Ok(out)
}

/// One (configuration, backend, pass) of the JSON: every timed round, and the fastest.
#[derive(serde::Serialize)]
struct Row {
    config: String,
    device: String,
    adapter: String,
    pass: String,
    /// Milliseconds per timed round (a pass that runs several times in a frame: their sum).
    rounds_ms: Vec<f64>,
    fastest_ms: f64,
    /// Reflection and specular term bit-identical to the first backend's (in every round).
    same_bits_as_first: bool,
}

/// Pass name -> milliseconds of one frame (passes that run several times summed), the frame
/// total under "frame", and the bits of the reflection and specular term.
fn one_frame(d: &Device, c: &Config) -> Result<(BTreeMap<String, f64>, Vec<String>, Vec<u32>)> {
    let (result, specular) = run_frame(&d.backend, &c.input, &c.args, &c.lut).with_context(|| format!("{} on {}", c.label, d.label))?;
    let mut order = Vec::new();
    let mut ms = BTreeMap::new();
    for t in &result.times {
        if !ms.contains_key(&t.name) {
            order.push(t.name.clone());
        }
        *ms.entry(t.name.clone()).or_insert(0.0) += t.seconds * 1e3;
    }
    let total: f64 = result.times.iter().map(|t| t.seconds * 1e3).sum();
    ms.insert("frame".into(), total);
    let bits = result.reflection.iter().chain(&specular).map(|v| v.to_bits()).collect();
    Ok((ms, order, bits))
}

pub fn run(a: &PassesArgs) -> Result<()> {
    crate::io::prepare_output(&a.report)?;
    let baseline = a.baseline.as_deref().map(load_baseline).transpose()?;
    let configs: Vec<Config> = a.configs.iter().map(|l| parse_config(l, a.width, a.height)).collect::<Result<_>>()?;
    let devices = parse_devices(&a.devices)?;
    for d in &devices {
        eprintln!("{}: {}", d.label, d.backend.describe());
    }
    let gpu_names: Vec<String> = devices.iter().filter(|d| d.backend.is_gpu()).map(|d| format!("{}: {}", d.label, d.backend.describe())).collect();
    let info = RunInfo::start(if gpu_names.is_empty() { None } else { Some(gpu_names.join("; ")) });
    // times[config][device][pass] = per-round ms; order[config] = pass names in frame order.
    let mut times: Vec<Vec<BTreeMap<String, Vec<f64>>>> = vec![vec![BTreeMap::new(); devices.len()]; configs.len()];
    let mut order: Vec<Vec<String>> = vec![Vec::new(); configs.len()];
    let mut same: Vec<Vec<bool>> = vec![vec![true; devices.len()]; configs.len()];
    for (ci, c) in configs.iter().enumerate() {
        let mut first_bits: Option<Vec<u32>> = None;
        for round in 0..=a.rounds {
            for (di, d) in devices.iter().enumerate() {
                let (ms, names, bits) = one_frame(d, c)?;
                match &first_bits {
                    None => first_bits = Some(bits),
                    Some(b) => same[ci][di] &= *b == bits,
                }
                for n in names {
                    if !order[ci].contains(&n) {
                        order[ci].push(n);
                    }
                }
                if round > 0 {
                    for (k, v) in ms {
                        times[ci][di].entry(k).or_default().push(v);
                    }
                }
            }
        }
        let frame = |di: usize| times[ci][di].get("frame").map(|v| fastest(v)).unwrap_or(f64::NAN);
        eprintln!("{}: frame {}", c.label, (0..devices.len()).map(|di| format!("{} {:.1} ms", devices[di].label, frame(di))).collect::<Vec<_>>().join(", "));
    }
    let mut rows = Vec::new();
    for (ci, c) in configs.iter().enumerate() {
        for (di, d) in devices.iter().enumerate() {
            for (pass, v) in &times[ci][di] {
                rows.push(Row {
                    config: c.label.clone(),
                    device: d.label.clone(),
                    adapter: d.backend.describe(),
                    pass: pass.clone(),
                    rounds_ms: v.clone(),
                    fastest_ms: fastest(v),
                    same_bits_as_first: same[ci][di],
                });
            }
        }
    }
    let md = markdown(a, &info, &configs, &devices, &order, &times, &same, baseline.as_ref());
    crate::io::write_file(&a.report, md)?;
    let json = write_json(&a.report, info, &rows)?;
    eprintln!("wrote {} and {}", a.report.display(), json.display());
    if let Some((ci, di)) = (0..configs.len()).flat_map(|ci| (0..devices.len()).map(move |di| (ci, di))).find(|&(ci, di)| !same[ci][di]) {
        bail!("{} on {}: the reflection or specular term differs from {}'s (the report says where)", configs[ci].label, devices[di].label, devices[0].label);
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn markdown(
    a: &PassesArgs,
    info: &RunInfo,
    configs: &[Config],
    devices: &[Device],
    order: &[Vec<String>],
    times: &[Vec<BTreeMap<String, Vec<f64>>>],
    same: &[Vec<bool>],
    baseline: Option<&Baseline>,
) -> String {
    let best = |ci: usize, di: usize, p: &str| times[ci][di].get(p).map(|r| fastest(r));
    let mut s = String::new();
    let _ = writeln!(s, "# SSR per-pass times\n");
    let _ = writeln!(s, "Command: `{}`  ", info.command);
    let _ = writeln!(s, "CPU: {} ({} threads); load average at start {:?}  ", info.cpu, info.cpu_threads, info.load_average_start.unwrap_or_default());
    for d in devices {
        let _ = writeln!(s, "`{}`: {}  ", d.label, d.backend.describe());
    }
    let _ = writeln!(
        s,
        "\nms per pass (GPU: timestamp queries; CPU: wall clock), the fastest of {} rounds after a warm-up round, each round running every configuration on every backend in turn; cells: {}.\n",
        a.rounds,
        devices.iter().map(|d| format!("`{}`", d.label)).collect::<Vec<_>>().join(" / ")
    );
    let _ = writeln!(s, "| # | configuration (`host ssr` options) | size |");
    let _ = writeln!(s, "| --- | --- | --- |");
    for (ci, c) in configs.iter().enumerate() {
        let _ = writeln!(s, "| {} | `{}` | {}x{} |", ci + 1, c.label, c.input.gbuffer.width, c.input.gbuffer.height);
    }
    let mut passes: Vec<String> = Vec::new();
    for o in order {
        for n in o {
            if !passes.contains(n) {
                passes.push(n.clone());
            }
        }
    }
    passes.push("frame".into());
    s.push('\n');
    pass_table(&mut s, configs.len(), &passes, |ci, p| {
        let v: Vec<Option<f64>> = (0..devices.len()).map(|di| best(ci, di, p)).collect();
        if v.iter().all(Option::is_none) {
            "-".into()
        } else {
            v.iter().map(|x| x.map(|m| format!("{m:.1}")).unwrap_or_else(|| "-".into())).collect::<Vec<_>>().join(" / ")
        }
    });
    let bits: Vec<String> = (0..configs.len())
        .map(|ci| if same[ci].iter().all(|&b| b) { "same".into() } else { "DIFFERENT".to_string() })
        .collect();
    let _ = writeln!(s, "| reflection + specular bits | {} |", bits.join(" | "));
    for (ri, r) in devices.iter().enumerate().filter(|(_, d)| !d.backend.is_gpu()) {
        let lines: Vec<String> = (0..devices.len())
            .filter(|&di| di != ri)
            .map(|di| against(configs.len(), &passes, &best, di, ri).describe(&devices[di].label))
            .collect();
        if !lines.is_empty() {
            let _ = writeln!(s, "\nAgainst `{}` (fastest times; configurations by number):\n", r.label);
            for l in lines {
                let _ = writeln!(s, "* {l}");
            }
        }
    }
    if let (Some(b), Some(path)) = (baseline, &a.baseline) {
        let _ = writeln!(s, "\nThis run's fastest time over the baseline's (`{}`), same cells:\n", path.display());
        pass_table(&mut s, configs.len(), &passes, |ci, p| {
            (0..devices.len())
                .map(|di| match (best(ci, di, p), b.get(&(configs[ci].label.clone(), devices[di].label.clone(), p.to_string()))) {
                    (Some(now), Some(then)) => format!("{:.2}x", now / then),
                    _ => "-".into(),
                })
                .collect::<Vec<_>>()
                .join(" / ")
        });
    }
    s
}

/// How one backend's times compare with a reference backend's, cell by cell.
#[derive(Debug, PartialEq)]
struct Against {
    /// Pass cells (configuration, pass; frames not counted) both backends ran.
    cells: usize,
    /// Of those, the ones where this backend was faster.
    faster: usize,
    /// Frames both ran, and the ones where this backend was faster.
    frames: usize,
    frames_faster: usize,
    /// The cells where it was not faster: configuration index, pass, time over the reference's.
    slower: Vec<(usize, String, f64)>,
}

impl Against {
    fn describe(&self, label: &str) -> String {
        let slower = if self.slower.is_empty() {
            String::new()
        } else {
            let list: Vec<String> = self.slower.iter().map(|(ci, p, x)| format!("{} {p} {x:.2}x", ci + 1)).collect();
            format!("; not faster: {}", list.join(", "))
        };
        format!("`{label}` faster on {} of {} pass cells and {} of {} frames{slower}", self.faster, self.cells, self.frames_faster, self.frames)
    }
}

/// Backend `di` against backend `ri` over every (configuration, pass) cell both have a time for.
fn against(configs: usize, passes: &[String], best: &impl Fn(usize, usize, &str) -> Option<f64>, di: usize, ri: usize) -> Against {
    let mut a = Against { cells: 0, faster: 0, frames: 0, frames_faster: 0, slower: Vec::new() };
    for ci in 0..configs {
        for p in passes {
            let (Some(t), Some(r)) = (best(ci, di, p), best(ci, ri, p)) else { continue };
            let faster = t < r;
            if p == "frame" {
                a.frames += 1;
                a.frames_faster += faster as usize;
            } else {
                a.cells += 1;
                a.faster += faster as usize;
                if !faster {
                    a.slower.push((ci, p.clone(), t / r));
                }
            }
        }
    }
    a
}

/// A table with a row per pass (the frame total in bold) and a column per configuration, each
/// cell `cell(configuration index, pass)`.
fn pass_table(s: &mut String, configs: usize, passes: &[String], cell: impl Fn(usize, &str) -> String) {
    let _ = writeln!(s, "| pass | {} |", (1..=configs).map(|i| i.to_string()).collect::<Vec<_>>().join(" | "));
    let _ = writeln!(s, "| --- |{}", " --- |".repeat(configs));
    for p in passes {
        let cells: Vec<String> = (0..configs).map(|ci| cell(ci, p)).collect();
        let name = if p == "frame" { "**frame**".to_string() } else { p.clone() };
        let _ = writeln!(s, "| {name} | {} |", cells.join(" | "));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn against_counts_faster_cells_and_lists_the_others() {
        let passes: Vec<String> = ["trace", "hits", "frame"].iter().map(|p| p.to_string()).collect();
        // best(config, device, pass): device 0 = reference; device 1 faster on the trace of both
        // configurations, slower on config 0's hits, equal on config 1's; no hits for config 2.
        let best = |ci: usize, di: usize, p: &str| -> Option<f64> {
            match (ci, di, p) {
                (2, _, "hits") => None,
                (_, 0, "trace") => Some(100.0),
                (_, 1, "trace") => Some(50.0),
                (0, 0, "hits") => Some(10.0),
                (0, 1, "hits") => Some(12.5),
                (_, _, "hits") => Some(10.0),
                (_, 0, "frame") => Some(110.0),
                (_, 1, "frame") => Some(62.5),
                _ => None,
            }
        };
        let a = against(3, &passes, &best, 1, 0);
        assert_eq!(
            a,
            Against { cells: 5, faster: 3, frames: 3, frames_faster: 3, slower: vec![(0, "hits".into(), 1.25), (1, "hits".into(), 1.0)] }
        );
        assert_eq!(a.describe("gpu"), "`gpu` faster on 3 of 5 pass cells and 3 of 3 frames; not faster: 1 hits 1.25x, 2 hits 1.00x");
        let all = against(1, &passes, &|_: usize, di: usize, _: &str| Some(if di == 1 { 1.0 } else { 2.0 }), 1, 0);
        assert_eq!(all.describe("gpu"), "`gpu` faster on 2 of 2 pass cells and 1 of 1 frames");
    }
}
