//! `HOST_DIV_SQRT`: the exact build is correctly rounded on the adapter at hand (probe of
//! `runner::div_sqrt_probe`), and the build the GPU backend loaded is the one the choice and the
//! adapter call for (auto: native on llvmpipe, whose probe must then pass; exact elsewhere).

use crosscheck::{gpu_backend, in_ci};
use host::gpu::GpuContext;
use host::shaders::{load_variant, DivSqrt, DivSqrtChoice};
use host::Backend;
use host::div_sqrt_probe;

fn context(b: &Backend) -> &GpuContext {
    b.gpu().expect("gpu_backend returned the CPU backend")
}

/// The exact build's division and square root pass the probe on every adapter: this is what
/// "bit-exact on any conformant Vulkan device" rests on, checked on the device.
#[test]
fn exact_build_passes_the_probe_on_this_adapter() {
    let Some(_) = gpu_backend() else { return };
    let g = GpuContext::new(&load_variant(DivSqrt::Exact).expect("exact module")).expect("GPU context");
    let p = div_sqrt_probe::run(&g).expect("probe dispatch");
    eprintln!("exact build on {}: {} rows, {} differing", g.info.name, p.rows, p.differing);
    assert!(p.passed(), "the exact build differs from correct rounding on {} of {} rows: {:?}", p.differing, p.rows, p.first);
}

/// The loaded build follows `HOST_DIV_SQRT`, and `auto` takes the native one exactly where
/// the driver is known to round correctly and the probe agrees.
#[test]
fn loaded_build_follows_the_choice() {
    let Some(b) = gpu_backend() else { return };
    let g = context(b);
    let choice = DivSqrtChoice::from_env().expect("HOST_DIV_SQRT parses");
    let native = GpuContext::new(&load_variant(DivSqrt::Native).expect("native module")).expect("GPU context");
    let native_probe = div_sqrt_probe::run(&native).expect("probe dispatch");
    eprintln!(
        "{}: choice {choice:?}, loaded {:?} ({}); native build's probe: {} of {} rows differ",
        g.info.name, g.div_sqrt, g.div_sqrt_why, native_probe.differing, native_probe.rows
    );
    let want = match choice {
        DivSqrtChoice::Exact => DivSqrt::Exact,
        DivSqrtChoice::Native => DivSqrt::Native,
        DivSqrtChoice::Auto if div_sqrt_probe::known_correctly_rounded(&g.info) && native_probe.passed() => DivSqrt::Native,
        DivSqrtChoice::Auto => DivSqrt::Exact,
    };
    assert_eq!(g.div_sqrt, want, "{}", g.div_sqrt_why);
    assert!(!g.div_sqrt_why.is_empty(), "the description must say why this build");
    // On the machine CI runs on (lavapipe), the native build is correctly rounded: if a Mesa
    // update broke that, auto would silently fall back to the slow build; say so here.
    if g.info.driver == "llvmpipe" && in_ci() {
        assert!(native_probe.passed(), "llvmpipe's OpFDiv/Sqrt differ from correct rounding: {:?}", native_probe.first);
    }
}

/// An adapter that can declare neither denormal mode gets its behaviour measured
/// (`runner::float_controls::measure`) rather than left unspecified: llvmpipe keeps denormals;
/// a driver that flushes them all (NVIDIA's, seen on an H200) makes the CPU backend flush too.
#[test]
fn denormal_behaviour_is_declared_or_measured() {
    use host::float_controls::DenormPolicy;
    let Some(b) = gpu_backend() else { return };
    let g = context(b);
    eprintln!("{}: {}", g.info.name, g.denorm_policy.describe());
    assert_ne!(g.denorm_policy, DenormPolicy::Unspecified, "the denormal probe found neither behaviour throughout (see the warning printed at start-up)");
    if g.info.driver == "llvmpipe" {
        assert!(matches!(g.denorm_policy, DenormPolicy::Preserve | DenormPolicy::MeasuredPreserve), "llvmpipe: {:?}", g.denorm_policy);
    }
}
