//! One scene file from text to image files: every image its render lines ask for, rendered
//! into memory by `draw`, each written atomically (a reader never sees a half-written image)
//! to where its render line says, confined to the scene's folder.

use super::draw::{blank_warnings, job_error, plan, render_to_memory_in, Encoded, ImageSink};
pub use super::draw::{ImageProgress, NoProgress};
use super::hdr;
pub use super::output::Output;
use anim_core::diag::{Diagnostic, Severity};
use anim_core::limits;
use anim_core::render::film::{self, ImageFormat};
use anim_core::render::shot::Shot;
use anim_core::render::{RayCounts, RenderSettings};
use anim_core::scene::RenderJob;
use anim_core::sdf::LoadOptions;
use anim_core::util::{write_atomically, Fnv64};
use std::io::Write as _;
use std::path::{Component, Path, PathBuf};

/// What rendering one scene file produced.
#[derive(Clone, Debug)]
pub struct FileOutcome {
    pub outputs: Vec<Output>,
    pub warnings: Vec<Diagnostic>,
    pub rays: RayCounts,
    /// For a frame traced from the frame before in a shot: the pixels it traced again, of all
    /// its pixels.
    pub retraced: Option<(u64, u64)>,
}

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

/// Loads a scene file, renders every image it asks for and writes them atomically. `Err` holds
/// every diagnostic (warnings too) once one is an error; no image is written after an error.
pub fn render_scene_file(
    path: &Path,
    load: &LoadOptions,
    settings: &RenderSettings,
    progress: &dyn ImageProgress,
) -> Result<FileOutcome, Vec<Diagnostic>> {
    render_scene_file_in(path, load, settings, progress, None)
}

/// [`render_scene_file`] of a file that is the next frame of `shot`, if any
/// (`draw::render_to_memory_in`).
pub(super) fn render_scene_file_in(
    path: &Path,
    load: &LoadOptions,
    settings: &RenderSettings,
    progress: &dyn ImageProgress,
    shot: Option<&mut Shot>,
) -> Result<FileOutcome, Vec<Diagnostic>> {
    let mut sink = ImageFiles::new(path, settings, load.strict);
    let drawn = render_to_memory_in(path, load, &mut sink, progress, shot)?;
    Ok(FileOutcome {
        outputs: sink.outputs,
        warnings: drawn.warnings,
        rays: drawn.rays,
        retraced: drawn.retraced,
    })
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
    let mut sink = ImageFiles::new(path, settings, load.strict);
    let planned = plan(path, &loaded.jobs, &mut sink, &mut warnings);
    let blanks = blank_warnings(path, &loaded.jobs, &sink);
    warnings.splice(blank_at..blank_at, blanks);
    let planned = match planned {
        Ok(planned) => planned,
        Err(errors) => {
            warnings.extend(errors);
            return Some(Err(warnings));
        }
    };
    // Each path, and whether it is a radiance file (which gets its mark).
    let paths: Vec<(PathBuf, bool)> = planned
        .into_iter()
        .flat_map(|p| {
            let out = p.target;
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
        retraced: None,
    }))
}

/// Where `anim render` puts a file's images: files beside the scene (or in `--out`), each
/// written atomically as soon as it is encoded, with its radiance file under `--hdr`.
struct ImageFiles<'a> {
    path: &'a Path,
    settings: &'a RenderSettings,
    strict: bool,
    /// The images accepted so far: two of one stem would write one radiance file.
    accepted: Vec<PathBuf>,
    outputs: Vec<Output>,
}

impl<'a> ImageFiles<'a> {
    fn new(path: &'a Path, settings: &'a RenderSettings, strict: bool) -> Self {
        ImageFiles {
            path,
            settings,
            strict,
            accepted: Vec::new(),
            outputs: Vec::new(),
        }
    }

    fn write(
        &mut self,
        job: &RenderJob,
        to: PathBuf,
        bytes: &[u8],
        radiance: bool,
    ) -> Result<(), Vec<Diagnostic>> {
        let written = film::write_encoded(&to, bytes).and_then(|written| {
            if radiance {
                hdr::mark_written(&to, &written)?;
            }
            Ok(written)
        });
        match written {
            Ok(bytes) => {
                self.outputs.push(Output { path: to, bytes });
                Ok(())
            }
            Err(e) => Err(vec![job_error(
                self.path,
                job,
                format!("cannot write '{}': {e}", to.display()),
            )]),
        }
    }
}

impl ImageSink for ImageFiles<'_> {
    type Target = PathBuf;

    fn settings(&self, _index: usize, _job: &RenderJob) -> Option<RenderSettings> {
        Some(self.settings.clone())
    }

    /// Where the image goes and in which format. A path confined to its folder warns (or is
    /// an error under `--strict`); under `--hdr`, the radiance file must be one of its own.
    fn check(
        &mut self,
        job: &RenderJob,
        settings: &RenderSettings,
        warnings: &mut Vec<Diagnostic>,
    ) -> Result<(PathBuf, ImageFormat), Vec<Diagnostic>> {
        let path = self.path;
        let mut errors = Vec::new();
        let (out, confined) = output_path(path, job, settings, self.strict);
        if let Some(d) = confined {
            if d.is_error() {
                errors.push(d);
            } else {
                warnings.push(d);
            }
        }
        let pfm = film::hdr_path(&out);
        if settings.hdr && self.accepted.iter().any(|t| film::hdr_path(t) == pfm) {
            errors.push(job_error(
                path,
                job,
                format!(
                    "with --hdr, '{}' would overwrite the radiance file of an earlier render line",
                    pfm.display()
                ),
            ));
            return Err(errors);
        }
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
            return Err(errors);
        }
        let Some(format) = ImageFormat::for_path(&out, settings.ppm_ascii) else {
            errors.push(
                job_error(
                    path,
                    job,
                    format!("cannot tell the image format of '{}'", job.output.display()),
                )
                .with_help(format!(
                    "end the file name with one of {}",
                    limits::image_extensions_list()
                )),
            );
            return Err(errors);
        };
        self.accepted.push(out.clone());
        if errors.is_empty() {
            Ok((out, format))
        } else {
            Err(errors)
        }
    }

    fn take(
        &mut self,
        job: &RenderJob,
        out: PathBuf,
        image: Encoded,
    ) -> Result<(), Vec<Diagnostic>> {
        let pfm = film::hdr_path(&out);
        self.write(job, out, &image.image, false)?;
        match image.radiance {
            Some(radiance) => self.write(job, pfm, &radiance, true),
            None => Ok(()),
        }
    }
}
