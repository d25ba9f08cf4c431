//! The one way from a scene file to encoded images, in memory: load the file, refuse an image
//! larger than the memory budget, look for images that would show nothing, render, say which
//! shapes were dropped, and encode. `anim render` writes what comes out (`scene_file`), frame
//! directories too, and `anim preview` serves it: the [`ImageSink`] each hands in decides which
//! images it wants, where they go and how they are encoded.

use anim_core::diag::{Diagnostic, Severity};
use anim_core::limits;
use anim_core::load::probe;
use anim_core::render::camera::CameraError;
use anim_core::render::film::{self, Coverage, Encoding, ImageFormat};
use anim_core::render::shot::Shot;
use anim_core::render::{render_prepared, Prepared, RayCounts, RenderSettings, Rendered};
use anim_core::scene::RenderJob;
use anim_core::sdf::LoadOptions;
use anim_core::util::human_bytes;
use std::path::Path;

/// Hears how the images of one file come along, for a progress display.
pub trait ImageProgress: Sync {
    /// Called once, with the pixels of every image the file asks for.
    fn begin(&self, _total_pixels: u64) {}
    /// An image starts; `name` is its file name.
    fn image(&self, _name: &str) {}
    /// `pixels` more pixels are done.
    fn advance(&self, _pixels: u64) {}
    /// The file is done, or has failed.
    fn end(&self) {}
}

/// Progress nobody watches (frames of a directory, the preview, tests).
pub struct NoProgress;

impl ImageProgress for NoProgress {}

/// One image, encoded.
#[derive(Clone, Debug)]
pub struct Encoded {
    /// The image file's bytes, in the format the sink asked for.
    pub image: Vec<u8>,
    /// The radiance before tone mapping as PFM bytes, under `--hdr`.
    pub radiance: Option<Vec<u8>>,
}

/// What the caller of [`render_to_memory`] decides about each image of a file.
pub trait ImageSink {
    /// What the sink keeps about an image between its check and its delivery.
    type Target;
    /// The settings the file's `index`th image (of `job`) renders with; `None` leaves it out.
    fn settings(&self, index: usize, job: &RenderJob) -> Option<RenderSettings>;
    /// Checks where `job`'s image goes, before any image of the file is rendered, and says how
    /// to encode it. Warnings go to `warnings`; an error keeps every image of the file from
    /// being rendered.
    fn check(
        &mut self,
        job: &RenderJob,
        settings: &RenderSettings,
        warnings: &mut Vec<Diagnostic>,
    ) -> Result<(Self::Target, ImageFormat), Vec<Diagnostic>>;
    /// Takes `job`'s encoded image as soon as it is made; an error stops the file.
    fn take(
        &mut self,
        job: &RenderJob,
        target: Self::Target,
        image: Encoded,
    ) -> Result<(), Vec<Diagnostic>>;
}

/// What rendering a file's images into memory said, beside the images the sink took.
#[derive(Clone, Debug)]
pub struct Drawn {
    pub warnings: Vec<Diagnostic>,
    pub rays: RayCounts,
    /// For a frame of a shot whose frame before it followed (`Shot::render`): the pixels it
    /// traced again, of all its pixels.
    pub retraced: Option<(u64, u64)>,
}

/// An image that passed every check, to render.
pub(super) struct Planned<'j, T> {
    pub job: &'j RenderJob,
    pub settings: RenderSettings,
    pub target: T,
    pub encoding: Encoding,
}

/// Loads scene file `path` and renders the images `sink` wants into memory, handing each to
/// the sink as it is encoded. Warnings come in the order `anim render` prints them: the file's
/// own, then those that an image would show nothing (each found when its image is about to
/// be rendered, with the geometry the render uses), then the rest. `Err` holds every
/// diagnostic (warnings too) once one is an error; the sink takes no image after an error.
pub fn render_to_memory<S: ImageSink>(
    path: &Path,
    load: &LoadOptions,
    sink: &mut S,
    progress: &dyn ImageProgress,
) -> Result<Drawn, Vec<Diagnostic>> {
    render_to_memory_in(path, load, sink, progress, None)
}

