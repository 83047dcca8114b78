//! A rust-gpu module handed to the driver one entry point at a time
//! ([`shader_manifest::entry_point`]): a driver reads the whole module it is given for every
//! pipeline, so the first use of an entry point costs that entry point's code, not the 45 MB
//! of every kernel. `HOST_WHOLE_MODULE=1` hands the whole module over instead (one driver module,
//! as before), to measure the difference (docs/kernels.md, "Per-entry-point modules"). Each driver
//! module is created by [`spirv_module`] (passed through unchanged, or translated by naga).

use crate::gpu_error::GpuError;
use shader_manifest::entry_point::EntryPoints;
use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::Mutex;

// Two values per backend: the size difference does not matter.
#[allow(clippy::large_enum_variant)]
enum Source {
    /// The whole module, handed to the driver as one module holding every entry point.
    Whole(Vec<u32>),
    /// The module indexed once; each entry point's own module cut on first use.
    Split(EntryPoints),
}

/// The main or subgroup module of the GPU backend and its entry points.
pub(crate) struct KernelModule {
    label: String,
    entry_points: Vec<String>,
    passthrough: bool,
    source: Source,
    /// Driver modules created, by (entry point, specialization values) (the whole module's by
    /// ("", values): it serves every entry point), and whether the specialization changed it.
    created: Mutex<HashMap<(String, Vec<u32>), (wgpu::ShaderModule, bool)>>,
}

/// Whether `HOST_WHOLE_MODULE` asks for the whole module (set and not `0`).
pub(crate) fn whole_module_requested() -> bool {
    std::env::var_os("HOST_WHOLE_MODULE").is_some_and(|v| v != "0")
}

impl KernelModule {
    /// Index `words` (the module with entry points `entry_points`), or with
    /// [`whole_module_requested`] keep them whole; driver modules are created on first use.
    ///
    /// # Safety
    /// As [`spirv_module`]: with `passthrough` the words reach the driver unvalidated.
    pub(crate) unsafe fn new(label: &str, words: Vec<u32>, entry_points: Vec<String>, passthrough: bool) -> Result<Self, GpuError> {
        let source = if whole_module_requested() {
            // Created at the first use of each specialization (`module`).
            Source::Whole(words)
        } else {
            let index = EntryPoints::new(words).map_err(|e| GpuError::Shader(format!("{label}: {e}")))?;
            if let Some(missing) = entry_points.iter().find(|e| !index.names().any(|n| n == e.as_str())) {
                return Err(GpuError::Shader(format!("{label}: its manifest lists entry point {missing:?}, which the SPIR-V lacks")));
            }
            Source::Split(index)
        };
        Ok(KernelModule { label: label.to_string(), entry_points, passthrough, source, created: Mutex::new(HashMap::new()) })
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
            Source::Split(_) => "one module per entry point",
        }
    }

    /// The driver module holding `entry` specialized with `spec` (its specialization constants
    /// 0..`spec.len()`, [`shader_manifest::spec_constant`]; created on first use), and whether the
    /// entry point declares any of them (if not, `spec` changed nothing and the module is the
    /// one every `spec` gets).
    pub(crate) fn module(&self, device: &wgpu::Device, entry: &str, spec: &[u32]) -> Result<(wgpu::ShaderModule, bool), GpuError> {
        // The whole module serves every entry point: its key names none.
        let name = match self.source {
            Source::Whole(_) => "",
            Source::Split(_) => entry,
        };
        let key = (name.to_string(), spec.to_vec());
        if let Some(m) = self.created.lock().unwrap().get(&key) {
            return Ok(m.clone());
        }
        let words = match &self.source {
            Source::Whole(words) => words.clone(),
            Source::Split(index) => index.module(entry).map_err(|e| GpuError::Shader(format!("{}: {e}", self.label)))?,
        };
        let (words, set) = shader_manifest::spec_constant::specialize(&words, spec).map_err(|e| GpuError::Shader(format!("{} {entry}: {e}", self.label)))?;
        let unspecialized = (name.to_string(), Vec::new());
        if set == 0 {
            let mut created = self.created.lock().unwrap();
            if let Some(m) = created.get(&unspecialized).cloned() {
                created.insert(key, m.clone());
                return Ok(m);
            }
        }
        let (label, names) = match self.source {
            Source::Whole(_) => (self.label.clone(), self.entry_points.clone()),
            Source::Split(_) => (format!("{} {entry}", self.label), vec![entry.to_string()]),
        };
        // SAFETY: the words are the module `new` was given (its contract), or a word-for-word
        // subset of it (the entry point, every global and the functions it calls), with at most
        // the literal values of specialization constants changed.
        let m = unsafe { spirv_module(device, &label, &words, &names, self.passthrough)? };
        let mut created = self.created.lock().unwrap();
        created.insert(key, (m.clone(), set > 0));
        if set == 0 {
            created.insert(unspecialized, (m.clone(), false));
        }
        Ok((m, set > 0))
    }
}

