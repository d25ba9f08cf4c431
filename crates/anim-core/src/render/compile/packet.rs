//! Closest hits of packets of coherent rays (see `crate::accel::Packet`): one walk of the
//! hierarchy for all of them, each leaf tested ray by ray with the single-ray leaf tests, so
//! every ray's answer is `RenderScene::closest`'s to the bit (the same winner of ties too).

use super::instance::Best;
use super::{RenderScene, SurfaceHit, LANES};
use crate::accel::Packet;
use crate::math::Ray;
use crate::render::primitive::Primitive;
use crate::shape::{BoxRay, SphereRay};
use glam::Vec4;

/// Wide nodes below which a scene's camera rays go one by one: with a hierarchy of a few
/// nodes (a room of ten shapes) the walk costs little, and gathering a packet's answers cost
/// more than it saved (mirror-glass at 9 spp, 1.06× main's CPU time in turns).
const PACKET_MIN_NODES: usize = 16;

impl RenderScene {
    /// Whether walking the hierarchy is worth sharing between the rays of a packet.
    pub fn packets_pay(&self) -> bool {
        self.bvh.node_count() >= PACKET_MIN_NODES
    }

    /// [`RenderScene::closest`] of each ray, all up to `t_max`. Rays whose directions do not
    /// share an octant are traced one by one.
    pub fn closest_packet<const N: usize>(
        &self,
        rays: &[Ray; N],
        t_max: f32,
    ) -> [Option<(u32, SurfaceHit)>; N] {
        let Some(packet) = Packet::new(rays) else {
            return rays.map(|r| self.closest(&r, t_max));
        };
        let mut best: [Option<Best>; N] = [None; N];
        let mut t_best = [t_max; N];
        let lanes: [SphereRay; N] = std::array::from_fn(|r| SphereRay::new(&rays[r]));
        if self.all_spheres {
            // No unbounded primitives and nothing placed per ray: no `Primitive` (240
            // bytes) is kept per ray, whose copies were 4 % of a grid10k render's
            // instructions.
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
                        t_max[r] = self.closest_in_spheres(
                            &lanes[r],
                            &spheres,
                            |k| first + k,
                            (1 << (end - first).min(LANES)) - 1,
                            t.next_up(),
                            t,
                            &mut best[r],
                        );
                    }
                });
            return std::array::from_fn(|r| {
                self.surface_of(&rays[r], best[r]?, None::<&Primitive>)
            });
        }
        let mut won: [Option<Primitive>; N] = std::array::from_fn(|_| None);
        for (r, ray) in rays.iter().enumerate() {
            (best[r], t_best[r]) = self.closest_unbounded(ray, t_max);
        }
        let boxes: [BoxRay; N] = std::array::from_fn(|r| BoxRay::new(&rays[r]));
        self.bvh
            .closest_leaves_packet(&packet, &mut t_best, |r, leaf, t_max| {
                self.closest_in_leaf(
                    &lanes[r],
                    &boxes[r],
                    &rays[r],
                    leaf,
                    t_max,
                    &mut best[r],
                    &mut won[r],
                )
            });
        std::array::from_fn(|r| self.surface_of(&rays[r], best[r]?, won[r].as_ref()))
    }
}

impl RenderScene {
    /// One group of `closest_in_sphere_leaf` (or of a cell's list): four packed spheres in
    /// lanes, primitive `id(k)` in lane `k`, of which the lanes `live` count, tested up to
    /// `limit` (the leaf's first `t_max`, moved up one ulp); returns the new `t_max`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn closest_in_spheres(
        &self,
        lanes: &SphereRay,
        spheres: &[Vec4; LANES],
        id: impl Fn(usize) -> usize,
        live: u32,
        limit: f32,
        mut t_max: f32,
        best: &mut Option<Best>,
    ) -> f32 {
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
}
