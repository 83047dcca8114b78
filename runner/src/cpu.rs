//! The CPU backend: the kernels' per-invocation functions, called natively for every
//! invocation, spread over all cores with rayon.

use rayon::prelude::*;
use shader_kernels::eval::FunctionInfo;

/// Rows per work item of the CPU batch loops: large enough that the per-chunk call is noise,
/// small enough to balance the cores.
const ROWS_PER_CHUNK: usize = 4096;

/// Evaluate `f` over `rows` rows with its batch loop, chunks of rows spread over all cores.
pub fn eval_table(f: &FunctionInfo, input: &[f32], rows: usize) -> Vec<f32> {
    let (ni, no) = (f.inputs.len(), f.outputs.len());
    assert_eq!(input.len(), rows * ni, "{}: input size", f.name);
    let mut out = vec![0.0f32; rows * no];
    if no == 0 || rows == 0 {
        return out;
    }
    out.par_chunks_mut(ROWS_PER_CHUNK * no).enumerate().for_each(|(k, y)| {
        let r0 = k * ROWS_PER_CHUNK;
        let n = y.len() / no;
        (f.cpu_rows)(&input[r0 * ni..(r0 + n) * ni], y)
    });
    out
}

/// Number of worker threads the CPU backend uses.
pub fn threads() -> usize {
    rayon::current_num_threads()
}
