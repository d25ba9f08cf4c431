//! The renderer library of anim: SDF scene text becomes an image.
//!
//! Data flow: SDF text → [`sdf`] statements (with source locations) → [`scene`] description
//! → [`render::compile`] compiled scene (geometry and its hierarchy from [`accel`], view,
//! shading) → [`render`] image. [`load`] reads a file as its author meant it, looking
//! through its cameras with the renderer where the transform order is in doubt.
#![forbid(unsafe_code)]
// The core's public items are its interface to the pipeline, the bench and the command: each
// says what it is for (`cargo clippy -D warnings` makes a missing one an error).
#![warn(missing_docs)]

pub mod accel;
pub mod diag;
pub mod input;
pub mod limits;
pub mod load;
pub mod math;
pub mod render;
pub mod scene;
pub mod sdf;
pub mod shape;
pub mod util;
