//! Rendering: a scene description and its camera become an image.
//!
//! The data flow of one frame (docs/architecture.md has the picture):
//!
//! ```text
//! RenderJob ──compile──▶ RenderScene { Aggregate (Arc, camera-free) · View · Shading }
//!           ──sampler──▶ camera ray (camera, motion) ──integrator──▶ radiance ──▶ film
//! ```
//!
//! The modules run downhill, each importing only those below it (`tests/layers.rs` checks
//! it): this entry (`render_job`, [`Prepared`], [`Rendered`]) → [`sampler`] (where the
//! samples go, and what adaptive sampling asks of the motion) → [`motion`] (the exposure:
//! the camera at an instant) and [`integrator`] (Whitted shading, docs/shading.md) →
//! [`compile`] (the facade: the [`compile::RenderScene`] and every question a ray asks of
//! it, with the worker's [`compile::Scratch`]) → [`view`] (candidate lists of rays from the
//! eye and the lights) → [`geometry`] (the [`geometry::Aggregate`]: the primitives and their
//! hierarchy) → [`policy`] (which structure answers which ray) and the leaves: [`shading`]
//! (materials and lights), [`camera`], [`film`] (radiance to image files), the settings and
//! the ray counts. The integrator and the samplers never name the geometry.

pub mod camera;
pub mod compile;
mod counts;
pub mod film;
pub mod geometry;
pub mod integrator;
pub mod motion;
pub mod policy;
pub mod sampler;
mod settings;
pub mod shading;
pub mod view;

pub use counts::RayCounts;
pub use film::HdrImage;
pub use settings::{RenderSettings, Sampling};

use crate::math::Transform;
use crate::scene::{Camera, RenderJob, Scene};
use camera::{CameraError, PinholeCamera};
use compile::RenderScene;
use geometry::{Aggregate, Dropped};
use glam::DVec3;
use integrator::Integrator;
use motion::Shutter;
use std::sync::Arc;
use view::Viewpoint;

/// One rendered image and what it took.
#[derive(Clone, Debug)]
pub struct Rendered {
    /// Linear radiance of every pixel.
    pub image: HdrImage,
    /// Per pixel (row-major), the fraction of its camera samples that hit a surface: 0 where
    /// every one saw the background, 1 where none did. Adaptive sampling's flat pixels keep
    /// their centre sample, so theirs is 0 or 1; an edge is refined and takes its coverage
    /// from its samples. The alpha of `--alpha` (`film::Coverage`).
    pub coverage: Vec<f32>,
    /// The rays traced.
    pub rays: RayCounts,
    /// Camera samples traced per pixel, on average.
    pub mean_spp: f64,
    /// Shapes that became degenerate once transformed (in f32) and were left out.
    pub dropped: Vec<Dropped>,
    /// Adaptive sampling's estimate of each pixel's error, in 8-bit levels of its tone-mapped
    /// mean, where the pixel stopped taking samples (row-major): NaN for a pixel that kept
    /// its centre sample (nothing estimated), infinite for one stopped by `max_spp` before
    /// an estimate. A pixel that motion's third pass resumed keeps its second-pass estimate.
    /// Empty for uniform sampling. `anim bench` sets it against the measured error.
    pub error_estimates: Vec<f32>,
}

/// A job made ready to render: its scene and camera moved (in f64) so that the eye sits at
/// the origin, and its geometry built. The blank-image probe looks at it and the render uses
/// it as it is, so the geometry is built once for both.
///
/// Rendering works in f32, which keeps about 7 digits relative to a coordinate's magnitude:
/// a scene far from the world origin would lose its detail near the camera, where the
/// picture needs it most. Moved together with the camera, the picture is the same.
pub struct Prepared<'j> {
    job: &'j RenderJob,
    /// The scene and camera moved, or `None` when the eye is at the origin already.
    rebased: Option<(Scene, Camera)>,
    /// The camera-free geometry, shared by the probe and the render.
    geometry: Arc<Aggregate>,
    /// Shapes that became degenerate once transformed (in f32) and were left out.
    pub dropped: Vec<Dropped>,
}

