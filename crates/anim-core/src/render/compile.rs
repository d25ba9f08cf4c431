//! Compiles a scene description into the flat render scene that the integrator touches per
//! ray: primitives in one array, a BVH over the bounded ones, materials in f32 SIMD form.

mod any_hit;
mod instance;
pub mod motion;
mod packet;
mod seen;

use super::primitive::{Primitive, SurfaceHit};
use crate::accel::{Bvh, DirectionCells, ImageTiles};
use crate::math::Ray;
use crate::scene::{Material, Scene};
use crate::shape::{BoxRay, Shape, ShapeHit, Sphere, SphereRay};
pub use any_hit::Shadow;
use glam::{Vec3A, Vec4};
use instance::{Best, Instances};
use motion::Moving;

#[derive(Clone, Debug)]
pub struct ShadeMaterial {
    pub ka: Vec3A,
    pub kd: Vec3A,
    pub ks: Vec3A,
    pub m: f32,
    pub reflectivity: f32,
    pub opacity: f32,
    pub ior: f32,
}

impl ShadeMaterial {
    fn from(m: &Material) -> Self {
        ShadeMaterial {
            ka: m.ka.into(),
            kd: m.kd.into(),
            ks: m.ks.into(),
            m: m.m,
            reflectivity: m.reflectivity.clamp(0.0, 1.0),
            opacity: m.opacity.clamp(0.0, 1.0),
            ior: m.ior,
        }
    }

    pub fn is_transparent(&self) -> bool {
        self.opacity < 1.0
    }
}

#[derive(Clone, Debug)]
pub struct PointLight {
    pub position: Vec3A,
    pub intensity: Vec3A,
}

/// `RenderScene::kind` of a primitive that is a packed world-space sphere.
const SPHERE: u32 = u32::MAX;
/// `RenderScene::kind` of a top-level use of a prototype: this bit, and the use's index.
const USE: u32 = 1 << 31;
/// `RenderScene::kind` of a shape that moves during the exposure: these bits, and its index
/// among the moving entries (`motion::Moving`).
const MOVING: u32 = USE | 1 << 30;
/// Spheres (or boxes) tested at once.
const LANES: usize = 4;
/// `w` of `RenderScene::bounds_min` for a world-space box (its bounds are the box itself,
/// and their slab test gives its hit), for any other kind whose bounds are tested before its
/// own test, and for a packed sphere (tested by `SphereRay::hit4` instead).
const BOUNDS_OF_BOX: f32 = 1.0;
const BOUNDS_OF_OTHER: f32 = 0.0;
const BOUNDS_OF_SPHERE: f32 = -1.0;

/// Most bounded primitives a scene may have for every ray to test them all instead of
/// walking the hierarchy (`RenderScene::flat_leaf`): four groups of four. The room of
/// scenes/bench/mirror-glass.sdf has ten, which its hierarchy puts in three leaves that
/// most rays inside the room meet.
const FLAT_MAX: usize = 16;
/// The primitive numbers `0..FLAT_MAX`, for a leaf of them all.
const FLAT: [u32; FLAT_MAX] = {
    let mut all = [0; FLAT_MAX];
    let mut i = 0;
    while i < FLAT_MAX {
        all[i] = i as u32;
        i += 1;
    }
    all
};

