//! f64 references for the shading kernels, written straight from the papers and sharing no code
//! with them: the microfacet functions ([`microfacet`]) and the energy-table quadrature
//! ([`energy`]); and the test suites' input generator ([`splitmix`]). Pure math (no wgpu, no I/O), so property tests and benchmarks can use them
//! without compiling a GPU stack: `cargo tree -p reference` lists rayon and libm only.

pub mod energy;
pub mod microfacet;
pub mod splitmix;
