//! Four primitives at a time: the tests every query of [`super::Aggregate`] ends in, whether
//! its candidates come from a leaf of the hierarchy, the flat leaf of a small scene or a
//! list looked up by a view. Packed spheres go four to one SIMD test, world-space boxes are
//! hit by the slab test of their bounds, and the other kinds are tested one by one where
//! that slab test passes.

use super::{Aggregate, Kind, MovingScratch, BOUNDS_OF_BOX, BOUNDS_OF_OTHER, BOUNDS_OF_SPHERE};
use crate::math::Ray;
use crate::render::geometry::Primitive;
use crate::shape::{BoxRay, ShapeHit, SphereRay};
use glam::Vec4;

/// Spheres (or boxes) tested at once.
pub(super) const LANES: usize = 4;

/// The closest hit so far: the id of what was hit, its distance, the depth-first number
/// that breaks ties (0 for unbounded primitives, which keep their ties), and the
/// object-space hit of a primitive that is not a packed sphere.
#[derive(Clone, Copy, Debug)]
pub struct Best {
    pub id: u32,
    pub t: f32,
    pub key: u32,
    pub hit: Option<ShapeHit>,
}

impl Best {
    /// Whether a hit at `t` numbered `key` wins over this one: closer, or as close and
    /// earlier in the flattened tree.
    #[inline(always)]
    pub fn loses_to(best: &Option<Best>, t_max: f32, t: f32, key: u32) -> bool {
        t < t_max || (t == t_max && best.is_some_and(|b| key < b.key))
    }
}

/// A ray as the tests four at a time read it: the ray, and its lanes for packed spheres.
#[derive(Clone, Copy)]
pub(super) struct LaneRay<'r> {
    pub ray: &'r Ray,
    pub spheres: &'r SphereRay,
}

/// One group of four primitives of a leaf or of a list: the primitive in each lane (`id`),
/// their slab tests (`classify_lanes`), and their packed spheres, loaded only if some lane
/// is a sphere.
pub(super) struct Four<I, S> {
    pub id: I,
    pub lanes: Lanes,
    pub spheres: S,
}

/// Four packed spheres in lanes: primitive `id(k)` in lane `k`, of which the lanes `live`
/// count.
pub(super) struct FourSpheres<'s, I> {
    pub spheres: &'s [Vec4; LANES],
    pub id: I,
    pub live: u32,
}

/// What a closest-hit query keeps as it goes: the closest hit so far, and the placed
/// primitive of an instanced winner (for its surface).
pub(super) struct Kept<'k> {
    pub best: &'k mut Option<Best>,
    pub won: &'k mut Option<Primitive>,
}

impl Kept<'_> {
    /// The same, lent to one call.
    #[inline(always)]
    pub fn reborrow(&mut self) -> Kept<'_> {
        Kept {
            best: &mut *self.best,
            won: &mut *self.won,
        }
    }
}

/// Four primitives sorted by [`Aggregate::classify`], as lane masks.
pub(super) struct Lanes {
    pub spheres: u32,
    pub boxes_hit: u32,
    pub box_t: Vec4,
    pub others_near: u32,
}

/// The four entries from `i` on.
#[inline(always)]
pub(super) fn four(v: &[Vec4], i: usize) -> [Vec4; LANES] {
    let s = &v[i..i + LANES];
    [s[0], s[1], s[2], s[3]]
}

/// A list of candidates (padded to a multiple of four) four primitive numbers at a time.
#[inline(always)]
pub(super) fn fours(listed: &[u32]) -> impl Iterator<Item = [usize; LANES]> + '_ {
    listed
        .chunks_exact(LANES)
        .map(|f| [f[0] as usize, f[1] as usize, f[2] as usize, f[3] as usize])
}

/// The entries `ids`.
#[inline(always)]
pub(super) fn gather(v: &[Vec4], ids: [usize; LANES]) -> [Vec4; LANES] {
    [v[ids[0]], v[ids[1]], v[ids[2]], v[ids[3]]]
}

/// Offers the lanes set in `mask` of four primitives (`id` of each lane) to `stop`, in lane
/// order, until it returns true (then true).
#[inline(always)]
pub(super) fn offer(
    id: impl Fn(usize) -> usize,
    mut mask: u32,
    stop: &mut impl FnMut(u32) -> bool,
) -> bool {
    while mask != 0 {
        let k = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        if stop(id(k) as u32) {
            return true;
        }
    }
    false
}

