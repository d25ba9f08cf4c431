//! `motion` lines (docs/scene-language.md §10) made into a job's [`Motion`]: per moving
//! target its transforms at the lines' instants (its own transforms followed by the line's
//! operations), keyed about its centre.
//!
//! Motion, one home per layer: `crate::math::motion` (keys and their interpolation),
//! `crate::sdf::parse::motion` (the `motion` lines), `crate::scene::motion` (what moves in a
//! scene) with `crate::scene::builder::motion` (made from the lines),
//! `crate::render::geometry::motion` (moving shapes as primitives), `crate::render::motion`
//! (the exposure, as the samplers see it), and the animation pipeline's `keyframe::motion`
//! (the lines a spec with a `shutter` writes).

use super::definitions::{Definitions, ObjectKind};
use super::transforms::{finite_transform, Snapshot, Space};
use super::Builder;
use crate::math::motion::MotionKeys;
use crate::math::Transform;
use crate::scene::motion::{CameraMotion, LightMotion, Motion, Own, SlotMotion};
use crate::scene::{Camera, Geometry, Instance, Light};
use crate::sdf::ast::{Statement, StatementKind};
use glam::{DMat4, DVec3};
use std::collections::HashMap;
use std::sync::Arc;

/// The motion lines of a file by target: each instant with the transform its operations make
/// (applied after the target's own transforms, in its parent's frame).
#[derive(Default)]
pub(super) struct MotionLines<'s> {
    by_target: HashMap<(Space, &'s str), Vec<(f64, Transform)>>,
}

impl MotionLines<'_> {
    pub(super) fn is_empty(&self) -> bool {
        self.by_target.is_empty()
    }

    /// Whether object `name` (a shape or composite) has motion lines.
    pub(super) fn moves_object(&self, name: &str) -> bool {
        self.by_target.contains_key(&(Space::Object, name))
    }

    /// The keys of target `key` placed by its own transform `own`, about `centre` (in the
    /// space `own` maps from); `None` when it has no lines, or keys that do not interpolate.
    fn keys(&self, key: (Space, &str), own: &Transform, centre: DVec3) -> Option<MotionKeys> {
        let lines = self.by_target.get(&key)?;
        // Placed one key at a time, twice (checked, then decomposed), rather than held: a
        // file may key a million instants.
        let keyed = || lines.iter().map(|(u, ops)| (*u, ops.then_after(own)));
        if !keyed().all(|(_, t)| finite_transform(&t)) {
            return None;
        }
        MotionKeys::from_keys(centre, keyed()).filter(|k| !k.is_still())
    }
}

impl Builder<'_> {
    /// The motion lines of `statements`. Their targets and instants were checked by the
    /// reader; a line whose target this builder does not know is left aside.
    pub(super) fn motion_lines<'s>(
        &mut self,
        statements: &'s [Statement],
        d: &Definitions<'s>,
    ) -> MotionLines<'s> {
        let mut out = MotionLines::default();
        for stmt in statements {
            let StatementKind::Motion(m) = &stmt.kind else {
                continue;
            };
            let name = m.target.name.as_str();
            // The same precedence as a transform line's target.
            let space = if d.object_index.contains_key(name) {
                Space::Object
            } else if d.camera_index.contains_key(name) {
                Space::Camera
            } else if d.light_index.contains_key(name) {
                Space::Light
            } else {
                continue;
            };
            let mut t = Transform::IDENTITY;
            for op in &m.ops {
                if let Some(o) = self.op_transform(op, stmt) {
                    t = o.then_after(&t);
                }
            }
            let lines = out.by_target.entry((space, name)).or_default();
            // Instants must increase (the reader says so where it read the file).
            if lines.last().is_none_or(|(u, _)| *u < m.at) && m.at.is_finite() {
                lines.push((m.at, t));
            }
        }
        out
    }
}

