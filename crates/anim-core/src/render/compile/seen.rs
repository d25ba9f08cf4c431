//! Where rays start or end at known points: cells of directions around the lights and the
//! eye in a flat scene, tiles of the image around them in a larger one
//! (`crate::accel::DirectionCells`, `crate::accel::ImageTiles`), and the closest hits of
//! camera rays looked up there.

use super::any_hit::{fours, gather};
use super::{takes_cells, RenderScene, SurfaceHit, FLAT_MAX};
use crate::accel::{DirectionCells, ImageTiles, ImageView};
use crate::math::{Aabb, Ray};
use crate::shape::{BoxRay, SphereRay};
use glam::Vec3A;

/// Fewest bounded primitives for which shadow rays look their candidates up in tiles around
/// the lights. The showcase's 57 shapes (boxes and transformed shapes, glass among them) took
/// 3.5 % more instructions with them; 64 random spheres 3 % fewer, 128 10 % fewer.
const LIGHT_TILES_MIN: usize = 64;

impl RenderScene {
    /// Where camera rays start: their candidates are then looked up by direction
    /// (`closest_seen`) in a scene that takes cells (`takes_cells`).
    pub fn watch_from(&mut self, eye: Vec3A) {
        self.eye_cells = self.cells_around(eye);
    }

    /// The image through which every camera ray passes, from one eye, for about
    /// `camera_rays` of them: camera rays then look their candidates up by where they cross
    /// it (`closest_seen`), and shadow rays by where each light sees them start (`shadow`),
    /// in a scene larger than a flat one (whose cells serve) with nothing moving, when there
    /// are at least as many camera rays as primitives. With fewer, building the tiles (a few
    /// hundred instructions a primitive and image) costs more than they save (a million
    /// spheres at 640×360, 1 spp: 13 % more instructions). Lights take tiles from
    /// `LIGHT_TILES_MIN` primitives on.
    pub fn watch_image(&mut self, view: ImageView, size: (u32, u32), camera_rays: u64) {
        let n = self.unbounded as usize;
        if self.moving.is_some() || n <= FLAT_MAX || n as u64 > camera_rays {
            return;
        }
        let bound = |i| self.bound(i);
        // Past the last primitive, every packed array holds NaN: never hit.
        let pad = self.len() as u32;
        let all = (0..n).fold(Aabb::EMPTY, |all, i| all.union(bound(i)));
        let lights = self.lights.iter().filter(|_| n >= LIGHT_TILES_MIN);
        let light_tiles = lights
            .map(|l| ImageTiles::around(l.position, &all, n, bound, pad))
            .collect();
        let eye_tiles = ImageTiles::new(view, size, n, bound, pad);
        (self.light_tiles, self.eye_tiles) = (light_tiles, eye_tiles);
    }

    /// Cells around `centre` listing the bounded primitives, if the scene takes them.
    pub(super) fn cells_around(&self, centre: Vec3A) -> Option<DirectionCells> {
        if !takes_cells(self.unbounded) {
            return None;
        }
        let bounds: Vec<Aabb> = (0..self.unbounded as usize)
            .map(|i| self.bound(i))
            .collect();
        // Past the last primitive, every packed array holds NaN: never hit.
        Some(DirectionCells::new(centre, &bounds, self.len() as u32))
    }

    /// The world bounds of bounded primitive `i`.
    fn bound(&self, i: usize) -> Aabb {
        if self.all_spheres {
            let s = self.spheres[i];
            let (c, r) = (Vec3A::from(s.truncate()), Vec3A::splat(s.w));
            Aabb::new(c - r, c + r)
        } else {
            Aabb::new(
                self.bounds_min[i].truncate().into(),
                self.bounds_max[i].truncate().into(),
            )
        }
    }

    /// `closest` of a camera ray, from the eye `watch_from` named through the image
    /// `watch_image` named (or, if it starts elsewhere or misses the image, as `closest`
    /// finds it), with no limit.
    #[inline]
    pub fn closest_seen(&self, ray: &Ray) -> Option<(u32, SurfaceHit)> {
        if let Some(cells) = &self.eye_cells {
            if let Some(listed) = cells.candidates(ray.origin, ray.dir, f32::INFINITY) {
                return self.closest_listed::<false>(ray, listed, &[]);
            }
        } else if let Some(tiles) = &self.eye_tiles {
            if let Some((listed, near)) = tiles.candidates(ray.origin, ray.dir) {
                return self.closest_listed::<true>(ray, listed, near);
            }
        }
        self.closest(ray, f32::INFINITY)
    }

