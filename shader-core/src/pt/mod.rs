//! A unidirectional path tracer on triangle scenes, written once for the CPU and the GPU
//! (Pharr, Jakob, Humphreys, "Physically Based Rendering", 4th ed., chapters 4-13; the glTF
//! 2.0 metal-rough material of [`crate::bxdf::gltf`]).
//!
//! One concept per module: [`scene`] (the flat buffer layout), [`ray`], [`triangle`] (watertight
//! intersection), [`bvh`] (stackless traversal), [`texture`] (glTF sampling), [`surface`] (the
//! shading point), [`camera`], [`sampler`] (the random numbers), [`light`] (punctual lights and emissive triangles),
//! [`environment`] (uniform or equirectangular, importance sampled), [`material`] (the glTF BxDF
//! with energy compensation and transmission), [`integrator`] (NEE with MIS, Russian roulette),
//! [`gbuffer`] (the SSR inputs and the path-traced glossy reflection they are judged against).

pub mod bvh;
pub mod camera;
pub mod environment;
pub mod gbuffer;
pub mod integrator;
pub mod light;
pub mod material;
pub mod ray;
pub mod sampler;
pub mod scene;
pub mod surface;
pub mod texture;
pub mod triangle;
