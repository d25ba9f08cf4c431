//! Loading a scene file as its author meant it: the reader's statements built into render
//! jobs, read in the other transform order when only that order shows something (a look
//! through each camera with the renderer's own camera and queries: [`probe`]), with every
//! diagnostic capped and quoted.

mod camera_sense;
pub mod probe;

pub use crate::input::read_input;
pub use crate::sdf::not_shown;
#[cfg(test)]
mod scale_tests;
#[cfg(test)]
mod tests;

use crate::diag::{Diagnostic, LeftOut, Severity};
use crate::limits::MAX_DIAGNOSTICS;
use crate::scene::{build_jobs, RenderJob};
use crate::sdf::ast::{Statement, StatementKind};
use crate::sdf::{self, finish_diagnostics, LoadOptions, TransformOrder};
use std::borrow::Cow;
use std::collections::HashMap;
use std::path::Path;

/// A successfully loaded file: its images to render and the warnings met on the way.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// The images to render, one job each.
    pub jobs: Vec<RenderJob>,
    /// The warnings, none of them an error: at most [`MAX_DIAGNOSTICS`], then one counting
    /// those left out. Each quotes its source line when it has a place in the file.
    pub diagnostics: Vec<Diagnostic>,
}

/// Reads and loads a file. `Err` holds every diagnostic (at least one error).
pub fn load_file(path: &Path, opts: &LoadOptions) -> Result<Loaded, Vec<Diagnostic>> {
    let bytes = read_input(path, opts.max_input, "file")?;
    // A regular file can be read again: its text is freed once parsed, before the scene is
    // built, and read again only if a diagnostic must quote one of its lines.
    let rereadable = std::fs::metadata(path).is_ok_and(|m| m.is_file());
    if !rereadable {
        return load_str(&String::from_utf8_lossy(&bytes), path, opts);
    }
    let length = bytes.len();
    // Valid UTF-8 (almost every file) is checked by the faster of the two validators.
    let text = match std::str::from_utf8(&bytes) {
        Ok(text) => Cow::Borrowed(text),
        Err(_) => String::from_utf8_lossy(&bytes),
    };
    let parsed = sdf::parse_source(&text, path, opts);
    drop(text);
    drop(bytes);
    let again = || {
        read_input(path, opts.max_input, "file")
            .ok()
            // A file changed since it was read is not quoted.
            .filter(|b| b.len() == length)
            .map(|b| Cow::Owned(String::from_utf8_lossy(&b).into_owned()))
    };
    finish_load(parsed, path, opts, again)
}

/// Builds the render jobs of a statement list (from [`sdf::parse`], or made by a program, whose
/// values are then checked here). `Err` holds every diagnostic when at least one is an error.
pub fn build(
    statements: &[Statement],
    path: &Path,
    opts: &LoadOptions,
) -> Result<Loaded, Vec<Diagnostic>> {
    let (jobs, diagnostics) = build_jobs(statements, Default::default(), path, opts, None);
    conclude(
        jobs,
        finish_diagnostics(diagnostics, opts),
        Quoting {
            path,
            opts,
            included: &[],
        },
        || None,
    )
}

/// Parses and builds a file's text. `Err` holds every diagnostic (warnings too) when at least
/// one is an error. At most [`MAX_DIAGNOSTICS`] are kept, then one saying how many were left
/// out.
pub fn load_str(text: &str, path: &Path, opts: &LoadOptions) -> Result<Loaded, Vec<Diagnostic>> {
    let parsed = sdf::parse_source(text, path, opts);
    finish_load(parsed, path, opts, || Some(Cow::Borrowed(text)))
}

/// [`load_str`] with the shapes of a flat file read as statements: what the compact form of
/// `sdf::ast::FlatShapes` must give the same result as.
#[cfg(test)]
pub(crate) fn load_str_whole(
    text: &str,
    path: &Path,
    opts: &LoadOptions,
) -> Result<Loaded, Vec<Diagnostic>> {
    let parsed = sdf::parse_source_whole(text, path, opts);
    finish_load(parsed, path, opts, || Some(Cow::Borrowed(text)))
}

