//! The pipeline contract: the keyframe spec and the commands around the renderer, through the
//! real binary. A test belongs here when its claim is about `anim generate`, `anim render DIR`,
//! `scripts/encode.sh` or `anim bench` rather than about one image (tests/images/) or what a
//! scene file may say (tests/dialect/).
//!
//! - `keyframe_spec`: parsing, located errors, interpolation, the orbit camera and how keyed
//!   transforms compose with the base scene's own.
//! - `frames`: generate → render a directory → encode, with skipping of unchanged frames,
//!   resuming, shards and failures.
//! - `holds`: frames of one scene rendered once and copied, byte for byte.
//! - `bench`: `anim bench` at its tiny size, and the files it writes.
//! - `animator`: aim, orientation keys, the inclusive end, curves kept in range, materials,
//!   visibility, reuse, the early check of the base scene, and the example specs' frames.
//! - `incremental`: frames traced from the frame before, to the byte the frames alone, whatever
//!   the thread count.
//! - `service`: the one way from a scene file to images in memory, which `anim render` and
//!   `anim preview` share, and the files a frame's fingerprint follows.

#[path = "../common/mod.rs"]
mod common;

mod animator;
mod bench;
mod frames;
mod holds;
mod incremental;
mod keyframe_spec;
mod service;
mod split;
