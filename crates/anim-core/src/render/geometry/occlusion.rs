//! Any-hit queries: whether, and what, a ray meets before a distance, in whatever order is
//! cheapest (shadow rays, and the tests that hold every strategy to brute force).

use super::leaf::{offer, Four, LaneRay, LANES};
use super::{Aggregate, Candidates, Kind, MovingScratch};
use crate::math::Ray;
use crate::shape::{BoxRay, SphereRay};

impl Aggregate {
    /// Offers each primitive among `candidates` hit before `t_max` (in an instanced
    /// composite, the first shape hit of each use) to `stop`, until it returns true. Which
    /// of several comes first is the strategy's: near first through the hierarchy, by
    /// distance from the ray's end in a list that gives distances.
    #[inline]
    pub(crate) fn any(
        &self,
        ray: &Ray,
        t_max: f32,
        candidates: Candidates,
        scratch: &mut MovingScratch,
        stop: impl FnMut(u32) -> bool,
    ) {
        match candidates {
            Candidates::All => self.any_of_all(ray, t_max, scratch, stop),
            Candidates::Listed { ids, near: None } => {
                self.any_listed::<false>(ray, t_max, ids, &[], scratch, stop)
            }
            Candidates::Listed {
                ids,
                near: Some(near),
            } => self.any_listed::<true>(ray, t_max, ids, near, scratch, stop),
        }
    }

    /// [`Aggregate::any`] among every primitive, in the hierarchy's near-first order. Not
    /// inlined, as the queries over lists are not: the dispatch that picks one of them stays
    /// small enough to be inlined where rays are traced.
    #[inline(never)]
    fn any_of_all(
        &self,
        ray: &Ray,
        t_max: f32,
        scratch: &mut MovingScratch,
        stop: impl FnMut(u32) -> bool,
    ) {
        self.any_hit(ray, t_max, scratch, stop)
    }

    /// [`Aggregate::any`] among every primitive, in the hierarchy's near-first order.
    #[inline(always)]
    fn any_hit(
        &self,
        ray: &Ray,
        t_max: f32,
        scratch: &mut MovingScratch,
        mut stop: impl FnMut(u32) -> bool,
    ) {
        for i in self.unbounded..self.len() as u32 {
            if self.hit(i, ray, t_max, scratch).is_some() && stop(i) {
                return;
            }
        }
        let lanes = SphereRay::new(ray);
        let flat = self.flat_leaf();
        if self.plan.spheres_only {
            let leaf = |leaf: &[u32]| {
                let first = leaf[0] as usize;
                let end = first + leaf.len();
                (first..end).step_by(LANES).any(|start| {
                    let live = (end - start).min(LANES);
                    let mask = lanes.hit4(self.four_spheres(start), t_max).0 & ((1 << live) - 1);
                    offer(|k| start + k, mask, &mut stop)
                })
            };
            match flat {
                Some(all) => _ = { leaf }(all),
                None => _ = self.bvh.any_leaves(ray, t_max, leaf),
            }
            return;
        }
        let boxes = BoxRay::new(ray);
        let leaf = |leaf: &[u32]| {
            let (first, end) = (leaf[0] as usize, leaf[0] as usize + leaf.len());
            (first..end).step_by(LANES).any(|start| {
                let group = Four {
                    id: |k| start + k,
                    lanes: self.classify(&boxes, start, end, t_max),
                    spheres: || self.four_spheres(start),
                };
                let at = LaneRay {
                    ray,
                    spheres: &lanes,
                };
                self.any_in_four(at, t_max, group, &mut stop, scratch)
            })
        };
        match flat {
            Some(all) => _ = { leaf }(all),
            None => _ = self.bvh.any_leaves(ray, t_max, leaf),
        }
    }

    /// Offers every primitive the ray may meet before `t_max` to `stop`, in no particular
    /// order (bounds tested, shapes not), until it returns true (then true).
    #[inline]
    pub(crate) fn any_candidate(
        &self,
        ray: &Ray,
        t_max: f32,
        mut stop: impl FnMut(u32) -> bool,
    ) -> bool {
        (self.unbounded..self.len() as u32).any(&mut stop)
            || self
                .bvh
                .any(ray, t_max, |i| match self.kind_of(i as usize) {
                    Kind::Instance(u) => self
                        .instances
                        .as_ref()
                        .is_some_and(|inst| inst.any(u, ray, t_max, &mut stop)),
                    _ => stop(i),
                })
    }
}