/// [`render_to_memory`] of a file that is the next frame of `shot` (when there is one and
/// the file has one image): it traces again only what may differ from the shot's frame
/// before.
pub fn render_to_memory_in<S: ImageSink>(
    path: &Path,
    load: &LoadOptions,
    sink: &mut S,
    progress: &dyn ImageProgress,
    shot: Option<&mut Shot>,
) -> Result<Drawn, Vec<Diagnostic>> {
    let loaded = anim_core::load::load_file(path, load)?;
    let mut warnings = loaded.diagnostics;
    let blank_at = warnings.len();
    // Every image is checked before anything renders, so a bad one fails fast.
    let planned = match plan(path, &loaded.jobs, sink, &mut warnings) {
        Ok(planned) => planned,
        Err(errors) => {
            let blanks = blank_warnings(path, &loaded.jobs, sink);
            warnings.splice(blank_at..blank_at, blanks);
            warnings.extend(errors);
            return Err(warnings);
        }
    };
    progress.begin(
        planned
            .iter()
            .map(|p| {
                let (w, h, _) = p.settings.resolve(p.job);
                w as u64 * h as u64
            })
            .sum(),
    );
    let mut blanks = Vec::new();
    let shot = shot.filter(|_| planned.len() == 1);
    let mut retraced = None;
    let told = Told {
        blanks: &mut blanks,
        diagnostics: &mut warnings,
        retraced: &mut retraced,
    };
    let result = render_planned(path, planned, sink, progress, told, shot);
    progress.end();
    warnings.splice(blank_at..blank_at, blanks);
    match result {
        Ok(rays) => Ok(Drawn {
            warnings,
            rays,
            retraced,
        }),
        Err(()) => Err(warnings),
    }
}

/// The warnings that an image `sink` wants of `jobs` (of scene file `path`) would show
/// nothing, found without rendering: for a file that renders nothing after all.
pub(super) fn blank_warnings<S: ImageSink>(
    path: &Path,
    jobs: &[RenderJob],
    sink: &S,
) -> Vec<Diagnostic> {
    jobs.iter()
        .enumerate()
        .filter(|(i, job)| sink.settings(*i, job).is_some())
        .filter_map(|(_, job)| Some(probe::blank_warning(job, &probe::blank_image(job)?, path)))
        .collect()
}

/// Checks every image `sink` wants of `jobs` (of scene file `path`) before anything renders:
/// an image too large for the memory budget is refused before anything else about it is
/// judged, then the sink checks where it goes, then its format must hold what the settings
/// ask (`--depth`, `--linear`, `--alpha`). `Err` holds every error, in the order of the
/// render lines.
pub(super) fn plan<'j, S: ImageSink>(
    path: &Path,
    jobs: &'j [RenderJob],
    sink: &mut S,
    warnings: &mut Vec<Diagnostic>,
) -> Result<Vec<Planned<'j, S::Target>>, Vec<Diagnostic>> {
    let mut planned = Vec::with_capacity(jobs.len());
    let mut errors = Vec::new();
    for (i, job) in jobs.iter().enumerate() {
        let Some(settings) = sink.settings(i, job) else {
            continue;
        };
        if let Some(refusal) = memory_refusal(path, job, &settings) {
            errors.push(refusal);
            continue;
        }
        let checked = sink
            .check(job, &settings, warnings)
            .and_then(|(target, format)| {
                let (depth, linear, alpha) = (settings.depth, settings.linear, settings.alpha);
                Encoding::new(format, depth, linear, alpha)
                    .map(|encoding| (target, encoding))
                    .map_err(|why| {
                        vec![job_error(
                            path,
                            job,
                            format!("'{}': {why}", job.output.display()),
                        )]
                    })
            });
        match checked {
            Ok((target, encoding)) => planned.push(Planned {
                job,
                settings,
                target,
                encoding,
            }),
            Err(e) => errors.extend(e),
        }
    }
    if errors.is_empty() {
        Ok(planned)
    } else {
        Err(errors)
    }
}

/// The error that `job`'s image, at the size `settings` gives it, needs more memory than the
/// budget allows or than the process can be given now; `None` when it fits.
fn memory_refusal(path: &Path, job: &RenderJob, settings: &RenderSettings) -> Option<Diagnostic> {
    let (width, height, _) = settings.resolve(job);
    let needed = limits::image_memory(width, height);
    let (why, raise) = if needed > settings.max_memory {
        (
            format!("more than the {} allowed", human_bytes(settings.max_memory)),
            "--max-memory raises the limit",
        )
    } else if !anim_core::util::can_allocate(needed) {
        (
            "more than the system will give this process now".to_string(),
            "a limit on the process (`ulimit -v`, a container's memory) is lower than --max-memory",
        )
    } else {
        return None;
    };
    Some(
        job_error(
            path,
            job,
            format!(
                "a {width}×{height} image needs about {} to render, {why}",
                human_bytes(needed)
            ),
        )
        .with_help(format!(
            "render it smaller, or in tiles (several cameras, each seeing part of the view); {raise}"
        )),
    )
}