/// Builds the jobs of a parsed file; `text` gives the file's text again for quoting. A frame
/// `anim generate` wrote is built with every guess turned off, as it was read.
fn finish_load<'t>(
    parsed: sdf::Parsed,
    path: &Path,
    opts: &LoadOptions,
    text: impl FnOnce() -> Option<Cow<'t, str>>,
) -> Result<Loaded, Vec<Diagnostic>> {
    let canonical;
    let opts = if parsed.generated {
        canonical = opts.without_inference();
        &canonical
    } else {
        opts
    };
    let (mut jobs, mut built) = if parsed.omissions.abandoned {
        (Vec::new(), Vec::new())
    } else {
        build_jobs(
            &parsed.statements,
            parsed.shapes,
            path,
            opts,
            Some(&parsed.omissions),
        )
    };
    if may_need_another_reading(&parsed.statements, &jobs, &built, opts) {
        let (statements, omissions) = (&parsed.statements, &parsed.omissions);
        // The camera's sense first: over the public corpus it shows what the other order
        // shows, and more (load/camera_sense.rs).
        let other =
            camera_sense::read_with_cameras_turned_back(statements, omissions, &jobs, path, opts)
                .or_else(|| {
                    is_composed(statements)
                        .then(|| read_in_other_order(statements, omissions, &jobs, path, opts))
                        .flatten()
                });
        if let Some(other) = other {
            (jobs, built) = other;
        }
    }
    // The statements are no longer needed once the jobs hold the scenes: freed before the
    // images are made.
    drop(parsed.statements);
    let mut diagnostics = parsed.diagnostics;
    diagnostics.extend(built);
    let quoting = Quoting {
        path,
        opts,
        included: &parsed.included,
    };
    conclude(jobs, finish_diagnostics(diagnostics, opts), quoting, text)
}

/// Whether the file is worth reading another way (`--transform-order auto`,
/// docs/scene-language.md §7): an image would be blank, and some object has several transform
/// operations (with one, the orders agree) or some camera is turned.
fn may_need_another_reading(
    statements: &[Statement],
    jobs: &[RenderJob],
    built: &[Diagnostic],
    opts: &LoadOptions,
) -> bool {
    if !opts.infer_transform_order || opts.strict || built.iter().any(Diagnostic::is_error) {
        return false;
    }
    (is_composed(statements) || camera_sense::turns_a_camera(statements))
        && jobs.iter().any(|job| probe::blank_image(job).is_some())
}

/// Whether some object has several transform operations, so that their order matters.
fn is_composed(statements: &[Statement]) -> bool {
    let mut ops: HashMap<&str, usize> = HashMap::new();
    statements.iter().any(|s| match &s.kind {
        StatementKind::Transform { target, ops: these } => {
            let n = ops.entry(target.name.as_str()).or_insert(0);
            *n += these.len();
            *n > 1
        }
        _ => false,
    })
}

/// The file's `statements` built again with `other_opts` (nothing inferred), when that
/// reading leaves fewer images blank than `jobs` and none blank that was not: its jobs and
/// diagnostics, and the first image of `jobs` that is blank, with why.
fn another_reading<'j>(
    statements: &[Statement],
    omissions: &sdf::Omissions,
    jobs: &'j [RenderJob],
    path: &Path,
    other_opts: &LoadOptions,
) -> Option<(Vec<RenderJob>, Vec<Diagnostic>, &'j RenderJob, String)> {
    let other_opts = LoadOptions {
        infer_transform_order: false,
        ..other_opts.clone()
    };
    let (other, built) = build_jobs(
        statements,
        Default::default(),
        path,
        &other_opts,
        Some(omissions),
    );
    if other.len() != jobs.len() || built.iter().any(Diagnostic::is_error) {
        return None;
    }
    let blank: Vec<Option<probe::Blank>> = jobs.iter().map(probe::blank_image).collect();
    let other_blank: Vec<bool> = other
        .iter()
        .map(|job| probe::blank_image(job).is_some())
        .collect();
    let newly_blank = blank
        .iter()
        .zip(&other_blank)
        .any(|(was, now)| was.is_none() && *now);
    let shown_before = blank.iter().filter(|b| b.is_none()).count();
    let shown_after = other_blank.iter().filter(|&&b| !b).count();
    if newly_blank || shown_after <= shown_before {
        return None;
    }
    let (job, reason) = jobs
        .iter()
        .zip(blank)
        .find_map(|(job, b)| b.map(|b| (job, b.reason)))?;
    Some((other, built, job, reason))
}

