//! `anim render DIR`: every `.sdf` file of a directory rendered as an animation frame —
//! frames in parallel (and rows within frames), unchanged frames skipped (see [`super::cache`]),
//! one shard of the frames when asked, and a summary at the end.

use super::cache::{
    frame_hash, is_up_to_date, prune_orphan_records, record_path, settings_fingerprint,
    write_record, CACHE_DIR,
};
use super::scene_file::{copy_scene_file, render_scene_file, FileOutcome, NoProgress};
use super::Shard;
use anim_core::diag::{Diagnostic, Loc, Severity};
use anim_core::load::read_input;
use anim_core::render::RenderSettings;
use anim_core::sdf::{image_names, scene_key, LoadOptions};
use anim_core::util::remove_stale_temp_files;
use rayon::prelude::*;
use std::cmp::Ordering;
use std::collections::{BTreeMap, HashMap, HashSet};
use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read as _, Seek as _, SeekFrom, Write as _};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Which frames of a directory to render.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameOptions {
    /// Render frames even when their record says they are up to date.
    pub force: bool,
    /// Render only this shard's frames.
    pub shard: Option<Shard>,
    /// Render only the frames from the first to the last of these, counting from 0 in
    /// natural order as shards do (`--frames A..B`; for generated frames, the numbers in
    /// their names).
    pub range: Option<(usize, usize)>,
}

/// What happened to the frames of one directory.
#[derive(Debug, Default)]
pub struct Summary {
    /// `.sdf` files in the directory.
    pub total: usize,
    /// Frame file names rendered, skipped as unchanged, and failed (with their errors), each
    /// in natural order.
    pub rendered: Vec<String>,
    pub skipped: Vec<String>,
    pub failed: Vec<(String, Vec<Diagnostic>)>,
    /// Frames whose scene is an earlier frame's but for the names of its images (a hold):
    /// their images are copies of that frame's, with the earlier frame's name.
    pub copied: Vec<(String, String)>,
    /// Warnings, one per distinct message, with the number of frames that had it.
    pub warnings: Vec<(Diagnostic, usize)>,
    pub rays: u64,
    pub wall: Duration,
    pub shard: Option<Shard>,
}

impl Summary {
    /// Frames this run was responsible for (its shard).
    pub fn selected(&self) -> usize {
        self.rendered.len() + self.skipped.len() + self.failed.len() + self.copied.len()
    }
}

/// How one frame ended.
pub enum FrameOutcome {
    Rendered {
        rays: u64,
        warnings: Vec<Diagnostic>,
    },
    /// Its images are copies of those of frame `from`, whose scene is the same.
    Copied {
        from: String,
        warnings: Vec<Diagnostic>,
    },
    Failed(Vec<Diagnostic>),
}

/// Nobody watches the frames either.
impl FrameObserver for super::NoProgress {}

/// Hears how the frames of a directory come along, for a progress display or a log. Frames
/// finish on several threads at once, in any order.
pub trait FrameObserver: Sync {
    /// The frames to render are known: `to_render` will be rendered, `skipped` are unchanged.
    fn planned(&self, _to_render: usize, _skipped: usize) {}
    /// Frame `name` is done, after `took`.
    fn finished(&self, _name: &str, _outcome: &FrameOutcome, _took: Duration) {}
    /// Every frame is done.
    fn end(&self) {}
    /// Something worth saying that is not about one frame.
    fn note(&self, _message: &str) {}
}

/// Holds the frame directory's lock file, `.anim-cache/lock`, for as long as it lives: two
/// runs on one directory would otherwise write records that vouch for each other's images. A
/// second run waits for the first, after saying which process it waits for.
fn lock_frames(out_dir: &Path, observer: &dyn FrameObserver) -> Result<File, Vec<Diagnostic>> {
    let path = out_dir.join(CACHE_DIR).join("lock");
    let fail = |e: std::io::Error| {
        vec![Diagnostic::file_error(
            &path,
            format!("cannot lock the frame directory: {e}"),
        )]
    };
    std::fs::create_dir_all(out_dir.join(CACHE_DIR)).map_err(fail)?;
    let mut file = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(&path)
        .map_err(fail)?;
    match file.try_lock() {
        Ok(()) => {}
        Err(TryLockError::WouldBlock) => {
            let mut holder = String::new();
            let _ = file.read_to_string(&mut holder);
            let holder = holder.trim();
            observer.note(&format!(
                "waiting for another anim render of this directory{} to finish",
                if holder.is_empty() {
                    String::new()
                } else {
                    format!(" (process {holder})")
                }
            ));
            file.lock().map_err(fail)?;
        }
        Err(TryLockError::Error(e)) => return Err(fail(e)),
    }
    // Who holds the lock, for the message of a run that has to wait.
    file.set_len(0).map_err(fail)?;
    file.seek(SeekFrom::Start(0)).map_err(fail)?;
    write!(file, "{}", std::process::id()).map_err(fail)?;
    Ok(file)
}

