//! `anim render DIR`: every `.sdf` file of a directory rendered as an animation frame —
//! frames in parallel (and tiles within frames), unchanged frames skipped, one shard of the
//! frames when asked, and a summary at the end.
//!
//! Skipping: after a frame's images are written (atomically, by the renderer) a small record
//! `.anim-cache/<frame>.sdf.hash` is written (atomically too) beside them, holding a hash of
//! the frame's SDF bytes, every setting that changes pixels and anim's version, and the size
//! of each image. A frame is skipped only when its record matches and its images are there
//! with those sizes. The record is removed before a frame is rendered again and written only
//! after its images are complete, so an interrupted run never leaves a record for an image
//! that is not finished: the next run renders that frame again.

use crate::cli::{RenderArgs, Shard};
use crate::diag::Diagnostic;
use crate::render::film::write_atomically;
use crate::render::{render_file, RenderSettings};
use crate::sdf::LoadOptions;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use std::cmp::Ordering;
use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicUsize, Ordering as AtomicOrdering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Directory of render records, beside the images.
pub const CACHE_DIR: &str = ".anim-cache";

/// Bumped when the record format or the meaning of the hash changes.
const RECORD_VERSION: u32 = 1;

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
    /// Warnings, one per distinct message, with the number of frames that had it.
    pub warnings: Vec<(Diagnostic, usize)>,
    pub rays: u64,
    pub wall: Duration,
    pub shard: Option<Shard>,
}

impl Summary {
    /// Frames this run was responsible for (its shard).
    pub fn selected(&self) -> usize {
        self.rendered.len() + self.skipped.len() + self.failed.len()
    }
}

/// `anim render DIR`: renders the directory, prints the summary, and exits non-zero if any
/// frame failed (or the directory cannot be read or holds no `.sdf` file).
pub fn render_dir(dir: &Path, args: &RenderArgs) -> ExitCode {
    match run(dir, args) {
        Ok(summary) => {
            print_summary(dir, &summary, args.quiet);
            if summary.failed.is_empty() {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            }
        }
        Err(d) => {
            eprintln!("{d}");
            ExitCode::FAILURE
        }
    }
}

/// Renders the frames of `dir` (see the module doc). `Err` only when the directory itself is
/// unusable; failing frames are listed in the summary.
pub fn run(dir: &Path, args: &RenderArgs) -> Result<Summary, Box<Diagnostic>> {
    let start = Instant::now();
    let frames = list_frames(dir).map_err(|e| {
        Box::new(Diagnostic::file_error(
            dir,
            format!("cannot read the frame directory: {e}"),
        ))
    })?;
    if frames.is_empty() {
        return Err(Box::new(Diagnostic::file_error(
            dir,
            "no .sdf files in this directory",
        )));
    }
    let settings = args.settings();
    let load = args.scene.load_options();
    let out_dir = settings
        .out_dir
        .clone()
        .unwrap_or_else(|| dir.to_path_buf());
    let fingerprint = settings_fingerprint(&settings, &load);

    let mut summary = Summary {
        total: frames.len(),
        shard: args.shard,
        ..Summary::default()
    };
    // Decide what to render first: checking a record is cheap, and the progress bar should
    // count only real work.
    let mut todo = Vec::new();
    for (i, path) in frames.iter().enumerate() {
        if args.shard.is_some_and(|s| !s.contains(i)) {
            continue;
        }
        let name = file_name(path);
        let hash = match std::fs::read(path) {
            Ok(bytes) => frame_hash(&bytes, &fingerprint),
            Err(e) => {
                summary.failed.push((
                    name,
                    vec![Diagnostic::file_error(
                        path,
                        format!("cannot read file: {e}"),
                    )],
                ));
                continue;
            }
        };
        if !args.force && is_up_to_date(&out_dir, &name, hash) {
            summary.skipped.push(name);
        } else {
            todo.push((path.clone(), name, hash));
        }
    }

    let progress = Progress::new(todo.len(), summary.skipped.len(), args.quiet);
    let results: Mutex<Vec<(String, FrameResult)>> = Mutex::new(Vec::new());
    let render_all = || {
        // Frames are taken in natural order as threads free up (rather than rayon splitting
        // the list in halves), so an interrupted run leaves a playable prefix behind.
        todo.iter().par_bridge().for_each(|(path, name, hash)| {
            let t0 = Instant::now();
            let record = record_path(&out_dir, name);
            // A stale record must not outlive an attempt to replace its images.
            let _ = std::fs::remove_file(&record);
            let result = match render_file(path, &load, &settings, false) {
                Ok(outcome) => match write_record(&record, &out_dir, *hash, &outcome.outputs) {
                    Ok(()) => FrameResult::Rendered {
                        rays: outcome.rays.total(),
                        warnings: outcome.warnings,
                    },
                    Err(e) => FrameResult::Failed(vec![Diagnostic::file_error(
                        &record,
                        format!("rendered, but cannot record it: {e}"),
                    )]),
                },
                Err(diags) => FrameResult::Failed(diags),
            };
            progress.done(name, &result, t0.elapsed());
            if let Ok(mut r) = results.lock() {
                r.push((name.clone(), result));
            }
        });
    };
    match rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.unwrap_or(0) as usize)
        .build()
    {
        Ok(pool) => pool.install(render_all),
        // Without a pool of our own (the system refused threads) the global one still works.
        Err(_) => render_all(),
    }
    progress.finish();

    let mut results = results.into_inner().unwrap_or_else(|e| e.into_inner());
    results.sort_by(|a, b| natural_cmp(&a.0, &b.0));
    let mut warnings: BTreeMap<String, (Diagnostic, usize)> = BTreeMap::new();
    for (name, result) in results {
        match result {
            FrameResult::Rendered { rays, warnings: w } => {
                summary.rays += rays;
                summary.rendered.push(name);
                for d in w {
                    // Frames of one animation repeat the same warning: show it once, with
                    // the first frame's location and a count.
                    warnings
                        .entry(d.message.clone())
                        .and_modify(|e| e.1 += 1)
                        .or_insert((d, 1));
                }
            }
            FrameResult::Failed(diags) => summary.failed.push((name, diags)),
        }
    }
    summary.failed.sort_by(|a, b| natural_cmp(&a.0, &b.0));
    summary.warnings = warnings.into_values().collect();
    summary.wall = start.elapsed();
    Ok(summary)
}

