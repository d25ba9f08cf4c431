//! Rendering: compile a scene description, trace it on rayon tiles, tone-map, write the image.

pub mod camera;
pub mod compile;
pub mod film;
pub mod integrator;
pub mod primitive;

use crate::scene::RenderJob;
use camera::{sample_offsets, CameraError, CameraRays};
use compile::RenderScene;
use glam::{Vec3, Vec3A};
use integrator::Integrator;
use rayon::prelude::*;
use std::path::PathBuf;

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
    /// Honour render lines that write outside the output folder (absolute paths, `..`).
    pub allow_any_output: bool,
    /// Bytes one image may take while it is made; bigger images are refused before any
    /// allocation.
    pub max_memory: u64,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            spp: None,
            width: None,
            height: None,
            max_depth: crate::limits::DEFAULT_MAX_DEPTH,
            ppm_ascii: false,
            out_dir: None,
            allow_any_output: false,
            max_memory: crate::limits::default_memory_budget(),
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

#[cfg(test)]
mod tests;