/// Renders the frames of `dir` on the current rayon pool. `Err` only when the directory itself
/// is unusable; failing frames are listed in the summary.
pub fn render_dir(
    dir: &Path,
    settings: &RenderSettings,
    load: &LoadOptions,
    options: &FrameOptions,
    observer: &dyn FrameObserver,
) -> Result<Summary, Vec<Diagnostic>> {
    let start = Instant::now();
    let frames = list_frames(dir).map_err(|e| {
        vec![Diagnostic::file_error(
            dir,
            format!("cannot read the frame directory: {e}"),
        )]
    })?;
    if frames.is_empty() {
        return Err(vec![Diagnostic::file_error(
            dir,
            "no .sdf files in this directory",
        )]);
    }
    let out_dir = settings
        .out_dir
        .clone()
        .unwrap_or_else(|| dir.to_path_buf());
    let fingerprint = settings_fingerprint(settings, load);
    let _lock = lock_frames(&out_dir, observer)?;
    // Temporary files of runs that were killed mid-write; the lock keeps live ones of another
    // run of this directory away, and other processes' temporary files are kept.
    if let Err(e) = prune_orphan_records(dir, &out_dir) {
        observer.note(&format!("cannot remove old render records: {e}"));
    }
    if let Err(e) = remove_stale_temp_files(&out_dir) {
        observer.note(&format!(
            "cannot clear old temporary files in {}: {e}",
            out_dir.display()
        ));
    }

    let mut summary = Summary {
        total: frames.len(),
        shard: options.shard,
        ..Summary::default()
    };
    let todo = plan_frames(&frames, load, &fingerprint, &out_dir, options, &mut summary);
    observer.planned(todo.len(), summary.skipped.len());
    let outcomes = render_planned(&todo, &out_dir, settings, load, observer);
    observer.end();

    summary.add_outcomes(outcomes);
    summary.wall = start.elapsed();
    Ok(summary)
}

/// A frame to render: its file, name, record hash, and the earlier frame of the same scene
/// (by index into the plan) when there is one.
struct Planned {
    path: PathBuf,
    name: String,
    hash: u64,
    same_as: Option<usize>,
}

/// Decides what to render before rendering anything: checking a record is cheap, and progress
/// should count only real work. Frames skipped as unchanged, and those that cannot be read,
/// go into `summary`; the others come back in natural order.
fn plan_frames(
    frames: &[PathBuf],
    load: &LoadOptions,
    fingerprint: &str,
    out_dir: &Path,
    options: &FrameOptions,
    summary: &mut Summary,
) -> Vec<Planned> {
    let mut todo: Vec<Planned> = Vec::new();
    let mut first_of_scene: HashMap<u64, usize> = HashMap::new();
    let mut images: HashMap<PathBuf, String> = HashMap::new();
    for (i, path) in frames.iter().enumerate() {
        let in_range = options.range.is_none_or(|(a, b)| (a..=b).contains(&i));
        if !in_range || options.shard.is_some_and(|s| !s.contains(i)) {
            continue;
        }
        let name = file_name(path);
        // Read as the loader reads it: a frame larger than `--max-input` is refused unread.
        let bytes = match read_frame(path, load.max_input, &name, out_dir, &mut images) {
            Ok(bytes) => bytes,
            Err(diags) => {
                summary.failed.push((name, diags));
                continue;
            }
        };
        let hash = frame_hash(&bytes, path, fingerprint, load);
        if !options.force && is_up_to_date(out_dir, &name, hash) {
            summary.skipped.push(name);
            continue;
        }
        let scene = std::str::from_utf8(&bytes).ok().and_then(scene_key);
        let same_as = scene.and_then(|key| match first_of_scene.get(&key) {
            Some(&first) => Some(first),
            None => {
                first_of_scene.insert(key, todo.len());
                None
            }
        });
        todo.push(Planned {
            path: path.clone(),
            name,
            hash,
            same_as,
        });
    }
    todo
}

