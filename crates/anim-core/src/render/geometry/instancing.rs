//! The prototypes of a scene's instanced composites, compiled: one hierarchy each, over its
//! shapes and nested uses in its own frame, entered by a use's transform (pbrt's
//! `TransformedPrimitive`). A top-level use is one primitive of the geometry's table
//! (`Kind::Instance`).
//!
//! Instancing, one home per layer: `crate::scene::instancing` (what a composite drawn in
//! several places expands to), `crate::scene::builder::instancing` (which composites are kept
//! once) and `crate::render::geometry::instancing` (their hierarchies, entered by a use's
//! transform).
//!
//! The hierarchies only cull. A shape they offer is placed with the world transform the
//! flattened tree gives it (`Scene::prototype_world`, composed top-down as the flattening
//! does) and tested with the world ray as the flattened scene's primitive would be, so its
//! hits are the same floats. Culling happens on a ray moved into the prototype's frame, whose
//! rounding differs from the world ray's; boxes and distances are widened by
//! `CULL_MARGIN` so that it never drops a shape the world test would hit.

use super::leaf::Best;
use super::Primitive;
use crate::accel::Bvh;
use crate::math::{Aabb, Ray, Transform};
use crate::scene::{Instance, Prototype, Scene, Use};
use glam::Vec3A;

/// Relative widening of the culling boxes and distances of prototypes (far beyond the f32
/// rounding of a ray moved into a prototype's frame).
const CULL_MARGIN: f32 = 1e-3;

/// A walk through the prototypes along one ray: the ray (in the world), how far it still
/// looks (which a closest-hit walk shortens as it goes), and what it does with each shape
/// the ray may meet: `shape(id, primitive)`, going on while that returns true.
struct Walk<'w> {
    ray: &'w Ray,
    limit: &'w dyn Fn() -> f32,
    shape: &'w mut dyn FnMut(u32, &Primitive) -> bool,
}

#[derive(Clone, Debug)]
struct Compiled {
    /// Over the entries: leaf `e` for `e < leaves`, then nested use `e - leaves`.
    bvh: Bvh,
    /// Of everything in it, in its frame, widened.
    bounds: Aabb,
}

/// The instanced part of a render scene.
#[derive(Clone, Debug)]
pub struct Instances {
    /// The scene's prototypes and transforms (its flat instances are not kept here).
    scene: Scene,
    compiled: Vec<Compiled>,
    /// Per top-level use: its frame as the flattening composed it.
    frames: Vec<Transform>,
    /// Ids of instanced shapes are `first_id` + their depth-first number.
    first_id: u32,
}

fn widen(b: Aabb) -> Aabb {
    if b.is_empty() || !b.is_finite() {
        return b;
    }
    let margin = (b.extent() + b.min.abs().max(b.max.abs())) * CULL_MARGIN + Vec3A::splat(1e-30);
    Aabb::new(b.min - margin, b.max + margin)
}

/// `b` mapped by `t`, widened.
fn transformed(b: &Aabb, t: &Transform) -> Aabb {
    if b.is_empty() {
        return *b;
    }
    widen(Aabb::from_points(b.corners().map(|c| {
        Vec3A::from(t.world_from_object.transform_point3(c.as_dvec3()).as_vec3())
    })))
}

/// The distance limit of a culling traversal for hits closer than `t`.
#[inline]
fn cull_limit(t: f32) -> f32 {
    t + t.abs() * CULL_MARGIN
}

impl Instances {
    /// Compiles the prototypes of `scene` (nested ones come first in its list); `first_id`
    /// is the render scene's primitive count.
    pub fn new(scene: &Scene, first_id: u32) -> Instances {
        let stub = Scene {
            instanced: scene.instanced.clone(),
            local_transforms: scene.local_transforms.clone(),
            moves: scene.moves.clone(),
            ..Scene::default()
        };
        let mut compiled: Vec<Compiled> = Vec::with_capacity(stub.instanced.prototypes.len());
        for p in &stub.instanced.prototypes {
            let mut bounds: Vec<Aabb> = p
                .leaves
                .iter()
                .map(|leaf| {
                    let rel = stub.prototype_world(p, &Transform::IDENTITY, leaf.transform);
                    Primitive::new(&leaf.geometry, &rel, leaf.material as u32)
                        .map_or(Aabb::EMPTY, |prim| widen(prim.bounds))
                })
                .collect();
            for u in &p.uses {
                let rel = stub.prototype_world(p, &Transform::IDENTITY, u.slot);
                let inner = compiled
                    .get(u.prototype as usize)
                    .map_or(Aabb::EMPTY, |c| c.bounds);
                bounds.push(transformed(&inner, &rel));
            }
            let all = bounds.iter().fold(Aabb::EMPTY, |a, b| a.union(*b));
            let entries = (0..bounds.len() as u32).filter(|&e| !bounds[e as usize].is_empty());
            compiled.push(Compiled {
                bvh: Bvh::build(&bounds, entries),
                bounds: all,
            });
        }
        let frames = stub
            .instanced
            .uses
            .iter()
            .map(|u| scene.use_frame(u))
            .collect();
        Instances {
            scene: stub,
            compiled,
            frames,
            first_id,
        }
    }

