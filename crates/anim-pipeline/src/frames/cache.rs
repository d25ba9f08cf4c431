//! Render records: what lets `anim render DIR` skip a frame whose images are already right.
//!
//! After a frame's images are written (atomically), a small record
//! `.anim-cache/<frame>.sdf.hash` is written (atomically too) beside them, holding a hash of the
//! frame's SDF bytes, every setting that changes pixels and anim's version, and the length and a
//! hash of the exact bytes this process wrote to each image (taken as they were written, not
//! read back, so a concurrent writer cannot slip its image under this record). A frame is
//! skipped only when its record matches and its images still hold exactly those bytes.
//!
//! The record is removed before a frame is rendered again and written only after its images
//! are complete, so an interrupted run never leaves a record for an image that is not
//! finished: the next run renders that frame again.

use super::output::Output;
use anim_core::render::RenderSettings;
use anim_core::sdf::{LoadOptions, Reference};
use anim_core::util::{write_atomically, Fnv64};
use std::io::{Read as _, Write as _};
use std::path::{Path, PathBuf};

/// Directory of render records, beside the images.
pub const CACHE_DIR: &str = ".anim-cache";

/// Bumped when the record format or the meaning of the hash changes.
const RECORD_VERSION: u32 = 2;

/// Where the render record of frame file `sdf_name` is kept, for images in `out_dir`.
pub fn record_path(out_dir: &Path, sdf_name: &str) -> PathBuf {
    out_dir.join(CACHE_DIR).join(format!("{sdf_name}.hash"))
}

/// Every setting that can change a frame's pixels (or whether it renders at all), as text.
/// It is the whole of both settings structs, so a setting added to either is part of the key
/// without anyone having to remember to list it here.
pub fn settings_fingerprint(settings: &RenderSettings, load: &LoadOptions) -> String {
    format!(
        "record={RECORD_VERSION};anim={};{settings:?};{load:?}",
        env!("CARGO_PKG_VERSION")
    )
}

/// The hash a frame's record holds: of the settings, the frame's bytes (`sdf`, read from
/// `path`), the bytes of every file it includes, so that a change to the static part of an
/// animation renders its frames again, and the size and modification time of every mesh they
/// name. The files are found by the loader's own rules (`anim_core::sdf::references`:
/// confined, never a pipe or a device, never round a cycle, each file once, within
/// `--max-input`). The preview keys its frames by it too.
pub fn frame_hash(sdf: &[u8], path: &Path, fingerprint: &str, load: &LoadOptions) -> u64 {
    let mut h = Fnv64::default();
    h.write(fingerprint.as_bytes());
    // A separator that cannot occur in the fingerprint keeps the two parts apart.
    h.write(&[0]);
    h.write(sdf);
    for reference in anim_core::sdf::references(sdf, path, load) {
        match reference {
            Reference::Mesh(file) => {
                h.write_part(file.as_os_str().as_encoded_bytes());
                // Metadata only: a mesh is not opened here (a pipe is refused by the loader).
                if let Ok(meta) = std::fs::metadata(&file) {
                    h.write_part(&meta.len().to_le_bytes());
                    let since_epoch = meta
                        .modified()
                        .ok()
                        .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok());
                    h.write_part(&since_epoch.map_or(0, |d| d.as_nanos()).to_le_bytes());
                }
            }
            Reference::Included(file, bytes) => {
                h.write_part(file.as_os_str().as_encoded_bytes());
                if let Some(bytes) = bytes {
                    h.write_part(&bytes);
                }
            }
        }
    }
    h.finish()
}

/// The files whose edits change the pictures of scene file `path`: those it includes, to any
/// depth, and the meshes they all name, as [`frame_hash`] finds them. Files that cannot be
/// read are listed too, so that a watcher sees them made.
pub fn referenced_files(path: &Path, load: &LoadOptions) -> Vec<PathBuf> {
    let Ok(sdf) = anim_core::load::read_input(path, load.max_input, "file") else {
        return Vec::new();
    };
    anim_core::sdf::references(&sdf, path, load)
        .into_iter()
        .map(|reference| match reference {
            Reference::Mesh(file) | Reference::Included(file, _) => file,
        })
        .collect()
}

/// Removes the records of frames whose `.sdf` file is gone from `frames_dir` (an animation
/// made shorter), with the images they vouch for: an image goes only when its bytes are still
/// exactly the ones this renderer wrote, so a file of the user's with the same name stays.
pub(super) fn prune_orphan_records(frames_dir: &Path, out_dir: &Path) -> std::io::Result<()> {
    let Ok(entries) = std::fs::read_dir(out_dir.join(CACHE_DIR)) else {
        return Ok(());
    };
    for entry in entries {
        let entry = entry?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let Some(sdf) = name.strip_suffix(".hash") else {
            continue;
        };
        if frames_dir.join(sdf).exists() {
            continue;
        }
        let text = read_record(&entry.path()).unwrap_or_default();
        for image in text.lines().skip(2).filter_map(RecordedImage::parse) {
            let path = out_dir.join(image.rel);
            if image.still_holds_what_was_written(&path) {
                std::fs::remove_file(&path)?;
            }
        }
        std::fs::remove_file(entry.path())?;
    }
    Ok(())
}