/// The bytes of frame `path` (file `name`), read as the loader reads it: a frame larger than
/// `--max-input` is refused unread. An empty frame fails (it would render the default view of
/// nothing, a blank image that looks like a frame), and so does a frame that names an image
/// an earlier frame of the run writes (`images`: image path → frame): the two would overwrite
/// each other, and every later run would render one of them again.
fn read_frame(
    path: &Path,
    max_input: u64,
    name: &str,
    out_dir: &Path,
    images: &mut HashMap<PathBuf, String>,
) -> Result<Vec<u8>, Vec<Diagnostic>> {
    let bytes = read_input(path, max_input, "file")?;
    if bytes.iter().all(u8::is_ascii_whitespace) {
        return Err(vec![Diagnostic::file_error(
            path,
            "the frame file is empty: a frame must say what to render",
        )]);
    }
    let names = std::str::from_utf8(&bytes).ok().and_then(image_names);
    let mut clashes = Vec::new();
    for image in names.unwrap_or_default() {
        let writer = images
            .entry(out_dir.join(&image.name))
            .or_insert_with(|| name.to_string());
        if writer != name {
            let loc = Loc {
                file: Arc::from(path),
                line: image.line,
                col: image.col,
            };
            let message = format!(
                "image '{}' is also written by {writer}, an earlier frame of this directory",
                image.name
            );
            clashes.push(
                Diagnostic::new(Severity::Error, loc, message)
                    .with_source(&image.text, image.width)
                    .with_help("each frame must write its own images (name them by frame, as `output: \"frame_{frame}.png\"` does)"),
            );
        }
    }
    if clashes.is_empty() {
        Ok(bytes)
    } else {
        Err(clashes)
    }
}

/// Renders the planned frames on the current rayon pool: first every frame whose scene is not
/// an earlier one's, then the copies of those (a copy whose original failed is rendered).
/// Frames are taken in natural order as threads free up (rather than rayon splitting the
/// list in halves), so an interrupted run leaves a playable prefix behind.
fn render_planned(
    todo: &[Planned],
    out_dir: &Path,
    settings: &RenderSettings,
    load: &LoadOptions,
    observer: &dyn FrameObserver,
) -> Vec<(String, FrameOutcome)> {
    let results: Mutex<Vec<(String, FrameOutcome)>> = Mutex::new(Vec::new());
    let originals: HashSet<usize> = todo.iter().filter_map(|f| f.same_as).collect();
    let rendered: Mutex<HashMap<usize, FileOutcome>> = Mutex::new(HashMap::new());
    let finish = |frame: &Planned, outcome: FrameOutcome, t0: Instant| {
        observer.finished(&frame.name, &outcome, t0.elapsed());
        if let Ok(mut r) = results.lock() {
            r.push((frame.name.clone(), outcome));
        }
    };
    let first = todo.iter().enumerate().filter(|(_, f)| f.same_as.is_none());
    first.par_bridge().for_each(|(i, frame)| {
        let t0 = Instant::now();
        let (outcome, file) = render_frame(frame, out_dir, settings, load);
        if let (Some(file), true) = (file, originals.contains(&i)) {
            if let Ok(mut r) = rendered.lock() {
                r.insert(i, file);
            }
        }
        finish(frame, outcome, t0);
    });
    let rendered = rendered.into_inner().unwrap_or_else(|e| e.into_inner());
    let copies = todo.iter().filter_map(|f| f.same_as.map(|i| (f, i)));
    copies.par_bridge().for_each(|(frame, original)| {
        let t0 = Instant::now();
        let copied = rendered.get(&original).and_then(|source| {
            copy_frame(frame, &todo[original].name, source, out_dir, settings, load)
        });
        let outcome = copied.unwrap_or_else(|| render_frame(frame, out_dir, settings, load).0);
        finish(frame, outcome, t0);
    });
    results.into_inner().unwrap_or_else(|e| e.into_inner())
}

/// Writes frame `frame`'s images as copies of `source`, the outcome of frame `from`, and
/// records them; `None` when the copies cannot stand for a render.
fn copy_frame(
    frame: &Planned,
    from: &str,
    source: &FileOutcome,
    out_dir: &Path,
    settings: &RenderSettings,
    load: &LoadOptions,
) -> Option<FrameOutcome> {
    let record = record_path(out_dir, &frame.name);
    let _ = std::fs::remove_file(&record);
    Some(
        match copy_scene_file(&frame.path, source, load, settings)? {
            Ok(file) => match write_record(&record, out_dir, frame.hash, Some(from), &file.outputs)
            {
                Ok(()) => FrameOutcome::Copied {
                    from: from.to_string(),
                    warnings: file.warnings,
                },
                Err(e) => FrameOutcome::Failed(vec![Diagnostic::file_error(
                    &record,
                    format!("copied, but cannot record it: {e}"),
                )]),
            },
            Err(diags) => FrameOutcome::Failed(diags),
        },
    )
}

/// Renders frame `frame` and records it under `out_dir`; the file's outcome comes back too
/// when it rendered, for frames of the same scene to copy.
fn render_frame(
    frame: &Planned,
    out_dir: &Path,
    settings: &RenderSettings,
    load: &LoadOptions,
) -> (FrameOutcome, Option<FileOutcome>) {
    let record = record_path(out_dir, &frame.name);
    // A stale record must not outlive an attempt to replace its images.
    let _ = std::fs::remove_file(&record);
    match render_scene_file(&frame.path, load, settings, &NoProgress) {
        Ok(file) => match write_record(&record, out_dir, frame.hash, None, &file.outputs) {
            Ok(()) => (
                FrameOutcome::Rendered {
                    rays: file.rays.total(),
                    warnings: file.warnings.clone(),
                },
                Some(file),
            ),
            Err(e) => (
                FrameOutcome::Failed(vec![Diagnostic::file_error(
                    &record,
                    format!("rendered, but cannot record it: {e}"),
                )]),
                None,
            ),
        },
        Err(diags) => (FrameOutcome::Failed(diags), None),
    }
}