enum FrameResult {
    Rendered {
        rays: u64,
        warnings: Vec<Diagnostic>,
    },
    Failed(Vec<Diagnostic>),
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// The `.sdf` files of `dir` (not hidden, not in subdirectories), in natural order.
pub fn list_frames(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut frames: Vec<(String, PathBuf)> = Vec::new();
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let is_sdf = Path::new(&name)
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("sdf"));
        if is_sdf && !name.starts_with('.') && entry.file_type()?.is_file() {
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

/// Where the render record of frame file `sdf_name` is kept, for images in `out_dir`.
pub fn record_path(out_dir: &Path, sdf_name: &str) -> PathBuf {
    out_dir.join(CACHE_DIR).join(format!("{sdf_name}.hash"))
}

/// FNV-1a, 64 bits: change detection, not security.
struct Fnv(u64);

impl Fnv {
    fn new() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}

/// Every setting that can change a frame's pixels (or whether it renders at all), as text.
fn settings_fingerprint(s: &RenderSettings, load: &LoadOptions) -> String {
    format!(
        "record={RECORD_VERSION};anim={};spp={:?};width={:?};height={:?};max_depth={};ppm_ascii={};strict={};material_fields={:?};transform_order={:?}",
        env!("CARGO_PKG_VERSION"),
        s.spp,
        s.width,
        s.height,
        s.max_depth,
        s.ppm_ascii,
        load.strict,
        load.material_fields,
        load.transform_order,
    )
}

fn frame_hash(sdf: &[u8], fingerprint: &str) -> u64 {
    let mut h = Fnv::new();
    h.write(fingerprint.as_bytes());
    // A separator that cannot occur in the fingerprint keeps the two parts apart.
    h.write(&[0]);
    h.write(sdf);
    h.0
}

/// The record's text: a header, the hash, and each image with its size in bytes.
fn record_text(hash: u64, out_dir: &Path, outputs: &[PathBuf]) -> std::io::Result<String> {
    let mut text = format!("anim-render-record {RECORD_VERSION}\nhash {hash:016x}\n");
    for out in outputs {
        let size = std::fs::metadata(out)?.len();
        let rel = out.strip_prefix(out_dir).unwrap_or(out);
        text.push_str(&format!("image {size} {}\n", rel.display()));
    }
    Ok(text)
}

fn write_record(
    record: &Path,
    out_dir: &Path,
    hash: u64,
    outputs: &[PathBuf],
) -> std::io::Result<()> {
    if let Some(parent) = record.parent() {
        std::fs::create_dir_all(parent)?;
    }
    let text = record_text(hash, out_dir, outputs)?;
    write_atomically(record, |w| w.write_all(text.as_bytes()))
}

/// Whether frame `name`'s record matches `hash` and every image it lists is there, whole.
fn is_up_to_date(out_dir: &Path, name: &str, hash: u64) -> bool {
    let Ok(text) = std::fs::read_to_string(record_path(out_dir, name)) else {
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
    for line in lines {
        let Some(rest) = line.strip_prefix("image ") else {
            return false;
        };
        let Some((size, rel)) = rest.split_once(' ') else {
            return false;
        };
        let Ok(size) = size.parse::<u64>() else {
            return false;
        };
        match std::fs::metadata(out_dir.join(rel)) {
            Ok(m) if m.is_file() && m.len() == size => images += 1,
            _ => return false,
        }
    }
    images > 0
}

/// Progress: a bar on a terminal; one plain line per frame otherwise (logs, Slurm output).
struct Progress {
    bar: Option<ProgressBar>,
    total: usize,
    done: AtomicUsize,
    quiet: bool,
}

impl Progress {
    fn new(total: usize, skipped: usize, quiet: bool) -> Progress {
        let bar = (!quiet && total > 0 && std::io::stderr().is_terminal()).then(|| {
            let bar = ProgressBar::with_draw_target(Some(total as u64), ProgressDrawTarget::stderr());
            if let Ok(style) = ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] [{bar:30}] {pos}/{len} frames  {per_sec}  ETA {eta}  {msg}",
            ) {
                bar.set_style(style.progress_chars("=> "));
            }
            if skipped > 0 {
                bar.set_message(format!("({skipped} unchanged, skipped)"));
            }
            bar.enable_steady_tick(Duration::from_millis(200));
            bar
        });
        if !quiet && bar.is_none() && skipped > 0 {
            eprintln!("skipping {skipped} unchanged frame{}", plural(skipped));
        }
        Progress {
            bar,
            total,
            done: AtomicUsize::new(0),
            quiet,
        }
    }

    fn done(&self, name: &str, result: &FrameResult, took: Duration) {
        let n = self.done.fetch_add(1, AtomicOrdering::Relaxed) + 1;
        let width = self.total.to_string().len();
        let line = match result {
            FrameResult::Rendered { .. } => {
                format!(
                    "[{n:>width$}/{}] rendered {name} in {:.2} s",
                    self.total,
                    took.as_secs_f64()
                )
            }
            FrameResult::Failed(diags) => {
                let first = diags
                    .iter()
                    .find(|d| d.is_error())
                    .map(|d| d.to_string().lines().next().unwrap_or_default().to_string())
                    .unwrap_or_default();
                format!("[{n:>width$}/{}] FAILED {name}: {first}", self.total)
            }
        };
        match &self.bar {
            Some(bar) => {
                if matches!(result, FrameResult::Failed(_)) {
                    bar.println(line);
                }
                bar.inc(1);
            }
            None if !self.quiet => eprintln!("{line}"),
            None => {}
        }
    }

    fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

fn plural(n: usize) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}

/// Prints warnings (unless quiet), failures with their located errors, and the totals.
pub fn print_summary(dir: &Path, s: &Summary, quiet: bool) {
    if !quiet {
        for (d, count) in &s.warnings {
            if *count > 1 {
                eprintln!(
                    "{d}\n  (and in {} other frame{})",
                    count - 1,
                    plural(count - 1)
                );
            } else {
                eprintln!("{d}");
            }
        }
    }
    if !s.failed.is_empty() {
        eprintln!("{} frame{} failed:", s.failed.len(), plural(s.failed.len()));
        for (name, diags) in &s.failed {
            eprintln!("  {name}:");
            for d in diags.iter().filter(|d| d.is_error() || !quiet) {
                for line in d.to_string().lines() {
                    eprintln!("    {line}");
                }
            }
        }
    }
    if quiet && s.failed.is_empty() {
        return;
    }
    let secs = s.wall.as_secs_f64();
    let shard = match s.shard {
        Some(sh) => format!(
            "shard {}/{} ({} of {} frames): ",
            sh.index,
            sh.count,
            s.selected(),
            s.total
        ),
        None => String::new(),
    };
    let rates = if secs > 0.0 && !s.rendered.is_empty() {
        format!(
            " ({:.2} frames/s, {:.2} Mrays/s)",
            s.rendered.len() as f64 / secs,
            s.rays as f64 / secs / 1e6
        )
    } else {
        String::new()
    };
    eprintln!(
        "{}: {shard}{} rendered, {} skipped (unchanged), {} failed in {:.2} s{rates}",
        dir.display(),
        s.rendered.len(),
        s.skipped.len(),
        s.failed.len(),
        secs
    );
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

    #[test]
    fn fnv_known_values() {
        // Published FNV-1a 64 test vectors.
        let mut h = Fnv::new();
        assert_eq!(h.0, 0xcbf29ce484222325);
        h.write(b"a");
        assert_eq!(h.0, 0xaf63dc4c8601ec8c);
        let mut h = Fnv::new();
        h.write(b"foobar");
        assert_eq!(h.0, 0x85944171f73967e8);
    }

    #[test]
    fn hash_sees_settings_and_content() {
        let load = LoadOptions::default();
        let a = settings_fingerprint(&RenderSettings::default(), &load);
        let b = settings_fingerprint(
            &RenderSettings {
                spp: Some(9),
                ..RenderSettings::default()
            },
            &load,
        );
        assert_ne!(frame_hash(b"x", &a), frame_hash(b"x", &b));
        assert_ne!(frame_hash(b"x", &a), frame_hash(b"y", &a));
    }
}
