//! One scene file from text to image files: load it, render every image its render lines ask
//! for, and write each atomically (a reader never sees a half-written image).

use crate::diag::{Diagnostic, Severity};
use crate::limits;
use crate::render::camera::CameraError;
use crate::render::film::{self, ImageFormat};
use crate::render::{render_job, RayCounts, RenderSettings, Rendered};
use crate::scene::RenderJob;
use crate::sdf::LoadOptions;
use std::path::{Path, PathBuf};

/// What rendering one scene file produced.
#[derive(Clone, Debug)]
pub struct FileOutcome {
    pub outputs: Vec<PathBuf>,
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
pub fn output_path(scene_file: &Path, job: &RenderJob, settings: &RenderSettings) -> PathBuf {
    let base = settings.out_dir.clone().unwrap_or_else(|| {
        scene_file
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default()
    });
    base.join(&job.output)
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
    let loaded = crate::sdf::load_file(path, load)?;
    let mut warnings = loaded.diagnostics;
    // Resolve every output before rendering anything, so a bad name fails fast.
    let mut targets = Vec::with_capacity(loaded.jobs.len());
    let mut errors = Vec::new();
    for job in &loaded.jobs {
        let out = output_path(path, job, settings);
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
    if !errors.is_empty() {
        warnings.extend(errors);
        return Err(warnings);
    }
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
    let result = render_jobs(
        path,
        &loaded.jobs,
        targets,
        settings,
        progress,
        &mut warnings,
    );
    progress.end();
    match result {
        Ok((outputs, rays)) => Ok(FileOutcome {
            outputs,
            warnings,
            rays,
        }),
        Err(()) => Err(warnings),
    }
}

/// Renders and writes each job; problems go to `diagnostics`, and an error stops the file.
fn render_jobs(
    path: &Path,
    jobs: &[RenderJob],
    targets: Vec<(PathBuf, ImageFormat)>,
    settings: &RenderSettings,
    progress: &dyn ImageProgress,
    diagnostics: &mut Vec<Diagnostic>,
) -> Result<(Vec<PathBuf>, RayCounts), ()> {
    let mut outputs = Vec::with_capacity(jobs.len());
    let mut rays = RayCounts::default();
    for (job, (out, format)) in jobs.iter().zip(targets) {
        progress.image(
            &out.file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default(),
        );
        let Rendered {
            image,
            rays: counts,
            dropped,
        } = match render_job(job, settings, &|n| progress.advance(n)) {
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
        if let Err(e) = film::write_image(&out, &image, format) {
            diagnostics.push(job_error(
                path,
                job,
                format!("cannot write '{}': {e}", out.display()),
            ));
            return Err(());
        }
        rays += counts;
        outputs.push(out);
    }
    Ok((outputs, rays))
}
