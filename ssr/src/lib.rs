//! Screen-space reflections: inputs (G-buffers from EXR files, procedural scenes, or a glTF scene
//! through the path tracer), the ray-traced reference they are judged against, the pass runner
//! of both pipelines (HDRP, stochastic SSR) on the CPU or a GPU backend, and the metrics;
//! `host ssr` and `host bench ssr*` are its command line.
//!
//! ```
//! // the procedural floor scene at 48x32: its G-buffer, the HDRP pipeline on the CPU backend,
//! // and the ray-traced reference
//! let scene = ssr::scene("floor")?;
//! let gb = scene.render_gbuffer(48, 32, 0);
//! let settings = ssr::SsrSettings::default();
//! let r = ssr::run_hdrp(&runner::Backend::Cpu, &gb, &settings, ssr::TraceMode::HiZ, ssr::HdrpResolve::Approx)?;
//! assert_eq!(r.reflection.len(), 4 * 48 * 32);
//! assert!(r.reflection.chunks_exact(4).any(|px| px[3] > 0.0), "something reflects");
//! let reference = ssr::render_reference(&scene, &gb, 1.0 - settings.min_smoothness, 4);
//! assert_eq!(reference.all.len(), 3 * 48 * 32);
//! # Ok::<(), anyhow::Error>(())
//! ```

pub mod camera;
pub mod gbuffer;
pub mod gltf_scenes;
pub mod metrics;
pub mod pipeline;
pub mod reference;
pub mod render_gbuffer;
pub mod scene;
pub mod sssr;

pub use camera::Camera;
pub use gbuffer::GBuffer;
pub use pipeline::{run_hdrp, HdrpResolve, SsrResult, SsrSettings, TraceMode};
pub use reference::{render_reference, Reference};
pub use scene::{scene, Scene, SCENES};
