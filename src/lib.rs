//! anim: an animation pipeline toolkit built around a Whitted-style ray tracer.
//!
//! Data flow: SDF text → [`sdf`] statements (with source locations) → [`scene`] description
//! → [`render::compile`] flat render scene with a BVH ([`accel`]) → [`render`] image.
//! [`anim`] turns a RON keyframe spec into one SDF file per frame; [`pipeline`] renders a
//! directory of frames.
#![forbid(unsafe_code)]

pub mod accel;
pub mod anim;
pub mod app;
pub mod bench;
pub mod cli;
pub mod diag;
pub mod limits;
pub mod math;
pub mod pipeline;
pub mod render;
pub mod scene;
pub mod sdf;
pub mod shape;
pub mod util;
