//! Queries over a list of candidates that a view looked up for a ray (direction cells, image
//! tiles: `crate::accel::DirectionCells`, `crate::accel::ImageTiles`): the listed bounded
//! primitives and the unbounded ones are tested, four at a time, and the answers are those
//! of the same query over every primitive.

use super::leaf::{fours, gather, offer, Four, FourSpheres, Kept, LaneRay};
use super::{Aggregate, MovingScratch, PrimId, SurfaceHit};
use crate::math::Ray;
use crate::shape::{BoxRay, SphereRay};

impl Aggregate {
    /// The closest hit (without limit) among the bounded primitives of `listed` (padded to a
    /// multiple of four) and the unbounded ones: which of those listed wins is judged as
    /// every closest-hit query judges it, by distance and number. `NEAREST_FIRST`: `near`
    /// gives each group of four a distance no hit in it comes closer than (groups nearest
    /// first), and the groups past the closest hit so far are not tested. Not inlined:
    /// the query over every primitive keeps the size, and the inlining, it has without lists.
    #[inline(never)]
    pub(super) fn closest_listed<const NEAREST_FIRST: bool>(
        &self,
        ray: &Ray,
        listed: &[u32],
        near: &[f32],
        scratch: &mut MovingScratch,
    ) -> Option<(PrimId, SurfaceHit)> {
        let (mut best, mut t_max) = self.closest_unbounded(ray, f32::INFINITY, scratch);
        let mut won = None;
        let lanes = SphereRay::new(ray);
        let limit = t_max.next_up();
        let boxes = (!self.plan.spheres_only).then(|| BoxRay::new(ray));
        for (group, ids) in fours(listed).enumerate() {
            if NEAREST_FIRST && near.get(group).is_some_and(|&n| n > t_max) {
                break;
            }
            let id = |k: usize| ids[k];
            let Some(boxes) = &boxes else {
                let spheres = SphereRay::lanes(gather(&self.spheres, ids));
                let group = FourSpheres {
                    spheres: &spheres,
                    id,
                    live: 0xF,
                };
                t_max = self.closest_in_spheres(&lanes, group, limit, t_max, &mut best);
                continue;
            };
            let (min, max) = (gather(&self.bounds_min, ids), gather(&self.bounds_max, ids));
            let group = Four {
                id,
                lanes: self.classify_lanes(boxes, min, max, 0xF, limit),
                spheres: || gather(&self.spheres, ids),
            };
            let kept = Kept {
                best: &mut best,
                won: &mut won,
            };
            let at = LaneRay {
                ray,
                spheres: &lanes,
            };
            t_max = self.closest_in_four(at, group, limit, t_max, kept, scratch);
        }
        self.surface_of(ray, best?, won.as_ref(), scratch)
    }

    /// Offers the primitives hit before `t_max` among the bounded ones of `listed` (padded
    /// to a multiple of four) and the unbounded ones to `stop`, until it returns true.
    /// `NEAREST_FIRST`: `near` gives each group of four a distance from the ray's far end
    /// that none of it comes closer than (groups nearest first), and the groups farther
    /// than the ray is long are not tested. Not inlined, as `closest_listed`.
    #[inline(never)]
    pub(super) fn any_listed<const NEAREST_FIRST: bool>(
        &self,
        ray: &Ray,
        t_max: f32,
        listed: &[u32],
        near: &[f32],
        scratch: &mut MovingScratch,
        mut stop: impl FnMut(u32) -> bool,
    ) {
        for i in self.unbounded..self.len() as u32 {
            if self.hit(i, ray, t_max, scratch).is_some() && stop(i) {
                return;
            }
        }
        let lanes = SphereRay::new(ray);
        let boxes = (!self.plan.spheres_only).then(|| BoxRay::new(ray));
        for (group, ids) in fours(listed).enumerate() {
            if NEAREST_FIRST && near.get(group).is_some_and(|&n| n > t_max) {
                return;
            }
            let id = |k: usize| ids[k];
            let Some(boxes) = &boxes else {
                let mask = lanes.hit4(gather(&self.spheres, ids), t_max).0;
                if offer(id, mask, &mut stop) {
                    return;
                }
                continue;
            };
            let (min, max) = (gather(&self.bounds_min, ids), gather(&self.bounds_max, ids));
            let group = Four {
                id,
                lanes: self.classify_lanes(boxes, min, max, 0xF, t_max),
                spheres: || gather(&self.spheres, ids),
            };
            let at = LaneRay {
                ray,
                spheres: &lanes,
            };
            if self.any_in_four(at, t_max, group, &mut stop, scratch) {
                return;
            }
        }
    }
}