/// The job's motion: its moving slots, lights and camera, or `None` when nothing moves.
pub(super) fn job_motion(
    d: &Definitions,
    (instances, flat_slots): (&[Instance], &[(u32, usize)]),
    snapshot: &Snapshot,
    lines: &MotionLines,
    transforms: &[Transform],
    lights: &[Light],
    camera: Option<&Camera>,
) -> Option<Arc<Motion>> {
    if lines.is_empty() {
        return None;
    }
    let own_of =
        |name: &str, space: Space| snapshot.get(&(space, name)).copied().unwrap_or_default();
    // Slot k (from 1) is `flat_slots[k - 1]`; parents come before children.
    let n = flat_slots.len() + 1;
    let mut slots: Vec<Option<SlotMotion>> = vec![None; n];
    let centres = if flat_slots
        .iter()
        .any(|&(_, i)| lines.moves_object(d.objects[i].name))
    {
        slot_centres(instances, flat_slots, transforms)
    } else {
        Vec::new()
    };
    for (k, &(parent, i)) in flat_slots.iter().enumerate() {
        let slot = k + 1;
        let name = d.objects[i].name;
        let own = own_of(name, Space::Object);
        let parent_moves = slots
            .get(parent as usize)
            .is_some_and(|s: &Option<SlotMotion>| s.is_some());
        let centre = centres
            .get(slot)
            .copied()
            .flatten()
            .map_or(DVec3::ZERO, |c| {
                transforms[slot].object_from_world.transform_point3(c)
            });
        let keys = lines.keys((Space::Object, name), &own, centre);
        if keys.is_none() && !parent_moves {
            continue;
        }
        let own = match keys {
            Some(k) => Own::Keys(k),
            None => Own::Still(own.world_from_object),
        };
        slots[slot] = Some(SlotMotion {
            parent: parent_moves.then_some(parent),
            base: transforms
                .get(parent as usize)
                .map_or(DMat4::IDENTITY, |t| t.world_from_object),
            own,
        });
    }
    let light_motion: Vec<Option<LightMotion>> = d
        .lights
        .iter()
        .zip(lights)
        .map(|(l, placed)| {
            let own = own_of(&l.name, Space::Light);
            let keys = lines.keys((Space::Light, &l.name), &own, l.position)?;
            Some(LightMotion {
                keys,
                local: l.position,
                placed: placed.position,
            })
        })
        .collect();
    let camera = camera.and_then(|c| {
        let def = d.cameras.iter().find(|def| def.name == c.name)?;
        let own = own_of(&def.name, Space::Camera);
        let keys = lines.keys((Space::Camera, &def.name), &own, def.eye)?;
        Some(CameraMotion {
            keys,
            eye: def.eye,
            dir: def.dir,
            up: def.up,
            placed_eye: c.eye,
        })
    });
    let motion = Motion {
        slots,
        lights: light_motion,
        camera,
        after: Transform::IDENTITY,
    };
    (motion.moves_geometry() || motion.moves_lights() || motion.camera.is_some())
        .then(|| Arc::new(motion))
}

/// Per transform slot: the centre (world space, as the statements place it) of the box
/// around every shape listed below it, if any is bounded.
fn slot_centres(
    instances: &[Instance],
    slots: &[(u32, usize)],
    transforms: &[Transform],
) -> Vec<Option<DVec3>> {
    let n = slots.len() + 1;
    let mut boxes: Vec<Option<(DVec3, DVec3)>> = vec![None; n];
    for inst in instances {
        let Some((lo, hi)) = object_box(&inst.geometry) else {
            continue;
        };
        let t = transforms
            .get(inst.transform as usize)
            .unwrap_or(&Transform::IDENTITY);
        let mut world: Option<(DVec3, DVec3)> = None;
        for c in 0..8 {
            let p = DVec3::new(
                if c & 1 == 0 { lo.x } else { hi.x },
                if c & 2 == 0 { lo.y } else { hi.y },
                if c & 4 == 0 { lo.z } else { hi.z },
            );
            let w = t.point(p);
            world = Some(world.map_or((w, w), |(a, b)| (a.min(w), b.max(w))));
        }
        let Some(world) = world else { continue };
        // Up the chain of slots: each encloses the shapes of those listed in it.
        let mut s = inst.transform as usize;
        let mut steps = 0;
        while s != 0 && s < n && steps < n {
            boxes[s] = Some(boxes[s].map_or(world, |(a, b)| (a.min(world.0), b.max(world.1))));
            s = slots[s - 1].0 as usize;
            steps += 1;
        }
    }
    boxes
        .into_iter()
        .map(|b| b.map(|(a, b)| (a + b) * 0.5))
        .collect()
}

/// A box around `g` in its own space, if it is bounded and its extent is known without
/// loading anything.
fn object_box(g: &Geometry) -> Option<(DVec3, DVec3)> {
    let (points, r) = g.span()?;
    let lo = points.iter().fold(DVec3::INFINITY, |a, p| a.min(*p));
    let hi = points.iter().fold(DVec3::NEG_INFINITY, |a, p| a.max(*p));
    let (lo, hi) = (lo - DVec3::splat(r.abs()), hi + DVec3::splat(r.abs()));
    (lo.is_finite() && hi.is_finite()).then_some((lo, hi))
}

/// Whether the file's motion lines move any shape or composite (the composite tree is then
/// flattened without prototypes: see `jobs`).
pub(super) fn moves_objects(lines: &MotionLines, d: &Definitions) -> bool {
    d.objects.iter().any(|o| {
        lines.moves_object(o.name) && !matches!(o.kind, ObjectKind::Shape { material: None, .. })
    })
}
