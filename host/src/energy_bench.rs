//! `host energy bench`: error of the precomputed E / E' / E_avg tables against the f64
//! quadrature reference ([`crate::energy_ref`]) vs resolution, sample count and sequence, with the
//! precompute time on the CPU and GPU backends; the saving of the roughness threshold. Writes
//! docs/energy-bench.md and a PNG (error vs time).

use crate::energy::{self, BenchArgs, Compensation, Sequence, TableSpec, Tables};
use crate::energy_ref::{self, Quadrature};
use crate::{Backend, DeviceChoice};
use anyhow::{Context, Result};
use shader_core::energy as core_energy;
use std::fmt::Write as _;
use std::time::Instant;

/// Max and RMS absolute error of `t` against the reference.
#[derive(Clone, Copy, Debug)]
pub struct TableError {
    pub e_max: f64,
    pub e_rms: f64,
    pub ep_max: f64,
    pub avg_max: f64,
}

/// Errors of `t` against (E, E', E_avg) references on the same grid.
pub fn table_error(t: &Tables, r: &(Vec<f64>, Vec<f64>, Vec<f64>)) -> TableError {
    let max = |a: &[f32], b: &[f64]| a.iter().zip(b).map(|(x, y)| (f64::from(*x) - y).abs()).fold(0.0, f64::max);
    let rms = (t.e.iter().zip(&r.0).map(|(x, y)| (f64::from(*x) - y).powi(2)).sum::<f64>() / t.e.len() as f64).sqrt();
    TableError { e_max: max(&t.e, &r.0), e_rms: rms, ep_max: max(&t.e_prime, &r.1), avg_max: max(&t.e_avg, &r.2) }
}

struct Row {
    backend: &'static str,
    seq: Sequence,
    res: u32,
    samples: u32,
    err: TableError,
    ms: f64,
    source: String,
    same_as_cpu: Option<bool>,
}

