//! The hostile-input contract: whatever the bytes, size or shape of what a user hands anim, it
//! ends quickly, within its memory budget, with a located message or the right image, never a
//! panic and never a half-written file. A test belongs here when its input is built to hurt;
//! honest mistakes in scene text have tests/dialect/.
//!
//! - `files`: line endings, control bytes, composite trees that multiply out, huge lines,
//!   endless devices, thousands of bad lines.
//! - `budgets`: reading and parsing within the memory `ulimit -v` leaves: huge glued lines,
//!   many shapes through an include, big meshes, same-name shapes.
//! - `confinement`: files swapped for links while anim opens them, `/` and the home folder
//!   as the current directory, messages that would tell whether a file outside exists.
//! - `includes`: includes that multiply, a frame directory whose shared part includes itself,
//!   a pipe or `/dev/stdin`, a million include lines.
//! - `hardening`: deep recursion, huge images, paths outside the scene's folder, corrupted
//!   images, two runs on one frame directory.
//! - `scale`: files beyond the old shape cap, and refusal only past `--max-memory`.
//! - `fuzz`: the stable-Rust fuzz harness of the two readers (ignored by default; FUZZING.md).

#[path = "../common/mod.rs"]
mod common;

mod budgets;
mod confinement;
mod files;
mod fuzz;
mod hardening;
mod includes;
mod scale;