/// Primitives are numbered in the BVH's leaf order (so a leaf reads consecutive entries),
/// then the unbounded ones. World-space spheres, the common case, are packed into 16 bytes
/// and tested four at a time with no dispatch; everything else is a [`Primitive`].
#[derive(Clone, Debug)]
pub struct RenderScene {
    /// Per primitive: its material.
    material: Vec<u32>,
    /// Per primitive: [`SPHERE`], or its index in `objects`.
    kind: Vec<u32>,
    /// Per primitive: the packed sphere (`Sphere::packed`; NaN for other kinds, which no
    /// sphere test hits), then `LANES - 1` NaN entries so a leaf can always load four.
    spheres: Vec<Vec4>,
    objects: Vec<Primitive>,
    /// Per primitive: its world bounds, `w` telling its kind (`BOUNDS_OF_BOX` ...), then
    /// `LANES - 1` NaN entries, so that a leaf slab-tests four at once (world-space boxes are
    /// hit by that test alone, other kinds only tested where it passes). Empty when every
    /// primitive is a packed sphere.
    bounds_min: Vec<Vec4>,
    bounds_max: Vec<Vec4>,
    /// Per primitive: its depth-first number in the flattened composite tree, which breaks
    /// ties between equally close hits (the first in the tree wins), whatever order the
    /// hierarchy offers them in.
    key: Vec<u32>,
    /// The scene's instanced composites. Their shapes have ids from `len()` on: `len()` plus
    /// their depth-first number.
    instances: Option<Box<Instances>>,
    /// What moves during the exposure, if anything does.
    moving: Option<Box<Moving>>,
    bvh: Bvh,
    /// Per light, in a scene of few primitives whose lights hold still (`takes_cells`):
    /// which of them a shadow ray towards the light may meet, by direction. Empty otherwise.
    light_cells: Vec<DirectionCells>,
    /// Per light, in a larger scene that holds still: which primitives a shadow ray towards
    /// the light may meet, by where the light sees its start (`ImageTiles::around`). Empty
    /// otherwise; `None` for a light no image around it serves.
    light_tiles: Vec<Option<ImageTiles>>,
    /// The same around the camera's eye (`watch_from`), for camera rays.
    eye_cells: Option<DirectionCells>,
    /// In a larger scene that holds still, which primitives each part of the camera's image
    /// may show (`watch_image`), for camera rays.
    eye_tiles: Option<ImageTiles>,
    /// The first primitive without finite bounds (planes); these are tested on every ray.
    unbounded: u32,
    /// Whether every primitive is a packed sphere: leaves are then tested without looking
    /// at kinds.
    all_spheres: bool,
    pub materials: Vec<ShadeMaterial>,
    pub lights: Vec<PointLight>,
    pub ambient: Vec3A,
    pub background: Vec3A,
    /// Whether any material lets light through: if not, shadow rays stop at the first hit.
    pub any_transparent: bool,
    /// An upper bound of the radiance any ray can carry (per channel max), used to stop
    /// tracing rays whose weight can no longer change the 8-bit result.
    pub max_radiance: f32,
}

/// A primitive that could not be placed (degenerate after transformation).
#[derive(Clone, Debug)]
pub struct Dropped {
    pub instance: String,
    pub loc: Option<crate::diag::Loc>,
}