impl<'j> Prepared<'j> {
    /// Moves `job` camera-relative and builds its geometry.
    pub fn new(job: &'j RenderJob) -> Prepared<'j> {
        let rebased = (job.camera.eye != DVec3::ZERO).then(|| {
            let eye = job.camera.eye;
            // The instances are shared, not copied: only the table of transforms is.
            let mut scene = job.scene.clone();
            scene.transform_all(&Transform::translate(-eye));
            for light in &mut scene.lights {
                light.position -= eye;
                if let Some(spot) = &mut light.spot {
                    spot.target -= eye;
                }
            }
            let camera = Camera {
                eye: DVec3::ZERO,
                ..job.camera.clone()
            };
            (scene, camera)
        });
        let scene = rebased.as_ref().map_or(&job.scene, |(s, _)| s);
        let (geometry, dropped) = Aggregate::build(scene);
        Prepared {
            job,
            rebased,
            geometry: Arc::new(geometry),
            dropped,
        }
    }

    /// The job.
    pub fn job(&self) -> &'j RenderJob {
        self.job
    }

    /// The scene, camera-relative.
    pub fn scene(&self) -> &Scene {
        self.rebased.as_ref().map_or(&self.job.scene, |(s, _)| s)
    }

    /// The camera, at the origin.
    pub fn camera(&self) -> &Camera {
        self.rebased.as_ref().map_or(&self.job.camera, |(_, c)| c)
    }

    /// The compiled scene, as seen from `viewpoint` (`None`: without a camera).
    pub fn compile(&self, viewpoint: Option<&Viewpoint>) -> RenderScene {
        RenderScene::with_geometry(self.geometry.clone(), self.scene(), viewpoint)
    }
}

/// Renders one job to an HDR image. `on_pixels(n)` is called as each band of `n` pixels
/// finishes.
pub fn render_job(
    job: &RenderJob,
    settings: &RenderSettings,
    on_pixels: &(dyn Fn(u64) + Sync),
) -> Result<Rendered, CameraError> {
    render_prepared(&Prepared::new(job), settings, on_pixels)
}

/// [`render_job`] of a job made ready already.
pub fn render_prepared(
    prepared: &Prepared,
    settings: &RenderSettings,
    on_pixels: &(dyn Fn(u64) + Sync),
) -> Result<Rendered, CameraError> {
    let job = prepared.job();
    let (width, height, _) = settings.resolve(job);
    let (scene, camera) = (prepared.scene(), prepared.camera());
    let shutter = scene
        .motion
        .as_ref()
        .map(|m| Shutter::new(m, camera, width, height));
    let camera = PinholeCamera::new(camera, width, height)?;
    let sampling = settings.sampling(job);
    let viewpoint = Viewpoint {
        view: camera.view(),
        size: (width, height),
        camera_rays: u64::from(width) * u64::from(height) * u64::from(sampling.least_spp()),
        motion: shutter.is_some(),
    };
    let scene = prepared.compile(Some(&viewpoint));
    let integrator = Integrator {
        scene: &scene,
        max_depth: settings.max_depth,
    };
    let frame = sampler::Frame {
        camera: &camera,
        shutter: shutter.as_ref(),
        integrator: &integrator,
        size: (width as usize, height as usize),
        draws: sampler::Draws::new(&camera, &integrator),
    };
    let sampled = sampler::render(&frame, sampling, on_pixels);
    let counts = sampled.rays;
    Ok(Rendered {
        image: HdrImage {
            width,
            height,
            pixels: sampled.pixels,
        },
        coverage: sampled.coverage,
        mean_spp: counts.primary as f64 / (width as f64 * height as f64),
        rays: counts,
        dropped: prepared.dropped.clone(),
        error_estimates: sampled.error_estimates,
    })
}

#[cfg(test)]
mod tests;