    /// The top-level uses and their world bounds (moves included), widened.
    pub fn use_bounds(&self) -> impl Iterator<Item = Aabb> + '_ {
        self.scene
            .instanced
            .uses
            .iter()
            .zip(&self.frames)
            .map(|(u, f)| {
                let inner = self
                    .compiled
                    .get(u.prototype as usize)
                    .map_or(Aabb::EMPTY, |c| c.bounds);
                transformed(&inner, &self.scene.moved(*f))
            })
    }

    /// Top-level uses of composites.
    pub fn uses(&self) -> usize {
        self.scene.instanced.uses.len()
    }

    /// The shape numbered `flat` in the flattened tree, unplaced.
    fn leaf(&self, flat: u32) -> Option<&Instance> {
        let inst = &self.scene.instanced;
        let k = inst
            .uses
            .partition_point(|u| u.offset <= flat)
            .checked_sub(1)?;
        let mut u = &inst.uses[k];
        let mut rest = flat - u.offset;
        loop {
            let p = inst.prototypes.get(u.prototype as usize)?;
            if let Ok(i) = p.offsets.binary_search(&rest) {
                return p.leaves.get(i);
            }
            let k = p
                .uses
                .partition_point(|n| n.offset <= rest)
                .checked_sub(1)?;
            u = &p.uses[k];
            rest -= u.offset;
        }
    }

    /// The shape numbered `flat` in the flattened tree, placed in the world.
    fn decode(&self, flat: u32) -> Option<(&Instance, Transform)> {
        let inst = &self.scene.instanced;
        let k = inst
            .uses
            .partition_point(|u| u.offset <= flat)
            .checked_sub(1)?;
        let mut u = &inst.uses[k];
        let mut frame = self.frames[k];
        let mut rest = flat - u.offset;
        loop {
            let p = inst.prototypes.get(u.prototype as usize)?;
            if let Ok(i) = p.offsets.binary_search(&rest) {
                let leaf = &p.leaves[i];
                let world = self.scene.prototype_world(p, &frame, leaf.transform);
                return Some((leaf, self.scene.moved(world)));
            }
            let k = p
                .uses
                .partition_point(|n| n.offset <= rest)
                .checked_sub(1)?;
            let nested = &p.uses[k];
            frame = self.scene.prototype_world(p, &frame, nested.slot);
            rest -= nested.offset;
            u = nested;
        }
    }

    /// The primitive with id `id` (at least `first_id`), placed.
    pub fn primitive(&self, id: u32) -> Option<Primitive> {
        let (leaf, world) = self.decode(id.checked_sub(self.first_id)?)?;
        Primitive::new(&leaf.geometry, &world, leaf.material as u32).ok()
    }

    /// The material of the primitive with id `id`.
    pub fn material(&self, id: u32) -> u32 {
        id.checked_sub(self.first_id)
            .and_then(|f| self.leaf(f))
            .map_or(0, |leaf| leaf.material as u32)
    }

    /// The ray in a prototype's frame (`world` is the frame, moves included), for culling.
    fn local_ray(world: &Transform, ray: &Ray) -> Ray {
        let m = &world.object_from_world;
        let o = m.transform_point3(ray.origin.as_dvec3());
        let d = m.transform_vector3(ray.dir.as_dvec3());
        Ray::new(Vec3A::from(o.as_vec3()), Vec3A::from(d.as_vec3()))
    }

    /// Visits, through use `u` (in `frame`, its shapes numbered from `base`), every shape the
    /// walk's ray may meet before its limit, as long as the walk goes on.
    fn visit(&self, u: &Use, frame: &Transform, base: u32, walk: &mut Walk) -> bool {
        let inst = &self.scene.instanced;
        let (Some(p), Some(c)) = (
            inst.prototypes.get(u.prototype as usize),
            self.compiled.get(u.prototype as usize),
        ) else {
            return true;
        };
        let local = Self::local_ray(&self.scene.moved(*frame), walk.ray);
        let mut go_on = true;
        c.bvh
            .closest_leaves(&local, cull_limit((walk.limit)()), |leaf, _| {
                for &e in leaf {
                    if !self.entry(p, e, frame, base, walk) {
                        go_on = false;
                        // Beyond every box: the traversal ends.
                        return f32::NEG_INFINITY;
                    }
                }
                cull_limit((walk.limit)())
            });
        go_on
    }

    /// Entry `e` of prototype `p` (a shape, or a nested use) as `visit` meets it.
    fn entry(&self, p: &Prototype, e: u32, frame: &Transform, base: u32, walk: &mut Walk) -> bool {
        let e = e as usize;
        if let Some(leaf) = p.leaves.get(e) {
            let world = self.scene.prototype_world(p, frame, leaf.transform);
            let flat = base + p.offsets[e];
            match Primitive::new(
                &leaf.geometry,
                &self.scene.moved(world),
                leaf.material as u32,
            ) {
                Ok(prim) => (walk.shape)(self.first_id + flat, &prim),
                Err(_) => true,
            }
        } else if let Some(nested) = p.uses.get(e - p.leaves.len()) {
            let inner = self.scene.prototype_world(p, frame, nested.slot);
            self.visit(nested, &inner, base + nested.offset, walk)
        } else {
            true
        }
    }

    /// The closest hit through top-level use `k`, ties broken by depth-first number; `won`
    /// keeps the placed primitive of an instanced winner (for its surface).
    pub fn closest(
        &self,
        k: u32,
        ray: &Ray,
        t_max: &mut f32,
        best: &mut Option<Best>,
        won: &mut Option<Primitive>,
    ) {
        let u = &self.scene.instanced.uses[k as usize];
        let t_cell = std::cell::Cell::new(*t_max);
        let mut found = *best;
        let first_id = self.first_id;
        let mut walk = Walk {
            ray,
            limit: &|| t_cell.get(),
            shape: &mut |id, prim| {
                let t_now = t_cell.get();
                if let Some(h) = prim.hit(ray, t_now.next_up()) {
                    let key = id - first_id;
                    if Best::loses_to(&found, t_now, h.t, key) {
                        t_cell.set(h.t);
                        found = Some(Best {
                            id,
                            t: h.t,
                            key,
                            hit: Some(h),
                        });
                        *won = Some(prim.clone());
                    }
                }
                true
            },
        };
        self.visit(u, &self.frames[k as usize], u.offset, &mut walk);
        *t_max = t_cell.get();
        *best = found;
    }

    /// Offers every instanced shape through top-level use `k` that the ray may meet before
    /// `t_max` to `stop`, until it returns true (then true).
    pub fn any(&self, k: u32, ray: &Ray, t_max: f32, stop: &mut dyn FnMut(u32) -> bool) -> bool {
        let u = &self.scene.instanced.uses[k as usize];
        let mut stopped = false;
        let mut walk = Walk {
            ray,
            limit: &|| t_max,
            shape: &mut |id, _| {
                stopped = stop(id);
                !stopped
            },
        };
        self.visit(u, &self.frames[k as usize], u.offset, &mut walk);
        stopped
    }

    /// An instanced shape through top-level use `k` that lies on the ray before `t_max`
    /// (its id), if there is one.
    pub fn occluder(&self, k: u32, ray: &Ray, t_max: f32) -> Option<u32> {
        let u = &self.scene.instanced.uses[k as usize];
        let mut hit = None;
        let mut walk = Walk {
            ray,
            limit: &|| t_max,
            shape: &mut |id, prim| {
                if prim.hit(ray, t_max).is_some() {
                    hit = Some(id);
                }
                hit.is_none()
            },
        };
        self.visit(u, &self.frames[k as usize], u.offset, &mut walk);
        hit
    }

    /// Bytes held by the compiled prototypes.
    pub fn memory_bytes(&self) -> usize {
        self.compiled
            .iter()
            .map(|c| c.bvh.memory_bytes())
            .sum::<usize>()
            + self.frames.capacity() * std::mem::size_of::<Transform>()
    }
}