impl RenderScene {
    pub fn compile(scene: &Scene) -> (RenderScene, Vec<Dropped>) {
        let n = scene.instances.len();
        let mut material = Vec::with_capacity(n);
        let mut kind = Vec::with_capacity(n);
        let mut spheres = Vec::with_capacity(n + LANES - 1);
        let mut bounds = Vec::with_capacity(n);
        let mut objects = Vec::new();
        let mut tags = Vec::with_capacity(n);
        let mut dropped = Vec::new();
        let mut key = Vec::with_capacity(n);
        let offsets = &scene.instanced.offsets;
        let mut moving = Moving::new(scene).map(Box::new);
        for (index, inst) in scene.instances.iter().enumerate() {
            if let Some(m) = moving.as_mut().filter(|m| m.moves(inst)) {
                let (k, b) = m.add(index);
                key.push(offsets.get(index).copied().unwrap_or(index as u32));
                bounds.push(b);
                tags.push(BOUNDS_OF_OTHER);
                material.push(inst.material as u32);
                kind.push(MOVING | k);
                spheres.push(Vec4::NAN);
                continue;
            }
            match Primitive::new(
                &inst.geometry,
                scene.transform_of(inst),
                inst.material as u32,
            ) {
                Ok(p) => {
                    key.push(offsets.get(index).copied().unwrap_or(index as u32));
                    bounds.push(p.bounds);
                    material.push(p.material);
                    tags.push(if p.world_box().is_some() {
                        BOUNDS_OF_BOX
                    } else if p.world_sphere().is_some() {
                        BOUNDS_OF_SPHERE
                    } else {
                        BOUNDS_OF_OTHER
                    });
                    if let Some(s) = p.world_sphere() {
                        spheres.push(s.packed());
                        kind.push(SPHERE);
                    } else {
                        spheres.push(Vec4::NAN);
                        kind.push(objects.len() as u32);
                        objects.push(p);
                    }
                }
                Err(_) => dropped.push(Dropped {
                    instance: scene.instance_name(inst),
                    loc: scene.instance_loc(inst),
                }),
            }
        }
        if let Some(m) = &mut moving {
            m.finish();
        }
        let instances = scene.has_prototypes().then(|| {
            let first_id = (material.len() + scene.instanced.uses.len()) as u32;
            Box::new(Instances::new(scene, first_id))
        });
        if let Some(inst) = &instances {
            for (k, (b, u)) in inst.use_bounds().zip(&scene.instanced.uses).enumerate() {
                bounds.push(b);
                tags.push(BOUNDS_OF_OTHER);
                material.push(0);
                kind.push(USE | k as u32);
                spheres.push(Vec4::NAN);
                key.push(u.offset);
            }
        }
        let (bounded, unbounded): (Vec<u32>, Vec<u32>) =
            (0..material.len() as u32).partition(|&i| bounds[i as usize].is_finite());
        let mut bvh = Bvh::build(&bounds, bounded);
        let mut order = bvh.renumber_in_leaf_order();
        let first_unbounded = order.len() as u32;
        order.extend(unbounded);
        let all_spheres = tags.iter().all(|&t| t == BOUNDS_OF_SPHERE);
        let (mut bounds_min, mut bounds_max) = if all_spheres {
            (Vec::new(), Vec::new())
        } else {
            order
                .iter()
                .map(|&i| {
                    let (b, tag) = (bounds[i as usize], tags[i as usize]);
                    (b.min.extend(tag), b.max.extend(tag))
                })
                .unzip()
        };
        if !all_spheres {
            bounds_min.resize(order.len() + LANES - 1, Vec4::NAN);
            bounds_max.resize(order.len() + LANES - 1, Vec4::NAN);
        }
        drop((bounds, tags));
        let permute = |v: &[u32]| order.iter().map(|&i| v[i as usize]).collect::<Vec<u32>>();
        let (material, kind, key) = (permute(&material), permute(&kind), permute(&key));
        let mut spheres: Vec<Vec4> = order.iter().map(|&i| spheres[i as usize]).collect();
        spheres.resize(order.len() + LANES - 1, Vec4::NAN);
        drop(order);
        let materials: Vec<ShadeMaterial> =
            scene.materials.iter().map(ShadeMaterial::from).collect();
        let lights: Vec<PointLight> = scene
            .lights
            .iter()
            .map(|l| PointLight {
                position: l.position.as_vec3().into(),
                intensity: l.intensity.into(),
            })
            .collect();
        let ambient: Vec3A = scene.ambient.into();
        let background: Vec3A = scene.background.into();
        let mut used = vec![false; materials.len()];
        let prototype_materials = scene
            .instanced
            .prototypes
            .iter()
            .flat_map(|p| p.leaves.iter().map(|l| l.material as u32));
        let top_materials = material
            .iter()
            .zip(&kind)
            .filter(|&(_, &k)| !is_use(k) || is_moving(k))
            .map(|(&m, _)| m);
        for m in top_materials.chain(prototype_materials) {
            if let Some(u) = used.get_mut(m as usize) {
                *u = true;
            }
        }
        let any_transparent = materials
            .iter()
            .zip(&used)
            .any(|(m, &used)| m.is_transparent() && used);
        // Every shaded colour is a convex combination of local colours and the background
        // (the weights in docs/shading.md §3 sum to 1), so the largest local colour bounds them all.
        let total_light: Vec3A = lights.iter().map(|l| l.intensity.max(Vec3A::ZERO)).sum();
        let max_local = materials
            .iter()
            .map(|m| {
                (m.ka * ambient + total_light * (m.kd.max(Vec3A::ZERO) + m.ks.max(Vec3A::ZERO)))
                    .max_element()
            })
            .fold(0.0f32, f32::max);
        let max_radiance = max_local.max(background.max_element());
        let mut scene = RenderScene {
            light_cells: Vec::new(),
            light_tiles: Vec::new(),
            eye_cells: None,
            eye_tiles: None,
            all_spheres,
            material,
            kind,
            spheres,
            objects,
            bounds_min,
            bounds_max,
            key,
            instances,
            moving,
            bvh,
            unbounded: first_unbounded,
            materials,
            lights,
            ambient,
            background,
            any_transparent,
            max_radiance,
        };
        let lights_hold = scene.moving.as_ref().is_none_or(|m| !m.moves_lights());
        scene.light_cells = scene
            .lights
            .iter()
            .filter(|_| lights_hold)
            .filter_map(|l| scene.cells_around(l.position))
            .collect();
        (scene, dropped)
    }

