//! `host eval`: run a registered function over a CSV table.
//!
//! The input CSV has a header naming the function's input columns (any order, extra columns are
//! an error so a typo cannot silently fall back to a default). The output CSV repeats the input
//! columns and appends the outputs. Floats are written in the shortest form that reads back to
//! the same bits.

use crate::backend::Backend;
use crate::timing::Timing;
use anyhow::{anyhow, bail, Context, Result};
use shader_kernels::table::{FunctionInfo, FUNCTIONS};
use std::io::{Read, Write};

/// Look up a function by name; the error lists the known names.
pub fn find_function(name: &str) -> Result<&'static FunctionInfo> {
    FUNCTIONS.iter().find(|f| f.name == name).ok_or_else(|| {
        let names: Vec<&str> = FUNCTIONS.iter().map(|f| f.name).collect();
        anyhow!("unknown function {name:?}; known functions: {}", names.join(", "))
    })
}

/// The `--list` text: every function with its columns.
pub fn list() -> String {
    let mut s = String::new();
    for f in FUNCTIONS {
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

/// A parsed input table in the function's column order.
#[derive(Debug)]
pub struct Table {
    pub rows: usize,
    pub values: Vec<f32>,
}

/// Parse CSV text for `f`. NaN and infinite values are rejected unless `allow_nonfinite`.
pub fn parse_csv(f: &FunctionInfo, reader: impl Read, allow_nonfinite: bool) -> Result<Table> {
    let mut rdr = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(reader);
    let header = rdr.headers().context("reading the CSV header")?.clone();
    let mut index = Vec::with_capacity(f.inputs.len());
    for col in f.inputs {
        let i = header.iter().position(|h| h == *col).ok_or_else(|| {
            anyhow!(
                "input CSV has no column {col:?}; {} needs columns {} (found: {})",
                f.name,
                f.inputs.join(","),
                header.iter().collect::<Vec<_>>().join(",")
            )
        })?;
        index.push(i);
    }
    for h in header.iter() {
        if !f.inputs.contains(&h) {
            bail!("input CSV column {h:?} is not an input of {} (inputs: {})", f.name, f.inputs.join(","));
        }
    }
    let mut values = Vec::new();
    let mut rows = 0;
    for (r, rec) in rdr.records().enumerate() {
        let rec = rec.with_context(|| format!("reading CSV row {}", r + 2))?;
        for (&i, col) in index.iter().zip(f.inputs) {
            let text = rec.get(i).unwrap_or("");
            let v: f32 = text
                .parse()
                .map_err(|_| anyhow!("row {}, column {col}: {text:?} is not a number", r + 2))?;
            if !v.is_finite() && !allow_nonfinite {
                bail!("row {}, column {col}: {text} is not finite (pass --allow-nonfinite to evaluate it anyway)", r + 2);
            }
            values.push(v);
        }
        rows += 1;
    }
    Ok(Table { rows, values })
}

/// Write inputs and outputs as CSV.
pub fn write_csv(f: &FunctionInfo, table: &Table, outputs: &[f32], writer: impl Write) -> Result<()> {
    let mut w = csv::Writer::from_writer(writer);
    let header: Vec<&str> = f.inputs.iter().chain(f.outputs).copied().collect();
    w.write_record(&header)?;
    let (ni, no) = (f.inputs.len(), f.outputs.len());
    for r in 0..table.rows {
        let rec: Vec<String> = table.values[r * ni..(r + 1) * ni]
            .iter()
            .chain(&outputs[r * no..(r + 1) * no])
            .map(|v| v.to_string())
            .collect();
        w.write_record(&rec)?;
    }
    w.flush()?;
    Ok(())
}

/// Evaluate `f` over `table` on `backend`.
pub fn run(backend: &Backend, f: &FunctionInfo, table: &Table) -> Result<(Vec<f32>, Timing)> {
    backend.eval_table(f.id, &table.values, f.inputs.len(), f.outputs.len(), table.rows)
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
        assert!(format!("{e:#}").contains("row 2, column alpha_x"), "{e:#}");
        let e = parse_csv(f, "wm_x,wm_y,wm_z,alpha_x,alpha_y\n0,0,NaN,0.5,0.5\n".as_bytes(), false).unwrap_err();
        assert!(format!("{e:#}").contains("not finite"), "{e:#}");
        assert!(parse_csv(f, "wm_x,wm_y,wm_z,alpha_x,alpha_y\n0,0,NaN,0.5,0.5\n".as_bytes(), true).is_ok());
        assert!(find_function("ggx").unwrap_err().to_string().contains("ggx_d"));
    }

    #[test]
    fn written_floats_read_back_exactly() {
        let f = find_function("ggx_d").unwrap();
        let t = Table { rows: 1, values: vec![0.1, 0.2, 0.97, 0.3, 0.3] };
        let mut buf = Vec::new();
        write_csv(f, &t, &[1.0 / 3.0], &mut buf).unwrap();
        let text = String::from_utf8(buf).unwrap();
        let last: f32 = text.lines().nth(1).unwrap().split(',').last().unwrap().parse().unwrap();
        assert_eq!(last.to_bits(), (1.0f32 / 3.0).to_bits());
    }
}
