//! Generated fuzz of the glTF loader: the repository's Cornell box with one to three of its JSON
//! values (numbers, indices, strings, arrays, objects) replaced, removed or duplicated, or keys
//! it does not use (strides, sparse storage, matrices, textures, ...) added, at random (most
//! often a number moved a little: an index one off, a factor just outside its range), thousands
//! of cases. Each is loaded with the scene loader; every one that loads is
//! rendered at 8x8, 1 spp on the CPU backend. No case may panic, and no rendered image may hold
//! a non-finite pixel: bad input gets a named error, good input a finite image.
//!
//! Bounded in time (`HOST_FUZZ_SECONDS`, default 30 s, and `HOST_FUZZ_CASES`, default 4000):
//! it stops at whichever comes first, and fails if fewer than 1000 cases ran. The cases are the
//! same on every run; `HOST_FUZZ_SEED` draws others.

use host::render::environment::{self, EnvSpec};
use host::render::scene::Scene;
use host::render::{render, RenderInputs};
use runner::Backend;
use serde_json::{json, Value};
use shader_core::pt::integrator::{RenderParams, STRATEGY_MIS};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

const CORNELL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell_box/cornell_box.gltf");

/// SplitMix64.
struct Rng(reference::splitmix::SplitMix64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0.next_u64()
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Every value's JSON pointer in `v` (the root excluded).
fn pointers(v: &Value, at: String, out: &mut Vec<String>) {
    match v {
        Value::Object(m) => {
            for (k, c) in m {
                let p = format!("{at}/{}", k.replace('~', "~0").replace('/', "~1"));
                out.push(p.clone());
                pointers(c, p, out);
            }
        }
        Value::Array(a) => {
            for (i, c) in a.iter().enumerate() {
                let p = format!("{at}/{i}");
                out.push(p.clone());
                pointers(c, p, out);
            }
        }
        _ => {}
    }
}

/// A replacement value: indices in and out of range, bounds' edges, overflow, wrong types.
fn value(rng: &mut Rng, old: &Value) -> Value {
    const NUMBERS: &[f64] = &[0.0, -0.0, 1.0, -1.0, 0.5, 2.0, 3.0, 7.0, 11.0, 99.0, 255.0, 65535.0, 4294967295.0, 4294967296.0, 1e30, -1e30, 1e39, -1e39, 1e-45, 3.2, 1.5707964, 4.0, -5.0, 1e300];
    match rng.below(12) {
        // a number near the old one: an index one off, a factor a little out of its range
        0..=4 => match old {
            Value::Number(n) if n.is_u64() => json!(n.as_u64().unwrap() as i64 + [-1, 1, 2, 5][rng.below(4)]),
            Value::Number(n) => json!(n.as_f64().unwrap() * [-1.0, 0.0, 0.5, 0.999, 1.001, 1.5, 2.0, 1e20][rng.below(8)]),
            _ => json!(NUMBERS[rng.below(NUMBERS.len())]),
        },
        5..=6 => json!(NUMBERS[rng.below(NUMBERS.len())]),
        7 => json!(["", "2.0", "1.0", "BLEND", "MASK", "cornell_box.bin", "missing.bin", "data:application/octet-stream;base64,AAAA", "perspective", "point"][rng.below(10)]),
        8..=9 => json!([rng.below(4), rng.below(12)]),
        10 => json!({}),
        _ => Value::Null,
    }
}

/// Mutate `doc` at one random place: replace a value, remove it, duplicate an array's element,
/// or add a key the box does not use to an object. Returns what it did.
fn mutate(rng: &mut Rng, doc: &mut Value) -> String {
    let mut ptrs = Vec::new();
    pointers(doc, String::new(), &mut ptrs);
    let p = &ptrs[rng.below(ptrs.len())];
    let (parent, key) = p.rsplit_once('/').unwrap();
    let op = rng.below(12);
    let old = doc.pointer(p).cloned().unwrap_or(Value::Null);
    let Some(container) = doc.pointer_mut(parent) else { return format!("{p}: gone") };
    match (op, container) {
        (0, Value::Object(m)) => {
            m.remove(key);
            format!("{p}: removed")
        }
        (0, Value::Array(a)) => {
            let i: usize = key.parse().unwrap();
            a.remove(i);
            format!("{p}: removed")
        }
        // a key the box does not use, added to an object: strides, offsets, sparse storage,
        // transforms, hierarchy, samplers, texture references
        (2, Value::Object(m)) => {
            const KEYS: &[&str] = &["byteStride", "byteOffset", "sparse", "matrix", "scale", "translation", "children", "normalized", "sampler", "baseColorTexture", "emissiveTexture", "alphaMode", "alphaCutoff", "doubleSided", "mode", "targets", "skin", "camera", "min", "max"];
            let k = KEYS[rng.below(KEYS.len())];
            let v = match k {
                "sparse" => {
                    let ty = [5121, 5123, 5125, 5126][rng.below(4)];
                    json!({"count": rng.below(4), "indices": {"bufferView": rng.below(12), "componentType": ty}, "values": {"bufferView": rng.below(12)}})
                }
                "matrix" => {
                    let w = [1.0, 0.0, 1e30][rng.below(3)];
                    json!([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, w])
                }
                "baseColorTexture" | "emissiveTexture" => json!({"index": rng.below(2)}),
                _ => value(rng, &Value::Null),
            };
            let d = format!("{parent}/{k}: added {v}");
            m.insert(k.to_string(), v);
            d
        }
        (1, Value::Array(a)) => {
            let i: usize = key.parse().unwrap();
            let e = a[i].clone();
            a.push(e);
            format!("{p}: appended again")
        }
        _ => {
            let v = value(rng, &old);
            let d = format!("{p}: {old} -> {v}");
            *doc.pointer_mut(p).unwrap() = v;
            d
        }
    }
}

/// Render `scene` at 8x8, 1 spp on the CPU; `Ok(None)` when the camera is refused with an error
/// (named, as the CLI reports it), `Ok(Some(non-finite pixel count))` otherwise.
fn tiny_render(scene: &Scene, lut: &[f32]) -> anyhow::Result<usize> {
    let (cam, _) = host::render::cli::pick_camera(scene, None)?;
    let camera = cam.kernel(8, 8)?;
    let env = environment::build(&if scene.has_lights() { EnvSpec::Black } else { EnvSpec::Uniform([1.0; 3]) }, 1.0, 0.0)?;
    let p_env = if scene.has_lights() { 0.0 } else { 1.0 };
    let params = RenderParams { width: 8, height: 8, spp: 1, sample_base: 0, seed: 1, max_depth: 4, rr_depth: 3, strategy: STRATEGY_MIS, compensation: host::energy::Compensation::None.id(), sampler: shader_core::pt::sampler::SAMPLER_PCG, clamp: 0.0, p_env, camera };
    let inputs = RenderInputs { scene: &scene.words, env: &env.words, lut };
    let (img, _) = render(&Backend::Cpu, &inputs, &params, 1, 1, |_| {})?;
    Ok(img.color.iter().chain(&img.albedo).chain(&img.normal).chain(&img.depth).filter(|v| !v.is_finite()).count())
}

#[test]
fn mutated_cornell_boxes_never_panic_nor_render_non_finite_pixels() {
    let seconds: f64 = std::env::var("HOST_FUZZ_SECONDS").ok().and_then(|s| s.parse().ok()).unwrap_or(30.0);
    let max_cases: usize = std::env::var("HOST_FUZZ_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(4000);
    let src = Path::new(CORNELL);
    let base: Value = serde_json::from_str(&std::fs::read_to_string(src).expect("the repository's Cornell box")).unwrap();
    Scene::load(src).expect("the unmutated box loads");
    // a second base with what the box lacks, so that mutations reach lights and emission too: a
    // spot light on its node "Light", a point light, an emissive material with a strength
    let mut lit = base.clone();
    lit["extensionsUsed"] = json!(["KHR_lights_punctual", "KHR_materials_emissive_strength"]);
    lit["extensions"] = json!({"KHR_lights_punctual": {"lights": [
        {"type": "spot", "color": [1.0, 0.9, 0.8], "intensity": 20.0, "range": 30.0, "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.6}},
        {"type": "point", "intensity": 5.0}
    ]}});
    lit["nodes"][1]["extensions"] = json!({"KHR_lights_punctual": {"light": 0}});
    lit["nodes"][0]["extensions"] = json!({"KHR_lights_punctual": {"light": 1}});
    lit["materials"][0]["emissiveFactor"] = json!([1.0, 0.5, 0.25]);
    lit["materials"][0]["extensions"] = json!({"KHR_materials_emissive_strength": {"emissiveStrength": 3.0}});
    let bases = [base, lit];
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(src.with_extension("bin"), dir.path().join("cornell_box.bin")).unwrap();
    let lit_path = dir.path().join("lit.gltf");
    std::fs::write(&lit_path, serde_json::to_string(&bases[1]).unwrap()).unwrap();
    let lit = Scene::load(&lit_path).unwrap_or_else(|e| panic!("the lit base loads: {e:#}"));
    assert_eq!(lit.counts.punctual_lights, 2);
    let lut = vec![0.0f32; shader_core::energy::LUT_HEADER];
    // panics are caught and counted; keep their messages off the test's output
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let t0 = std::time::Instant::now();
    let seed: u64 = std::env::var("HOST_FUZZ_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(0x005e_ed42);
    let mut rng = Rng(reference::splitmix::SplitMix64(seed));
    let (mut cases, mut loaded, mut rendered) = (0usize, 0usize, 0usize);
    let mut failures: Vec<String> = Vec::new();
    while cases < max_cases && t0.elapsed().as_secs_f64() < seconds {
        let mut doc = bases[cases % 2].clone();
        let n = [1, 1, 1, 2, 3][rng.below(5)];
        let done: Vec<String> = (0..n).map(|_| mutate(&mut rng, &mut doc)).collect();
        let path = dir.path().join(format!("case{}.gltf", cases % 4));
        std::fs::write(&path, serde_json::to_string(&doc).unwrap()).unwrap();
        cases += 1;
        let what = || format!("case {cases} ({} base): {}", ["the box's", "the lit"][(cases - 1) % 2], done.join("; "));
        let result = catch_unwind(AssertUnwindSafe(|| Scene::load(&path).map(|s| {
            let r = tiny_render(&s, &lut);
            (s.counts.triangles, r)
        })));
        match result {
            Err(p) => {
                let msg = p.downcast_ref::<String>().cloned().or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string())).unwrap_or_default();
                failures.push(format!("panic ({msg}) while loading or rendering: {}", what()))
            }
            Ok(Err(_named)) => {}
            Ok(Ok((_, Err(_named)))) => loaded += 1,
            Ok(Ok((_, Ok(bad)))) => {
                loaded += 1;
                rendered += 1;
                if bad > 0 {
                    failures.push(format!("{bad} non-finite values in the image of a scene that loaded without error: {}", what()));
                }
            }
        }
        if failures.len() >= 5 {
            break;
        }
    }
    std::panic::set_hook(hook);
    println!("{cases} cases in {:.1} s: {loaded} loaded, {rendered} rendered, {} failures", t0.elapsed().as_secs_f64(), failures.len());
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
    assert!(cases >= 1000, "only {cases} cases ran in {seconds} s");
    assert!(loaded > cases / 20 && loaded < cases, "{loaded} of {cases} loaded: the mutations are too mild or too harsh to test anything");
}

/// The Cornell box as a GLB (JSON chunk, BIN chunk) with bytes of its header and chunk headers
/// (lengths, types, magic, version) and of its body overwritten at random: no panic, and every
/// case that loads renders a finite image.
#[test]
fn corrupted_glb_containers_never_panic() {
    let src = Path::new(CORNELL);
    let mut doc: Value = serde_json::from_str(&std::fs::read_to_string(src).unwrap()).unwrap();
    let bin = std::fs::read(src.with_extension("bin")).unwrap();
    doc["buffers"] = json!([{"byteLength": bin.len()}]);
    let mut text = serde_json::to_vec(&doc).unwrap();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let mut padded = bin.clone();
    while !padded.len().is_multiple_of(4) {
        padded.push(0);
    }
    let total = 12 + 8 + text.len() + 8 + padded.len();
    let mut glb = Vec::with_capacity(total);
    glb.extend_from_slice(b"glTF");
    glb.extend_from_slice(&2u32.to_le_bytes());
    glb.extend_from_slice(&(total as u32).to_le_bytes());
    glb.extend_from_slice(&(text.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"JSON");
    glb.extend_from_slice(&text);
    glb.extend_from_slice(&(padded.len() as u32).to_le_bytes());
    glb.extend_from_slice(b"BIN\0");
    glb.extend_from_slice(&padded);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("box.glb");
    std::fs::write(&path, &glb).unwrap();
    Scene::load(&path).unwrap_or_else(|e| panic!("the GLB box loads: {e:#}"));
    let lut = vec![0.0f32; shader_core::energy::LUT_HEADER];
    // the places a container's structure lives: file header, both chunk headers
    let json_end = 20 + text.len();
    let structural: Vec<usize> = (0..20).chain(json_end..json_end + 8).collect();
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let mut rng = Rng(reference::splitmix::SplitMix64(7));
    let (mut loaded, mut failures) = (0, Vec::new());
    let cases = 2000;
    for case in 0..cases {
        let mut g = glb.clone();
        let n = 1 + rng.below(3);
        let mut what = Vec::new();
        for _ in 0..n {
            let at = if rng.below(3) > 0 { structural[rng.below(structural.len())] } else { rng.below(g.len()) };
            let v = [0u8, 1, 0x7f, 0x80, 0xff, g[at] ^ 1, g[at].wrapping_add(4)][rng.below(7)];
            what.push(format!("byte {at}: {:#04x} -> {v:#04x}", g[at]));
            g[at] = v;
        }
        if rng.below(10) == 0 {
            let cut = rng.below(g.len());
            g.truncate(cut);
            what.push(format!("cut at {cut}"));
        }
        std::fs::write(&path, &g).unwrap();
        match catch_unwind(AssertUnwindSafe(|| Scene::load(&path).map(|s| tiny_render(&s, &lut)))) {
            Err(p) => {
                let msg = p.downcast_ref::<String>().cloned().or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string())).unwrap_or_default();
                failures.push(format!("case {case}: panic ({msg}): {}", what.join("; ")));
            }
            Ok(Ok(Ok(bad))) if bad > 0 => failures.push(format!("case {case}: {bad} non-finite values: {}", what.join("; "))),
            Ok(Ok(_)) => loaded += 1,
            Ok(Err(_named)) => {}
        }
    }
    std::panic::set_hook(hook);
    println!("{cases} GLB cases: {loaded} loaded, {} failures", failures.len());
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(loaded > 0 && loaded < cases, "{loaded} of {cases} loaded");
}