/// The jobs and diagnostics of the file read in the other transform order, with a warning
/// that says so, when that order leaves fewer images blank and none blank that was not: the
/// file was written for a loader that composes transforms the other way.
fn read_in_other_order(
    statements: &[Statement],
    omissions: &sdf::Omissions,
    jobs: &[RenderJob],
    path: &Path,
    opts: &LoadOptions,
) -> Option<(Vec<RenderJob>, Vec<Diagnostic>)> {
    let other = match opts.transform_order {
        TransformOrder::World => TransformOrder::Local,
        TransformOrder::Local => TransformOrder::World,
    };
    let other_opts = LoadOptions {
        transform_order: other,
        ..opts.clone()
    };
    let (other_jobs, mut built, job, reason) =
        another_reading(statements, omissions, jobs, path, &other_opts)?;
    let at = statements
        .iter()
        .find(|s| matches!(s.kind, StatementKind::Transform { .. }))
        .map_or_else(|| job.loc.clone(), |s| Some(s.loc.clone()))?;
    let (written, taken) = match other {
        TransformOrder::Local => ("M ← T·M", "M ← M·T"),
        TransformOrder::World => ("M ← M·T", "M ← T·M"),
    };
    built.push(
        Diagnostic::new(
            Severity::Warning,
            at,
            format!(
                "transforms composed as {taken}, each applied before the ones written above it: \
                 composed as {written} the image `{}` shows nothing: {reason}",
                job.output.display()
            ),
        )
        .with_help(format!(
            "this is how loaders that compose the other way read the file; pass \
             `--transform-order {}` to read it as {written}",
            match opts.transform_order {
                TransformOrder::World => "world",
                TransformOrder::Local => "local",
            }
        )),
    );
    Some((other_jobs, built))
}

/// Where the lines diagnostics quote come from: the scene file `path` and the files it
/// included (`included`, read again only while they hold what was read).
struct Quoting<'q> {
    path: &'q Path,
    opts: &'q LoadOptions,
    included: &'q [sdf::FileRead],
}

/// `Err` with the diagnostics when one is an error. They are capped first, then the kept
/// ones that lack their source line quote it from `text()` (the file's text, `None` for
/// statements made by a program, asked for only when a line is to be quoted): quoting is
/// done here so that only the diagnostics shown
/// are quoted, each copying only the part of its line it shows (a line of a million bad names
/// would otherwise be scanned once per name), in one pass over the text.
fn conclude<'t>(
    jobs: Vec<RenderJob>,
    diagnostics: Vec<Diagnostic>,
    quoting: Quoting<'_>,
    text: impl FnOnce() -> Option<Cow<'t, str>>,
) -> Result<Loaded, Vec<Diagnostic>> {
    let path = quoting.path;
    let failed = diagnostics.iter().any(Diagnostic::is_error);
    let mut diagnostics = cap(diagnostics, path);
    quote_lines(&mut diagnostics, path, text);
    // Lines of the files a scene includes are quoted from those files, confined as when
    // they were included, and only while they hold the bytes that were read: a file swapped
    // since (for a link to another file) is not quoted.
    for file in quoting.included {
        quote_lines(&mut diagnostics, file.shown(), || {
            file.read_again(path, quoting.opts)
                .map(|b| Cow::Owned(String::from_utf8_lossy(&b).into_owned()))
        });
    }
    if failed {
        Err(diagnostics)
    } else {
        Ok(Loaded { jobs, diagnostics })
    }
}

/// Quotes its source line in each diagnostic located in `path` that has none, from `text`
/// (asked for only when some diagnostic needs it).
fn quote_lines<'t>(
    diagnostics: &mut [Diagnostic],
    path: &Path,
    text: impl FnOnce() -> Option<Cow<'t, str>>,
) {
    let in_file = |d: &Diagnostic| {
        d.source_line.is_none() && d.loc.as_ref().is_some_and(|l| &*l.file == path)
    };
    let mut wanted: Vec<u32> = diagnostics
        .iter()
        .filter(|d| in_file(d))
        .filter_map(|d| d.loc.as_ref().map(|l| l.line))
        .collect();
    wanted.sort_unstable();
    wanted.dedup();
    let Some(text) = (!wanted.is_empty()).then(text).flatten() else {
        return;
    };
    let mut lines: HashMap<u32, &str> = HashMap::with_capacity(wanted.len());
    let mut next = wanted.iter().peekable();
    for (i, raw) in sdf::raw_lines(&text).enumerate() {
        let Some(&&want) = next.peek() else { break };
        if u32::try_from(i + 1) == Ok(want) {
            lines.insert(want, raw);
            next.next();
        }
    }
    for d in diagnostics.iter_mut().filter(|d| in_file(d)) {
        if let Some(line) = d.loc.as_ref().and_then(|l| lines.get(&l.line)) {
            d.quote(line);
        }
    }
}

