//! From scene files to image files: one scene file rendered and written (`scene_file`), and a
//! directory of animation frames rendered in parallel with unchanged frames skipped
//! (`dir`, records in `cache`). Nothing here prints: progress is reported through the
//! [`ImageProgress`] and [`FrameObserver`] callbacks, and the command layer shows it.

mod cache;
mod dir;
mod hdr;
mod output;
mod scene_file;
mod shard;

pub use cache::{record_path, settings_fingerprint, CACHE_DIR};
pub use dir::{
    list_frames, natural_cmp, render_dir, FrameObserver, FrameOptions, FrameOutcome, Summary,
};
pub use scene_file::{
    output_path, render_scene_file, FileOutcome, ImageProgress, NoProgress, Output,
};
pub use shard::Shard;
