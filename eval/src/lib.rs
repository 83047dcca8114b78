//! Run a registered function (`shader_kernels::eval`) over a table of rows read from CSV or
//! `.npy`, on the CPU backend or a GPU; `host eval` is its command line.
//!
//! CSV: a header naming the function's input columns (any order; a missing, unknown or repeated
//! column is an error, so a typo cannot silently fall back to a default). The output CSV repeats
//! the input columns and appends the outputs; floats are written in the shortest form that reads
//! back to the same bits. Parsing and formatting run on all cores.
//!
//! NumPy `.npy` (chosen by the file extension): a 2-D C- or Fortran-order array of shape
//! (rows, inputs) with dtype `<f4` (or `<f8`, rounded to the nearest f32), columns in the order
//! `host eval --list` gives; the output `.npy` holds the outputs only, shape (rows, outputs),
//! dtype `<f4`.
//!
//! Any other extension (`.npz`, `.txt`, ...) is refused for input and output, rather than read
//! or written as CSV under a name that says otherwise. Errors number the data rows from 1 in
//! both formats (the CSV header is not counted).
//!
//! ```
//! // the GGX NDF at two microfacet normals, on the CPU backend
//! let f = eval::find_function("ggx_d")?;
//! let table = eval::parse_csv(f, "wm_x,wm_y,wm_z,alpha_x,alpha_y\n0,0,1,0.5,0.5\n0.6,0,0.8,0.5,0.5\n".as_bytes(), false)?;
//! let (d, _timing) = eval::run(&runner::Backend::Cpu, f, &table)?;
//! // D(n) = 1 / (pi alpha^2) at the normal, and less away from it
//! assert!((d[0] - 1.0 / (std::f32::consts::PI * 0.25)).abs() < 1e-6 && d[1] < d[0]);
//! # Ok::<(), anyhow::Error>(())
//! ```

pub mod npy;

use runner::{Backend, Timing};
use anyhow::{anyhow, bail, Context, Result};
use rayon::prelude::*;
use shader_kernels::eval::{functions, FunctionInfo};
use std::io::{Read, Write};
use std::path::Path;

/// Look up a function by name; the error lists the known names.
pub fn find_function(name: &str) -> Result<&'static FunctionInfo> {
    shader_kernels::eval::find(name).ok_or_else(|| {
        let names: Vec<&str> = functions().map(|f| f.name).collect();
        anyhow!("unknown function {name:?}; known functions: {}", names.join(", "))
    })
}

/// The `--list` text: every function with its columns.
pub fn list() -> String {
    let mut s = String::new();
    for f in functions() {
        s.push_str(&format!(
            "{:<28} {}\n{:<28} in:  {}\n{:<28} out: {}\n",
            f.name,
            f.summary,
            "",
            f.inputs.join(","),
            "",
            f.outputs.join(",")
        ));
    }
    s
}

/// The `--list --json` document: an array of {name, summary, group, inputs, outputs, entry_point}.
pub fn list_json() -> String {
    let v: Vec<serde_json::Value> = functions()
        .map(|f| {
            serde_json::json!({
                "name": f.name,
                "summary": f.summary,
                "group": f.group,
                "inputs": f.inputs,
                "outputs": f.outputs,
                "entry_point": f.entry,
            })
        })
        .collect();
    serde_json::to_string_pretty(&v).expect("serializing the function list")
}

/// A parsed input table in the function's column order.
#[derive(Debug)]
pub struct Table {
    pub rows: usize,
    pub values: Vec<f32>,
}

/// The table formats `host eval` reads and writes, chosen by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Csv,
    Npy,
}

impl Format {
    /// `.npy` is NumPy; `.csv`, no extension or standard input/output (`-`) is CSV; any other
    /// extension is an error naming the two formats.
    pub fn of(path: &Path) -> Result<Format> {
        match path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).as_deref() {
            Some("npy") => Ok(Format::Npy),
            Some("csv") | None => Ok(Format::Csv),
            Some(e) => bail!("{}: host eval reads and writes .csv (text) and .npy (NumPy, float32) tables only, not .{e}", path.display()),
        }
    }
}

/// Reject NaN and infinite inputs unless `allow_nonfinite`, naming the row (data rows from 1)
/// and column.
fn check_finite(f: &FunctionInfo, values: &[f32], allow_nonfinite: bool) -> Result<()> {
    if allow_nonfinite {
        return Ok(());
    }
    let ni = f.inputs.len().max(1);
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        bail!(
            "row {}, column {}: {} is not finite (pass --allow-nonfinite to evaluate it anyway)",
            i / ni + 1,
            f.inputs[i % ni],
            values[i]
        );
    }
    Ok(())
}

