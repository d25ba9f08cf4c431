//! The closest hit along a ray: among every primitive (through the hierarchy, or one flat
//! leaf of a small scene) or among a list of candidates (`listed.rs`). Of equally close
//! hits, an unbounded primitive's wins (the first of them), else the first in the flattened
//! composite tree's order, whatever order the primitives are tested in: every strategy gives
//! the same answer to the bit.

use super::leaf::{Best, Kept, LaneRay};
use super::{placed_surface, sphere_surface, Aggregate, Kind, MovingScratch, PrimId, SurfaceHit};
use crate::math::Ray;
use crate::render::geometry::Primitive;
use crate::shape::{BoxRay, SphereRay};

/// Which primitives a query tests.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Candidates<'a> {
    /// Every primitive: the hierarchy's walk, or the flat leaf of a small scene.
    All,
    /// The bounded primitives of `ids` (padded to a multiple of four) and the unbounded ones:
    /// the others are known to lie off the ray. With `near`, each group of four has a
    /// distance no hit in it comes closer than, groups nearest first, and the groups past
    /// the closest hit so far (or past the ray's end) are not tested.
    Listed {
        /// Bounded primitives (padded with a never-hit number to whole groups of four).
        ids: &'a [u32],
        /// Per group of four, a distance none of them comes closer than (groups nearest first).
        near: Option<&'a [f32]>,
    },
}

/// The primitive numbers `0..FLAT_MAX`, for a leaf of them all.
const FLAT: [u32; crate::render::policy::FLAT_MAX] = {
    let mut all = [0; crate::render::policy::FLAT_MAX];
    let mut i = 0;
    while i < all.len() {
        all[i] = i as u32;
        i += 1;
    }
    all
};

impl Aggregate {
    /// Nearest surface along the ray with `t < t_max` among `candidates`.
    #[inline]
    pub(crate) fn closest(
        &self,
        ray: &Ray,
        t_max: f32,
        candidates: Candidates,
        scratch: &mut MovingScratch,
    ) -> Option<(PrimId, SurfaceHit)> {
        match candidates {
            Candidates::All => self.closest_of_all(ray, t_max, scratch),
            Candidates::Listed { ids, near: None } => {
                self.closest_listed::<false>(ray, ids, &[], scratch)
            }
            Candidates::Listed {
                ids,
                near: Some(near),
            } => self.closest_listed::<true>(ray, ids, near, scratch),
        }
    }

    /// [`Aggregate::closest`] among every primitive.
    #[inline]
    fn closest_of_all(
        &self,
        ray: &Ray,
        t_max: f32,
        scratch: &mut MovingScratch,
    ) -> Option<(PrimId, SurfaceHit)> {
        // Filled in place, not returned: a `Primitive` is 240 bytes, and moving even a `None`
        // of it in and out of calls costs more than the tests of a small scene.
        let (mut best, t_best) = self.closest_unbounded(ray, t_max, scratch);
        let mut won = None;
        let lanes = SphereRay::new(ray);
        let flat = self.flat_leaf();
        if self.plan.spheres_only {
            let mut leaf =
                |leaf: &[u32], t_max| self.closest_in_sphere_leaf(&lanes, leaf, t_max, &mut best);
            match flat {
                Some(all) => _ = leaf(all, t_best),
                None => _ = self.bvh.closest_leaves(ray, t_best, leaf),
            }
        } else {
            let boxes = BoxRay::new(ray);
            let at = LaneRay {
                ray,
                spheres: &lanes,
            };
            let mut leaf = |leaf: &[u32], t_max| {
                let kept = Kept {
                    best: &mut best,
                    won: &mut won,
                };
                self.closest_in_leaf(at, &boxes, leaf, t_max, kept, scratch)
            };
            match flat {
                Some(all) => _ = leaf(all, t_best),
                None => _ = self.bvh.closest_leaves(ray, t_best, leaf),
            }
        }
        self.surface_of(ray, best?, won.as_ref(), scratch)
    }

    /// All bounded primitives as one leaf, when the plan tests them so (`policy::FLAT_MAX`):
    /// testing them all, four at a time, costs less than walking the hierarchy to them. The
    /// answers are the hierarchy's: the closest hit is judged by distance and number, not by
    /// the order of the tests, and any-hit callers take any order.
    #[inline(always)]
    pub(super) fn flat_leaf(&self) -> Option<&'static [u32]> {
        self.plan.flat.then(|| &FLAT[..self.unbounded as usize])
    }

    /// The nearest unbounded primitive's hit before `t_max` and the new `t_max`: what every
    /// closest-hit query starts from. The winner's object-space hit is kept for its surface
    /// (spheres recompute theirs).
    #[inline(always)]
    pub(super) fn closest_unbounded(
        &self,
        ray: &Ray,
        t_max: f32,
        scratch: &mut MovingScratch,
    ) -> (Option<Best>, f32) {
        let mut best: Option<Best> = None;
        let mut t_best = t_max;
        for i in self.unbounded..self.len() as u32 {
            if let Some(h) = self.shape_hit(i, ray, t_best, scratch) {
                t_best = h.t;
                best = Some(Best {
                    id: i,
                    t: h.t,
                    key: 0,
                    hit: Some(h),
                });
            }
        }
        (best, t_best)
    }

    /// The world-space surface of the closest hit's winner (`won`: the placed instanced
    /// primitive when the winner is one).
    #[inline(always)]
    pub(super) fn surface_of<P: std::borrow::Borrow<Primitive>>(
        &self,
        ray: &Ray,
        best: Best,
        won: Option<P>,
        scratch: &mut MovingScratch,
    ) -> Option<(PrimId, SurfaceHit)> {
        let Best { id: i, t, hit, .. } = best;
        let kind = self.kind.get(i as usize).map(|k| k.kind());
        let surface = match (kind, hit) {
            (Some(Kind::Sphere), _) => sphere_surface(&self.sphere(i as usize).hit_at(ray, t)),
            (Some(Kind::Moving(k)), Some(h)) => self.moving_surface(k, ray, &h, scratch)?,
            (Some(Kind::Shape(o)), Some(h)) => self.objects[o as usize].surface(&h),
            // A box hit by the four-at-a-time test: its own test finds the same `t`, and the
            // rest of the hit, for the winner alone.
            (Some(Kind::Shape(o)), None) => {
                let p = &self.objects[o as usize];
                p.surface(&p.hit(ray, t.next_up())?)
            }
            (_, Some(h)) => placed_surface(won?.borrow(), ray, t, &h),
            (_, None) => unreachable!("instanced and moving shapes keep their hit"),
        };
        Some((i, surface))
    }
}
