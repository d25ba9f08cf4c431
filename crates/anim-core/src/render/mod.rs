//! Rendering: a scene description and its camera become an image.
//!
//! The data flow of one frame (docs/architecture.md has the picture):
//!
//! ```text
//! RenderJob ──compile──▶ RenderScene { Geometry (Arc, camera-free) · View · Shading }
//!           ──sampler──▶ camera ray (camera, motion) ──integrator──▶ radiance ──▶ film
//! ```
//!
//! [`compile`] builds the three parts of a [`compile::RenderScene`] and holds the one query
//! surface the integrator asks (closest hit, occlusion, with a hint of what the ray is);
//! [`policy`] is the table that picks which structure answers which ray; [`geometry`] holds
//! the primitives and their hierarchy, [`view`] the candidate lists of rays from the eye and
//! the lights, [`shading`] the materials and lights. [`sampler`] places the samples,
//! [`camera`] and [`motion`] make their rays, [`integrator`] shades them (docs/shading.md),
//! and [`film`] turns the radiance into image files.

pub mod camera;
pub mod compile;
pub mod film;
pub mod geometry;
pub mod integrator;
pub mod motion;
pub mod policy;
pub mod sampler;
mod settings;
pub mod shading;
pub mod view;

pub use film::HdrImage;
pub use settings::{RenderSettings, Sampling};

use crate::math::Transform;
use crate::scene::{Camera, RenderJob, Scene};
use camera::{CameraError, PinholeCamera};
use compile::RenderScene;
use geometry::Dropped;
use glam::DVec3;
use integrator::Integrator;
use motion::Shutter;
use view::Viewpoint;

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

    /// `a + b`, for reductions over workers.
    pub fn sum(mut a: RayCounts, b: RayCounts) -> RayCounts {
        a += b;
        a
    }
}

impl std::ops::AddAssign for RayCounts {
    fn add_assign(&mut self, o: RayCounts) {
        self.primary += o.primary;
        self.shadow += o.shadow;
        self.reflected += o.reflected;
        self.refracted += o.refracted;
    }
}

/// One rendered image and what it took.
#[derive(Clone, Debug)]
pub struct Rendered {
    pub image: HdrImage,
    pub rays: RayCounts,
    /// Camera samples traced per pixel, on average.
    pub mean_spp: f64,
    /// Shapes that became degenerate once transformed (in f32) and were left out.
    pub dropped: Vec<Dropped>,
}

/// The job's scene and camera moved (in f64) so that the eye sits at the origin, or `None`
/// when it already does. Rendering works in f32, which keeps about 7 digits relative to a
/// coordinate's magnitude: a scene far from the world origin would lose its detail near the
/// camera, where the picture needs it most. Moved together, the picture is the same.
fn camera_relative(job: &RenderJob) -> Option<(Scene, Camera)> {
    let eye = job.camera.eye;
    if eye == DVec3::ZERO {
        return None;
    }
    let to_camera = Transform::translate(-eye);
    // The instances are shared, not copied: only the table of transforms is.
    let mut scene = job.scene.clone();
    scene.transform_all(&to_camera);
    for light in &mut scene.lights {
        light.position -= eye;
    }
    let camera = Camera {
        eye: DVec3::ZERO,
        ..job.camera.clone()
    };
    Some((scene, camera))
}

/// Renders one job to an HDR image. `on_pixels(n)` is called as each band of `n` pixels
/// finishes.
pub fn render_job(
    job: &RenderJob,
    settings: &RenderSettings,
    on_pixels: &(dyn Fn(u64) + Sync),
) -> Result<Rendered, CameraError> {
    let (width, height, _) = settings.resolve(job);
    let rebased = camera_relative(job);
    let (scene, camera) = rebased
        .as_ref()
        .map_or((&job.scene, &job.camera), |(s, c)| (s, c));
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
    let (scene, dropped) = RenderScene::compile(scene, Some(&viewpoint));
    let integrator = Integrator {
        scene: &scene,
        max_depth: settings.max_depth,
    };
    let frame = sampler::Frame {
        camera: &camera,
        shutter: shutter.as_ref(),
        integrator: &integrator,
        size: (width as usize, height as usize),
    };
    let (pixels, counts) = sampler::render(&frame, sampling, on_pixels);
    Ok(Rendered {
        image: HdrImage {
            width,
            height,
            pixels,
        },
        mean_spp: counts.primary as f64 / (width as f64 * height as f64),
        rays: counts,
        dropped,
    })
}

#[cfg(test)]
mod tests;