/// An error about `job` of scene file `path`: at its render line, else at the file.
pub(super) fn job_error(path: &Path, job: &RenderJob, message: String) -> Diagnostic {
    match &job.loc {
        Some(loc) => Diagnostic::new(Severity::Error, loc.clone(), message),
        None => Diagnostic::file_error(path, message),
    }
}

/// What rendering a file's images tells besides the images: the warnings that an image shows
/// nothing, the other problems, and what a frame of a shot traced again.
struct Told<'a> {
    blanks: &'a mut Vec<Diagnostic>,
    diagnostics: &'a mut Vec<Diagnostic>,
    retraced: &'a mut Option<(u64, u64)>,
}

/// Renders, encodes and hands over each planned image (through `shot`, the one image of a
/// frame of a shot); what else it finds goes to `told`, and an error stops the file.
fn render_planned<S: ImageSink>(
    path: &Path,
    planned: Vec<Planned<'_, S::Target>>,
    sink: &mut S,
    progress: &dyn ImageProgress,
    told: Told,
    mut shot: Option<&mut Shot>,
) -> Result<RayCounts, ()> {
    let Told {
        blanks,
        diagnostics,
        retraced,
    } = told;
    let mut rays = RayCounts::default();
    for p in planned {
        let job = p.job;
        progress.image(
            &job.output
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default(),
        );
        let prepared = Prepared::new(job);
        let blank = probe::blank_image_of(&prepared);
        if let Some(blank) = &blank {
            blanks.push(probe::blank_warning(job, blank, path));
        }
        let on_pixels = |n| progress.advance(n);
        let rendered = match shot.as_deref_mut() {
            Some(shot) => shot.render(&prepared, &p.settings, &on_pixels).map(|f| {
                let pixels = f.rendered.image.pixels.len() as u64;
                *retraced = f.follows.then_some((f.retraced, pixels));
                f.rendered
            }),
            None => render_prepared(&prepared, &p.settings, &on_pixels),
        };
        let Rendered {
            image,
            coverage,
            rays: counts,
            dropped,
            ..
        } = match rendered {
            Ok(r) => r,
            Err(e) => {
                diagnostics.push(job_error(path, job, camera_problem(job, e)));
                return Err(());
            }
        };
        if blank.is_none() {
            // Something shows, yet a person may see nothing: say why.
            if let Some((share, reason)) = probe::one_colour(&prepared, &image) {
                blanks.push(probe::one_colour_warning(job, share, &reason, path));
            }
        }
        for d in dropped {
            let message = format!(
                "shape '{}' is degenerate once transformed (too thin or too small to intersect) and is not drawn",
                d.instance
            );
            diagnostics.push(match d.loc {
                Some(loc) => Diagnostic::new(Severity::Warning, loc, message),
                None => job_error(path, job, message).with_severity(Severity::Warning),
            });
        }
        let coverage = Coverage {
            fraction: &coverage,
            background: job.scene.background,
        };
        let encoded = match film::encode_image(&image, Some(&coverage), p.encoding) {
            Ok(bytes) => Encoded {
                image: bytes,
                radiance: p.settings.hdr.then(|| film::encode_pfm(&image)),
            },
            Err(e) => {
                let what = format!("cannot encode '{}': {e}", job.output.display());
                diagnostics.push(job_error(path, job, what));
                return Err(());
            }
        };
        if let Err(errors) = sink.take(job, p.target, encoded) {
            diagnostics.extend(errors);
            return Err(());
        }
        rays += counts;
    }
    Ok(rays)
}

/// Why `job`'s camera cannot render.
fn camera_problem(job: &RenderJob, e: CameraError) -> String {
    match e {
        CameraError::Fov => format!(
            "camera '{}' has a field of view of {}°; it must be {}",
            job.camera.name,
            job.camera.fov_x_deg,
            limits::FOV_RULE
        ),
        CameraError::Orientation => format!(
            "camera '{}' has no usable orientation: its direction is zero or parallel to its up vector",
            job.camera.name
        ),
    }
}