/// Parse CSV text for `f`. NaN and infinite values are rejected unless `allow_nonfinite`.
/// Errors number the data rows from 1 (the header is not counted), as for `.npy`.
pub fn parse_csv(f: &FunctionInfo, mut reader: impl Read, allow_nonfinite: bool) -> Result<Table> {
    let mut text = String::new();
    reader.read_to_string(&mut text).context("reading the CSV (is it UTF-8 text?)")?;
    let (header_line, body) = match text.find('\n') {
        Some(i) => (&text[..i], &text[i + 1..]),
        None => (text.as_str(), ""),
    };
    let header: Vec<&str> = header_line.trim_end_matches('\r').split(',').map(|h| h.trim().trim_matches('"')).collect();
    if header.len() == 1 && header[0].is_empty() {
        bail!("the CSV is empty: expected a header with the columns {}", f.inputs.join(","));
    }
    for (k, h) in header.iter().enumerate() {
        if let Some(j) = header[..k].iter().position(|p| p == h) {
            bail!("input CSV names column {h:?} twice (columns {} and {})", j + 1, k + 1);
        }
        if !f.inputs.contains(h) {
            bail!("input CSV column {h:?} is not an input of {} (inputs: {})", f.name, f.inputs.join(","));
        }
    }
    let mut index = Vec::with_capacity(f.inputs.len());
    for col in f.inputs {
        let i = header.iter().position(|h| h == col).ok_or_else(|| {
            anyhow!(
                "input CSV has no column {col:?}; {} needs columns {} (found: {})",
                f.name,
                f.inputs.join(","),
                header.join(",")
            )
        })?;
        index.push(i);
    }
    if body.contains('"') {
        bail!("quoted CSV fields are not supported: every field must be a plain number");
    }
    let lines: Vec<&str> = body.lines().collect();
    // Trailing blank lines are allowed; a blank line inside the table is an error below.
    let n_lines = lines.iter().rposition(|l| !l.trim().is_empty()).map_or(0, |i| i + 1);
    let ni = f.inputs.len();
    let mut values = vec![0.0f32; n_lines * ni];
    values
        .par_chunks_mut(ni.max(1))
        .zip(lines[..n_lines].par_iter())
        .enumerate()
        .try_for_each(|(r, (row, line))| -> Result<()> {
            let fields: Vec<&str> = line.trim_end_matches('\r').split(',').collect();
            if fields.len() != header.len() {
                bail!("row {}: {} fields, the header has {}", r + 1, fields.len(), header.len());
            }
            for ((slot, &i), col) in row.iter_mut().zip(&index).zip(f.inputs) {
                let t = fields[i].trim();
                *slot = t.parse().map_err(|_| anyhow!("row {}, column {col}: {t:?} is not a number", r + 1))?;
            }
            Ok(())
        })?;
    check_finite(f, &values, allow_nonfinite)?;
    Ok(Table { rows: n_lines, values })
}

/// Write inputs and outputs as CSV (rows formatted on all cores, written in order).
pub fn write_csv(f: &FunctionInfo, table: &Table, outputs: &[f32], mut writer: impl Write) -> Result<()> {
    let (ni, no) = (f.inputs.len(), f.outputs.len());
    let header: Vec<&str> = f.inputs.iter().chain(f.outputs).copied().collect();
    writeln!(writer, "{}", header.join(","))?;
    const CHUNK: usize = 8192;
    let chunks: Vec<String> = (0..table.rows.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut s = String::with_capacity(CHUNK * (ni + no) * 12);
            for r in c * CHUNK..((c + 1) * CHUNK).min(table.rows) {
                let mut first = true;
                for v in table.values[r * ni..(r + 1) * ni].iter().chain(&outputs[r * no..(r + 1) * no]) {
                    if !first {
                        s.push(',');
                    }
                    first = false;
                    use std::fmt::Write as _;
                    let _ = write!(s, "{v}");
                }
                s.push('\n');
            }
            s
        })
        .collect();
    for c in chunks {
        writer.write_all(c.as_bytes())?;
    }
    writer.flush()?;
    Ok(())
}

/// Parse a NumPy `.npy` array of shape (rows, inputs) for `f`.
pub fn parse_npy(f: &FunctionInfo, bytes: &[u8], allow_nonfinite: bool) -> Result<Table> {
    let npy = crate::npy::read(bytes)?;
    let ni = f.inputs.len();
    let (rows, cols) = match npy.shape.as_slice() {
        [r, c] => (*r, *c),
        [r] if ni == 1 => (*r, 1),
        s => bail!("the array has shape {s:?}; {} needs shape (rows, {ni}) with columns {}", f.name, f.inputs.join(",")),
    };
    if cols != ni {
        bail!("the array has {cols} columns; {} needs {ni}: {}", f.name, f.inputs.join(","));
    }
    check_finite(f, &npy.values, allow_nonfinite)?;
    Ok(Table { rows, values: npy.values })
}

