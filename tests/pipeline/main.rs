//! The pipeline contract: the keyframe spec and the commands around the renderer, through the
//! real binary. A test belongs here when its claim is about `anim generate`, `anim render DIR`,
//! `scripts/encode.sh` or `anim bench` rather than about one image (tests/images/) or what a
//! scene file may say (tests/dialect/).
//!
//! - `keyframe_spec`: parsing, located errors, interpolation, the orbit camera and how keyed
//!   transforms compose with the base scene's own.
//! - `frames`: generate → render a directory → encode, with skipping of unchanged frames,
//!   resuming, shards and failures.
//! - `encode`: `scripts/encode.sh` and `animate.sh`: the rate and the images' names read from
//!   the frames, the codecs (alpha kept where it can be), OpenEXR and 16-bit frames tone-mapped
//!   as anim's 8-bit images, and the refusals that come before any work.
//! - `holds`: frames of one scene rendered once and copied, byte for byte.
//! - `bench`: `anim bench` at its tiny size, and the files it writes.
//! - `animator`: aim, orientation keys, the inclusive end, curves kept in range, materials,
//!   visibility, reuse, the early check of the base scene, and the example specs' frames.
//! - `expressions`: channels as formulas of time, named values, noise.
//! - `generated_frames`: frames read as what they say (no inference), and the first-frame
//!   check that says what `anim check` would.
//! - `timing`: keys at `Frames(n)`, fractional frame rates, `--frames A..B`.
//! - `layering`: tracks on one value combined by `blend`, or refused without it.
//! - `meshes`: the meshes frames name, copied into the frame folder from outside it, so that
//!   the frames render from any current directory.
//! - `optics`: keyed light radii, spot cones and lenses, `focus: Object` (a rack focus), and
//!   their example shots rendered and encoded.
//! - `rigs`: paths at constant speed, `orient: AlongPath`, parents.
//! - `tangents`: a key's `in` and `out` sides, and the clamped spline `Auto`.
//! - `shots`: the example shots of round two (candle, rig, flythrough) do what they show.
//! - `spec_bounds`: numbers a spec gives beyond what a frame can hold, refused at the number.
//! - `incremental`: frames traced from the frame before, to the byte the frames alone, whatever
//!   the thread count.
//! - `service`: the one way from a scene file to images in memory, which `anim render` and
//!   `anim preview` share, and the files a frame's fingerprint follows.

#[path = "../common/mod.rs"]
mod common;

mod animator;
mod bench;
mod encode;
mod expressions;
mod frames;
mod generated_frames;
mod holds;
mod incremental;
mod keyframe_spec;
mod layering;
mod meshes;
mod optics;
mod rigs;
mod service;
mod shots;
mod spec_bounds;
mod split;
mod tangents;
mod timing;