    /// `closest_seen` of each ray of a packet of camera rays, which lie on the image within the
    /// rectangle that the first and the last span (a block of pixels, or a run of a row).
    pub fn closest_seen_packet<const N: usize>(
        &self,
        rays: &[Ray; N],
    ) -> [Option<(u32, SurfaceHit)>; N] {
        let Some(tiles) = &self.eye_tiles else {
            return self.closest_packet(rays, f32::INFINITY);
        };
        // Rays of one tile in a scene of packed spheres alone: each group of four spheres is
        // put in lanes once for them all. The rays between the first and the last on the
        // image lie in the tile of both (up to round-off, which the tiles' widening covers).
        let ends = [&rays[0], &rays[N - 1]].map(|r| tiles.candidates(r.origin, r.dir));
        match ends {
            [Some(first), Some(last)] if self.all_spheres && std::ptr::eq(first.0, last.0) => {
                self.closest_in_tile(rays, first)
            }
            _ => std::array::from_fn(|r| self.closest_seen(&rays[r])),
        }
    }

    /// `closest_listed::<true>` of each of `rays` (camera rays of one tile, whose list and
    /// distances are `listed` and `near`) in a scene of packed spheres alone (so with nothing
    /// unbounded): a group is tested for the rays whose closest hit so far does not lie nearer.
    #[inline(never)]
    fn closest_in_tile<const N: usize>(
        &self,
        rays: &[Ray; N],
        (listed, near): (&[u32], &[f32]),
    ) -> [Option<(u32, SurfaceHit)>; N] {
        let lanes: [SphereRay; N] = std::array::from_fn(|r| SphereRay::new(&rays[r]));
        let mut best = [None; N];
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
                t_max[r] = self.closest_in_spheres(
                    &lanes[r],
                    &spheres,
                    |k| ids[k],
                    0xF,
                    f32::INFINITY,
                    t_max[r],
                    &mut best[r],
                );
            }
        }
        std::array::from_fn(|r| {
            self.surface_of(
                &rays[r],
                best[r]?,
                None::<&crate::render::primitive::Primitive>,
            )
        })
    }

    /// `closest` (without limit) among the bounded primitives of `listed` alone
    /// (`DirectionCells::candidates` or `ImageTiles::candidates`, padded to a multiple of
    /// four): the others are known to lie off the ray, and which of those listed wins is
    /// judged as `closest` judges it, by distance and number. `NEAREST_FIRST`: `near` gives
    /// each group of four a distance no hit in it comes closer than (groups nearest first),
    /// and the groups past the closest hit so far are not tested. Not inlined, as
    /// `RenderScene::any_listed`.
    #[inline(never)]
    fn closest_listed<const NEAREST_FIRST: bool>(
        &self,
        ray: &Ray,
        listed: &[u32],
        near: &[f32],
    ) -> Option<(u32, SurfaceHit)> {
        let (mut best, mut t_max) = self.closest_unbounded(ray, f32::INFINITY);
        let mut won = None;
        let lanes = SphereRay::new(ray);
        let limit = t_max.next_up();
        let boxes = (!self.all_spheres).then(|| BoxRay::new(ray));
        for (group, ids) in fours(listed).enumerate() {
            if NEAREST_FIRST && near.get(group).is_some_and(|&n| n > t_max) {
                break;
            }
            let id = |k: usize| ids[k];
            let Some(boxes) = &boxes else {
                let spheres = SphereRay::lanes(gather(&self.spheres, ids));
                t_max = self.closest_in_spheres(&lanes, &spheres, id, 0xF, limit, t_max, &mut best);
                continue;
            };
            let (min, max) = (gather(&self.bounds_min, ids), gather(&self.bounds_max, ids));
            let c = self.classify_lanes(boxes, min, max, 0xF, limit);
            let group = (id, c, || gather(&self.spheres, ids));
            t_max = self.closest_in_four(&lanes, ray, group, limit, t_max, &mut best, &mut won);
        }
        self.surface_of(ray, best?, won.as_ref())
    }
}
