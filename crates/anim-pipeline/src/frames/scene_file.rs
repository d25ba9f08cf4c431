//! One scene file from text to image files: load it, render every image its render lines ask
//! for, and write each atomically (a reader never sees a half-written image).

use super::hdr;
pub use super::output::Output;
use anim_core::diag::{Diagnostic, Severity};
use anim_core::limits;
use anim_core::load::probe;
use anim_core::render::camera::CameraError;
use anim_core::render::film::{self, ImageFormat};
use anim_core::render::{render_prepared, Prepared, RayCounts, RenderSettings, Rendered};
use anim_core::scene::RenderJob;
use anim_core::sdf::LoadOptions;
use anim_core::util::{human_bytes, write_atomically, Fnv64};
use std::io::Write as _;
use std::path::{Component, Path, PathBuf};

/// What rendering one scene file produced.
#[derive(Clone, Debug)]
pub struct FileOutcome {
    pub outputs: Vec<Output>,
    pub warnings: Vec<Diagnostic>,
    pub rays: RayCounts,
}

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

/// Progress nobody watches (frames of a directory, tests).
pub struct NoProgress;

impl ImageProgress for NoProgress {}

/// Where a job's image goes: relative paths are taken against `--out` or the scene's folder.
/// A path that would leave that folder (absolute, or climbing out with `..`) is confined to it:
/// its file name is written there instead, and the second value says so (an error under
/// `--strict`). `--allow-any-output` honours every path as written.
pub fn output_path(
    scene_file: &Path,
    job: &RenderJob,
    settings: &RenderSettings,
    strict: bool,
) -> (PathBuf, Option<Diagnostic>) {
    let base = settings.out_dir.clone().unwrap_or_else(|| {
        scene_file
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default()
    });
    if settings.allow_any_output || stays_inside(&job.output) {
        return (base.join(&job.output), None);
    }
    let Some(name) = job.output.file_name() else {
        return (base.join(&job.output), None);
    };
    let confined = base.join(name);
    let severity = if strict {
        Severity::Error
    } else {
        Severity::Warning
    };
    let folder = if settings.out_dir.is_some() {
        "the output folder (--out)"
    } else {
        "the scene's folder"
    };
    let diagnostic = job_error(
        scene_file,
        job,
        format!(
            "'{}' is outside {folder}; the image is written to '{}' instead",
            job.output.display(),
            confined.display()
        ),
    )
    .with_severity(severity)
    .with_help("pass --allow-any-output to write where the render line says");
    (confined, Some(diagnostic))
}

/// Whether a relative path stays inside the folder it is taken against (`a/../b` does,
/// `../b` and `/b` do not).
fn stays_inside(path: &Path) -> bool {
    let mut depth = 0usize;
    for component in path.components() {
        match component {
            Component::Normal(_) => depth += 1,
            Component::CurDir => {}
            Component::ParentDir => {
                let Some(up) = depth.checked_sub(1) else {
                    return false;
                };
                depth = up;
            }
            Component::RootDir | Component::Prefix(_) => return false,
        }
    }
    true
}

fn job_error(path: &Path, job: &RenderJob, message: String) -> Diagnostic {
    match &job.loc {
        Some(loc) => Diagnostic::new(Severity::Error, loc.clone(), message),
        None => Diagnostic::file_error(path, message),
    }
}

/// Loads a scene file, renders every image it asks for and writes them atomically. `Err` holds
/// every diagnostic (warnings too) once one is an error; no image is written after an error.
pub fn render_scene_file(
    path: &Path,
    load: &LoadOptions,
    settings: &RenderSettings,
    progress: &dyn ImageProgress,
) -> Result<FileOutcome, Vec<Diagnostic>> {
    let loaded = anim_core::load::load_file(path, load)?;
    let mut warnings = loaded.diagnostics;
    // A file that loads but would render one flat colour says why, instead of handing back a
    // blank image in silence: those warnings go here, after the file's own, though each is
    // found when its image is about to be rendered (with the geometry the render uses).
    let blank_at = warnings.len();
    // Resolve every output before rendering anything, so a bad name fails fast.
    let targets = match resolve_targets(path, &loaded.jobs, settings, load.strict, &mut warnings) {
        Ok(targets) => targets,
        Err(errors) => {
            let blanks = probe::blank_image_warnings(&loaded.jobs, path);
            warnings.splice(blank_at..blank_at, blanks);
            warnings.extend(errors);
            return Err(warnings);
        }
    };
    progress.begin(
        loaded
            .jobs
            .iter()
            .map(|j| {
                let (w, h, _) = settings.resolve(j);
                w as u64 * h as u64
            })
            .sum(),
    );
    let mut blanks = Vec::new();
    let result = render_jobs(
        path,
        &loaded.jobs,
        targets,
        settings,
        progress,
        (&mut blanks, &mut warnings),
    );
    progress.end();
    warnings.splice(blank_at..blank_at, blanks);
    match result {
        Ok((outputs, rays)) => Ok(FileOutcome {
            outputs,
            warnings,
            rays,
        }),
        Err(()) => Err(warnings),
    }
}

