//! The `anim` command: [`cli`] turns the command line into plain configurations, and [`app`]
//! runs them over the renderer library (`anim_core`), the animation pipeline
//! (`anim_pipeline`) and the benchmarks (`anim_bench`).
#![forbid(unsafe_code)]

pub mod app;
pub mod cli;
