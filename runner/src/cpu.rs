//! The CPU backend: the kernels' per-invocation functions, called natively for every
//! invocation, spread over all cores with rayon.

use rayon::prelude::*;
use shader_kernels::eval::FunctionInfo;

/// Rows per work item of the CPU batch loops: large enough that the per-chunk call is noise,
/// small enough to balance the cores.
const ROWS_PER_CHUNK: usize = 4096;

/// Run `op` on a thread of rayon's global pool, the CPU backend's threads, whose floating-point
/// controls follow the GPU's denormal behaviour (`float_controls::DenormPolicy::apply_to_cpu`:
/// FTZ/DAZ on a device that flushes). A parallel iterator with one item runs on the calling
/// thread, which may not have those controls: the CPU launchers go through here.
pub fn on_backend_threads<R: Send>(op: impl FnOnce() -> R + Send) -> R {
    if rayon::current_thread_index().is_some() {
        op()
    } else {
        // `rayon::scope` runs its body on a worker thread of the current (here: global) pool.
        rayon::scope(|_| op())
    }
}

/// Evaluate `f` over `rows` rows with its batch loop, chunks of rows spread over all cores.
pub fn eval_table(f: &FunctionInfo, input: &[f32], rows: usize) -> Vec<f32> {
    let mut out = vec![0.0f32; rows * f.outputs.len()];
    eval_table_into(f, input, rows, &mut out);
    out
}

/// [`eval_table`] into `out` (`rows * f.outputs.len()` values, every one overwritten): repeated
/// evaluations reuse one buffer instead of allocating and page-faulting a new one each time,
/// which for the cheapest functions costs as much as the evaluation and serialises the cores.
pub fn eval_table_into(f: &FunctionInfo, input: &[f32], rows: usize, out: &mut [f32]) {
    let (ni, no) = (f.inputs.len(), f.outputs.len());
    assert_eq!(input.len(), rows * ni, "{}: input size", f.name);
    assert_eq!(out.len(), rows * no, "{}: output size", f.name);
    if no == 0 || rows == 0 {
        return;
    }
    on_backend_threads(|| {
        out.par_chunks_mut(ROWS_PER_CHUNK * no).enumerate().for_each(|(k, y)| {
            let r0 = k * ROWS_PER_CHUNK;
            let n = y.len() / no;
            (f.cpu_rows)(&input[r0 * ni..(r0 + n) * ni], y)
        })
    });
}

/// Number of worker threads the CPU backend uses.
pub fn threads() -> usize {
    rayon::current_num_threads()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The CPU launchers' work runs on the pool's threads (whose FTZ/DAZ follow the GPU), also
    /// when called from another thread and when the loop has a single item.
    #[test]
    fn launchers_run_on_the_pool_threads() {
        assert!(rayon::current_thread_index().is_none(), "the test harness's thread is not a pool thread");
        assert!(on_backend_threads(rayon::current_thread_index).is_some());
        let one_item = on_backend_threads(|| {
            let mut seen = vec![None; 1];
            seen.par_iter_mut().for_each(|s| *s = Some(rayon::current_thread_index()));
            seen[0].flatten()
        });
        assert!(one_item.is_some());
        // Nested: already on a pool thread, the work stays there.
        assert!(rayon::scope(|_| on_backend_threads(|| rayon::current_thread_index().is_some())));
    }

    /// Every function's batch loop writes every output: evaluating into a buffer full of a stale
    /// NaN pattern gives the bits of a fresh evaluation, for chunk-sized and ragged row counts.
    #[test]
    fn eval_into_overwrites_every_output() {
        for f in shader_kernels::eval::functions() {
            for rows in [1usize, ROWS_PER_CHUNK + 37] {
                let ni = f.inputs.len();
                let input: Vec<f32> = (0..rows * ni).map(|k| 0.05 + 0.9 * (((k * 7919) % 1000) as f32 / 1000.0)).collect();
                let fresh = eval_table(f, &input, rows);
                let mut reused = vec![f32::from_bits(0x7fc0_dead); rows * f.outputs.len()];
                eval_table_into(f, &input, rows, &mut reused);
                let differ = fresh.iter().zip(&reused).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
                assert_eq!(differ, 0, "{}: {differ} outputs of {rows} rows not overwritten", f.name);
            }
        }
    }
}