/// Writes the images of scene file `path` as copies of `source`'s, the outcome of a file whose
/// scene is the same but for the names of its images (`sdf::scene_key`): the file is loaded
/// and checked as for a render (its own warnings, its own output paths) and nothing is traced.
/// `None` when the copies cannot stand for a render: the two files turn out to ask for a
/// different number of images, or an image of `source` no longer holds what was written.
pub fn copy_scene_file(
    path: &Path,
    source: &FileOutcome,
    load: &LoadOptions,
    settings: &RenderSettings,
) -> Option<Result<FileOutcome, Vec<Diagnostic>>> {
    let loaded = match anim_core::load::load_file(path, load) {
        Ok(loaded) => loaded,
        Err(diags) => return Some(Err(diags)),
    };
    let mut warnings = loaded.diagnostics;
    let blank_at = warnings.len();
    let targets = resolve_targets(path, &loaded.jobs, settings, load.strict, &mut warnings);
    let blanks = probe::blank_image_warnings(&loaded.jobs, path);
    warnings.splice(blank_at..blank_at, blanks);
    let targets = match targets {
        Ok(targets) => targets,
        Err(errors) => {
            warnings.extend(errors);
            return Some(Err(warnings));
        }
    };
    // Each path, and whether it is a radiance file (which gets its mark).
    let paths: Vec<(PathBuf, bool)> = targets
        .into_iter()
        .flat_map(|(out, _)| {
            let hdr = settings.hdr.then(|| (film::hdr_path(&out), true));
            std::iter::once((out, false)).chain(hdr)
        })
        .collect();
    if paths.len() != source.outputs.len() {
        return None;
    }
    let mut outputs = Vec::with_capacity(paths.len());
    for ((to, is_radiance), from) in paths.into_iter().zip(&source.outputs) {
        let bytes = std::fs::read(&from.path).ok()?;
        if bytes.len() as u64 != from.bytes.len || Fnv64::of(&bytes) != from.bytes.hash {
            return None;
        }
        let written = write_atomically(&to, |w| w.write_all(&bytes));
        let marked = written.and_then(|()| match is_radiance {
            true => hdr::mark_written(&to, &from.bytes),
            false => Ok(()),
        });
        if let Err(e) = marked {
            warnings.push(Diagnostic::file_error(
                path,
                format!("cannot write '{}': {e}", to.display()),
            ));
            return Some(Err(warnings));
        }
        outputs.push(Output {
            path: to,
            bytes: from.bytes,
        });
    }
    Some(Ok(FileOutcome {
        outputs,
        warnings,
        rays: RayCounts::default(),
    }))
}

/// Why an image that needs `needed` bytes cannot be made, and what would let it: more than
/// the budget allows, or more than the process can be given now.
fn memory_refusal(needed: u64, budget: u64) -> Option<(String, &'static str)> {
    if needed > budget {
        Some((
            format!("more than the {} allowed", human_bytes(budget)),
            "--max-memory raises the limit",
        ))
    } else if !anim_core::util::can_allocate(needed) {
        Some((
            "more than the system will give this process now".to_string(),
            "a limit on the process (`ulimit -v`, a container's memory) is lower than --max-memory",
        ))
    } else {
        None
    }
}

