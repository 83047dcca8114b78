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

/// A zeroed output buffer of `len` floats whose pages are already mapped (one write per 4 KiB
/// page): a timed CPU pass that fills it measures its kernel, not the page faults of a fresh
/// allocation, as the GPU backend's buffers exist before its timed dispatch (a 1080p pass's
/// output of 33-91 MB cost up to 25 ms of faults on two cores: the hits pass, docs/ssr.md).
pub fn touched_zeros(len: usize) -> Vec<f32> {
    let mut v = vec![0.0f32; len];
    for i in (0..len).step_by(1024) {
        // SAFETY: `i < len`; a volatile write so that the compiler keeps the store to memory it
        // knows to be zero.
        unsafe { std::ptr::write_volatile(v.as_mut_ptr().add(i), 0.0) };
    }
    v
}

/// A list entry's record that the CPU launcher of a compacted list could not store.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum ScatterError {
    #[error("list entry {entry}: slot {slot} is outside the output's {slots} records")]
    OutOfRange { entry: u32, slot: usize, slots: usize },
    #[error("list entry {entry}: slot {slot} was already written by another entry")]
    Duplicate { entry: u32, slot: usize },
}

/// Raw pointer to the output of [`scatter_records`], shared by its threads.
struct SharedOut(*mut f32);
// SAFETY: the threads write disjoint records only, each claimed first through an atomic flag.
unsafe impl Sync for SharedOut {}
unsafe impl Send for SharedOut {}

/// The CPU launcher of a pass over a compacted list of `entries` (pbrt-v4's `ParallelFor` over
/// the list, as the GPU kernel runs it): on all cores, `f(k, record)` computes entry `k`'s record
/// (`stride` floats, zeroed first) and returns the slot it belongs to, and the record is stored
/// at that slot of `out` (`stride` floats per slot), as the GPU kernel writes it there; slots no
/// entry names keep their value. Each slot is claimed once through an atomic flag before it is
/// written, so two entries naming one slot (a race on the GPU) or a slot past the end are an
/// error, not a silently overwritten or dropped record.
pub fn scatter_records(entries: usize, stride: usize, out: &mut [f32], f: impl Fn(u32, &mut [f32]) -> usize + Sync) -> Result<(), ScatterError> {
    use std::sync::atomic::{AtomicU64, Ordering};
    let slots = out.len() / stride.max(1);
    let claimed: Vec<AtomicU64> = (0..slots.div_ceil(64)).map(|_| AtomicU64::new(0)).collect();
    let base = SharedOut(out.as_mut_ptr());
    let base = &base;
    (0..entries as u32).into_par_iter().try_for_each_init(
        || vec![0.0f32; stride],
        |r, k| {
            r.fill(0.0);
            let slot = f(k, r);
            if slot >= slots {
                return Err(ScatterError::OutOfRange { entry: k, slot, slots });
            }
            let bit = 1u64 << (slot % 64);
            if claimed[slot / 64].fetch_or(bit, Ordering::Relaxed) & bit != 0 {
                return Err(ScatterError::Duplicate { entry: k, slot });
            }
            // SAFETY: `slot < slots`, so the record lies inside `out`, which is borrowed mutably
            // for this call; this entry alone set the slot's flag, so no other thread touches it.
            unsafe { std::ptr::copy_nonoverlapping(r.as_ptr(), base.0.add(slot * stride), stride) };
            Ok(())
        },
    )
}

/// The CPU launcher of a pass that updates `buf` in place: on all cores, `f(buf, i)` computes
/// invocation `i`'s writes, which `store` applies once its block of invocations is computed (as
/// on the GPU, an invocation reads only values no other invocation of the pass writes).
pub fn update_in_place<W: Send>(buf: &mut [f32], n: usize, f: impl Fn(&[f32], u32) -> W + Sync, store: impl Fn(&W, &mut [f32])) {
    const BLOCK: usize = 1 << 18;
    let mut out = Vec::with_capacity(BLOCK.min(n));
    for start in (0..n).step_by(BLOCK) {
        let end = (start + BLOCK).min(n);
        let src = &*buf;
        (start..end).into_par_iter().map(|i| f(src, i as u32)).collect_into_vec(&mut out);
        for w in &out {
            store(w, buf);
        }
    }
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

    /// The list launcher stores each record at the slot its entry names, leaves the other slots
    /// as they were, and names a repeated or out-of-range slot instead of racing or dropping it.
    #[test]
    fn scatter_stores_records_at_their_slots_and_rejects_bad_slots() {
        let entries = 5000usize;
        let mut out = vec![-1.0f32; 3 * 7001];
        // Entry k goes to slot (k * 7 + 3) % 7001 (a prime): distinct slots in a shuffled order.
        on_backend_threads(|| scatter_records(entries, 3, &mut out, |k, r| {
            r.copy_from_slice(&[k as f32, 0.5, -(k as f32)]);
            (k as usize * 7 + 3) % 7001
        }))
        .unwrap();
        let mut written = 0;
        for slot in 0..7001 {
            let rec = &out[slot * 3..slot * 3 + 3];
            match (0..entries).find(|&k| (k * 7 + 3) % 7001 == slot) {
                Some(k) => {
                    assert_eq!(rec, [k as f32, 0.5, -(k as f32)]);
                    written += 1;
                }
                None => assert_eq!(rec, [-1.0; 3], "slot {slot} named by no entry changed"),
            }
        }
        assert_eq!(written, entries);
        let mut out = vec![0.0f32; 2 * 10];
        // Which of the three entries finds the slot taken depends on the threads.
        let e = scatter_records(3, 2, &mut out, |_, _| 4).unwrap_err();
        assert!(matches!(e, ScatterError::Duplicate { slot: 4, .. }), "{e:?}");
        let e = scatter_records(3, 2, &mut out, |k, _| 8 + k as usize).unwrap_err();
        assert_eq!(e, ScatterError::OutOfRange { entry: 2, slot: 10, slots: 10 });
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
