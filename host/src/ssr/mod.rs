//! Screen-space reflections on the host: inputs (G-buffers from EXR or procedural scenes), the
//! ray-traced reference, the pass runner for both pipelines (HDRP, stochastic SSR), metrics and
//! the `host ssr` command.

pub mod camera;
pub mod bench;
pub mod cli;
pub mod gbuffer;
pub mod gltf_scenes;
pub mod legend;
pub mod metrics;
pub mod passes;
pub mod pipeline;
pub mod reference;
pub mod scene;
pub mod sssr;

pub use camera::Camera;
pub use gbuffer::GBuffer;
pub use pipeline::{run_hdrp, HdrpResolve, SsrResult, SsrSettings, TraceMode};
pub use reference::{render_reference, Reference};
pub use scene::{scene, Scene, SCENES};
