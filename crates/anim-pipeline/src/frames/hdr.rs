//! `--hdr` writes a radiance file (`NAME.pfm`) beside each image: a name that no render line
//! asked for. A file of that name that anim did not write is the user's, and is never
//! replaced. Each radiance file anim writes is vouched for by a mark,
//! `.anim-cache/NAME.pfm.written` beside it, holding the length and fingerprint of the bytes
//! written; a file that still holds exactly those bytes is anim's to replace.

use super::cache::CACHE_DIR;
use anim_core::render::film::ImageBytes;
use anim_core::util::{write_atomically, Fnv64};
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// Where the mark of radiance file `pfm` is kept.
fn mark_path(pfm: &Path) -> PathBuf {
    let name = pfm.file_name().map(|n| n.to_string_lossy().into_owned());
    let folder = pfm.parent().unwrap_or(Path::new(""));
    folder
        .join(CACHE_DIR)
        .join(format!("{}.written", name.unwrap_or_default()))
}

/// The text of a mark: the length and fingerprint of what was written.
fn mark_text(bytes: &ImageBytes) -> String {
    format!("anim-hdr {} {:016x}\n", bytes.len, bytes.hash)
}

/// Whether `--hdr` may write `pfm`: nothing is there, or anim wrote what is there.
pub fn may_replace(pfm: &Path) -> bool {
    let Ok(meta) = std::fs::symlink_metadata(pfm) else {
        return true;
    };
    if !meta.is_file() {
        return false;
    }
    // A mark is one short line: anything longer is not one.
    let mark = std::fs::read(mark_path(pfm)).ok().filter(|m| m.len() < 64);
    let Some(mark) = mark else {
        return false;
    };
    std::fs::read(pfm).is_ok_and(|held| {
        let held = ImageBytes {
            len: held.len() as u64,
            hash: Fnv64::of(&held),
        };
        mark == mark_text(&held).as_bytes()
    })
}

/// Records that anim wrote `bytes` to `pfm`.
pub fn mark_written(pfm: &Path, bytes: &ImageBytes) -> std::io::Result<()> {
    let mark = mark_path(pfm);
    if let Some(folder) = mark.parent() {
        std::fs::create_dir_all(folder)?;
    }
    write_atomically(&mark, |w| w.write_all(mark_text(bytes).as_bytes()))
}
