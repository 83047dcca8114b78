//! Reciprocity to the bit: every G2 form and every BxDF `f` (reflection) gives the same bits with
//! wo and wi swapped, on 10^6 random pairs per function (both hemispheres, anisotropic alphas,
//! grazing directions). A form like `1 / (1 + lo + li)` rounds `(1 + lo) + li` and
//! `(1 + li) + lo` differently and fails here; the dielectric's transmission obeys generalized
//! reciprocity (eta^2 scaling, not bitwise) and is checked in `bxdf_properties.rs` instead.
//!
//! Run: `cargo test --release -p crosscheck --test reciprocity -- --nocapture`.

use rayon::prelude::*;
use shader_core::bxdf::{BxDF, ConductorBxDF, DielectricBxDF, DiffuseBxDF, GltfMetalRoughBxDF, TrowbridgeReitz, MODE_RADIANCE};
use shader_core::rng::Pcg32;
use shader_core::{masking, Vec3};

const PAIRS: u32 = 1_000_000;

/// A unit direction with z in [zmin, 1] (grazing included), from two uniforms.
fn dir(rng: &mut Pcg32, zmin: f32) -> Vec3 {
    let z = zmin + (1.0 - zmin) * rng.next_f32();
    let phi = 2.0 * std::f32::consts::PI * rng.next_f32();
    let s = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), z)
}

/// Alphas log-spaced over [1e-3, 1.5], anisotropic.
fn alpha(rng: &mut Pcg32) -> f32 {
    1e-3 * (1500.0f32).powf(rng.next_f32())
}

/// Count the pairs (of `PAIRS`, chunked over threads) where `f(wo, wi) != f(wi, wo)` bitwise;
/// `zmin` = lowest cos theta drawn (negative: both hemispheres).
fn asymmetric<F: Fn(Vec3, Vec3, f32, f32) -> Vec<u32> + Sync>(zmin: f32, f: F) -> (u32, Option<String>) {
    let chunks = 64u32;
    let per = PAIRS / chunks;
    let res: Vec<(u32, Option<String>)> = (0..chunks)
        .into_par_iter()
        .map(|c| {
            let mut rng = Pcg32::new(0x5ec1_u32 ^ c, c);
            let (mut bad, mut first) = (0, None);
            for _ in 0..per {
                let (wo, wi) = (dir(&mut rng, zmin), dir(&mut rng, zmin));
                let (ax, ay) = (alpha(&mut rng), alpha(&mut rng));
                let (a, b) = (f(wo, wi, ax, ay), f(wi, wo, ax, ay));
                if a != b {
                    bad += 1;
                    first.get_or_insert_with(|| format!("wo {wo:?} wi {wi:?} alpha ({ax}, {ay}): {a:x?} vs {b:x?}"));
                }
            }
            (bad, first)
        })
        .collect();
    (res.iter().map(|r| r.0).sum(), res.into_iter().find_map(|r| r.1))
}

fn bits(v: Vec3) -> Vec<u32> {
    vec![v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]
}

#[test]
fn g2_forms_and_bxdfs_are_reciprocal_to_the_bit() {
    type Case = (&'static str, f32, Box<dyn Fn(Vec3, Vec3, f32, f32) -> Vec<u32> + Sync>);
    let cases: Vec<Case> = vec![
        ("ggx_g2_separable", -1.0, Box::new(|o, i, ax, ay| vec![masking::ggx_g2_separable(o, i, ax, ay).to_bits()])),
        ("ggx_g2_height_correlated", -1.0, Box::new(|o, i, ax, ay| vec![masking::ggx_g2_height_correlated(o, i, ax, ay).to_bits()])),
        ("ggx_g2_direction_correlated", -1.0, Box::new(|o, i, ax, ay| vec![masking::ggx_g2_direction_correlated(o, i, ax, ay).to_bits()])),
        ("ggx_g2_height_direction_correlated", -1.0, Box::new(|o, i, ax, ay| vec![masking::ggx_g2_height_direction_correlated(o, i, ax, ay).to_bits()])),
        ("beckmann_g2_height_correlated", -1.0, Box::new(|o, i, ax, ay| vec![masking::beckmann_g2_height_correlated(o, i, ax, ay).to_bits()])),
        ("TrowbridgeReitz::g", -1.0, Box::new(|o, i, ax, ay| vec![TrowbridgeReitz::new(ax, ay).g(o, i).to_bits()])),
        ("DiffuseBxDF::f", -1.0, Box::new(|o, i, _, _| bits(DiffuseBxDF::new(Vec3::new(0.8, 0.5, 0.2)).f(o, i, MODE_RADIANCE)))),
        (
            "ConductorBxDF::f",
            -1.0,
            Box::new(|o, i, ax, ay| bits(ConductorBxDF::new(TrowbridgeReitz::new(ax, ay), Vec3::new(0.2, 0.9, 1.1), Vec3::new(3.9, 2.4, 2.2)).f(o, i, MODE_RADIANCE))),
        ),
        ("DielectricBxDF::f (reflection)", 0.0, Box::new(|o, i, ax, ay| bits(DielectricBxDF::new(TrowbridgeReitz::new(ax, ay), 1.5).f(o, i, MODE_RADIANCE)))),
        (
            "GltfMetalRoughBxDF::f",
            -1.0,
            Box::new(|o, i, ax, _| bits(GltfMetalRoughBxDF::new(Vec3::new(0.9, 0.6, 0.3), 0.5, ax.min(1.0).sqrt()).f(o, i, MODE_RADIANCE))),
        ),
    ];
    let mut failures = Vec::new();
    for (name, zmin, f) in &cases {
        let (bad, first) = asymmetric(*zmin, f);
        eprintln!("{name:<36} {bad:>7} of {PAIRS} swapped pairs differ");
        if bad > 0 {
            failures.push(format!("{name}: {bad} of {PAIRS} differ; first: {}", first.unwrap_or_default()));
        }
    }
    assert!(failures.is_empty(), "not reciprocal to the bit:\n{}", failures.join("\n"));
}
