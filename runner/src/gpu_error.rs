//! Why the GPU backend could not be created, or a GPU run failed: [`GpuError`].

/// Why no GPU backend could be created.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error(
        "no Vulkan adapter found (is a Vulkan driver installed? on a CPU-only machine install Mesa \
         lavapipe: `apt-get install -y mesa-vulkan-drivers libvulkan1`)"
    )]
    NoAdapter,
    /// No adapter's name or driver contains the name asked for (shown as asked: `HOST_ADAPTER="..."`
    /// or the quoted name); the second field lists the adapters.
    #[error("no Vulkan adapter matches {0}; available: {1}")]
    NoMatchingAdapter(String, String),
    #[error("the GPU SPIR-V cannot be used: {0}")]
    Shader(String),
    #[error("requesting a device from {0}: {1}")]
    Device(String, String),
    #[error("GPU error while running {0}: {1}")]
    Runtime(String, String),
}
