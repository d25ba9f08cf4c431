//! The exposure of a frame in which something moves (docs/scene-language.md §10): each camera
//! sample gets an instant `u` of the exposure, its ray and every ray spawned from it carry
//! that instant (`Ray::time`), and the camera is placed at it. A frame in which nothing moves
//! never builds a [`Shutter`] and renders by the path it always took. Siblings:
//! `crate::render::geometry::motion` (the moving shapes), `crate::render::sampler::motion`
//! (what adaptive sampling asks of the motion), `crate::scene::motion` (what moves in a scene
//! description).

use super::camera::PinholeCamera;
use crate::limits::{motion_step, motion_step_middle, quantized_time, MOTION_TIME_STEPS};
use crate::math::Ray;
use crate::scene::motion::Motion;
use crate::scene::Camera;
use std::sync::Arc;

/// A moving frame's exposure, as the renderer samples it: the camera at an instant.
pub struct Shutter {
    motion: Arc<Motion>,
    /// The job's camera, as the scene is placed (the eye rebased with it).
    camera: Camera,
    width: u32,
    height: u32,
    /// The camera at each instant camera samples are rounded to, when it moves (`None` where
    /// it is degenerate then): placed once per frame, not once per sample.
    at_step: Vec<Option<PinholeCamera>>,
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
            at_step: Vec::new(),
        };
        if motion.camera.is_some() {
            shutter.at_step = (0..MOTION_TIME_STEPS)
                .map(|i| shutter.camera_at(motion_step_middle(i)))
                .collect();
        }
        shutter
    }

    /// Whether the camera moves.
    pub fn camera_moves(&self) -> bool {
        self.motion.camera.is_some()
    }

    /// Whether a light moves.
    pub fn lights_move(&self) -> bool {
        self.motion.moves_lights()
    }

    /// The instants of the camera's motion keys; `None` when the camera holds still.
    pub fn camera_keys(&self) -> Option<Vec<f64>> {
        self.motion
            .camera
            .as_ref()
            .map(|c| c.keys.instants().collect())
    }

    /// The camera at instant `time` of the exposure (`None` where it is degenerate then).
    pub fn camera_at(&self, time: f32) -> Option<PinholeCamera> {
        let cam = self.motion.camera_at(&self.camera, time as f64);
        PinholeCamera::new(&cam, self.width, self.height).ok()
    }

    /// The camera ray through (`x`, `y`) at instant `time`; `still` is the camera at the
    /// middle of the exposure (used as it is when the camera does not move, or where its
    /// placement at `time` is degenerate).
    /// The time is rounded to the instants moving shapes are placed at
    /// (`limits::quantized_time`), so every thing of the scene is seen at one instant.
    #[inline]
    pub fn ray(&self, still: &PinholeCamera, x: f32, y: f32, time: f32) -> Ray {
        self.placed(still, time)
            .ray(x, y)
            .at_time(quantized_time(time))
    }

    /// [`Shutter::ray`] from the point of the camera's lens that `uv` of the unit square maps
    /// to (`PinholeCamera::lens_ray`).
    #[inline]
    pub fn lens_ray(&self, still: &PinholeCamera, x: f32, y: f32, time: f32, uv: [f32; 2]) -> Ray {
        let camera = self.placed(still, time);
        camera.lens_ray(x, y, uv).at_time(quantized_time(time))
    }

    /// The camera at the instant `time` is rounded to (`still` where it holds still, or is
    /// degenerate then).
    #[inline]
    fn placed<'c>(&'c self, still: &'c PinholeCamera, time: f32) -> &'c PinholeCamera {
        let step = motion_step(time);
        self.at_step
            .get(step as usize)
            .and_then(Option::as_ref)
            .unwrap_or(still)
    }
}