pub fn run(a: &BenchArgs) -> Result<()> {
    let gpu = match a.device {
        DeviceChoice::Cpu => None,
        d => match Backend::select(d) {
            Ok(b) if b.is_gpu() => Some(b),
            Ok(_) => None,
            Err(e) if d == DeviceChoice::Auto => {
                eprintln!("notice: no GPU backend ({e:#}); timing the CPU backend only");
                None
            }
            Err(e) => return Err(e),
        },
    };
    let cpu = Backend::Cpu;
    eprintln!("{}", cpu.describe());
    if let Some(g) = &gpu {
        eprintln!("{}", g.describe());
    }
    let q = Quadrature::default();
    let mut rows = Vec::new();
    let mut refs = Vec::new();
    for &res in &a.resolutions {
        let t0 = Instant::now();
        let r = energy_ref::tables(res as usize, res as usize, res as usize, &q);
        eprintln!("f64 reference {res}x{res}: {:.1} s", t0.elapsed().as_secs_f64());
        for seq in [Sequence::Pcg, Sequence::Sobol] {
            for &samples in &a.samples {
                let spec = TableSpec { n_mu: res, n_r: res, n_avg: res, samples, avg_samples: 4 * samples, seq, ..TableSpec::default() };
                let (tc, times) = energy::precompute(&cpu, &spec, false)?;
                let err = table_error(&tc, &r);
                rows.push(Row {
                    backend: "cpu",
                    seq,
                    res,
                    samples,
                    err,
                    ms: (times.table.seconds + times.avg.seconds) * 1e3,
                    source: times.table.source.to_string(),
                    same_as_cpu: None,
                });
                if let Some(g) = &gpu {
                    let (tg, times) = energy::precompute(g, &spec, false)?;
                    rows.push(Row {
                        backend: "gpu",
                        seq,
                        res,
                        samples,
                        err: table_error(&tg, &r),
                        ms: (times.table.seconds + times.avg.seconds) * 1e3,
                        source: times.table.source.to_string(),
                        same_as_cpu: Some(tg == tc),
                    });
                }
                eprintln!("{res}x{res} {} {samples}: E max err {:.2e}", seq.label(), err.e_max);
            }
        }
        refs.push((res, r));
    }
    // Threshold saving: the per-shading-point compensation terms (LUT lookups and formulas, what
    // a renderer evaluates per pixel) over 2^20 pregenerated (mu, roughness) points sorted by
    // roughness (a coherent material per region, as in a frame), with the threshold vs without it
    // (CPU, one thread, interleaved, best of 15).
    let spec = TableSpec::default();
    let (tables, _) = energy::precompute(&cpu, &spec, false)?;
    let lut = tables.lut_buffer();
    let mut saving = String::new();
    for mode in [Compensation::KullaConty, Compensation::Turquin] {
        for (lo, hi) in [(0.0f32, core_energy::COMPENSATION_MIN_ROUGHNESS), (0.0, 0.05), (0.0, 1.0)] {
            let n = 1u32 << 20;
            let unit = |k: u32| (shader_core::rng::pcg_hash(k) >> 8) as f32 / 16_777_216.0;
            let mut pts: Vec<(f32, f32)> = (0..n).map(|k| (unit(k), lo + (hi - lo) * unit(k ^ 0x5bd1_e995))).collect();
            pts.sort_by(|a, b| a.1.total_cmp(&b.1));
            let once = |min_roughness: f32| -> f64 {
                let t0 = Instant::now();
                let mut sink = 0.0f32;
                for &(mu, r) in &pts {
                    let m = core_energy::FurnaceMaterial { base: 1.0, metallic: 1.0, roughness: r, mode: mode.id(), min_roughness };
                    let c = core_energy::compensation_terms(&lut, &m, std::hint::black_box(mu));
                    sink += c.turquin_m + c.kc_m;
                }
                std::hint::black_box(sink);
                t0.elapsed().as_secs_f64() * 1e9 / f64::from(n)
            };
            // Interleaved, best of 15 each, so load from other processes hits both alike.
            let (mut t_all, mut t_thr) = (f64::INFINITY, f64::INFINITY);
            for _ in 0..15 {
                t_all = t_all.min(once(0.0));
                t_thr = t_thr.min(once(core_energy::COMPENSATION_MIN_ROUGHNESS));
            }
            writeln!(saving, "| {} | [{lo}, {hi}) | {t_all:.2} | {t_thr:.2} | {:.1} % |", mode.label(), 100.0 * (t_all - t_thr) / t_all)?;
        }
    }
    let report = write_report(a, &rows, &saving, gpu.as_ref())?;
    eprintln!("wrote {}", a.report.display());
    eprintln!("wrote {}", report.display());
    Ok(())
}

fn write_report(a: &BenchArgs, rows: &[Row], saving: &str, gpu: Option<&Backend>) -> Result<std::path::PathBuf> {
    let mut md = String::new();
    writeln!(md, "# Energy tables: error vs resolution, samples and precompute time\n")?;
    writeln!(md, "Generated by `cargo run --release -p host -- energy bench` (see docs/energy.md). Errors are")?;
    writeln!(md, "absolute, against the f64 Gauss-Legendre reference (`host/src/energy_ref.rs`) at the same cell")?;
    writeln!(md, "centers; E_avg uses 4x the samples. Time = E/E' table + E_avg, summed over dispatches")?;
    writeln!(md, "(chunks of 1024 samples).\n")?;
    writeln!(md, "- CPU: {}", Backend::Cpu.describe())?;
    match gpu {
        Some(g) => writeln!(md, "- GPU: {}\n", g.describe())?,
        None => writeln!(md, "- GPU: not available in this run\n")?,
    }
    writeln!(md, "| backend | sequence | resolution | samples | max abs err E | RMS err E | max abs err E' | max abs err E_avg | time ms | time source | bits = CPU |")?;
    writeln!(md, "|---|---|---|---|---|---|---|---|---|---|---|")?;
    for r in rows {
        writeln!(
            md,
            "| {} | {} | {} | {} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.1} | {} | {} |",
            r.backend,
            r.seq.label(),
            r.res,
            r.samples,
            r.err.e_max,
            r.err.e_rms,
            r.err.ep_max,
            r.err.avg_max,
            r.ms,
            r.source,
            match r.same_as_cpu {
                Some(true) => "yes",
                Some(false) => "NO",
                None => "-",
            }
        )?;
    }
    writeln!(md, "\n## Roughness threshold\n")?;
    writeln!(md, "Cost of the per-shading-point compensation terms (`shader_core::energy::compensation_terms`: LUT")?;
    writeln!(md, "lookups and formulas; metal) for 2^20 points, mu uniform, roughness uniform in the range and sorted")?;
    writeln!(md, "(coherent materials), one CPU thread, the two variants interleaved, best of 15 each: compensation at every roughness vs skipped below roughness {} (`COMPENSATION_MIN_ROUGHNESS`).\n", core_energy::COMPENSATION_MIN_ROUGHNESS)?;
    writeln!(md, "| mode | roughness range | all ns/point | threshold ns/point | saving |\n|---|---|---|---|---|\n{saving}")?;
    crate::io::create_parent_dir(&a.report)?;
    std::fs::write(&a.report, &md).with_context(|| format!("writing {}", a.report.display()))?;
    let png = a.report.with_extension("png");
    plot(&png, rows)?;
    Ok(png)
}

