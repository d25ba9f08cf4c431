//! Closest hits of packets of coherent rays: one walk of the hierarchy for all of them, each
//! leaf tested ray by ray with the single-ray leaf tests, so every ray's answer is
//! [`Aggregate::closest`]'s to the bit (the same winner of ties too).
//!
//! Packets, one home per layer: `crate::accel::wide::packet` (the shared walk of the
//! hierarchy), `crate::render::geometry::packet` (closest hits of a packet) and
//! `crate::render::sampler::packet` (camera rays of a block of pixels, traced together).

use super::leaf::{fours, gather, Best, FourSpheres, Kept, LaneRay, LANES};
use super::{Aggregate, Candidates, MovingScratch, PrimId, Primitive, SurfaceHit};
use crate::accel::Packet;
use crate::math::Ray;
use crate::shape::{BoxRay, SphereRay};

impl Aggregate {
    /// The closest hit (as `Aggregate::closest` finds it) of each ray among every primitive,
    /// all up to `t_max`. Rays whose directions do not share an octant are traced one by one.
    pub fn closest_packet<const N: usize>(
        &self,
        rays: &[Ray; N],
        t_max: f32,
        scratch: &mut MovingScratch,
    ) -> [Option<(PrimId, SurfaceHit)>; N] {
        let Some(packet) = Packet::new(rays) else {
            return rays.map(|r| self.closest(&r, t_max, Candidates::All, scratch));
        };
        let mut best: [Option<Best>; N] = [None; N];
        let mut t_best = [t_max; N];
        let lanes: [SphereRay; N] = std::array::from_fn(|r| SphereRay::new(&rays[r]));
        if self.plan.spheres_only {
            // No unbounded primitives and nothing placed per ray: no `Primitive` (240
            // bytes) is kept per ray, whose copies cost a sphere scene's packets much.
            // A leaf of one group (all but depth-capped ones) is put in lanes once for all
            // the rays that visit it.
            self.bvh
                .closest_leaf_visits_packet(&packet, &mut t_best, |rays, leaf, t_max| {
                    let mut rays = rays;
                    if leaf.len() > LANES {
                        while rays != 0 {
                            let r = rays.trailing_zeros() as usize;
                            rays &= rays - 1;
                            t_max[r] = self.closest_in_sphere_leaf(
                                &lanes[r],
                                leaf,
                                t_max[r],
                                &mut best[r],
                            );
                        }
                        return;
                    }
                    let (first, end) = (leaf[0] as usize, leaf[0] as usize + leaf.len());
                    let spheres = SphereRay::lanes(self.four_spheres(first));
                    while rays != 0 {
                        let r = rays.trailing_zeros() as usize;
                        rays &= rays - 1;
                        let t = t_max[r];
                        let group = FourSpheres {
                            spheres: &spheres,
                            id: |k| first + k,
                            live: (1 << (end - first).min(LANES)) - 1,
                        };
                        t_max[r] =
                            self.closest_in_spheres(&lanes[r], group, t.next_up(), t, &mut best[r]);
                    }
                });
            return std::array::from_fn(|r| {
                self.surface_of(&rays[r], best[r]?, None::<&Primitive>, scratch)
            });
        }
        let mut won: [Option<Primitive>; N] = std::array::from_fn(|_| None);
        for (r, ray) in rays.iter().enumerate() {
            (best[r], t_best[r]) = self.closest_unbounded(ray, t_max, scratch);
        }
        let boxes: [BoxRay; N] = std::array::from_fn(|r| BoxRay::new(&rays[r]));
        self.bvh
            .closest_leaves_packet(&packet, &mut t_best, |r, leaf, t_max| {
                let at = LaneRay {
                    ray: &rays[r],
                    spheres: &lanes[r],
                };
                let kept = Kept {
                    best: &mut best[r],
                    won: &mut won[r],
                };
                self.closest_in_leaf(at, &boxes[r], leaf, t_max, kept, scratch)
            });
        std::array::from_fn(|r| self.surface_of(&rays[r], best[r]?, won[r].as_ref(), scratch))
    }

    /// The closest hit of each of `rays` (camera rays of one tile, whose list and distances
    /// are `listed` and `near`) in a scene of packed spheres alone (so with nothing
    /// unbounded): a group is tested for the rays whose closest hit so far does not lie
    /// nearer. Each answer is `closest_listed::<true>`'s.
    #[inline(never)]
    pub(crate) fn closest_in_tile<const N: usize>(
        &self,
        rays: &[Ray; N],
        (listed, near): (&[u32], &[f32]),
        scratch: &mut MovingScratch,
    ) -> [Option<(PrimId, SurfaceHit)>; N] {
        let lanes: [SphereRay; N] = std::array::from_fn(|r| SphereRay::new(&rays[r]));
        let mut best: [Option<Best>; N] = [None; N];
        let mut t_max = [f32::INFINITY; N];
        let mut live: u64 = (1 << N) - 1;
        for (group, ids) in fours(listed).enumerate() {
            let mut rays = live;
            while rays != 0 {
                let r = rays.trailing_zeros() as usize;
                rays &= rays - 1;
                if near[group] > t_max[r] {
                    live &= !(1 << r);
                }
            }
            if live == 0 {
                break;
            }
            let spheres = SphereRay::lanes(gather(&self.spheres, ids));
            let mut rays = live;
            while rays != 0 {
                let r = rays.trailing_zeros() as usize;
                rays &= rays - 1;
                let group = FourSpheres {
                    spheres: &spheres,
                    id: |k| ids[k],
                    live: 0xF,
                };
                t_max[r] = self.closest_in_spheres(
                    &lanes[r],
                    group,
                    f32::INFINITY,
                    t_max[r],
                    &mut best[r],
                );
            }
        }
        std::array::from_fn(|r| self.surface_of(&rays[r], best[r]?, None::<&Primitive>, scratch))
    }
}
