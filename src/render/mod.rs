//! Rendering: compile a scene description, trace it on rayon tiles, tone-map, write the image.

pub mod camera;
pub mod compile;
pub mod film;
pub mod integrator;
pub mod primitive;

use crate::diag::{Diagnostic, Severity};
use crate::scene::RenderJob;
use crate::sdf::LoadOptions;
use camera::{sample_offsets, CameraError, CameraRays};
use compile::RenderScene;
use film::ImageFormat;
use glam::{Vec3, Vec3A};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use integrator::Integrator;
use rayon::prelude::*;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Tile edge in pixels: small enough to balance two to many cores, big enough that the
/// per-tile overhead (one allocation, one progress update) vanishes.
const TILE: u32 = 32;

/// Samples per pixel when neither `--spp` nor the render statement says.
pub const DEFAULT_SPP: u32 = 4;

#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Overrides the render statement's sample count.
    pub spp: Option<u32>,
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub max_depth: u32,
    pub ppm_ascii: bool,
    /// Images go here instead of beside the scene file.
    pub out_dir: Option<PathBuf>,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            spp: None,
            width: None,
            height: None,
            max_depth: 8,
            ppm_ascii: false,
            out_dir: None,
        }
    }
}

/// How many rays of each kind a render traced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    pub primary: u64,
    pub shadow: u64,
    pub reflected: u64,
    pub refracted: u64,
}

impl RayCounts {
    pub fn total(&self) -> u64 {
        self.primary + self.shadow + self.reflected + self.refracted
    }
}

/// Linear (HDR) radiance per pixel, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct HdrImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Vec3>,
}

/// What rendering one scene file produced.
#[derive(Clone, Debug)]
pub struct FileOutcome {
    pub outputs: Vec<PathBuf>,
    pub warnings: Vec<Diagnostic>,
    pub rays: RayCounts,
}

impl std::ops::AddAssign for RayCounts {
    fn add_assign(&mut self, o: RayCounts) {
        self.primary += o.primary;
        self.shadow += o.shadow;
        self.reflected += o.reflected;
        self.refracted += o.refracted;
    }
}

impl RenderSettings {
    /// The image size and samples per pixel for `job` under these settings.
    pub fn resolve(&self, job: &RenderJob) -> (u32, u32, u32) {
        let spp = self.spp.or(job.samples).unwrap_or(DEFAULT_SPP).max(1);
        (
            self.width.unwrap_or(job.width),
            self.height.unwrap_or(job.height),
            spp,
        )
    }
}

/// One rendered image and what it took.
#[derive(Clone, Debug)]
pub struct Rendered {
    pub image: HdrImage,
    pub rays: RayCounts,
    /// Shapes that became degenerate once transformed (in f32) and were left out.
    pub dropped: Vec<compile::Dropped>,
}

