//! A rust-gpu module handed to the driver one entry point at a time
//! ([`shader_manifest::entry_point`]): a driver reads the whole module it is given for every
//! pipeline, so the first use of an entry point costs that entry point's code, not the 45 MB
//! of every kernel. `HOST_WHOLE_MODULE=1` hands the whole module over instead (one driver module,
//! as before), to measure the difference (docs/kernels.md, "Per-entry-point modules").

use crate::gpu::{spirv_module, GpuError};
use shader_manifest::entry_point::EntryPoints;
use std::collections::HashMap;
use std::sync::Mutex;

// Two values per backend: the size difference does not matter.
#[allow(clippy::large_enum_variant)]
enum Source {
    /// One driver module holding every entry point.
    Whole(wgpu::ShaderModule),
    /// The module indexed once; each entry point's own module created on first use.
    Split { index: EntryPoints, created: Mutex<HashMap<String, wgpu::ShaderModule>> },
}

/// The main or subgroup module of the GPU backend and its entry points.
pub(crate) struct KernelModule {
    label: String,
    entry_points: Vec<String>,
    passthrough: bool,
    source: Source,
}

/// Whether `HOST_WHOLE_MODULE` asks for the whole module (set and not `0`).
pub(crate) fn whole_module_requested() -> bool {
    std::env::var_os("HOST_WHOLE_MODULE").is_some_and(|v| v != "0")
}

impl KernelModule {
    /// Index `words` (the module with entry points `entry_points`), or with
    /// [`whole_module_requested`] create its one driver module now.
    ///
    /// # Safety
    /// As [`spirv_module`]: with `passthrough` the words reach the driver unvalidated.
    pub(crate) unsafe fn new(device: &wgpu::Device, label: &str, words: Vec<u32>, entry_points: Vec<String>, passthrough: bool) -> Result<Self, GpuError> {
        let source = if whole_module_requested() {
            // SAFETY: the caller's contract.
            Source::Whole(unsafe { spirv_module(device, label, &words, &entry_points, passthrough)? })
        } else {
            let index = EntryPoints::new(words).map_err(|e| GpuError::Shader(format!("{label}: {e}")))?;
            if let Some(missing) = entry_points.iter().find(|e| !index.names().any(|n| n == e.as_str())) {
                return Err(GpuError::Shader(format!("{label}: its manifest lists entry point {missing:?}, which the SPIR-V lacks")));
            }
            Source::Split { index, created: Mutex::new(HashMap::new()) }
        };
        Ok(KernelModule { label: label.to_string(), entry_points, passthrough, source })
    }

    /// The entry points (from the manifest).
    pub(crate) fn entry_points(&self) -> &[String] {
        &self.entry_points
    }

    pub(crate) fn has(&self, entry: &str) -> bool {
        self.entry_points.iter().any(|n| n == entry)
    }

    /// "one module per entry point" or "whole module", for [`crate::gpu::GpuContext::describe`].
    pub(crate) fn describe(&self) -> &'static str {
        match self.source {
            Source::Whole(_) => "whole module per pipeline (HOST_WHOLE_MODULE)",
            Source::Split { .. } => "one module per entry point",
        }
    }

    /// The driver module holding `entry` (created on first use when split).
    pub(crate) fn module(&self, device: &wgpu::Device, entry: &str) -> Result<wgpu::ShaderModule, GpuError> {
        match &self.source {
            Source::Whole(m) => Ok(m.clone()),
            Source::Split { index, created } => {
                if let Some(m) = created.lock().unwrap().get(entry) {
                    return Ok(m.clone());
                }
                let words = index.module(entry).map_err(|e| GpuError::Shader(format!("{}: {e}", self.label)))?;
                let label = format!("{} {entry}", self.label);
                // SAFETY: the words are a word-for-word subset of the module `new` was given
                // (its contract): the entry point, every global and the functions it calls.
                let m = unsafe { spirv_module(device, &label, &words, &[entry.to_string()], self.passthrough)? };
                created.lock().unwrap().insert(entry.to_string(), m.clone());
                Ok(m)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use shader_manifest::entry_point::EntryPoints;

    /// Every entry point of the three committed modules cuts into a module with that entry point
    /// alone, a small part of the whole (the point of cutting).
    #[test]
    fn every_entry_point_cuts_into_a_small_module() {
        use crate::shaders::{load_subgroup, load_variant, DivSqrt};
        for m in [load_variant(DivSqrt::Exact).unwrap(), load_variant(DivSqrt::Native).unwrap(), load_subgroup().unwrap()] {
            let t0 = std::time::Instant::now();
            let index = EntryPoints::new(m.words.clone()).unwrap();
            let t_index = t0.elapsed().as_secs_f64();
            let t0 = std::time::Instant::now();
            let mut sizes = Vec::new();
            for e in &m.manifest.entry_points {
                let words = index.module(e).unwrap();
                let names = shader_manifest::uniform_bindings(&words).unwrap();
                assert_eq!(names.len(), 1, "{e}: one entry point");
                assert_eq!(&names[0].0, e);
                sizes.push(words.len());
            }
            sizes.sort_unstable();
            let (max, median) = (sizes[sizes.len() - 1], sizes[sizes.len() / 2]);
            eprintln!(
                "{} words: index {t_index:.3} s, {} cuts {:.3} s, median {median} max {max} words",
                m.words.len(),
                sizes.len(),
                t0.elapsed().as_secs_f64()
            );
            assert!(max < m.words.len() / 2 || sizes.len() < 3, "largest cut {max} of {} words", m.words.len());
        }
    }
}
