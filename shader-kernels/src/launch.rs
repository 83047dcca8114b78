//! Kernel declarations as the host launches them (pbrt-v4's `ParallelFor` with its GPU twin):
//! each entry point's name beside the per-invocation function the CPU backend calls in its
//! place, in one [`Kernel`] constant next to the `#[spirv(compute)]` entry point. The launchers
//! (`runner::Backend::run` and its list, in-place and serial forms) take the constant, so no
//! caller writes an entry-point name or chooses between the backends.
//!
//! The buffers a launch binds after its argument record travel as bytes ([`Bindings`]), in the
//! entry point's binding order: bound as they are on the GPU, read through the typed accessors
//! on the CPU, so the binding order is written once, in the declaration.

/// A compute kernel: its SPIR-V entry point and `cpu`, what the CPU backend runs for it (one of
/// [`ItemFn`], [`ListFn`], [`BlockFns`], [`SerialFn`]: the form decides how it is launched).
#[derive(Clone, Copy, Debug)]
pub struct Kernel<F> {
    /// The entry point (`module::function`).
    pub entry: &'static str,
    /// The CPU backend's per-invocation function.
    pub cpu: F,
}

/// The buffers of a launch after its argument record (binding 1 on), as bytes.
#[derive(Clone, Copy, Debug)]
pub struct Bindings<'a>(pub &'a [&'a [u8]]);

impl<'a> Bindings<'a> {
    /// Binding `k` as `f32` values.
    #[inline]
    pub fn f32(&self, k: usize) -> &'a [f32] {
        bytemuck::cast_slice(self.0[k])
    }

    /// Binding `k` as `u32` words.
    #[inline]
    pub fn u32(&self, k: usize) -> &'a [u32] {
        bytemuck::cast_slice(self.0[k])
    }

    /// Binding `k` as one record of type `T` (a parameter block).
    #[inline]
    pub fn record<T: bytemuck::Pod>(&self, k: usize) -> &'a T {
        bytemuck::from_bytes(self.0[k])
    }
}

/// One invocation per output record: `f(args, bindings, i, out)` writes invocation `i`'s record
/// (`out`: its `stride` values) of a launch with argument record `args`.
pub type ItemFn<A> = fn(&A, &Bindings<'_>, u32, &mut [f32]);

/// One invocation per entry of a compacted list: `f(args, bindings, k, record)` computes entry
/// `k`'s record into `record` (zeroed, `stride` values) and returns the slot of the output it
/// belongs to (the GPU kernel writes it there).
pub type ListFn<A> = fn(&A, &Bindings<'_>, u32, &mut [f32]) -> u32;

/// One invocation per block of a buffer updated in place (a mip of a pyramid from the one
/// below): `block(args, bindings, buf, i)` reads the buffer and computes invocation `i`'s
/// values, `store` writes them back once every invocation has read.
#[derive(Clone, Copy, Debug)]
pub struct BlockFns<A, W> {
    pub block: fn(&A, &Bindings<'_>, &[f32], u32) -> W,
    pub store: fn(&W, &mut [f32]),
}

/// Invocations writing disjoint parts of shared outputs at places they compute (list emission
/// from scanned offsets, a one-workgroup scan): `f(args, bindings, i, outputs)`; the CPU runs
/// the invocations in order on one thread.
pub type SerialFn<A> = fn(&A, &Bindings<'_>, u32, &mut [&mut [f32]]);