/// Largest record read: a header and a line of about a hundred bytes per image, so ten
/// thousand images. Anything larger was not written by anim.
const MAX_RECORD_BYTES: u64 = 1 << 20;

/// The text of the record at `path`; `None` (the frame renders again, and its record is
/// replaced) when it is missing, not a regular file (a pipe would block the run), larger than
/// any record anim writes, or not text.
fn read_record(path: &Path) -> Option<String> {
    let meta = std::fs::metadata(path).ok()?;
    if !meta.is_file() || meta.len() > MAX_RECORD_BYTES {
        return None;
    }
    let mut text = String::new();
    std::fs::File::open(path)
        .ok()?
        .take(MAX_RECORD_BYTES)
        .read_to_string(&mut text)
        .ok()?;
    Some(text)
}

/// How a record names the frame its images were copied from.
const COPIED_FROM: &str = "from ";

/// How a record says that its frame was traced from the frame before it in its shot:
/// `incremental <pixels traced again> <all pixels> <frame before>`.
const INCREMENTAL: &str = "incremental ";

/// How a frame's images were made, as its record tells: copied from frame `from`, or traced
/// from frame `traced.2` before it in its shot, again in `traced.0` of `traced.1` pixels.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Made<'a> {
    pub from: Option<&'a str>,
    pub traced: Option<(u64, u64, &'a str)>,
}

impl<'a> Made<'a> {
    /// Copied from frame `from`.
    pub fn copied(from: &'a str) -> Made<'a> {
        Made {
            from: Some(from),
            traced: None,
        }
    }
}

/// An image line of a record: `image <len> <hash> <path relative to the images>`.
struct RecordedImage<'a> {
    len: u64,
    hash: u64,
    rel: &'a str,
}

impl RecordedImage<'_> {
    fn parse(line: &str) -> Option<RecordedImage<'_>> {
        let mut fields = line.splitn(4, ' ');
        let (Some("image"), Some(len), Some(hash), Some(rel)) =
            (fields.next(), fields.next(), fields.next(), fields.next())
        else {
            return None;
        };
        Some(RecordedImage {
            len: len.parse().ok()?,
            hash: u64::from_str_radix(hash, 16).ok()?,
            rel,
        })
    }

    /// Whether `path` holds exactly the bytes recorded (the length first: a changed size is
    /// caught without reading the file).
    fn still_holds_what_was_written(&self, path: &Path) -> bool {
        let same_length = std::fs::metadata(path).is_ok_and(|m| m.is_file() && m.len() == self.len);
        same_length && std::fs::read(path).map(|b| Fnv64::of(&b)).ok() == Some(self.hash)
    }
}

/// The record's text: a header, the hash, how its images were made (copied: `from <name>`;
/// traced from the frame before: `incremental ...`), and each image with its length and
/// byte hash.
fn record_text(hash: u64, made: Made, out_dir: &Path, outputs: &[Output]) -> String {
    let mut text = format!("anim-render-record {RECORD_VERSION}\nhash {hash:016x}\n");
    if let Some(from) = made.from {
        text.push_str(&format!("{COPIED_FROM}{from}\n"));
    }
    if let Some((again, of, before)) = made.traced {
        text.push_str(&format!("{INCREMENTAL}{again} {of} {before}\n"));
    }
    for out in outputs {
        let rel = out.path.strip_prefix(out_dir).unwrap_or(&out.path);
        text.push_str(&format!(
            "image {} {:016x} {}\n",
            out.bytes.len,
            out.bytes.hash,
            rel.display()
        ));
    }
    text
}

pub(super) fn write_record(
    record: &Path,
    out_dir: &Path,
    hash: u64,
    made: Made,
    outputs: &[Output],
) -> std::io::Result<()> {
    if let Some(parent) = record.parent() {
        std::fs::create_dir_all(parent)?;
    }
    let text = record_text(hash, made, out_dir, outputs);
    write_atomically(record, |w| w.write_all(text.as_bytes()))
}

/// Whether frame `name`'s record matches `hash` and every image it lists still holds exactly
/// the bytes that were written (a truncated, corrupted or replaced image is rendered again).
pub(super) fn is_up_to_date(out_dir: &Path, name: &str, hash: u64) -> bool {
    let Some(text) = read_record(&record_path(out_dir, name)) else {
        return false;
    };
    let mut lines = text.lines();
    if lines.next() != Some(format!("anim-render-record {RECORD_VERSION}").as_str()) {
        return false;
    }
    if lines.next() != Some(format!("hash {hash:016x}").as_str()) {
        return false;
    }
    let mut images = 0;
    for line in lines.skip_while(|l| l.starts_with(COPIED_FROM) || l.starts_with(INCREMENTAL)) {
        let Some(image) = RecordedImage::parse(line) else {
            return false;
        };
        if !image.still_holds_what_was_written(&out_dir.join(image.rel)) {
            return false;
        }
        images += 1;
    }
    images > 0
}