/// Read the input table from `path` ('-' = standard input, CSV), by extension.
pub fn read_table(f: &FunctionInfo, path: &Path, allow_nonfinite: bool) -> Result<Table> {
    if path.as_os_str() == "-" {
        return parse_csv(f, std::io::stdin().lock(), allow_nonfinite).context("in standard input");
    }
    let format = Format::of(path)?;
    let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
    match format {
        Format::Npy => parse_npy(f, &bytes, allow_nonfinite),
        Format::Csv => parse_csv(f, bytes.as_slice(), allow_nonfinite),
    }
    .with_context(|| format!("in {}", path.display()))
}

/// Write the result to `path` ('-' = standard output, CSV), by extension: written to a
/// temporary file beside it and renamed, so a failed write leaves an existing file untouched.
pub fn write_table(f: &FunctionInfo, table: &Table, outputs: &[f32], path: &Path) -> Result<()> {
    if path.as_os_str() == "-" {
        return write_csv(f, table, outputs, std::io::stdout().lock());
    }
    let format = Format::of(path)?;
    fileio::write_atomic(path, |tmp| {
        let file = std::fs::File::create(tmp)?;
        let mut w = std::io::BufWriter::new(file);
        match format {
            Format::Npy => crate::npy::write(&mut w, &[table.rows, f.outputs.len()], outputs)?,
            Format::Csv => write_csv(f, table, outputs, &mut w)?,
        }
        w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        Ok(())
    })
}

/// Refuse NaN outputs unless `allow_nonfinite`: the functions return NaN exactly for inputs
/// outside their domain (a negative or NaN roughness, a zero vector, a cosine outside [-1, 1]:
/// docs/microfacet.md, "invalid-input behaviour"), so the first such row is named with its
/// inputs. Infinite outputs are results (some functions are exactly +inf at a bound).
pub fn check_outputs(f: &FunctionInfo, table: &Table, outputs: &[f32], allow_nonfinite: bool) -> Result<()> {
    if allow_nonfinite {
        return Ok(());
    }
    let (ni, no) = (f.inputs.len(), f.outputs.len().max(1));
    if let Some(i) = outputs.iter().position(|v| v.is_nan()) {
        let r = i / no;
        let inputs: Vec<String> = f.inputs.iter().zip(&table.values[r * ni..(r + 1) * ni]).map(|(c, v)| format!("{c} = {v}")).collect();
        bail!(
            "row {}: {} returns NaN for {} (inputs outside its domain; {} of {} rows so; pass --allow-nonfinite to write NaN rows)",
            r + 1,
            f.name,
            inputs.join(", "),
            outputs.chunks(no).filter(|row| row.iter().any(|v| v.is_nan())).count(),
            table.rows
        );
    }
    Ok(())
}

