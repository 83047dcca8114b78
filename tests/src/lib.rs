//! The CPU-vs-GPU cross-check harness, shared by every kernel's tests.
//!
//! [`gpu_backend`] opens the GPU backend or, when none can run, fails under `CI=true` and
//! otherwise says loudly that the comparison was skipped. [`compare_table`] runs a registered
//! function on both backends over the same rows and reports, per output column, the elements
//! compared, the elements whose bits differ, the largest distance in ULPs and the NaN/Inf each
//! backend produced.

use host::{Backend, DeviceChoice};
use std::fmt::Write as _;
use std::sync::OnceLock;

pub mod chi2;
pub mod inputs;
pub mod ssr;

/// Is this a CI run (`CI=true`)? There, a GPU comparison that cannot run is a failure.
pub fn in_ci() -> bool {
    std::env::var("CI").map(|v| v == "true" || v == "1").unwrap_or(false)
}

static GPU: OnceLock<Result<Backend, String>> = OnceLock::new();

/// The GPU backend shared by all tests of a binary, or `None` (after a loud notice) when no
/// GPU path can run outside CI. Under `CI=true` a missing GPU path panics.
pub fn gpu_backend() -> Option<&'static Backend> {
    let gpu = GPU.get_or_init(|| match Backend::select(DeviceChoice::Gpu) {
        Ok(b) => {
            eprintln!("[crosscheck] {}", b.describe());
            Ok(b)
        }
        Err(e) => Err(format!("{e:#}")),
    });
    match gpu {
        Ok(b) => Some(b),
        Err(e) if in_ci() => panic!("CI=true and the GPU comparison cannot run: {e}"),
        Err(e) => {
            eprintln!(
                "\n!!!!! GPU COMPARISON SKIPPED: {e}\n!!!!! (under CI=true this is a failure)\n"
            );
            None
        }
    }
}

/// Order-preserving integer image of an f32: adjacent floats differ by 1, -0 and +0 both map to 0.
pub fn ordered(x: f32) -> i64 {
    let b = x.to_bits() as i32;
    if b < 0 {
        i64::from(i32::MIN) - i64::from(b)
    } else {
        i64::from(b)
    }
}

/// Distance in units in the last place between two floats; 0 for two NaNs, u64::MAX for NaN vs number.
pub fn ulp_distance(a: f32, b: f32) -> u64 {
    match (a.is_nan(), b.is_nan()) {
        (true, true) => 0,
        (false, false) => (ordered(a) - ordered(b)).unsigned_abs(),
        _ => u64::MAX,
    }
}

/// Bits differ (two NaNs of any payload count as equal: drivers may canonicalize NaNs).
pub fn differs(a: f32, b: f32) -> bool {
    !(a.is_nan() && b.is_nan()) && a.to_bits() != b.to_bits()
}

/// Per-output-column result of a comparison.
#[derive(Clone, Debug, Default)]
pub struct ColumnReport {
    pub name: String,
    pub compared: usize,
    pub differing: usize,
    pub max_ulp: u64,
    pub cpu_nan: usize,
    pub cpu_inf: usize,
    pub gpu_nan: usize,
    pub gpu_inf: usize,
    /// The first differing row: (row, cpu value, gpu value).
    pub first_difference: Option<(usize, f32, f32)>,
}

/// Result of running one function on both backends.
#[derive(Clone, Debug)]
pub struct Comparison {
    pub function: String,
    pub adapter: String,
    pub rows: usize,
    pub inputs: Vec<f32>,
    pub in_stride: usize,
    pub columns: Vec<ColumnReport>,
}

impl Comparison {
    /// Total elements whose bits differ.
    pub fn differing(&self) -> usize {
        self.columns.iter().map(|c| c.differing).sum()
    }

    /// A table, one line per output column, with the first difference spelled out.
    pub fn report(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "{} on {} ({} rows)", self.function, self.adapter, self.rows);
        let _ = writeln!(
            s,
            "  {:<14} {:>9} {:>9} {:>8} {:>8} {:>8} {:>8} {:>8}",
            "output", "compared", "differing", "max ULP", "cpu NaN", "cpu Inf", "gpu NaN", "gpu Inf"
        );
        for c in &self.columns {
            let ulp = if c.max_ulp == u64::MAX { "NaN-vs-num".to_string() } else { c.max_ulp.to_string() };
            let _ = writeln!(
                s,
                "  {:<14} {:>9} {:>9} {:>8} {:>8} {:>8} {:>8} {:>8}",
                c.name, c.compared, c.differing, ulp, c.cpu_nan, c.cpu_inf, c.gpu_nan, c.gpu_inf
            );
            if let Some((row, a, b)) = c.first_difference {
                let x = &self.inputs[row * self.in_stride..(row + 1) * self.in_stride];
                let _ = writeln!(s, "    first difference at row {row}: inputs {x:?} -> cpu {a:e} ({:#010x}), gpu {b:e} ({:#010x})", a.to_bits(), b.to_bits());
            }
        }
        s
    }
}