    /// Number of primitives.
    pub fn len(&self) -> usize {
        self.material.len()
    }

    pub fn is_empty(&self) -> bool {
        self.material.is_empty()
    }

    /// The material of primitive `i`.
    #[inline(always)]
    pub fn material_of(&self, i: u32) -> u32 {
        match self.material.get(i as usize) {
            Some(&m) => m,
            None => self.instances.as_ref().map_or(0, |inst| inst.material(i)),
        }
    }

    /// `f` of the moving entry of kind `k` placed at the ray's time.
    #[inline(never)]
    fn moving_with<R>(&self, k: u32, ray: &Ray, f: impl FnOnce(&Primitive) -> R) -> Option<R> {
        self.moving.as_ref()?.with(k & !MOVING, ray, f)
    }

    /// The world-space surface of moving entry of kind `k` where the ray hit it (`hit`): the
    /// entry placed at the ray's time again, which is the same floats, rather than a copy of
    /// it kept from the test (a clone and its free were 2 % of a blurred frame).
    fn moving_surface(&self, k: u32, ray: &Ray, hit: &ShapeHit) -> Option<SurfaceHit> {
        let moving = self.moving.as_ref()?;
        moving.placed_with(k & !MOVING, ray.time, |p| {
            placed_surface(p, ray, hit.t, hit)
        })
    }

    /// Where light `k` is at `time` (its position unless it moves).
    #[inline(always)]
    pub fn light_position(&self, k: usize, light: &PointLight, time: f32) -> Vec3A {
        match &self.moving {
            None => light.position,
            Some(m) => m.light_position(k, time),
        }
    }

    /// The moving entry primitive `i` (as `closest` names it) is, if it moves.
    #[inline]
    pub fn moving_entry(&self, i: u32) -> Option<u32> {
        self.moving.as_ref()?;
        let k = *self.kind.get(i as usize)?;
        is_moving(k).then_some(k & !MOVING)
    }

    /// Whether [`RenderScene::moving_blocks`] answers.
    pub fn answers_moving_blocks(&self) -> bool {
        self.moving.as_ref().is_none_or(|m| m.answers_blocks())
    }

    /// Whether a moving shape blocks a shadow ray before `t_max` at the ray's time, leaving
    /// moving entry `from` outwards (see `Moving::blocks`); `Some(false)` when nothing moves.
    #[inline]
    pub fn moving_blocks(&self, ray: &Ray, t_max: f32, from: Option<u32>) -> Option<bool> {
        self.moving
            .as_ref()
            .map_or(Some(false), |m| m.blocks(ray, t_max, from))
    }

