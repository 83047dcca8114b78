//! Every registered eval function (shader-kernels/src/eval/), generically: its columns are
//! well formed, its own entry point is in the committed SPIR-V, and CPU and GPU agree to the bit
//! on random rows from the bench's input ranges mixed with adversarial values (signed zeros,
//! denormals, 1 +- ulp, huge, NaN, Inf) in every column. A function added to the registry is
//! covered here without touching this file; the per-family files test their inputs in depth.
//!
//! Run: `cargo test --release -p crosscheck --test eval_registry -- --nocapture`.

use crosscheck::{compare_table, gpu_backend, inputs};
use host::bench_kernels::bench_inputs;
use shader_kernels::eval::functions;

#[test]
fn columns_are_unique_and_entry_points_are_in_the_module() {
    let module = host::shaders::load().expect("committed SPIR-V");
    let mut names = std::collections::HashSet::new();
    for f in functions() {
        assert!(names.insert(f.name), "{} registered twice", f.name);
        for cols in [f.inputs, f.outputs] {
            let mut seen = std::collections::HashSet::new();
            for c in cols {
                assert!(seen.insert(c), "{}: column {c} appears twice", f.name);
            }
        }
        assert!(!f.outputs.is_empty(), "{} has no outputs", f.name);
        assert!(module.manifest.entry_points.iter().any(|e| e == f.entry), "{}: entry point {} is not in the SPIR-V", f.name, f.entry);
    }
    // And no eval entry point without a registered function.
    for e in module.manifest.entry_points.iter().filter(|e| e.starts_with("eval::")) {
        assert!(functions().any(|f| f.entry == e), "entry point {e} has no registered function");
    }
}

/// The CPU backend splits the rows into chunks over the threads: every row must land where one
/// batch loop over the whole table puts it (a row count that is not a multiple of the chunk).
#[test]
fn chunked_cpu_backend_equals_one_batch_loop() {
    for f in functions() {
        let rows = 3 * 4096 + 17;
        let x = bench_inputs(f, rows);
        let mut batch = vec![0.0f32; rows * f.outputs.len()];
        (f.cpu_rows)(&x, &mut batch);
        let (backend, _) = host::Backend::Cpu.eval_table(f, &x, rows).unwrap();
        let same = batch.iter().zip(&backend).all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same && batch.len() == backend.len(), "{}: chunked CPU backend and one batch loop differ", f.name);
    }
}

#[test]
fn unknown_entry_point_is_an_error_not_zeros() {
    let Some(b) = gpu_backend() else { return };
    let g = b.gpu().expect("a GPU backend");
    let e = g
        .dispatch("eval::basic::no_such_function::kernel", &[&[0u8; 8]], &[host::gpu::OutputSpec::zeroed(4)], (1, 1, 1))
        .unwrap_err();
    assert!(e.to_string().contains("no entry point"), "{e}");
}

#[test]
fn every_function_cpu_equals_gpu_bit_for_bit() {
    let Some(gpu) = gpu_backend() else { return };
    let special = {
        let mut s = inputs::adversarial_scalars();
        s.extend([f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -f32::NAN]);
        s
    };
    let mut bad = Vec::new();
    let mut compared = 0usize;
    for f in functions() {
        let ni = f.inputs.len();
        let rows = 4096;
        let mut x = bench_inputs(f, rows);
        // Every other row: one column replaced by an adversarial value, cycling through both.
        for r in (0..rows).step_by(2) {
            let k = r / 2;
            x[r * ni + k % ni] = special[(k / ni) % special.len()];
        }
        let cmp = compare_table(gpu, f.name, &x);
        compared += cmp.columns.iter().map(|c| c.compared).sum::<usize>();
        if cmp.differing() != 0 {
            bad.push(cmp.report());
        }
    }
    eprintln!("{} functions, {compared} output values compared", functions().count());
    assert!(bad.is_empty(), "CPU and GPU differ:\n{}", bad.concat());
}