impl Aggregate {
    /// The four primitives from `start` on (those before `end`), sorted by the slab test of
    /// their bounds: the packed spheres; the boxes hit before `t_max`, and where; the other
    /// kinds whose bounds the ray meets before `t_max`.
    #[inline(always)]
    pub(super) fn classify(&self, boxes: &BoxRay, start: usize, end: usize, t_max: f32) -> Lanes {
        let (min, max) = (four(&self.bounds_min, start), four(&self.bounds_max, start));
        self.classify_lanes(boxes, min, max, (1 << (end - start).min(LANES)) - 1, t_max)
    }

    /// `classify` of four primitives' bounds `min` and `max`, of which the lanes `live` count.
    #[inline(always)]
    pub(super) fn classify_lanes(
        &self,
        boxes: &BoxRay,
        min: [Vec4; LANES],
        max: [Vec4; LANES],
        live: u32,
        t_max: f32,
    ) -> Lanes {
        let s = boxes.slabs4(min, max);
        let tagged = |tag: f32| s.tag.cmpeq(Vec4::splat(tag)).bitmask() & live;
        let (hit, box_t) = s.hits(t_max);
        Lanes {
            spheres: tagged(BOUNDS_OF_SPHERE),
            boxes_hit: hit & tagged(BOUNDS_OF_BOX),
            box_t,
            others_near: s.overlaps(t_max) & tagged(BOUNDS_OF_OTHER),
        }
    }

    /// The closest hit among a leaf of packed spheres only: the same tests and the same
    /// winner as [`Aggregate::closest_in_leaf`], without asking each primitive its kind. Only
    /// the lanes hit are looked at, in lane order, which is the order `closest_in_leaf`
    /// judges them in. Returns the new `t_max`.
    #[inline(always)]
    pub(super) fn closest_in_sphere_leaf(
        &self,
        lanes: &SphereRay,
        leaf: &[u32],
        mut t_max: f32,
        best: &mut Option<Best>,
    ) -> f32 {
        let first = leaf[0] as usize;
        let end = first + leaf.len();
        let limit = t_max.next_up();
        for start in (first..end).step_by(LANES) {
            let spheres = SphereRay::lanes(self.four_spheres(start));
            let group = FourSpheres {
                spheres: &spheres,
                id: |k| start + k,
                live: (1 << (end - start).min(LANES)) - 1,
            };
            t_max = self.closest_in_spheres(lanes, group, limit, t_max, best);
        }
        t_max
    }

    /// The closest hit among one leaf's primitives (their bounds slab-tested by `boxes`);
    /// returns the new `t_max`.
    #[inline(always)]
    pub(super) fn closest_in_leaf(
        &self,
        ray: LaneRay,
        boxes: &BoxRay,
        leaf: &[u32],
        mut t_max: f32,
        mut kept: Kept,
        scratch: &mut MovingScratch,
    ) -> f32 {
        let first = leaf[0] as usize;
        let end = first + leaf.len();
        // A hit as close as the kept one is found too, to be judged by its number.
        let limit = t_max.next_up();
        for start in (first..end).step_by(LANES) {
            let group = Four {
                id: |k| start + k,
                lanes: self.classify(boxes, start, end, limit),
                spheres: || self.four_spheres(start),
            };
            t_max = self.closest_in_four(ray, group, limit, t_max, kept.reborrow(), scratch);
        }
        t_max
    }

    /// The closest hit among one group of four primitives of a leaf (or of a list), up to
    /// `limit` (the leaf's first `t_max`, moved up one ulp). Only those hit (spheres, boxes)
    /// or whose bounds the ray meets (other kinds) are looked at, in lane order. Returns the
    /// new `t_max`.
    #[inline(always)]
    pub(super) fn closest_in_four(
        &self,
        at: LaneRay,
        group: Four<impl Fn(usize) -> usize, impl FnOnce() -> [Vec4; LANES]>,
        limit: f32,
        mut t_max: f32,
        kept: Kept,
        scratch: &mut MovingScratch,
    ) -> f32 {
        let (ray, c, id) = (at.ray, &group.lanes, &group.id);
        let Kept { best, won } = kept;
        let (sphere_hit, sphere_t) = if c.spheres != 0 {
            at.spheres.hit4((group.spheres)(), limit)
        } else {
            (0, Vec4::ZERO)
        };
        let mut todo = (sphere_hit & c.spheres) | c.boxes_hit | c.others_near;
        while todo != 0 {
            let k = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            let i = id(k);
            let (t, hit) = if c.others_near & (1 << k) != 0 {
                match self.kind_of(i) {
                    Kind::Moving(m) => {
                        self.closest_moving(m, i, ray, &mut t_max, best, scratch);
                        continue;
                    }
                    Kind::Instance(u) => {
                        if let Some(inst) = &self.instances {
                            inst.closest(u, ray, &mut t_max, best, won);
                        }
                        continue;
                    }
                    Kind::Shape(o) => match self.objects[o as usize].hit(ray, t_max.next_up()) {
                        Some(h) => (h.t, Some(h)),
                        None => continue,
                    },
                    Kind::Sphere => continue,
                }
            } else if c.spheres & (1 << k) != 0 {
                (sphere_t[k], None)
            } else {
                (c.box_t[k], None)
            };
            if Best::loses_to(best, t_max, t, self.key[i]) {
                t_max = t;
                *best = Some(Best {
                    id: i as u32,
                    t,
                    key: self.key[i],
                    hit,
                });
            }
        }
        t_max
    }

