//! Any-hit queries of the render scene: whether and what a ray meets before a distance, in
//! whatever order is cheapest, for shadow rays (`RenderScene::shadow`) and occlusion.

use super::{is_moving, is_use, Lanes, RenderScene, LANES, USE};
use crate::math::Ray;
use crate::shape::{BoxRay, SphereRay};
use glam::Vec4;

impl RenderScene {
    /// Whether anything lies on the ray before `t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.occluder(ray, t_max).is_some()
    }

    /// Something that lies on the ray before `t_max` (a primitive id, for [`Self::hit`]), if
    /// anything does; which one, of several, is left to the hierarchy.
    #[inline]
    pub fn occluder(&self, ray: &Ray, t_max: f32) -> Option<u32> {
        let mut found = None;
        self.any_hit(ray, t_max, |i| {
            found = Some(i);
            true
        });
        found
    }

    /// What a shadow ray towards light `light` meets before `t_max`, looking past transparent
    /// primitives for an opaque one (which one, of several, is left to the hierarchy).
    #[inline]
    pub fn shadow(&self, ray: &Ray, t_max: f32, light: usize) -> Shadow {
        let mut seen = Shadow::Clear;
        let stop = |i| {
            // As the walk in `Integrator::visibility` tells them apart.
            if !self.any_transparent || self.materials[self.material_of(i) as usize].opacity >= 1.0
            {
                seen = Shadow::Blocked(i);
                return true;
            }
            seen = match seen {
                // Inside an instanced composite, what lies past `i` is not looked at.
                Shadow::Clear if i < self.len() as u32 => Shadow::Through(i),
                Shadow::Through(j) if j == i => Shadow::Through(i),
                _ => Shadow::Walk,
            };
            false
        };
        let listed = match self.light_cells.get(light) {
            Some(cells) => cells
                .candidates(ray.origin, ray.dir, t_max)
                .map(|listed| (listed, None)),
            None => self
                .light_tiles
                .get(light)
                .and_then(|tiles| tiles.as_ref()?.towards(ray.origin))
                .map(|(listed, near)| (listed, Some(near))),
        };
        match listed {
            Some((listed, None)) => self.any_listed::<false>(ray, t_max, listed, &[], stop),
            Some((listed, Some(near))) => self.any_listed::<true>(ray, t_max, listed, near, stop),
            None => self.any_hit(ray, t_max, stop),
        }
        seen
    }

    /// `any_hit` for the bounded primitives of `listed` (`DirectionCells::candidates` or
    /// `ImageTiles::towards`, padded to a multiple of four) alone: the others are known to
    /// lie off the ray. `NEAREST_FIRST`: `near` gives each group of four a distance from the
    /// ray's far end that none of it comes closer than (groups nearest first), and the groups
    /// farther than the ray is long are not tested.
    // Not inlined: in the scenes without cells or tiles, `shadow` stays the size it was, and
    // so do the inlining choices around it (inlined, random1k took 0.9 % more instructions).
    #[inline(never)]
    fn any_listed<const NEAREST_FIRST: bool>(
        &self,
        ray: &Ray,
        t_max: f32,
        listed: &[u32],
        near: &[f32],
        mut stop: impl FnMut(u32) -> bool,
    ) {
        for i in self.unbounded..self.len() as u32 {
            if self.hit(i, ray, t_max).is_some() && stop(i) {
                return;
            }
        }
        let lanes = SphereRay::new(ray);
        let boxes = (!self.all_spheres).then(|| BoxRay::new(ray));
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
            let c = self.classify_lanes(boxes, min, max, 0xF, t_max);
            let group = (id, c, || gather(&self.spheres, ids));
            if self.any_in_four(ray, &lanes, t_max, group, &mut stop) {
                return;
            }
        }
    }

    /// Offers each primitive hit before `t_max` (in an instanced composite, the first hit of
    /// each use) to `stop`, in the hierarchy's near-first order, until it returns true.
    #[inline(always)]
    fn any_hit(&self, ray: &Ray, t_max: f32, mut stop: impl FnMut(u32) -> bool) {
        for i in self.unbounded..self.len() as u32 {
            if self.hit(i, ray, t_max).is_some() && stop(i) {
                return;
            }
        }
        let lanes = SphereRay::new(ray);
        let flat = self.flat_leaf();
        if self.all_spheres {
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
                let c = self.classify(&boxes, start, end, t_max);
                let group = (|k| start + k, c, || self.four_spheres(start));
                self.any_in_four(ray, &lanes, t_max, group, &mut stop)
            })
        };
        match flat {
            Some(all) => _ = { leaf }(all),
            None => _ = self.bvh.any_leaves(ray, t_max, leaf),
        }
    }

    /// One group of four primitives of `any_hit` (or of a cell's list): `id` of each lane,
    /// their slab tests `c` (`classify_lanes`), and their packed spheres, loaded only if some
    /// lane is a sphere. Offers those hit to `stop`: boxes, then spheres, then the other
    /// kinds whose bounds the ray meets; true when `stop` did.
    #[inline(always)]
    fn any_in_four(
        &self,
        ray: &Ray,
        lanes: &SphereRay,
        t_max: f32,
        (id, c, four_spheres): (
            impl Fn(usize) -> usize,
            Lanes,
            impl FnOnce() -> [Vec4; LANES],
        ),
        stop: &mut impl FnMut(u32) -> bool,
    ) -> bool {
        if offer(&id, c.boxes_hit, stop) {
            return true;
        }
        if c.spheres != 0 && offer(&id, lanes.hit4(four_spheres(), t_max).0 & c.spheres, stop) {
            return true;
        }
        let mut near = c.others_near;
        while near != 0 {
            let k = near.trailing_zeros() as usize;
            near &= near - 1;
            if self.other_hit(id(k), ray, t_max).is_some_and(&mut *stop) {
                return true;
            }
        }
        false
    }

    /// Primitive `i`, of a kind whose bounds do not give its hit, as `any_hit` offers it if
    /// the ray meets it before `t_max`: itself, or in an instanced composite the shape hit.
    #[inline(always)]
    fn other_hit(&self, i: usize, ray: &Ray, t_max: f32) -> Option<u32> {
        match self.kind[i] {
            m if is_moving(m) => self
                .moving_with(m, ray, |p| p.hit(ray, t_max).is_some())
                .filter(|&hit| hit)
                .map(|_| i as u32),
            u if is_use(u) => self
                .instances
                .as_ref()
                .and_then(|inst| inst.occluder(u & !USE, ray, t_max)),
            o => self.objects[o as usize].hit(ray, t_max).map(|_| i as u32),
        }
    }

    /// Offers every primitive the ray may meet before `t_max` to `stop`, in no particular
    /// order, until it returns true (then true).
    #[inline]
    pub fn any_candidate(&self, ray: &Ray, t_max: f32, mut stop: impl FnMut(u32) -> bool) -> bool {
        (self.unbounded..self.len() as u32).any(&mut stop)
            || self.bvh.any(ray, t_max, |i| match self.kind[i as usize] {
                m if is_moving(m) => stop(i),
                u if is_use(u) => self
                    .instances
                    .as_ref()
                    .is_some_and(|inst| inst.any(u & !USE, ray, t_max, &mut stop)),
                _ => stop(i),
            })
    }
}

/// What a shadow ray meets ([`RenderScene::shadow`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shadow {
    /// Nothing.
    Clear,
    /// This opaque primitive (and maybe more).
    Blocked(u32),
    /// This transparent primitive, maybe more than once, and nothing else.
    Through(u32),
    /// Transparent primitives only, but more than one, or some inside an instanced
    /// composite: which of them it crosses, and how often, is for the caller to find out.
    Walk,
}

/// Offers the lanes set in `mask` of four primitives (`id` of each lane) to `stop`, in lane
/// order, until it returns true (then true).
#[inline(always)]
fn offer(id: impl Fn(usize) -> usize, mut mask: u32, stop: &mut impl FnMut(u32) -> bool) -> bool {
    while mask != 0 {
        let k = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        if stop(id(k) as u32) {
            return true;
        }
    }
    false
}

/// A cell's list (`DirectionCells::candidates`, padded to a multiple of four) four
/// primitive numbers at a time.
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
