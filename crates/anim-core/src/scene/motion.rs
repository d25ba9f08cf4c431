//! What moves while the shutter is open (docs/scene-language.md §10): per transform slot of a
//! moving shape or composite, per moving light and for a moving camera, its keyed transforms
//! over the exposure, from the file's `motion` lines. A scene in which nothing moves has none
//! of this (`Scene::motion` is `None`) and renders by the path it always took.
//!
//! A slot's world placement at instant `u` composes its ancestors' placements at `u`: a
//! moving composite carries its children, each part interpolated about its own centre
//! (`crate::math::motion`).
//!
//! Motion, one home per layer: `crate::math::motion` (keys and their interpolation),
//! `crate::sdf::parse::motion` (the `motion` lines), `crate::scene::motion` (what moves in a
//! scene) with `crate::scene::builder::motion` (made from the lines),
//! `crate::render::geometry::motion` (moving shapes as primitives), `crate::render::motion`
//! (the exposure, as the samplers see it), and the animation pipeline's `keyframe::motion`
//! (the lines a spec with a `shutter` writes).

use super::Camera;
use crate::math::motion::MotionKeys;
use crate::math::Transform;
use glam::{DMat4, DVec3};

/// An object's own transform (into its parent's frame) during the exposure.
#[derive(Clone, Debug, PartialEq)]
pub enum Own {
    /// The same at every instant: an object placed by transform statements only, listed in
    /// a composite that moves.
    Still(DMat4),
    /// Keyed by the object's `motion` lines and interpolated between the keys.
    Keys(MotionKeys),
}

impl Own {
    fn matrix_at(&self, u: f64) -> DMat4 {
        match self {
            Own::Still(m) => *m,
            Own::Keys(k) => k.matrix_at(u),
        }
    }
}

/// How one transform slot moves.
#[derive(Clone, Debug, PartialEq)]
pub struct SlotMotion {
    /// The slot this one is listed in, when that one moves too.
    pub parent: Option<u32>,
    /// The world transform of the (still) slot it is listed in, when `parent` is `None`.
    pub base: DMat4,
    /// The object's own transform over the exposure, into the frame of the slot it is listed
    /// in.
    pub own: Own,
}

/// A moving light: its keyed transform, its position in its own statement, and where the
/// scene's `Light::position` put it when the motion was built.
#[derive(Clone, Debug, PartialEq)]
pub struct LightMotion {
    /// The light's transform over the exposure, from its `motion` lines, about its own
    /// position.
    pub keys: MotionKeys,
    /// The position its statement gives it, before any transform.
    pub local: DVec3,
    /// The scene's `Light::position` when the motion was built (world space); the light moves
    /// by its offset from this.
    pub placed: DVec3,
}

/// A moving camera: its keyed transform and its statement's eye, direction and up, and the
/// eye the job's `Camera` had when the motion was built.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraMotion {
    /// The camera's transform over the exposure, from its `motion` lines, about its eye.
    pub keys: MotionKeys,
    /// The eye its statement gives, before any transform.
    pub eye: DVec3,
    /// The viewing direction its statement gives, before any transform.
    pub dir: DVec3,
    /// The up vector its statement gives, before any transform.
    pub up: DVec3,
    /// The job's `Camera::eye` when the motion was built (world space); the eye moves by its
    /// offset from this.
    pub placed_eye: DVec3,
}

/// Everything that moves during one job's exposure.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Motion {
    /// By transform slot (`Instance::transform`): how it moves, or `None` when still.
    pub slots: Vec<Option<SlotMotion>>,
    /// By light (`Scene::lights`).
    pub lights: Vec<Option<LightMotion>>,
    /// How the job's camera moves; `None` when it stands still.
    pub camera: Option<CameraMotion>,
    /// The transforms `Scene::transform_all` applied since, composed.
    pub after: Transform,
}

impl Motion {
    /// Whether slot `slot` moves.
    #[inline]
    pub fn moves_slot(&self, slot: u32) -> bool {
        matches!(self.slots.get(slot as usize), Some(Some(_)))
    }

    /// Whether any shape or composite moves.
    pub fn moves_geometry(&self) -> bool {
        self.slots.iter().any(Option::is_some)
    }

    /// The world transform of moving slot `slot` at `u`, without its inverse; the identity
    /// for a slot that does not move (callers ask only for moving ones).
    pub fn slot_matrix(&self, slot: u32, u: f64) -> DMat4 {
        let mut m = DMat4::IDENTITY;
        let mut next = Some(slot);
        // Walked upwards: each parent's placement applies before (to the left of) the child's.
        // Bounded by the slot count, so a malformed table cannot loop.
        let mut steps = 0;
        while let Some(Some(s)) = next.map(|k| self.slots.get(k as usize).and_then(Option::as_ref))
        {
            m = s.own.matrix_at(u) * m;
            steps += 1;
            if steps > self.slots.len() {
                break;
            }
            if s.parent.is_none() {
                m = s.base * m;
            }
            next = s.parent;
        }
        self.after.world_from_object * m
    }

    /// `slot_matrix` with its inverse.
    pub fn slot_at(&self, slot: u32, u: f64) -> Transform {
        let m = self.slot_matrix(slot, u);
        Transform {
            world_from_object: m,
            object_from_world: m.inverse(),
        }
    }

    /// The instants at which something on moving slot `slot`'s chain has a key.
    pub fn slot_instants(&self, slot: u32) -> Vec<f64> {
        let mut out = Vec::new();
        let mut next = Some(slot);
        let mut steps = 0;
        while let Some(Some(s)) = next.map(|k| self.slots.get(k as usize).and_then(Option::as_ref))
        {
            if let Own::Keys(k) = &s.own {
                out.extend(k.instants());
            }
            steps += 1;
            if steps > self.slots.len() {
                break;
            }
            next = s.parent;
        }
        out.sort_by(f64::total_cmp);
        out.dedup();
        out
    }

    /// Where light `k`, at `position` in the scene, is at `u`.
    #[inline]
    pub fn light_position(&self, k: usize, position: DVec3, u: f64) -> DVec3 {
        match self.lights.get(k) {
            Some(Some(l)) => {
                position
                    + self
                        .after
                        .vector(l.keys.matrix_at(u).transform_point3(l.local) - l.placed)
            }
            _ => position,
        }
    }

    /// Whether any light moves.
    pub fn moves_lights(&self) -> bool {
        self.lights.iter().any(Option::is_some)
    }

    /// `camera` (the job's, as the scene is placed now) at `u`.
    pub fn camera_at(&self, camera: &Camera, u: f64) -> Camera {
        let Some(c) = &self.camera else {
            return camera.clone();
        };
        let m = c.keys.matrix_at(u);
        Camera {
            eye: camera.eye + self.after.vector(m.transform_point3(c.eye) - c.placed_eye),
            dir: self.after.vector(m.transform_vector3(c.dir)),
            up: self.after.vector(m.transform_vector3(c.up)),
            ..camera.clone()
        }
    }
}