#[cfg(test)]
mod tests {
    use super::*;
    use anim_core::sdf::{MaterialField, MaterialLayout, TransformOrder};

    /// Changing any one setting changes the key.
    #[test]
    fn every_setting_is_part_of_the_key() {
        let base = RenderSettings::default();
        let load = LoadOptions::default();
        let variants = render_variants(&base)
            .into_iter()
            .map(|s| (s, load.clone()))
            .chain(load_variants(&load).into_iter().map(|l| (base.clone(), l)));
        let key = |s: &RenderSettings, l: &LoadOptions| {
            frame_hash(
                b"x",
                Path::new("x.sdf"),
                &settings_fingerprint(s, l),
                &LoadOptions::default(),
            )
        };
        let unchanged = key(&base, &load);
        for (s, l) in variants {
            assert_ne!(key(&s, &l), unchanged, "{s:?} {l:?}");
        }
        assert_ne!(
            key(&base, &load),
            frame_hash(
                b"y",
                Path::new("y.sdf"),
                &settings_fingerprint(&base, &load),
                &load
            )
        );
    }

    /// `base` with each of its settings changed in turn. The struct is taken apart field by
    /// field without `..`, so a new setting does not compile here until it has a case of its
    /// own.
    fn render_variants(base: &RenderSettings) -> Vec<RenderSettings> {
        let RenderSettings {
            spp,
            error,
            max_spp,
            width,
            height,
            max_depth,
            ppm_ascii,
            out_dir,
            allow_any_output,
            max_memory,
            hdr,
            depth,
            linear,
            alpha,
        } = base.clone();
        vec![
            RenderSettings {
                spp: Some(spp.unwrap_or(1) + 1),
                ..base.clone()
            },
            RenderSettings {
                error: Some(error.unwrap_or(1.0) * 2.0),
                ..base.clone()
            },
            RenderSettings {
                max_spp: Some(max_spp.unwrap_or(1) + 1),
                ..base.clone()
            },
            RenderSettings {
                width: Some(width.unwrap_or(1) + 1),
                ..base.clone()
            },
            RenderSettings {
                height: Some(height.unwrap_or(1) + 1),
                ..base.clone()
            },
            RenderSettings {
                max_depth: max_depth + 1,
                ..base.clone()
            },
            RenderSettings {
                ppm_ascii: !ppm_ascii,
                ..base.clone()
            },
            RenderSettings {
                out_dir: Some(out_dir.unwrap_or_default().join("elsewhere")),
                ..base.clone()
            },
            RenderSettings {
                allow_any_output: !allow_any_output,
                ..base.clone()
            },
            RenderSettings {
                max_memory: max_memory / 2,
                ..base.clone()
            },
            RenderSettings {
                hdr: !hdr,
                ..base.clone()
            },
            RenderSettings {
                depth: Some(depth.map_or(16, |d| d * 2)),
                ..base.clone()
            },
            RenderSettings {
                linear: !linear,
                ..base.clone()
            },
            RenderSettings {
                alpha: !alpha,
                ..base.clone()
            },
        ]
    }

    /// `load` with each option the key covers changed in turn, taken apart as in
    /// `render_variants`.
    fn load_variants(load: &LoadOptions) -> Vec<LoadOptions> {
        let LoadOptions {
            strict,
            material_fields,
            transform_order,
            infer_transform_order,
            // The input limit decides whether a file is read at all, never what it renders.
            max_input: _,
            // Which files may be read decides whether a scene is read at all, likewise.
            allow_any_input: _,
            // The memory budget decides whether a scene is built at all, never what it
            // renders.
            max_memory: _,
            // The mesh cache decides how often a mesh file is read, never what it renders.
            meshes: _,
            // Likewise the cache of included files.
            includes: _,
        } = load.clone();
        vec![
            LoadOptions {
                strict: !strict,
                ..load.clone()
            },
            LoadOptions {
                material_fields: match material_fields {
                    MaterialLayout::Auto => MaterialLayout::Fields(vec![MaterialField::Ior]),
                    MaterialLayout::Fields(_) => MaterialLayout::Auto,
                },
                ..load.clone()
            },
            LoadOptions {
                transform_order: match transform_order {
                    TransformOrder::World => TransformOrder::Local,
                    TransformOrder::Local => TransformOrder::World,
                },
                ..load.clone()
            },
            LoadOptions {
                infer_transform_order: !infer_transform_order,
                ..load.clone()
            },
        ]
    }
}