    /// Whether a shape or light moves during the exposure.
    pub fn has_motion(&self) -> bool {
        self.moving.is_some()
    }

    /// Instanced primitive `i` (an id from `len()` on), placed.
    fn instanced(&self, i: u32) -> Option<Primitive> {
        self.instances.as_ref()?.primitive(i)
    }

    /// The object-space shape of primitive `i`, or `None` for a packed world-space sphere
    /// (for tools that report by kind of shape).
    pub fn object_shape(&self, i: u32) -> Option<&Shape> {
        match self.kind.get(i as usize).copied() {
            Some(SPHERE) | None => None,
            Some(k) if is_use(k) => None,
            Some(k) => Some(&self.objects[k as usize].shape),
        }
    }

    #[inline]
    fn sphere(&self, i: usize) -> Sphere {
        let s = self.spheres[i];
        Sphere {
            center: s.truncate().into(),
            radius: s.w,
        }
    }

    /// The four packed spheres from primitive `i` on.
    #[inline(always)]
    pub(super) fn four_spheres(&self, i: usize) -> [Vec4; LANES] {
        four(&self.spheres, i)
    }

    /// Distance to primitive `i` along the ray, if it is hit with `0 < t < t_max`.
    #[inline(always)]
    pub fn hit(&self, i: u32, ray: &Ray, t_max: f32) -> Option<f32> {
        match self.kind.get(i as usize).copied() {
            Some(SPHERE) => self.sphere(i as usize).intersect(ray, t_max).map(|h| h.t),
            Some(k) if !is_use(k) => self.objects[k as usize].hit(ray, t_max).map(|h| h.t),
            Some(k) if is_moving(k) => {
                self.moving_with(k, ray, |p| p.hit(ray, t_max).map(|h| h.t))?
            }
            _ => self.instanced(i)?.hit(ray, t_max).map(|h| h.t),
        }
    }

    /// Primitive `i`'s hit with `0 < t < t_max`, in world space.
    #[inline]
    pub fn intersect(&self, i: u32, ray: &Ray, t_max: f32) -> Option<SurfaceHit> {
        match self.kind.get(i as usize).copied() {
            Some(SPHERE) => self
                .sphere(i as usize)
                .intersect(ray, t_max)
                .map(|h| sphere_surface(&h)),
            Some(k) if !is_use(k) => self.objects[k as usize].intersect(ray, t_max),
            Some(k) if is_moving(k) => {
                let h = self.moving_with(k, ray, |p| p.hit(ray, t_max))??;
                self.moving_surface(k, ray, &h)
            }
            _ => {
                let p = self.instanced(i)?;
                let h = p.hit(ray, t_max)?;
                Some(placed_surface(&p, ray, h.t, &h))
            }
        }
    }

    /// Nearest surface along the ray with `t < t_max`. Of equally close hits, an unbounded
    /// primitive's wins (the first of them), else the first in the flattened tree's order.
    #[inline]
    pub fn closest(&self, ray: &Ray, t_max: f32) -> Option<(u32, SurfaceHit)> {
        // Filled in place, not returned: a `Primitive` is 240 bytes, and moving even a `None`
        // of it in and out of calls cost 5 % of a render of the mirror-and-glass room.
        let (mut best, t_best) = self.closest_unbounded(ray, t_max);
        let mut won = None;
        let lanes = SphereRay::new(ray);
        let flat = self.flat_leaf();
        if self.all_spheres {
            let mut leaf =
                |leaf: &[u32], t_max| self.closest_in_sphere_leaf(&lanes, leaf, t_max, &mut best);
            match flat {
                Some(all) => _ = leaf(all, t_best),
                None => _ = self.bvh.closest_leaves(ray, t_best, leaf),
            }
        } else {
            let boxes = BoxRay::new(ray);
            let mut leaf = |leaf: &[u32], t_max| {
                self.closest_in_leaf(&lanes, &boxes, ray, leaf, t_max, &mut best, &mut won)
            };
            match flat {
                Some(all) => _ = leaf(all, t_best),
                None => _ = self.bvh.closest_leaves(ray, t_best, leaf),
            }
        }
        self.surface_of(ray, best?, won.as_ref())
    }

