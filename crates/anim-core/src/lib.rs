//! The renderer library of anim: SDF scene text becomes an image.
//!
//! Data flow: SDF text → [`sdf`] statements (with source locations) → [`scene`] description
//! → [`render::compile`] flat render scene with a BVH ([`accel`]) → [`render`] image.
#![forbid(unsafe_code)]

pub mod accel;
pub mod diag;
pub mod limits;
pub mod math;
pub mod render;
pub mod scene;
pub mod sdf;
pub mod shape;
pub mod util;