/// Look a registered function up by name.
pub fn function(name: &str) -> &'static shader_kernels::eval::FunctionInfo {
    shader_kernels::eval::find(name).unwrap_or_else(|| panic!("no registered function {name}"))
}

/// Run `name` on the CPU backend and on `gpu` over `inputs` (rows of the function's input
/// columns) and compare every output element.
pub fn compare_table(gpu: &Backend, name: &str, inputs: &[f32]) -> Comparison {
    let f = function(name);
    let in_stride = f.inputs.len();
    assert_eq!(inputs.len() % in_stride, 0, "inputs must be whole rows");
    let rows = inputs.len() / in_stride;
    let (cpu, _) = Backend::Cpu.eval_table(f, inputs, rows).unwrap();
    let (gpu_out, _) = gpu.eval_table(f, inputs, rows).expect("GPU run");
    let adapter = gpu.gpu().map_or_else(|| "CPU".into(), |g| g.info.name.clone());
    let columns = compare_outputs(f.outputs, &cpu, &gpu_out);
    Comparison { function: name.into(), adapter, rows, inputs: inputs.to_vec(), in_stride, columns }
}

/// Compare two interleaved output arrays column by column.
pub fn compare_outputs(names: &[&str], cpu: &[f32], gpu: &[f32]) -> Vec<ColumnReport> {
    assert_eq!(cpu.len(), gpu.len(), "output lengths");
    let stride = names.len();
    let mut cols: Vec<ColumnReport> = names.iter().map(|n| ColumnReport { name: n.to_string(), ..Default::default() }).collect();
    for (i, (&a, &b)) in cpu.iter().zip(gpu).enumerate() {
        let c = &mut cols[i % stride];
        c.compared += 1;
        c.cpu_nan += a.is_nan() as usize;
        c.cpu_inf += a.is_infinite() as usize;
        c.gpu_nan += b.is_nan() as usize;
        c.gpu_inf += b.is_infinite() as usize;
        if differs(a, b) {
            c.differing += 1;
            c.max_ulp = c.max_ulp.max(ulp_distance(a, b));
            if c.first_difference.is_none() {
                c.first_difference = Some((i / stride, a, b));
            }
        }
    }
    cols
}

/// Assert that two interleaved arrays (`stride` values per element) are bit-identical (NaN = NaN),
/// printing how many values were compared; the panic names the first differing column and
/// element. The whole-pass form of the CPU-vs-GPU comparison.
pub fn assert_bits_equal(what: &str, stride: usize, cpu: &[f32], gpu: &[f32]) {
    assert_eq!(cpu.len(), gpu.len(), "{what}: CPU has {} values, GPU {}", cpu.len(), gpu.len());
    let cols: Vec<String> = (0..stride.max(1)).map(|k| format!("{what}[{k}]")).collect();
    let refs: Vec<&str> = cols.iter().map(|s| s.as_str()).collect();
    let rep = compare_outputs(&refs, cpu, gpu);
    let diff: usize = rep.iter().map(|c| c.differing).sum();
    let first = rep.iter().find_map(|c| c.first_difference.map(|d| (c.name.clone(), d)));
    eprintln!("{what}: {} values compared, {diff} differ", cpu.len());
    assert_eq!(diff, 0, "{what}: CPU and GPU differ; first (column, element, cpu, gpu): {first:?}");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ulp_distance_counts_representable_steps() {
        assert_eq!(ulp_distance(1.0, 1.0), 0);
        assert_eq!(ulp_distance(1.0, f32::from_bits(1.0f32.to_bits() + 3)), 3);
        assert_eq!(ulp_distance(-0.0, 0.0), 0);
        assert_eq!(ulp_distance(f32::from_bits(1), -f32::from_bits(1)), 2);
        assert_eq!(ulp_distance(f32::NAN, 1.0), u64::MAX);
        assert!(differs(-0.0, 0.0));
        assert!(!differs(f32::NAN, -f32::NAN));
    }

    #[test]
    fn compare_outputs_finds_the_difference() {
        let cpu = [1.0, 2.0, 3.0, f32::NAN];
        let gpu = [1.0, 2.0, f32::from_bits(3.0f32.to_bits() + 2), f32::NAN];
        let cols = compare_outputs(&["a", "b"], &cpu, &gpu);
        assert_eq!(cols[0].differing, 1);
        assert_eq!(cols[0].max_ulp, 2);
        assert_eq!(cols[0].first_difference.unwrap().0, 1);
        assert_eq!(cols[1].differing, 0);
        assert_eq!(cols[1].cpu_nan, 1);
    }
}