/// The first [`MAX_DIAGNOSTICS`] diagnostics and, if there were more (kept, or left out
/// while reading: `sdf::keep_shown`), one saying how many were left out ([`not_shown`]).
fn cap(diagnostics: Vec<Diagnostic>, path: &Path) -> Vec<Diagnostic> {
    let mut left = LeftOut::default();
    let mut kept: Vec<Diagnostic> = diagnostics
        .into_iter()
        .filter(|d| {
            if d.left_out.is_some() {
                left.add(d);
            }
            d.left_out.is_none()
        })
        .collect();
    if kept.len() > MAX_DIAGNOSTICS {
        for d in kept.split_off(MAX_DIAGNOSTICS) {
            left.add(&d);
        }
    }
    if !left.is_empty() {
        kept.push(not_shown(path, left.errors, left.warnings));
    }
    kept
}

#[cfg(test)]
mod order_tests {
    use super::*;

    /// The assignment's extended example: its camera looks away from the scene when each
    /// transform applies after the ones above it.
    const EXTENDED: &str = "define material red 1 0 0 1 0 0 1 0 0 10
define shape box rbottom -100 -80 -200 100 80 -100 red
define shape sphere bsphere 0 0 -100 50 red
define light sun 500 800 0 1.0 1.0 1.0 10
ambient 0.1 0.1 0.1
define camera eye 60.0
transform eye rotate -45 0 1 0
transform eye translate 100 0 100
render eye image.ppm 48 32
";

    fn load(text: &str, infer: bool) -> Loaded {
        let opts = LoadOptions {
            infer_transform_order: infer,
            ..LoadOptions::default()
        };
        load_str(text, Path::new("x.sdf"), &opts).expect("loads")
    }

    fn blank(loaded: &Loaded) -> bool {
        probe::blank_image(&loaded.jobs[0]).is_some()
    }

    fn warned(loaded: &Loaded) -> bool {
        loaded
            .diagnostics
            .iter()
            .any(|d| d.message.contains("transforms composed as M ← M·T"))
    }

    fn camera_turned_back(loaded: &Loaded) -> bool {
        loaded
            .diagnostics
            .iter()
            .any(|d| d.message.contains("turned the opposite way from a shape"))
    }

    /// A sphere moved and then turned out of the view, in the standard order; turned in
    /// place and then moved, in the other.
    const SHAPE_ORDER: &str = "define material red 1 0 0 1 0 0 1 0 0 10
define shape sphere s 0 0 0 1 red
define light sun 0 5 5 1 1 1 1
define camera eye 60
transform s translate 0 0 -5
transform s rotate 90 0 1 0
render eye image.ppm 48 32
";

    #[test]
    fn a_file_blank_in_the_standard_order_is_read_the_other_way() {
        let standard = load(SHAPE_ORDER, false);
        assert!(blank(&standard) && !warned(&standard));
        let inferred = load(SHAPE_ORDER, true);
        assert!(!blank(&inferred) && warned(&inferred));
        assert!(!camera_turned_back(&inferred));
    }

    #[test]
    fn a_camera_that_sees_nothing_is_turned_the_course_frameworks_way_first() {
        let standard = load(EXTENDED, false);
        assert!(blank(&standard) && !camera_turned_back(&standard));
        let inferred = load(EXTENDED, true);
        assert!(!blank(&inferred) && camera_turned_back(&inferred));
        // The other order would show it too; the camera's sense is tried first.
        assert!(!warned(&inferred));
    }

    #[test]
    fn a_file_that_shows_something_keeps_the_standard_order() {
        // Two operations on the camera, so the orders differ, but it sees the scene as written.
        let text = EXTENDED.replace(
            "transform eye rotate -45 0 1 0\ntransform eye translate 100 0 100",
            "transform eye rotate 10 0 1 0\ntransform eye translate 0 0 300",
        );
        assert_ne!(text, EXTENDED);
        let loaded = load(&text, true);
        assert!(!warned(&loaded) && !camera_turned_back(&loaded));
    }

    #[test]
    fn generated_frames_are_never_read_the_other_way() {
        let text = format!(
            "# Frame 3 of 120 (t = 0.125 s at 24 fps), generated from orbit.ron {} 0.1.0.\n{EXTENDED}",
            sdf::GENERATED_FRAME_SIGNATURE
        );
        assert!(sdf::is_generated_frame(&text));
        let loaded = load(&text, true);
        assert!(blank(&loaded) && !warned(&loaded) && !camera_turned_back(&loaded));
    }
}
