//! Shading math shared bit-for-bit by the CPU backend and the rust-gpu SPIR-V kernels.
#![no_std]
