//! From scene files to images: one scene file rendered into memory (`draw`, the one way there,
//! which `anim render` and `anim preview` both take), one scene file rendered and written
//! (`scene_file`), and a directory of animation frames rendered in parallel with unchanged
//! frames skipped (`dir`, records and the frame fingerprint in `cache`). Nothing here prints:
//! progress is reported through the [`ImageProgress`] and [`FrameObserver`] callbacks, and the
//! command layer shows it.

mod cache;
mod dir;
mod draw;
mod hdr;
mod output;
mod scene_file;
mod shard;
mod shots;

pub use cache::{frame_hash, record_path, referenced_files, settings_fingerprint, CACHE_DIR};
pub use dir::{
    distinct_warnings, list_frames, natural_cmp, render_dir, FrameObserver, FrameOptions,
    FrameOutcome, Summary,
};
pub use draw::{render_to_memory, Drawn, Encoded, ImageProgress, ImageSink, NoProgress};
pub use scene_file::{output_path, render_scene_file, FileOutcome, Output};
pub use shard::Shard;