/// Where each of `jobs` writes its image, and in which format. A path confined to its folder
/// warns in `warnings` (or is an error under `strict`); `Err` holds every error, in the order
/// of the render lines.
fn resolve_targets(
    path: &Path,
    jobs: &[RenderJob],
    settings: &RenderSettings,
    strict: bool,
    warnings: &mut Vec<Diagnostic>,
) -> Result<Vec<(PathBuf, ImageFormat)>, Vec<Diagnostic>> {
    let mut targets = Vec::with_capacity(jobs.len());
    let mut errors = Vec::new();
    for job in jobs {
        let (out, confined) = output_path(path, job, settings, strict);
        if let Some(d) = confined {
            if d.is_error() {
                errors.push(d);
            } else {
                warnings.push(d);
            }
        }
        let (width, height, _) = settings.resolve(job);
        let needed = limits::image_memory(width, height);
        let refused = memory_refusal(needed, settings.max_memory);
        if let Some((why, raise)) = refused {
            errors.push(
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
            );
            continue;
        }
        // Two images of one stem (`a.png`, `a.ppm`) would write one radiance file.
        let pfm_taken = settings.hdr
            && targets
                .iter()
                .any(|(t, _): &(PathBuf, _)| film::hdr_path(t) == film::hdr_path(&out));
        if pfm_taken {
            errors.push(job_error(
                path,
                job,
                format!(
                    "with --hdr, '{}' would overwrite the radiance file of an earlier render line",
                    film::hdr_path(&out).display()
                ),
            ));
            continue;
        }
        let pfm = film::hdr_path(&out);
        if settings.hdr && !hdr::may_replace(&pfm) {
            errors.push(
                job_error(
                    path,
                    job,
                    format!(
                        "with --hdr, the radiance file '{}' would replace a file that anim did not write",
                        pfm.display()
                    ),
                )
                .with_help(
                    "move that file away or name the image differently (or, if an interrupted render wrote it, delete it)",
                ),
            );
            continue;
        }
        match ImageFormat::for_path(&out, settings.ppm_ascii) {
            Some(format) => targets.push((out, format)),
            None => errors.push(
                job_error(
                    path,
                    job,
                    format!("cannot tell the image format of '{}'", job.output.display()),
                )
                .with_help(format!(
                    "end the file name with one of {}",
                    limits::image_extensions_list()
                )),
            ),
        }
    }
    if errors.is_empty() {
        Ok(targets)
    } else {
        Err(errors)
    }
}

/// Renders and writes each job; the warnings that an image would be blank go to `blanks`,
/// other problems to `diagnostics`, and an error stops the file.
fn render_jobs(
    path: &Path,
    jobs: &[RenderJob],
    targets: Vec<(PathBuf, ImageFormat)>,
    settings: &RenderSettings,
    progress: &dyn ImageProgress,
    (blanks, diagnostics): (&mut Vec<Diagnostic>, &mut Vec<Diagnostic>),
) -> Result<(Vec<Output>, RayCounts), ()> {
    let mut outputs = Vec::with_capacity(jobs.len());
    let mut rays = RayCounts::default();
    for (job, (out, format)) in jobs.iter().zip(targets) {
        progress.image(
            &out.file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default(),
        );
        let prepared = Prepared::new(job);
        let blank = probe::blank_image_of(&prepared);
        if let Some(blank) = &blank {
            blanks.push(probe::blank_warning(job, blank, path));
        }
        let Rendered {
            image,
            rays: counts,
            dropped,
            ..
        } = match render_prepared(&prepared, settings, &|n| progress.advance(n)) {
            Ok(r) => r,
            Err(e) => {
                let what = match e {
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
                };
                diagnostics.push(job_error(path, job, what));
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
        let bytes = match film::write_image(&out, &image, format) {
            Ok(bytes) => bytes,
            Err(e) => {
                diagnostics.push(job_error(
                    path,
                    job,
                    format!("cannot write '{}': {e}", out.display()),
                ));
                return Err(());
            }
        };
        rays += counts;
        let hdr = settings.hdr.then(|| film::hdr_path(&out));
        outputs.push(Output { path: out, bytes });
        if let Some(pfm) = hdr {
            match film::write_pfm(&pfm, &image).and_then(|bytes| {
                hdr::mark_written(&pfm, &bytes)?;
                Ok(bytes)
            }) {
                Ok(bytes) => outputs.push(Output { path: pfm, bytes }),
                Err(e) => {
                    diagnostics.push(job_error(
                        path,
                        job,
                        format!("cannot write '{}': {e}", pfm.display()),
                    ));
                    return Err(());
                }
            }
        }
    }
    Ok((outputs, rays))
}