/// Evaluate `f` over `table` on `backend`.
pub fn run(backend: &Backend, f: &FunctionInfo, table: &Table) -> Result<(Vec<f32>, Timing)> {
    backend.eval_table(f, &table.values, table.rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_are_matched_by_name_and_checked() {
        let f = find_function("ggx_d").unwrap();
        let t = parse_csv(f, "alpha_y,alpha_x,wm_z,wm_y,wm_x\n0.5,0.25,1,0,0\n".as_bytes(), false).unwrap();
        assert_eq!(t.values, vec![0.0, 0.0, 1.0, 0.25, 0.5]);
        let e = parse_csv(f, "wm_x,wm_y,wm_z,alpha_x\n0,0,1,0.5\n".as_bytes(), false).unwrap_err();
        assert!(format!("{e:#}").contains("no column \"alpha_y\""), "{e:#}");
        let e = parse_csv(f, "wm_x,wm_y,wm_z,alpha_x,alpha_y,alhpa\n0,0,1,0.5,0.5,1\n".as_bytes(), false).unwrap_err();
        assert!(format!("{e:#}").contains("\"alhpa\" is not an input"), "{e:#}");
        let e = parse_csv(f, "wm_x,wm_y,wm_z,alpha_x,alpha_y\n0,0,1,x,0.5\n".as_bytes(), false).unwrap_err();
        assert!(format!("{e:#}").contains("row 1, column alpha_x"), "{e:#}");
        let e = parse_csv(f, "wm_x,wm_y,wm_z,alpha_x,alpha_y\n0,0,1,0.5,0.5\n0,0,NaN,0.5,0.5\n".as_bytes(), false).unwrap_err();
        assert!(format!("{e:#}").contains("row 2, column wm_z"), "{e:#}");
        assert!(parse_csv(f, "wm_x,wm_y,wm_z,alpha_x,alpha_y\n0,0,NaN,0.5,0.5\n".as_bytes(), true).is_ok());
        assert!(find_function("ggx").unwrap_err().to_string().contains("ggx_d"));
    }

    #[test]
    fn repeated_columns_short_rows_and_empty_input_are_named() {
        let f = find_function("ggx_d").unwrap();
        let e = parse_csv(f, "wm_x,wm_y,wm_z,alpha_x,alpha_y,wm_x\n0,0,1,0.5,0.5,1\n".as_bytes(), false).unwrap_err();
        assert!(format!("{e:#}").contains("\"wm_x\" twice (columns 1 and 6)"), "{e:#}");
        let e = parse_csv(f, "wm_x,wm_y,wm_z,alpha_x,alpha_y\n0,0,1,0.5\n".as_bytes(), false).unwrap_err();
        assert!(format!("{e:#}").contains("row 1: 4 fields, the header has 5"), "{e:#}");
        let e = parse_csv(f, "".as_bytes(), false).unwrap_err();
        assert!(format!("{e:#}").contains("empty"), "{e:#}");
        let t = parse_csv(f, "wm_x,wm_y,wm_z,alpha_x,alpha_y\n".as_bytes(), false).unwrap();
        assert_eq!(t.rows, 0);
        let e = parse_csv(f, "wm_x,wm_y,wm_z,alpha_x,alpha_y\n0,0,1,0.5,0.5\n\n0,0,1,0.5,0.5\n".as_bytes(), false).unwrap_err();
        assert!(format!("{e:#}").contains("row 2"), "{e:#}");
    }

    #[test]
    fn csv_and_npy_number_data_rows_alike_and_other_formats_are_refused() {
        let f = find_function("ggx_d").unwrap();
        let e = parse_csv(f, "wm_x,wm_y,wm_z,alpha_x,alpha_y\n0,0,1,0.5,0.5\n0,0,1,inf,0.5\n".as_bytes(), false).unwrap_err();
        let mut bytes = Vec::new();
        crate::npy::write(&mut bytes, &[2, 5], &[0.0, 0.0, 1.0, 0.5, 0.5, 0.0, 0.0, 1.0, f32::INFINITY, 0.5]).unwrap();
        let n = parse_npy(f, &bytes, false).unwrap_err();
        assert!(format!("{e:#}").contains("row 2, column alpha_x"), "{e:#}");
        assert!(format!("{n:#}").contains("row 2, column alpha_x"), "{n:#}");
        assert_eq!(Format::of(Path::new("a.CSV")).unwrap(), Format::Csv);
        assert_eq!(Format::of(Path::new("a")).unwrap(), Format::Csv);
        assert_eq!(Format::of(Path::new("a.npy")).unwrap(), Format::Npy);
        let e = Format::of(Path::new("out.npz")).unwrap_err();
        assert!(format!("{e:#}").contains("not .npz"), "{e:#}");
    }

    #[test]
    fn written_floats_read_back_exactly() {
        let f = find_function("ggx_d").unwrap();
        let t = Table { rows: 1, values: vec![0.1, 0.2, 0.97, 0.3, 0.3] };
        let mut buf = Vec::new();
        write_csv(f, &t, &[1.0 / 3.0], &mut buf).unwrap();
        let text = String::from_utf8(buf).unwrap();
        let last: f32 = text.lines().nth(1).unwrap().split(',').next_back().unwrap().parse().unwrap();
        assert_eq!(last.to_bits(), (1.0f32 / 3.0).to_bits());
    }

    #[test]
    fn npy_shape_and_columns_are_checked() {
        let f = find_function("ggx_d").unwrap();
        let mut bytes = Vec::new();
        crate::npy::write(&mut bytes, &[2, 5], &[0.0, 0.0, 1.0, 0.5, 0.5, 0.6, 0.0, 0.8, 0.3, 0.3]).unwrap();
        let t = parse_npy(f, &bytes, false).unwrap();
        assert_eq!((t.rows, t.values[8]), (2, 0.3));
        let mut bytes = Vec::new();
        crate::npy::write(&mut bytes, &[2, 4], &[0.0; 8]).unwrap();
        let e = parse_npy(f, &bytes, false).unwrap_err();
        assert!(format!("{e:#}").contains("4 columns; ggx_d needs 5"), "{e:#}");
    }
}