/// Run `create` inside a validation error scope; its error names `label`.
pub(crate) fn validated(device: &wgpu::Device, label: &str, create: impl FnOnce() -> wgpu::ShaderModule) -> Result<wgpu::ShaderModule, GpuError> {
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let m = create();
    match pollster::block_on(scope.pop()) {
        Some(err) => Err(GpuError::Shader(format!("{label}: {err}"))),
        None => Ok(m),
    }
}

/// A SPIR-V module with compute entry points `entries` (workgroup size
/// [`shader_kernels::WORKGROUP_SIZE`] in x): handed to the driver unchanged with `passthrough`,
/// else translated by naga.
///
/// # Safety
/// With `passthrough` the words reach the driver unvalidated: they must be a valid SPIR-V
/// compute module whose bindings are storage buffers in the order the dispatches bind them.
pub(crate) unsafe fn spirv_module(device: &wgpu::Device, label: &str, words: &[u32], entries: &[String], passthrough: bool) -> Result<wgpu::ShaderModule, GpuError> {
    validated(device, label, || {
        if passthrough {
            let entry_points: Vec<wgpu::PassthroughShaderEntryPoint> = entries
                .iter()
                .map(|name| wgpu::PassthroughShaderEntryPoint { name: Cow::Owned(name.clone()), workgroup_size: (shader_kernels::WORKGROUP_SIZE, 1, 1) })
                .collect();
            // SAFETY: the caller's contract (see above).
            unsafe {
                device.create_shader_module_passthrough(wgpu::ShaderModuleDescriptorPassthrough {
                    label: Some(label),
                    entry_points: Cow::Owned(entry_points),
                    spirv: Some(Cow::Borrowed(words)),
                    ..Default::default()
                })
            }
        } else {
            device.create_shader_module(wgpu::ShaderModuleDescriptor { label: Some(label), source: wgpu::ShaderSource::SpirV(Cow::Borrowed(words)) })
        }
    })
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

    /// Every SSR pass that reads the parameter record declares the mode words as its
    /// specialization constants 0..MODE_WORDS (so the GPU backend's pipelines pin them), each
    /// defaulting to MODE_UNSET. (Another entry point's cut may keep some of them, unused, where
    /// one of its literals equals their id; nothing passes it values.)
    #[test]
    fn ssr_passes_declare_the_mode_words_as_specialization_constants() {
        use crate::shaders::{load_subgroup, load_variant, DivSqrt};
        use shader_core::ssr::params::{MODE_UNSET, MODE_WORDS};
        use shader_manifest::spec_constant::specialize;
        let values: Vec<u32> = (0..MODE_WORDS as u32).map(|k| 100 + k).collect();
        let mut ssr = 0;
        for m in [load_variant(DivSqrt::Exact).unwrap(), load_variant(DivSqrt::Native).unwrap(), load_subgroup().unwrap()] {
            let index = EntryPoints::new(m.words.clone()).unwrap();
            for e in &m.manifest.entry_points {
                let words = index.module(e).unwrap();
                let (set_words, set) = specialize(&words, &values).unwrap();
                if e.starts_with("ssr::") && !e.contains("scan") {
                    assert_eq!(set, MODE_WORDS, "{e}");
                    ssr += 1;
                    // The defaults are MODE_UNSET, and exactly the MODE_WORDS literals change.
                    let changed: Vec<(u32, u32)> = words.iter().zip(&set_words).filter(|(a, b)| a != b).map(|(&a, &b)| (a, b)).collect();
                    assert_eq!(changed, values.iter().map(|&v| (MODE_UNSET, v)).collect::<Vec<_>>(), "{e}");
                }
            }
        }
        assert!(ssr >= 2 * 15, "{ssr} SSR entry points in the two main modules");
    }
}