fn plot(path: &std::path::Path, rows: &[Row]) -> Result<()> {
    use plotters::prelude::*;
    static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    fn e<E: std::fmt::Display>(x: E) -> anyhow::Error {
        anyhow::anyhow!("{x}")
    }
    let (w, h) = (1200u32, 800u32);
    let mut buf = vec![255u8; (w * h * 3) as usize];
    let tmin = rows.iter().map(|r| r.ms).fold(f64::INFINITY, f64::min).max(1e-3);
    let tmax = rows.iter().map(|r| r.ms).fold(0.0, f64::max).max(tmin * 10.0);
    let emin = rows.iter().map(|r| r.err.e_max).fold(f64::INFINITY, f64::min).max(1e-7);
    let emax = rows.iter().map(|r| r.err.e_max).fold(0.0, f64::max).max(emin * 10.0);
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(e)?;
        let mut chart = ChartBuilder::on(&root)
            .caption("GGX E table: max abs error vs precompute time (solid dot = Sobol, ring = PCG)", ("sans-serif", 24))
            .margin(20)
            .x_label_area_size(60)
            .y_label_area_size(80)
            .build_cartesian_2d((tmin * 0.8..tmax * 1.25).log_scale(), (emin * 0.8..emax * 1.25).log_scale())
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc("precompute time (ms)")
            .y_desc("max |E - E_ref|")
            .label_style(("sans-serif", 16))
            .axis_desc_style(("sans-serif", 18))
            .x_label_formatter(&|x| format!("{x:.0e}"))
            .y_label_formatter(&|y| format!("{y:.0e}"))
            .draw()
            .map_err(e)?;
        let colors = [RGBColor(31, 119, 180), RGBColor(214, 39, 40), RGBColor(44, 160, 44), RGBColor(148, 103, 189), RGBColor(140, 86, 75), RGBColor(23, 190, 207)];
        let mut keys: Vec<(&str, Sequence, u32)> = Vec::new();
        for r in rows {
            if !keys.contains(&(r.backend, r.seq, r.res)) {
                keys.push((r.backend, r.seq, r.res));
            }
        }
        let mut ress: Vec<u32> = rows.iter().map(|r| r.res).collect();
        ress.dedup();
        for (backend, seq, res) in keys {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.backend == backend && r.seq == seq && r.res == res)
                .map(|r| (r.ms.max(tmin), r.err.e_max.max(emin)))
                .collect();
            let ci = ress.iter().position(|&x| x == res).unwrap_or(0) * 2 + usize::from(backend == "gpu");
            let color = colors[ci % colors.len()];
            chart
                .draw_series(std::iter::once(PathElement::new(pts.clone(), color.stroke_width(2))))
                .map_err(e)?
                .label(format!("{backend} {} {res}x{res}", seq.label()))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
            let style = if seq == Sequence::Sobol { color.filled() } else { color.stroke_width(2) };
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 5, style))).map_err(e)?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .draw()
            .map_err(e)?;
        root.present().map_err(e)?;
    }
    let img = image::RgbImage::from_raw(w, h, buf).context("plot buffer")?;
    crate::io::create_parent_dir(path)?;
    img.save(path).with_context(|| format!("writing {}", path.display()))
}
