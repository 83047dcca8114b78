//! The GGX reflection samplers of `shader_core::vndf` and their densities (docs/vndf.md):
//! `wo = reflect(wi, wm)`; `pdf` is the solid-angle density of `wo` on the whole sphere.

use shader_core::vndf::{self, ReflectionSample};
use shader_core::Vec3;

/// A sample's columns.
#[inline(always)]
fn columns(s: ReflectionSample) -> (Vec3, f32) {
    (s.wo, s.pdf)
}

crate::evaluable! { group = "vndf";
    sample_ndf "GGX reflection by classic NDF sampling, pdf D(wm) wm.z / (4 |wi.wm|) (Walter et al. 2007 eqs. 35-38)"
        (wi: Vec3, alpha_x: f32, alpha_y: f32, u1: f32, u2: f32) -> (wo: Vec3, pdf: f32) {
            columns(vndf::sample_ndf(wi, alpha_x, alpha_y, u1, u2))
        }
    sample_vndf_heitz "GGX reflection by Heitz 2018 ellipsoid VNDF sampling (JCGT 7(4) listing 1)"
        (wi: Vec3, alpha_x: f32, alpha_y: f32, u1: f32, u2: f32) -> (wo: Vec3, pdf: f32) {
            columns(vndf::sample_vndf_heitz(wi, alpha_x, alpha_y, u1, u2))
        }
    sample_vndf_caps "GGX reflection by Dupuy & Benyoub 2023 spherical-cap VNDF sampling (with the ellipsoid stretch)"
        (wi: Vec3, alpha_x: f32, alpha_y: f32, u1: f32, u2: f32) -> (wo: Vec3, pdf: f32) {
            columns(vndf::sample_vndf_caps(wi, alpha_x, alpha_y, u1, u2))
        }
    sample_vndf_bounded "GGX reflection by Eto & Tokuyoshi 2023 bounded VNDF sampling (SampleGGXReflection)"
        (wi: Vec3, alpha_x: f32, alpha_y: f32, u1: f32, u2: f32) -> (wo: Vec3, pdf: f32) {
            columns(vndf::sample_vndf_bounded(wi, alpha_x, alpha_y, u1, u2))
        }
    pdf_ndf "Density of sample_ndf at wo: D(wm) wm.z / (4 |wi.wm|), wm = +-normalize(wi + wo) with wm.z >= 0"
        (wi: Vec3, wo: Vec3, alpha_x: f32, alpha_y: f32) -> (pdf: f32) { vndf::pdf_ndf(wi, wo, alpha_x, alpha_y) }
    pdf_vndf_heitz "Density of sample_vndf_heitz at wo: D(wm) / (2 (wi.z + t)), stable form for wi.z < 0 (Heitz 2018 eq. 2)"
        (wi: Vec3, wo: Vec3, alpha_x: f32, alpha_y: f32) -> (pdf: f32) { vndf::pdf_vndf_heitz(wi, wo, alpha_x, alpha_y) }
    pdf_vndf_caps "Density of sample_vndf_caps at wo (the same as pdf_vndf_heitz)"
        (wi: Vec3, wo: Vec3, alpha_x: f32, alpha_y: f32) -> (pdf: f32) { vndf::pdf_vndf_caps(wi, wo, alpha_x, alpha_y) }
    pdf_vndf_bounded "Density of sample_vndf_bounded at wo: D(wm) / (2 (k wi.z + t)) in the bounded cap (Eto & Tokuyoshi 2023 GGXReflectionPDF)"
        (wi: Vec3, wo: Vec3, alpha_x: f32, alpha_y: f32) -> (pdf: f32) { vndf::pdf_vndf_bounded(wi, wo, alpha_x, alpha_y) }
}