    /// All bounded primitives as one leaf, when there are so few that testing them all, four
    /// at a time, costs less than walking the hierarchy to them; `None` otherwise (or when
    /// there are none). In a closed room every ray's box overlaps most of the few leaves
    /// anyway. The answers are the hierarchy's: the closest hit is judged by distance and
    /// number, not by the order of the tests, and `any_hit`'s callers take any order.
    #[inline(always)]
    fn flat_leaf(&self) -> Option<&'static [u32]> {
        is_flat(self.unbounded, self.moving.is_some()).then(|| &FLAT[..self.unbounded as usize])
    }

    /// The nearest unbounded primitive's hit before `t_max` and the new `t_max`: what
    /// `closest` starts from. The winner's object-space hit is kept for its surface (spheres
    /// recompute theirs).
    #[inline(always)]
    fn closest_unbounded(&self, ray: &Ray, t_max: f32) -> (Option<Best>, f32) {
        let mut best: Option<Best> = None;
        let mut t_best = t_max;
        for i in self.unbounded..self.len() as u32 {
            let h = match self.kind[i as usize] {
                k if is_moving(k) => self.moving_with(k, ray, |p| p.hit(ray, t_best)).flatten(),
                _ => self.shape_hit(i, ray, t_best),
            };
            if let Some(h) = h {
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

    /// The world-space surface of `closest`'s winner (`won`: the placed instanced primitive
    /// when the winner is one).
    #[inline(always)]
    fn surface_of<P: std::borrow::Borrow<Primitive>>(
        &self,
        ray: &Ray,
        best: Best,
        won: Option<P>,
    ) -> Option<(u32, SurfaceHit)> {
        let Best { id: i, t, hit, .. } = best;
        let surface = match (self.kind.get(i as usize).copied(), hit) {
            (Some(SPHERE), _) => sphere_surface(&self.sphere(i as usize).hit_at(ray, t)),
            (Some(o), Some(h)) if is_moving(o) => self.moving_surface(o, ray, &h)?,
            (Some(o), Some(h)) => self.objects[o as usize].surface(&h),
            // A box hit by the four-at-a-time test: its own test finds the same `t`, and the
            // rest of the hit, for the winner alone.
            (Some(o), None) if !is_moving(o) => {
                let p = &self.objects[o as usize];
                p.surface(&p.hit(ray, t.next_up())?)
            }
            (_, Some(h)) => placed_surface(won?.borrow(), ray, t, &h),
            (_, None) => unreachable!("instanced and moving shapes keep their hit"),
        };
        Some((i, surface))
    }

    /// `closest_in_leaf` for a scene of packed spheres only: the same tests and the same
    /// winner, without asking each primitive its kind. Only the lanes hit are looked at, in
    /// lane order, which is the order `closest_in_leaf` judges them in.
    #[inline(always)]
    fn closest_in_sphere_leaf(
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
            let live = (1 << (end - start).min(LANES)) - 1;
            t_max =
                self.closest_in_spheres(lanes, &spheres, |k| start + k, live, limit, t_max, best);
        }
        t_max
    }

    /// Tests one leaf's primitives (see `closest`); returns the new `t_max`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn closest_in_leaf(
        &self,
        lanes: &SphereRay,
        boxes: &BoxRay,
        ray: &Ray,
        leaf: &[u32],
        mut t_max: f32,
        best: &mut Option<Best>,
        won: &mut Option<Primitive>,
    ) -> f32 {
        let first = leaf[0] as usize;
        let end = first + leaf.len();
        // A hit as close as the kept one is found too, to be judged by its number.
        let limit = t_max.next_up();
        for start in (first..end).step_by(LANES) {
            let c = self.classify(boxes, start, end, limit);
            let four_spheres = || self.four_spheres(start);
            let group = (|k| start + k, c, four_spheres);
            t_max = self.closest_in_four(lanes, ray, group, limit, t_max, best, won);
        }
        t_max
    }

    /// One group of four primitives of `closest_in_leaf` (or of a cell's list): `id` of each
    /// lane, their slab tests `c` (`classify_lanes`), and their packed spheres, loaded only if
    /// some lane is a sphere. Only those hit (spheres, boxes) or whose bounds the ray meets
    /// (other kinds) are looked at, in lane order. Returns the new `t_max`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn closest_in_four(
        &self,
        lanes: &SphereRay,
        ray: &Ray,
        (id, c, four_spheres): (
            impl Fn(usize) -> usize,
            Lanes,
            impl FnOnce() -> [Vec4; LANES],
        ),
        limit: f32,
        mut t_max: f32,
        best: &mut Option<Best>,
        won: &mut Option<Primitive>,
    ) -> f32 {
        let (sphere_hit, sphere_t) = if c.spheres != 0 {
            lanes.hit4(four_spheres(), limit)
        } else {
            (0, Vec4::ZERO)
        };
        let mut todo = (sphere_hit & c.spheres) | c.boxes_hit | c.others_near;
        while todo != 0 {
            let k = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            let i = id(k);
            let (t, hit) = if c.others_near & (1 << k) != 0 {
                let kind = self.kind[i];
                if is_moving(kind) {
                    let h = self
                        .moving_with(kind, ray, |p| p.hit(ray, t_max.next_up()))
                        .flatten();
                    if let Some(h) = h.filter(|h| Best::loses_to(best, t_max, h.t, self.key[i])) {
                        t_max = h.t;
                        *best = Some(Best {
                            id: i as u32,
                            t: t_max,
                            key: self.key[i],
                            hit: Some(h),
                        });
                    }
                    continue;
                }
                if is_use(kind) {
                    if let Some(inst) = &self.instances {
                        inst.closest(kind & !USE, ray, &mut t_max, best, won);
                    }
                    continue;
                }
                match self.objects[kind as usize].hit(ray, t_max.next_up()) {
                    Some(h) => (h.t, Some(h)),
                    None => continue,
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

    /// The four primitives from `start` on (those before `end`), sorted by the slab test of
    /// their bounds: the packed spheres; the boxes hit before `t_max`, and where; the other
    /// kinds whose bounds the ray meets before `t_max`.
    #[inline(always)]
    fn classify(&self, boxes: &BoxRay, start: usize, end: usize, t_max: f32) -> Lanes {
        let (min, max) = (four(&self.bounds_min, start), four(&self.bounds_max, start));
        self.classify_lanes(boxes, min, max, (1 << (end - start).min(LANES)) - 1, t_max)
    }

    /// `classify` of four primitives' bounds `min` and `max`, of which the lanes `live` count.
    #[inline(always)]
    fn classify_lanes(
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

    #[inline]
    fn shape_hit(&self, i: u32, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        match self.kind[i as usize] {
            SPHERE => self.sphere(i as usize).intersect(ray, t_max),
            k if is_use(k) => None,
            k => self.objects[k as usize].hit(ray, t_max),
        }
    }

    /// Bytes the scene's geometry holds (primitives, hierarchy and direction cells, not
    /// materials or lights).
    pub fn geometry_bytes(&self) -> usize {
        self.material.capacity() * 4
            + self.kind.capacity() * 4
            + (self.spheres.capacity() + self.bounds_min.capacity() + self.bounds_max.capacity())
                * std::mem::size_of::<Vec4>()
            + self.objects.capacity() * std::mem::size_of::<Primitive>()
            + self.key.capacity() * 4
            + self.bvh.memory_bytes()
            + self
                .instances
                .as_ref()
                .map_or(0, |inst| inst.memory_bytes())
            + self.moving.as_ref().map_or(0, |m| m.memory_bytes())
            + self
                .light_cells
                .iter()
                .chain(&self.eye_cells)
                .map(DirectionCells::memory_bytes)
                .sum::<usize>()
            + self
                .light_tiles
                .iter()
                .chain([&self.eye_tiles])
                .flatten()
                .map(ImageTiles::memory_bytes)
                .sum::<usize>()
    }

    /// How many lights keep direction cells, and whether the eye does (`takes_cells`,
    /// `watch_from`): for tests and tools that report what a scene was given.
    pub fn cells_kept(&self) -> (usize, bool) {
        (self.light_cells.len(), self.eye_cells.is_some())
    }

    /// Top-level uses of prototypes (each stands for all the shapes of its composite).
    pub fn instance_uses(&self) -> usize {
        self.instances.as_ref().map_or(0, |inst| inst.uses())
    }
}

/// Whether a scene of `bounded` primitives with finite bounds is tested as one flat leaf
/// (`RenderScene::flat_leaf`). Not with moving shapes: their bounds span the whole exposure,
/// and the hierarchy skips them where a flat leaf would test them (1.5 % fewer instructions,
/// blur frame 10).
fn is_flat(bounded: u32, moving: bool) -> bool {
    bounded > 0 && bounded as usize <= FLAT_MAX && !moving
}

/// Whether a scene of `bounded` primitives with finite bounds keeps `DirectionCells` around
/// each light and the eye, for the candidates of shadow and camera rays: in a scene that is
/// flat but for what moves (at most `FLAT_MAX` of them) of more than one test of four. One
/// test of four is all a list could save there; in the hierarchy of a larger scene, a light's
/// cells list too many primitives to beat its walk (the showcase's 57: 4 % more instructions).
/// A moving shape is listed by its bounds over the whole exposure, as the hierarchy bounds
/// it, and tested where a ray's cell lists it (the hierarchy answers where a cell does not).
/// When a light moves no light keeps cells: its shadow rays end where it is at their
/// instant, away from the cells' centre, where cells answer few rays.
fn takes_cells(bounded: u32) -> bool {
    bounded as usize <= FLAT_MAX && bounded as usize > LANES
}

/// Whether a `kind` is a moving shape (which `is_use` also says, so that the paths of
/// static scenes test one bit as before).
#[inline(always)]
fn is_moving(kind: u32) -> bool {
    kind != SPHERE && kind & MOVING == MOVING
}

/// Four primitives sorted by [`RenderScene::classify`], as lane masks.
struct Lanes {
    spheres: u32,
    boxes_hit: u32,
    box_t: Vec4,
    others_near: u32,
}

/// The four entries from `i` on.
#[inline(always)]
fn four(v: &[Vec4], i: usize) -> [Vec4; LANES] {
    let s = &v[i..i + LANES];
    [s[0], s[1], s[2], s[3]]
}

/// Whether a `kind` is a top-level use of a prototype.
#[inline(always)]
fn is_use(kind: u32) -> bool {
    kind != SPHERE && kind & USE != 0
}

/// The world-space surface of placed primitive `p` (instanced or moving) where the ray hit
/// it at `t` (`hit`, in its own space): a sphere that stays one in the world recomputes its
/// hit there, as world-space spheres do.
#[inline]
fn placed_surface(p: &Primitive, ray: &Ray, t: f32, hit: &ShapeHit) -> SurfaceHit {
    match p.world_sphere() {
        Some(s) => sphere_surface(&s.hit_at(ray, t)),
        None => p.surface(hit),
    }
}

/// What `Primitive::surface` makes of a world-space hit: the normal renormalised.
#[inline]
fn sphere_surface(h: &ShapeHit) -> SurfaceHit {
    SurfaceHit::on_face(h.t, h.point, h.normal.normalize_or_zero())
}
