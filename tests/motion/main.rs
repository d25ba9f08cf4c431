//! The motion contract: motion blur from the keyframe spec's `shutter` through the `motion`
//! lines of the frames it writes to the pixels the renderer draws (docs/scene-language.md §10).
//! A test belongs here when its claim involves time within a frame; still images have
//! tests/images/, the spec's other keys tests/pipeline/.
//!
//! - `spec`: the spec's `shutter`, the `motion` lines of blurred frames and `anim check`.
//! - `render`: a sliding ball's streak against the exposure it covers, thread independence,
//!   and `motion` lines that move nothing.
//! - `blur`: real specs end to end: a blurred frame against the mean of its instants, still
//!   frames unchanged by a shutter, and a blurred MP4.

#[path = "../common/mod.rs"]
mod common;

mod blur;
mod render;
mod spec;