impl Summary {
    /// Adds the outcomes of the frames rendered (finished in any order) in natural order, with
    /// each distinct warning once.
    fn add_outcomes(&mut self, mut results: Vec<(String, FrameOutcome)>) {
        results.sort_by(|a, b| natural_cmp(&a.0, &b.0));
        let mut warnings = Vec::new();
        for (name, outcome) in results {
            let frame_warnings = match outcome {
                FrameOutcome::Rendered { rays, warnings } => {
                    self.rays += rays;
                    self.rendered.push(name);
                    warnings
                }
                FrameOutcome::Copied { from, warnings } => {
                    self.copied.push((name, from));
                    warnings
                }
                FrameOutcome::Failed(diags) => {
                    self.failed.push((name, diags));
                    continue;
                }
            };
            warnings.extend(frame_warnings);
        }
        self.failed.sort_by(|a, b| natural_cmp(&a.0, &b.0));
        self.warnings = distinct_warnings(warnings);
    }
}

/// Each distinct warning of `warnings` (the frames' in natural order) once, with the first
/// one's location and how many times it came: frames of one animation repeat the same
/// warning. In the order of their messages.
pub fn distinct_warnings(
    warnings: impl IntoIterator<Item = Diagnostic>,
) -> Vec<(Diagnostic, usize)> {
    let mut distinct: BTreeMap<String, (Diagnostic, usize)> = BTreeMap::new();
    for d in warnings {
        distinct
            .entry(d.message.clone())
            .and_modify(|e| e.1 += 1)
            .or_insert((d, 1));
    }
    distinct.into_values().collect()
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// The `.sdf` files of `dir` (not hidden, not in subdirectories), in natural order. A symbolic
/// link is a frame when it leads to a file, and when it leads nowhere (reading it then fails
/// the frame with the reason, rather than leaving it out in silence).
pub fn list_frames(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut frames: Vec<(String, PathBuf)> = Vec::new();
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let is_sdf = Path::new(&name)
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("sdf"));
        let is_frame = match std::fs::metadata(entry.path()) {
            Ok(meta) => meta.is_file(),
            Err(_) => entry.file_type()?.is_symlink(),
        };
        if is_sdf && !name.starts_with('.') && is_frame {
            frames.push((name, entry.path()));
        }
    }
    frames.sort_by(|a, b| natural_cmp(&a.0, &b.0));
    Ok(frames.into_iter().map(|(_, p)| p).collect())
}

/// Natural order: runs of digits compare as numbers, so `frame_2` comes before `frame_10`.
/// Names equal as numbers (`f01`, `f1`) fall back to plain text order, so the order is total.
pub fn natural_cmp(a: &str, b: &str) -> Ordering {
    let (mut x, mut y) = (a, b);
    loop {
        match (x.chars().next(), y.chars().next()) {
            (None, None) => return a.cmp(b),
            (None, Some(_)) => return Ordering::Less,
            (Some(_), None) => return Ordering::Greater,
            (Some(c), Some(d)) if c.is_ascii_digit() && d.is_ascii_digit() => {
                let (nx, rx) = split_digits(x);
                let (ny, ry) = split_digits(y);
                let (tx, ty) = (nx.trim_start_matches('0'), ny.trim_start_matches('0'));
                let ord = tx.len().cmp(&ty.len()).then_with(|| tx.cmp(ty));
                if ord != Ordering::Equal {
                    return ord;
                }
                x = rx;
                y = ry;
            }
            (Some(c), Some(d)) => {
                if c != d {
                    return c.cmp(&d);
                }
                x = &x[c.len_utf8()..];
                y = &y[d.len_utf8()..];
            }
        }
    }
}

fn split_digits(s: &str) -> (&str, &str) {
    let n = s.bytes().take_while(u8::is_ascii_digit).count();
    s.split_at(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn natural_order() {
        let mut names = vec![
            "frame_10.sdf",
            "frame_2.sdf",
            "frame_1.sdf",
            "a.sdf",
            "frame_02.sdf",
        ];
        names.sort_by(|a, b| natural_cmp(a, b));
        assert_eq!(
            names,
            [
                "a.sdf",
                "frame_1.sdf",
                "frame_02.sdf",
                "frame_2.sdf",
                "frame_10.sdf"
            ]
        );
    }
}
