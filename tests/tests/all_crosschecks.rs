//! Every test file of this crate in one binary, for the real-GPU check (`cargo xtask gpu-bundle`):
//! each test binary embeds the SPIR-V modules (about 9 MiB compressed), so separate binaries would
//! not fit the device tool's 64 MiB transfer. Not run by `cargo test` (`test = false` in
//! Cargo.toml: the files run as their own binaries there); build it with
//! `cargo test --release -p crosscheck --test all_crosschecks --no-run`. Test names keep their file
//! as a prefix (`eval_registry::...`), so a filter selects one file.

#[path = "bxdf_crosscheck.rs"]
mod bxdf_crosscheck;
#[path = "bxdf_properties.rs"]
mod bxdf_properties;
#[path = "bxdf_stress.rs"]
mod bxdf_stress;
#[path = "div_sqrt_probe.rs"]
mod div_sqrt_probe;
#[path = "energy_crosscheck.rs"]
mod energy_crosscheck;
#[path = "energy_properties.rs"]
mod energy_properties;
#[path = "eval_registry.rs"]
mod eval_registry;
#[path = "foundation.rs"]
mod foundation;
#[path = "math_crosscheck.rs"]
mod math_crosscheck;
#[path = "microfacet_crosscheck.rs"]
mod microfacet_crosscheck;
#[path = "microfacet_properties.rs"]
mod microfacet_properties;
#[path = "microfacet_stress.rs"]
mod microfacet_stress;
#[path = "reciprocity.rs"]
mod reciprocity;
#[path = "render_crosscheck.rs"]
mod render_crosscheck;
#[path = "ssr_1080p.rs"]
mod ssr_1080p;
#[path = "ssr_fringes.rs"]
mod ssr_fringes;
#[path = "ssr_formulas.rs"]
mod ssr_formulas;
#[path = "ssr_gltf.rs"]
mod ssr_gltf;
#[path = "ssr_hdrp.rs"]
mod ssr_hdrp;
#[path = "ssr_hits.rs"]
mod ssr_hits;
#[path = "ssr_inputs.rs"]
mod ssr_inputs;
#[path = "ssr_specular.rs"]
mod ssr_specular;
#[path = "ssr_sssr.rs"]
mod ssr_sssr;
#[path = "user_shader.rs"]
mod user_shader;
#[path = "vndf_chi2.rs"]
mod vndf_chi2;
#[path = "vndf_crosscheck.rs"]
mod vndf_crosscheck;
