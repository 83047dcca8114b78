//! The CPU backend: the kernels' per-invocation functions, called natively for every
//! invocation, spread over all cores with rayon.

use rayon::prelude::*;

/// Evaluate registered function `id` over `rows` rows (see `shader_kernels::table`).
pub fn eval_table(id: u32, input: &[f32], in_stride: usize, out_stride: usize, rows: usize) -> Vec<f32> {
    assert_eq!(input.len(), rows * in_stride, "input size");
    let mut out = vec![0.0f32; rows * out_stride];
    if out_stride == 0 {
        return out;
    }
    out.par_chunks_mut(out_stride)
        .with_min_len(256)
        .enumerate()
        .for_each(|(row, y)| shader_kernels::table::eval_row(id, input, row * in_stride, y, 0));
    out
}

/// Number of worker threads the CPU backend uses.
pub fn threads() -> usize {
    rayon::current_num_threads()
}
