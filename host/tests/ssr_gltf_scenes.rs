//! The project's glTF writer and the SSR benchmark's glTF scenes: what is written loads back
//! through the loader as written (materials, cameras, lights, geometry), without warnings; the
//! Cornell box variant keeps the repository's scene and adds its floor and light; bad input is named.

use host::render::scene::gltf_write::{look_rotation, quaternion_from_columns, GltfWriter};
use host::render::scene::{LightKind, Material, PunctualLight, Scene};
use host::ssr::camera::V3 as DVec3;
use host::ssr::gltf_scenes::{cuboid, GltfScene, NAMES};

const CORNELL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/cornell_box/cornell_box.gltf");

fn rotate(q: [f32; 4], v: DVec3) -> DVec3 {
    let (u, w) = (DVec3::new(q[0] as f64, q[1] as f64, q[2] as f64), q[3] as f64);
    // v' = v + 2 w (q x v) + 2 q x (q x v)
    let qv = u.cross(v);
    v + qv * (2.0 * w) + u.cross(qv) * 2.0
}

#[test]
fn look_rotation_turns_minus_z_to_the_view_direction() {
    for (f, up) in [([0.0, 0.0, -1.0], [0.0, 1.0, 0.0]), ([1.0, -0.5, 0.2], [0.0, 1.0, 0.0]), ([0.0, -1.0, 0.0], [1.0, 0.0, 0.0]), ([-0.3, 0.1, 0.9], [0.0, 1.0, 0.0])] {
        let (f, up) = (DVec3::from(f), DVec3::from(up));
        let q = look_rotation(f, up).unwrap();
        let d = rotate(q, DVec3::NEG_Z);
        assert!((d - f / f.length()).abs().max_element() < 1e-6, "forward {f:?}: -Z goes to {d:?}");
        let u = rotate(q, DVec3::Y);
        assert!(u.dot(up) > 0.0, "up {up:?}: +Y goes to {u:?}");
    }
    assert!(look_rotation(DVec3::Y, DVec3::new(0.0, 2.0, 0.0)).is_err(), "up parallel to forward is named");
    // Each branch of Shepperd's method: a rotation by pi about each axis.
    for axis in 0..3 {
        let c = |k: usize| DVec3::from(std::array::from_fn::<f64, 3, _>(|r| if r == k { if k == axis { 1.0 } else { -1.0 } } else { 0.0 }));
        let q = quaternion_from_columns(c(0), c(1), c(2));
        assert!((q[axis].abs() - 1.0).abs() < 1e-6, "pi about axis {axis}: {q:?}");
    }
}

#[test]
fn written_documents_load_back_as_written() {
    let dir = tempfile::tempdir().unwrap();
    let mut w = GltfWriter::new();
    let red = w.material(&Material::pbr("red", [0.8, 0.1, 0.1], 0.25, 0.3));
    let lamp = w.material(&Material { emissive: [4.0, 2.0, 1.0], ..Material::pbr("lamp", [0.0; 3], 0.0, 1.0) });
    w.mesh(&cuboid("box", [0.0, 0.0, 0.0], [1.0, 2.0, 3.0]), red).unwrap();
    w.mesh(&cuboid("lamp", [0.0, 3.0, 0.0], [0.5, 3.1, 0.5]), lamp).unwrap();
    w.camera("cam", DVec3::new(0.0, 1.0, 8.0), DVec3::Y, DVec3::Y, 0.7).unwrap();
    let spot = PunctualLight { name: "spot".into(), kind: LightKind::Spot { inner_cone: 0.2, outer_cone: 0.5 }, position: [1.0, 4.0, 1.0], direction: [0.0, -1.0, 0.0], intensity: [10.0, 5.0, 2.5], range: 0.0 };
    w.light(&spot).unwrap();
    let path = dir.path().join("doc.gltf");
    w.write(&path).unwrap();
    let s = Scene::load(&path).unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!(s.counts.triangles, 24);
    assert_eq!(s.counts.materials, 2);
    assert_eq!(s.counts.punctual_lights, 1);
    assert_eq!(s.counts.emissive_triangles, 12);
    assert_eq!((s.bounds.min, s.bounds.max), ([0.0, 0.0, 0.0], [1.0, 3.1, 3.0]));
    let c = &s.cameras[0];
    assert_eq!(c.name, "cam");
    assert_eq!(c.position, [0.0, 1.0, 8.0]);
    assert!((c.forward[2] + 1.0).abs() < 1e-6 && (c.up[1] - 1.0).abs() < 1e-6, "{c:?}");
    let l = &s.punctual_lights[0];
    assert!(matches!(l.kind, LightKind::Spot { .. }));
    assert!((l.direction[1] + 1.0).abs() < 1e-6, "{:?}", l.direction);
    for k in 0..3 {
        assert!((l.intensity[k] - spot.intensity[k]).abs() < 1e-5, "{:?}", l.intensity);
    }
    // Bad input is named.
    let mut w = GltfWriter::new();
    assert!(w.mesh(&cuboid("orphan", [0.0; 3], [1.0; 3]), 0).unwrap_err().to_string().contains("material 0"));
    let m = w.material(&Material::default());
    let mut bad = cuboid("bad", [0.0; 3], [1.0; 3]);
    bad.indices.as_mut().unwrap()[5] = 99;
    assert!(w.mesh(&bad, m).unwrap_err().to_string().contains("index 99"));
    assert!(w.light(&PunctualLight { intensity: [0.0; 3], ..spot }).unwrap_err().to_string().contains("intensity"));
}

#[test]
fn benchmark_scenes_load_without_warnings() {
    let dir = tempfile::tempdir().unwrap();
    let cornell = Scene::load(CORNELL).unwrap();
    for name in NAMES {
        let which = GltfScene::by_name(name).unwrap();
        let path = which.write(dir.path(), Some(std::path::Path::new(CORNELL))).unwrap();
        let s = Scene::load(&path).unwrap();
        assert!(s.warnings.is_empty(), "{name}: {:?}", s.warnings);
        assert!(!s.cameras.is_empty(), "{name}: a camera");
        assert!(s.counts.punctual_lights >= 1, "{name}: a light");
        match which {
            GltfScene::Cornell => {
                // The box as it is, plus two floor triangles and the lamp.
                assert_eq!(s.counts.triangles, cornell.counts.triangles + 2);
                assert_eq!(s.counts.materials, cornell.counts.materials + 1);
                assert_eq!(s.cameras.len(), cornell.cameras.len());
            }
            GltfScene::Pillars => assert!(s.counts.triangles > 10_000, "{}", s.counts.triangles),
            GltfScene::Orbit => assert_eq!(which.orbit(), Some(host::ssr::gltf_scenes::ORBIT_DEGREES)),
        }
    }
    assert!(GltfScene::by_name("nope").is_none());
    // Without --cornell the scene is made from the copy built into the program: the same files.
    let built_in = tempfile::tempdir().unwrap();
    let a = GltfScene::Cornell.write(built_in.path(), None).unwrap();
    let b = dir.path().join("cornell.gltf");
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert_eq!(std::fs::read(a.with_file_name("cornell.base.bin")).unwrap(), std::fs::read(b.with_file_name("cornell.base.bin")).unwrap());
    let e = GltfScene::Cornell.write(dir.path(), Some(std::path::Path::new("/nonexistent/box.gltf"))).unwrap_err();
    assert!(format!("{e:#}").contains("/nonexistent/box.gltf"), "{e:#}");
}