    /// Moving entry `m` (primitive `i`) placed at the ray's time, kept in `best` if it is hit
    /// closer than `t_max` (or as close, and earlier in the tree).
    #[inline(always)]
    fn closest_moving(
        &self,
        m: u32,
        i: usize,
        ray: &Ray,
        t_max: &mut f32,
        best: &mut Option<Best>,
        scratch: &mut MovingScratch,
    ) {
        let h = self
            .moving_with(m, ray, scratch, |p| p.hit(ray, t_max.next_up()))
            .flatten();
        if let Some(h) = h.filter(|h| Best::loses_to(best, *t_max, h.t, self.key[i])) {
            *t_max = h.t;
            *best = Some(Best {
                id: i as u32,
                t: *t_max,
                key: self.key[i],
                hit: Some(h),
            });
        }
    }

    /// The closest hit among one group of four packed spheres, tested up to `limit` (the
    /// leaf's first `t_max`, moved up one ulp); returns the new `t_max`.
    #[inline(always)]
    pub(super) fn closest_in_spheres(
        &self,
        lanes: &SphereRay,
        group: FourSpheres<impl Fn(usize) -> usize>,
        limit: f32,
        mut t_max: f32,
        best: &mut Option<Best>,
    ) -> f32 {
        let FourSpheres { spheres, id, live } = group;
        let (mask, t) = lanes.hit_lanes(spheres, limit);
        let mut mask = mask & live;
        while mask != 0 {
            let k = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let i = id(k);
            if Best::loses_to(best, t_max, t[k], self.key[i]) {
                t_max = t[k];
                *best = Some(Best {
                    id: i as u32,
                    t: t_max,
                    key: self.key[i],
                    hit: None,
                });
            }
        }
        t_max
    }

    /// One group of four primitives of an any-hit query (of a leaf or a list): offers those
    /// hit before `t_max` to `stop`: boxes, then spheres, then the other kinds whose bounds the
    /// ray meets; true when `stop` did.
    #[inline(always)]
    pub(super) fn any_in_four(
        &self,
        at: LaneRay,
        t_max: f32,
        group: Four<impl Fn(usize) -> usize, impl FnOnce() -> [Vec4; LANES]>,
        stop: &mut impl FnMut(u32) -> bool,
        scratch: &mut MovingScratch,
    ) -> bool {
        let (c, id) = (&group.lanes, &group.id);
        if offer(id, c.boxes_hit, stop) {
            return true;
        }
        if c.spheres != 0 {
            let hit = at.spheres.hit4((group.spheres)(), t_max).0;
            if offer(id, hit & c.spheres, stop) {
                return true;
            }
        }
        let mut near = c.others_near;
        while near != 0 {
            let k = near.trailing_zeros() as usize;
            near &= near - 1;
            if self
                .other_hit(id(k), at.ray, t_max, scratch)
                .is_some_and(&mut *stop)
            {
                return true;
            }
        }
        false
    }

    /// Primitive `i`, of a kind whose bounds do not give its hit, as an any-hit query offers
    /// it if the ray meets it before `t_max`: itself, or in an instanced composite the shape
    /// hit.
    #[inline(always)]
    fn other_hit(
        &self,
        i: usize,
        ray: &Ray,
        t_max: f32,
        scratch: &mut MovingScratch,
    ) -> Option<u32> {
        match self.kind_of(i) {
            Kind::Moving(k) => self
                .moving_with(k, ray, scratch, |p| p.hit(ray, t_max).is_some())
                .filter(|&hit| hit)
                .map(|_| i as u32),
            Kind::Instance(u) => self
                .instances
                .as_ref()
                .and_then(|inst| inst.occluder(u, ray, t_max)),
            Kind::Shape(o) => self.objects[o as usize].hit(ray, t_max).map(|_| i as u32),
            Kind::Sphere => None,
        }
    }
}