/// Renders one job to an HDR image. `on_tile(pixels)` is called as tiles finish.
pub fn render_job(
    job: &RenderJob,
    settings: &RenderSettings,
    on_tile: &(dyn Fn(u64) + Sync),
) -> Result<Rendered, CameraError> {
    let (width, height, spp) = settings.resolve(job);
    let camera = CameraRays::new(&job.camera, width, height)?;
    let (scene, dropped) = RenderScene::compile(&job.scene);
    let integrator = Integrator {
        scene: &scene,
        max_depth: settings.max_depth,
    };
    let offsets = sample_offsets(spp);
    let inv_spp = 1.0 / offsets.len() as f32;
    let tiles_x = width.div_ceil(TILE);
    let tiles: Vec<(u32, u32)> = (0..height.div_ceil(TILE))
        .flat_map(|ty| (0..tiles_x).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    // Each pixel depends only on its own position, so the result is the same for any
    // thread count or tile order.
    let rendered: Vec<(Vec<Vec3>, RayCounts)> = tiles
        .par_iter()
        .map(|&(x0, y0)| {
            let (x1, y1) = ((x0 + TILE).min(width), (y0 + TILE).min(height));
            let mut counts = RayCounts::default();
            let mut out = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
            for y in y0..y1 {
                for x in x0..x1 {
                    let mut sum = Vec3A::ZERO;
                    for &(dx, dy) in &offsets {
                        let ray = camera.ray(x as f32 + dx, y as f32 + dy);
                        sum += integrator.trace(&ray, 0, 1.0, &mut counts);
                    }
                    counts.primary += offsets.len() as u64;
                    out.push(Vec3::from(sum * inv_spp));
                }
            }
            on_tile(out.len() as u64);
            (out, counts)
        })
        .collect();
    let mut pixels = vec![Vec3::ZERO; (width * height) as usize];
    let mut counts = RayCounts::default();
    for (&(x0, y0), (tile, c)) in tiles.iter().zip(rendered) {
        counts += c;
        let w = (x0 + TILE).min(width) - x0;
        for (row, chunk) in tile.chunks(w as usize).enumerate() {
            let start = ((y0 + row as u32) * width + x0) as usize;
            pixels[start..start + chunk.len()].copy_from_slice(chunk);
        }
    }
    Ok(Rendered {
        image: HdrImage {
            width,
            height,
            pixels,
        },
        rays: counts,
        dropped,
    })
}

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

/// A progress bar on stderr that appears only once a render has run for about a second, and
/// never when stderr is not a terminal.
struct LazyProgress {
    bar: Option<ProgressBar>,
    start: Instant,
    shown: AtomicBool,
}

impl LazyProgress {
    fn new(enabled: bool, total: u64) -> Self {
        let bar = (enabled && std::io::stderr().is_terminal()).then(|| {
            let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::hidden());
            if let Ok(style) =
                ProgressStyle::with_template("{spinner} {msg} [{bar:30}] {percent:>3}% ETA {eta}")
            {
                bar.set_style(style.progress_chars("=> "));
            }
            bar
        });
        LazyProgress {
            bar,
            start: Instant::now(),
            shown: AtomicBool::new(false),
        }
    }

    fn advance(&self, n: u64) {
        if let Some(bar) = &self.bar {
            bar.inc(n);
            if self.start.elapsed() > Duration::from_secs(1)
                && !self.shown.swap(true, Ordering::Relaxed)
            {
                bar.set_draw_target(ProgressDrawTarget::stderr());
            }
        }
    }

    fn set_message(&self, msg: String) {
        if let Some(bar) = &self.bar {
            bar.set_message(msg);
        }
    }

    fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

/// Loads a scene file, renders every image it asks for and writes them atomically.
/// `show_progress`: draw a progress bar on a terminal for renders longer than about a second.
pub fn render_file(
    path: &Path,
    load: &LoadOptions,
    settings: &RenderSettings,
    show_progress: bool,
) -> Result<FileOutcome, Vec<Diagnostic>> {
    let loaded = crate::scene::load_file(path, load)?;
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
                    film::KNOWN_EXTENSIONS
                )),
            ),
        }
    }
    if !errors.is_empty() {
        warnings.extend(errors);
        return Err(warnings);
    }
    let total: u64 = loaded
        .jobs
        .iter()
        .map(|j| {
            let (w, h, _) = settings.resolve(j);
            w as u64 * h as u64
        })
        .sum();
    let progress = LazyProgress::new(show_progress, total);
    let mut outcome = FileOutcome {
        outputs: Vec::new(),
        warnings: Vec::new(),
        rays: RayCounts::default(),
    };
    for (job, (out, format)) in loaded.jobs.iter().zip(targets) {
        progress.set_message(
            out.file_name()
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
                progress.finish();
                let what = match e {
                    CameraError::Fov => format!(
                        "camera '{}' has a field of view of {}°; it must be between 0 and 180",
                        job.camera.name, job.camera.fov_x_deg
                    ),
                    CameraError::Orientation => format!(
                        "camera '{}' has no usable orientation: its direction is zero or parallel to its up vector",
                        job.camera.name
                    ),
                };
                warnings.push(job_error(path, job, what));
                return Err(warnings);
            }
        };
        for d in dropped {
            let message = format!(
                "shape '{}' is degenerate once transformed (too thin or too small to intersect) and is not drawn",
                d.instance
            );
            warnings.push(match d.loc {
                Some(loc) => Diagnostic::new(Severity::Warning, loc, message),
                None => job_error(path, job, message).with_severity(Severity::Warning),
            });
        }
        if let Err(e) = film::write_image(&out, &image, format) {
            progress.finish();
            warnings.push(job_error(
                path,
                job,
                format!("cannot write '{}': {e}", out.display()),
            ));
            return Err(warnings);
        }
        outcome.rays += counts;
        outcome.outputs.push(out);
    }
    progress.finish();
    outcome.warnings = warnings;
    Ok(outcome)
}

#[cfg(test)]
mod tests;
