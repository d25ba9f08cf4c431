//! The exposure of a frame in which something moves (docs/scene-language.md §10): each camera
//! sample gets an instant `u` of the exposure, its ray and every ray spawned from it carry
//! that instant (`Ray::time`), and the camera is placed at it. A frame in which nothing moves
//! never builds a [`Shutter`] and renders by the path it always took.

use super::camera::CameraRays;
use crate::math::Ray;
use crate::scene::motion::Motion;
use crate::scene::Camera;
use glam::Vec3A;
use std::sync::Arc;

/// Largest neighbourhood radius (pixels) over which adaptive sampling judges a pixel flat
/// under a moving camera; a hit point that moves further across the image is refined.
const MAX_FLAT_RADIUS: u32 = 8;

/// Instants at which a moving camera's sweep over the image is measured, besides its keys.
const SWEEP_STEPS: usize = 8;

/// A moving frame's exposure, as the renderer samples it.
pub struct Shutter {
    motion: Arc<Motion>,
    /// The job's camera, as the scene is placed (the eye rebased with it).
    camera: Camera,
    width: u32,
    height: u32,
    /// The camera at instants spread over the exposure, when it moves.
    sweep: Vec<CameraRays>,
}

impl Shutter {
    /// The exposure of a job whose scene has `motion`; `camera` is the job's camera as the
    /// scene is placed for rendering.
    pub fn new(motion: &Arc<Motion>, camera: &Camera, width: u32, height: u32) -> Shutter {
        let mut shutter = Shutter {
            motion: motion.clone(),
            camera: camera.clone(),
            width,
            height,
            sweep: Vec::new(),
        };
        if let Some(c) = &motion.camera {
            let mut instants: Vec<f64> = (0..=SWEEP_STEPS)
                .map(|s| s as f64 / SWEEP_STEPS as f64)
                .chain(c.keys.instants())
                .collect();
            instants.sort_by(f64::total_cmp);
            instants.dedup();
            shutter.sweep = instants
                .into_iter()
                .filter_map(|u| shutter.camera_at(u as f32))
                .collect();
        }
        shutter
    }

    /// Whether the camera moves.
    pub fn camera_moves(&self) -> bool {
        self.motion.camera.is_some()
    }

    fn camera_at(&self, time: f32) -> Option<CameraRays> {
        let cam = self.motion.camera_at(&self.camera, time as f64);
        CameraRays::new(&cam, self.width, self.height).ok()
    }

    /// The camera ray through (`x`, `y`) at instant `time`; `still` is the camera at the
    /// middle of the exposure (used as it is when the camera does not move, or where its
    /// placement at `time` is degenerate).
    /// The time is rounded to the instants moving shapes are placed at
    /// (`compile::motion::quantize`), so every thing of the scene is seen at one instant.
    #[inline]
    pub fn ray(&self, still: &CameraRays, x: f32, y: f32, time: f32) -> Ray {
        let time = super::compile::motion::quantize(time);
        let ray = if self.camera_moves() {
            self.camera_at(time)
                .unwrap_or_else(|| still.clone())
                .ray(x, y)
        } else {
            still.ray(x, y)
        };
        ray.at_time(time)
    }

    /// How far (pixels) the point the middle instant's centre ray of (`x`, `y`) meets at
    /// distance `t` (`None`: nothing, the background far away) moves across the image while
    /// the camera moves; 0 for a still camera.
    pub fn camera_sweep(&self, still: &CameraRays, x: u32, y: u32, t: Option<f32>) -> f32 {
        if self.sweep.is_empty() {
            return 0.0;
        }
        let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
        let ray = still.ray(cx, cy);
        // The background: a point far enough that the eye's slide does not move it.
        let p: Vec3A = ray.at(t.unwrap_or(1e7));
        let mut most = 0.0f32;
        for c in &self.sweep {
            match c.project(p) {
                Some((px, py)) => most = most.max((px - cx).hypot(py - cy)),
                None => return f32::INFINITY,
            }
        }
        most
    }

    /// The radius (pixels) of the neighbourhood that must be flat for a pixel whose hit point
    /// sweeps `sweep` pixels to keep its centre sample, or `None` when it sweeps too far.
    pub fn flat_radius(sweep: f32) -> Option<u32> {
        if sweep.is_finite() && sweep <= MAX_FLAT_RADIUS as f32 {
            Some((sweep.ceil() as u32).max(1))
        } else {
            None
        }
    }
}
