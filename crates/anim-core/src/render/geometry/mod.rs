//! The camera-free part of a compiled scene, the [`Aggregate`] (pbrt's and Mitsuba's name for
//! the structure that answers rays over every primitive): every primitive placed in the
//! world, the hierarchy over them, the instanced composites and the shapes that move. Built
//! once from a scene description (`Aggregate::build`), immutable afterwards and shared
//! (`Arc`) by whatever renders that scene. Only the facade (`super::compile`) asks it rays;
//! the integrator and the samplers never name it.
//!
//! It answers two questions about a ray, each in its own file: the closest hit
//! (`closest.rs`) and whether, and what, the ray meets before a distance (`occlusion.rs`);
//! both for every primitive (walking the hierarchy, or one flat leaf in a small scene) or for
//! a list of candidates a [`super::view::View`] looked up (`Candidates`). `packet.rs` asks
//! the closest hit for several coherent rays at once. A leaf's primitives are tested four at
//! a time (`leaf.rs`). Instanced composites (`instancing.rs`) and moving shapes (`motion.rs`)
//! are primitives of the table like the others: a `Kind` says which, and each answers the
//! same two questions.

mod closest;
mod cone;
mod instancing;
mod leaf;
mod listed;
mod motion;
mod occlusion;
mod packet;
pub mod primitive;

pub(crate) use closest::Candidates;
pub use cone::Cone;
pub use motion::{MovingScratch, MovingShadow};
pub use primitive::{Primitive, SurfaceHit};

use super::policy::{self, GeometryPlan};
use crate::accel::Bvh;
use crate::math::{Aabb, Ray};
use crate::scene::Scene;
use crate::shape::{Shape, ShapeHit, Sphere};
use glam::{Vec3A, Vec4};
use instancing::Instances;
use leaf::{four, LANES};
use motion::Moving;

/// A primitive's number in a compiled scene: its place in the hierarchy's leaf order, then
/// the unbounded ones, then (from [`Aggregate::len`] on) the shapes of instanced composites.
/// Equal numbers are the same surface, which adaptive sampling compares between pixels.
pub type PrimId = u32;

/// What a primitive of the table is, and where the rest of it is kept.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    /// A sphere in world space, packed in 16 bytes and tested four at a time.
    Sphere,
    /// Any other shape: object `k` of the table.
    Shape(u32),
    /// A top-level use `k` of an instanced composite, standing for all its shapes.
    Instance(u32),
    /// Moving entry `k`: a shape placed at the instant of the ray that tests it.
    Moving(u32),
}

/// [`Kind`] packed into 32 bits, as the table keeps it per primitive: the hot loops test a
/// bit or two instead of matching a tagged enum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct KindTag(u32);

impl KindTag {
    const SPHERE: u32 = u32::MAX;
    const INSTANCE: u32 = 1 << 31;
    const MOVING: u32 = Self::INSTANCE | 1 << 30;

    fn of(kind: Kind) -> KindTag {
        KindTag(match kind {
            Kind::Sphere => Self::SPHERE,
            Kind::Shape(k) => k,
            Kind::Instance(k) => Self::INSTANCE | k,
            Kind::Moving(k) => Self::MOVING | k,
        })
    }

    #[inline(always)]
    fn kind(self) -> Kind {
        match self.0 {
            Self::SPHERE => Kind::Sphere,
            t if t & Self::MOVING == Self::MOVING => Kind::Moving(t & !Self::MOVING),
            t if t & Self::INSTANCE != 0 => Kind::Instance(t & !Self::INSTANCE),
            t => Kind::Shape(t),
        }
    }
}

/// `w` of [`Aggregate`]'s bounds: how a primitive's slab test is read. A world-space box's
/// bounds are the box itself, and their slab test gives its hit; any other kind's bounds are
/// tested before its own test; a packed sphere is tested by `SphereRay::hit4` instead.
const BOUNDS_OF_BOX: f32 = 1.0;
const BOUNDS_OF_OTHER: f32 = 0.0;
const BOUNDS_OF_SPHERE: f32 = -1.0;

/// The compiled primitive table and its hierarchy. Primitives are numbered in the hierarchy's
/// leaf order (so a leaf reads consecutive entries), then the unbounded ones. World-space spheres, the common case, are packed into
/// 16 bytes and tested four at a time with no dispatch; everything else is a [`Primitive`].
#[derive(Clone, Debug)]
pub struct Aggregate {
    /// Per primitive: its material.
    material: Vec<u32>,
    /// Per primitive: its [`Kind`].
    kind: Vec<KindTag>,
    /// Per primitive: the packed sphere (`Sphere::packed`; NaN for other kinds, which no
    /// sphere test hits), then `LANES - 1` NaN entries so a leaf can always load four.
    spheres: Vec<Vec4>,
    objects: Vec<Primitive>,
    /// Per primitive: its world bounds, `w` telling its kind (`BOUNDS_OF_BOX` ...), then
    /// `LANES - 1` NaN entries, so that a leaf slab-tests four at once. Empty when every
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
    /// The shapes that move during the exposure, if any do.
    moving: Option<Box<Moving>>,
    bvh: Bvh,
    /// The first primitive without finite bounds (planes); these are tested on every ray.
    unbounded: u32,
    /// How rays meet the primitives (`policy::geometry_plan`).
    plan: GeometryPlan,
}

/// A primitive that could not be placed (degenerate after transformation).
#[derive(Clone, Debug)]
pub struct Dropped {
    /// The path of the shape through the composite tree.
    pub instance: String,
    /// Where the shape is defined.
    pub loc: Option<crate::diag::Loc>,
}

/// The primitives of a scene as they are placed, before the hierarchy orders them.
#[derive(Default)]
struct Table {
    material: Vec<u32>,
    kind: Vec<KindTag>,
    spheres: Vec<Vec4>,
    objects: Vec<Primitive>,
    bounds: Vec<Aabb>,
    tags: Vec<f32>,
    key: Vec<u32>,
}

impl Table {
    fn push(&mut self, kind: Kind, material: u32, bounds: Aabb, tag: f32, sphere: Vec4, key: u32) {
        self.kind.push(KindTag::of(kind));
        self.material.push(material);
        self.bounds.push(bounds);
        self.tags.push(tag);
        self.spheres.push(sphere);
        self.key.push(key);
    }

    /// Every flat instance of `scene`, placed (moving ones added to `moving`), and the
    /// shapes that could not be.
    fn of_instances(scene: &Scene, moving: &mut Option<Box<Moving>>) -> (Table, Vec<Dropped>) {
        let n = scene.instances.len();
        let mut table = Table {
            material: Vec::with_capacity(n),
            kind: Vec::with_capacity(n),
            spheres: Vec::with_capacity(n + LANES - 1),
            bounds: Vec::with_capacity(n),
            tags: Vec::with_capacity(n),
            key: Vec::with_capacity(n),
            objects: Vec::new(),
        };
        let mut dropped = Vec::new();
        let offsets = &scene.instanced.offsets;
        for (index, inst) in scene.instances.iter().enumerate() {
            let key = offsets.get(index).copied().unwrap_or(index as u32);
            let material = inst.material as u32;
            if let Some(m) = moving.as_mut().filter(|m| m.moves(inst)) {
                let (k, b) = m.add(index);
                table.push(
                    Kind::Moving(k),
                    material,
                    b,
                    BOUNDS_OF_OTHER,
                    Vec4::NAN,
                    key,
                );
                continue;
            }
            let Ok(p) = Primitive::new(&inst.geometry, scene.transform_of(inst), material) else {
                dropped.push(Dropped {
                    instance: scene.instance_name(inst),
                    loc: scene.instance_loc(inst),
                });
                continue;
            };
            if let Some(s) = p.world_sphere() {
                table.push(
                    Kind::Sphere,
                    material,
                    p.bounds,
                    BOUNDS_OF_SPHERE,
                    s.packed(),
                    key,
                );
                continue;
            }
            let tag = if p.world_box().is_some() {
                BOUNDS_OF_BOX
            } else {
                BOUNDS_OF_OTHER
            };
            let kind = Kind::Shape(table.objects.len() as u32);
            table.push(kind, p.material, p.bounds, tag, Vec4::NAN, key);
            table.objects.push(p);
        }
        (table, dropped)
    }
}

impl Aggregate {
    /// Places every shape of `scene` (the ones that stay degenerate once transformed are
    /// left out and returned) and builds the hierarchy over them.
    pub(crate) fn build(scene: &Scene) -> (Aggregate, Vec<Dropped>) {
        let mut moving = Moving::new(scene).map(Box::new);
        let (mut table, dropped) = Table::of_instances(scene, &mut moving);
        let instances = scene.has_prototypes().then(|| {
            let first_id = (table.material.len() + scene.instanced.uses.len()) as u32;
            Box::new(Instances::new(scene, first_id))
        });
        if let Some(inst) = &instances {
            for (k, (b, u)) in inst.use_bounds().zip(&scene.instanced.uses).enumerate() {
                let kind = Kind::Instance(k as u32);
                table.push(kind, 0, b, BOUNDS_OF_OTHER, Vec4::NAN, u.offset);
            }
        }
        let (bounded, unbounded): (Vec<u32>, Vec<u32>) =
            (0..table.material.len() as u32).partition(|&i| table.bounds[i as usize].is_finite());
        let mut bvh = Bvh::build(&table.bounds, bounded);
        let mut order = bvh.renumber_in_leaf_order();
        let first_unbounded = order.len() as u32;
        order.extend(unbounded);
        let all_spheres = table.tags.iter().all(|&t| t == BOUNDS_OF_SPHERE);
        let moving_entries = moving.as_ref().map_or(0, |m| m.len());
        let plan = policy::geometry_plan(first_unbounded as usize, moving_entries, all_spheres);
        if let Some(m) = &mut moving {
            m.finish(plan.ask_moving);
        }
        let (bounds_min, bounds_max) = packed_bounds(&table, &order, plan.spheres_only);
        let permute = |v: &[u32]| order.iter().map(|&i| v[i as usize]).collect::<Vec<u32>>();
        let (material, key) = (permute(&table.material), permute(&table.key));
        let kind = order.iter().map(|&i| table.kind[i as usize]).collect();
        let mut spheres: Vec<Vec4> = order.iter().map(|&i| table.spheres[i as usize]).collect();
        spheres.resize(order.len() + LANES - 1, Vec4::NAN);
        let geometry = Aggregate {
            material,
            kind,
            spheres,
            objects: table.objects,
            bounds_min,
            bounds_max,
            key,
            instances,
            moving,
            bvh,
            unbounded: first_unbounded,
            plan,
        };
        (geometry, dropped)
    }

    /// Number of primitives (instanced shapes not counted).
    pub fn len(&self) -> usize {
        self.material.len()
    }

    /// Whether there is no primitive.
    pub fn is_empty(&self) -> bool {
        self.material.is_empty()
    }

    /// Primitives with finite bounds (they come first).
    pub(crate) fn bounded(&self) -> usize {
        self.unbounded as usize
    }

    /// The strategies chosen for this geometry.
    pub(crate) fn plan(&self) -> GeometryPlan {
        self.plan
    }

    /// Nodes of the hierarchy.
    pub(crate) fn hierarchy_nodes(&self) -> usize {
        self.bvh.node_count()
    }

    /// The material of primitive `i`.
    #[inline(always)]
    pub fn material_of(&self, i: PrimId) -> u32 {
        match self.material.get(i as usize) {
            Some(&m) => m,
            None => self.instances.as_ref().map_or(0, |inst| inst.material(i)),
        }
    }

    #[inline(always)]
    fn kind_of(&self, i: usize) -> Kind {
        self.kind[i].kind()
    }

    /// The world bounds of bounded primitive `i`.
    pub(crate) fn bound(&self, i: usize) -> Aabb {
        if self.plan.spheres_only {
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

    /// Whether primitive `i` encloses a solid (`Shape::is_closed`), which a camera can be
    /// inside.
    pub(crate) fn is_closed(&self, i: PrimId) -> bool {
        match self.kind.get(i as usize).map(|k| k.kind()) {
            Some(Kind::Sphere) => true,
            Some(Kind::Shape(k)) => self.objects[k as usize].shape.is_closed(),
            Some(Kind::Moving(k)) => self.moving.as_ref().is_some_and(|m| m.is_closed(k)),
            Some(Kind::Instance(_)) | None => false,
        }
    }

    /// The depth-first number of primitive `i` in the flattened composite tree: the index
    /// of its instance in the scene description when the scene has no instanced composites.
    pub(crate) fn source(&self, i: PrimId) -> Option<u32> {
        self.key.get(i as usize).copied()
    }

    /// The object-space shape of primitive `i`, or `None` for a packed world-space sphere
    /// (for tools that report by kind of shape).
    pub fn object_shape(&self, i: PrimId) -> Option<&Shape> {
        match self.kind.get(i as usize)?.kind() {
            Kind::Shape(k) => Some(&self.objects[k as usize].shape),
            _ => None,
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
    fn four_spheres(&self, i: usize) -> [Vec4; LANES] {
        four(&self.spheres, i)
    }

    /// Distance to primitive `i` along the ray, if it is hit with `0 < t < t_max`.
    #[inline(always)]
    pub(crate) fn hit(
        &self,
        i: PrimId,
        ray: &Ray,
        t_max: f32,
        scratch: &mut MovingScratch,
    ) -> Option<f32> {
        let Some(tag) = self.kind.get(i as usize) else {
            return self.instanced(i)?.hit(ray, t_max).map(|h| h.t);
        };
        match tag.kind() {
            Kind::Sphere => self.sphere(i as usize).intersect(ray, t_max).map(|h| h.t),
            Kind::Shape(k) => self.objects[k as usize].hit(ray, t_max).map(|h| h.t),
            Kind::Moving(k) => {
                self.moving_with(k, ray, scratch, |p| p.hit(ray, t_max).map(|h| h.t))?
            }
            Kind::Instance(_) => None,
        }
    }

    /// Primitive `i`'s hit with `0 < t < t_max`, in world space.
    #[inline]
    pub(crate) fn intersect(
        &self,
        i: PrimId,
        ray: &Ray,
        t_max: f32,
        scratch: &mut MovingScratch,
    ) -> Option<SurfaceHit> {
        let Some(tag) = self.kind.get(i as usize) else {
            let p = self.instanced(i)?;
            let h = p.hit(ray, t_max)?;
            return Some(placed_surface(&p, ray, h.t, &h));
        };
        match tag.kind() {
            Kind::Sphere => self
                .sphere(i as usize)
                .intersect(ray, t_max)
                .map(|h| sphere_surface(&h)),
            Kind::Shape(k) => self.objects[k as usize].intersect(ray, t_max),
            Kind::Moving(k) => {
                let h = self.moving_with(k, ray, scratch, |p| p.hit(ray, t_max))??;
                self.moving_surface(k, ray, &h, scratch)
            }
            Kind::Instance(_) => None,
        }
    }

    /// The hit of primitive `i` (not a use of a composite) before `t_max`, as the shape
    /// reports it; what the closest-hit query starts from for the unbounded ones.
    #[inline]
    fn shape_hit(
        &self,
        i: PrimId,
        ray: &Ray,
        t_max: f32,
        scratch: &mut MovingScratch,
    ) -> Option<ShapeHit> {
        match self.kind_of(i as usize) {
            Kind::Sphere => self.sphere(i as usize).intersect(ray, t_max),
            Kind::Shape(k) => self.objects[k as usize].hit(ray, t_max),
            Kind::Moving(k) => self.moving_with(k, ray, scratch, |p| p.hit(ray, t_max))?,
            Kind::Instance(_) => None,
        }
    }

    /// Instanced primitive `i` (an id from `len()` on), placed.
    fn instanced(&self, i: PrimId) -> Option<Primitive> {
        self.instances.as_ref()?.primitive(i)
    }

    /// Top-level uses of prototypes (each stands for all the shapes of its composite).
    pub fn instance_uses(&self) -> usize {
        self.instances.as_ref().map_or(0, |inst| inst.uses())
    }

    /// Whether a shape moves during the exposure.
    pub fn has_motion(&self) -> bool {
        self.moving.is_some()
    }

    /// The moving entry primitive `i` (as the closest-hit query names it) is, if it moves.
    #[inline]
    pub fn moving_entry(&self, i: PrimId) -> Option<u32> {
        match self.kind.get(i as usize)?.kind() {
            Kind::Moving(k) => Some(k),
            _ => None,
        }
    }

    /// `f` of moving entry `k` placed at the ray's time.
    #[inline(never)]
    fn moving_with<R>(
        &self,
        k: u32,
        ray: &Ray,
        scratch: &mut MovingScratch,
        f: impl FnOnce(&Primitive) -> R,
    ) -> Option<R> {
        self.moving.as_ref()?.with(k, ray, scratch, f)
    }

    /// The world-space surface of moving entry `k` where the ray hit it (`hit`): the entry
    /// placed at the ray's time again, which is the same floats, rather than a copy of it
    /// kept from the test (a copy and its free cost more than placing it again).
    fn moving_surface(
        &self,
        k: u32,
        ray: &Ray,
        hit: &ShapeHit,
        scratch: &mut MovingScratch,
    ) -> Option<SurfaceHit> {
        let moving = self.moving.as_ref()?;
        moving.placed_with(k, ray.time, scratch, |p| placed_surface(p, ray, hit.t, hit))
    }

    /// What the moving shapes do to a shadow ray before `t_max` at the ray's time, leaving
    /// moving entry `from` outwards (see `Moving::blocks`); `Clear` when nothing moves.
    #[inline]
    pub(crate) fn moving_blocks(
        &self,
        ray: &Ray,
        t_max: f32,
        from: Option<u32>,
        scratch: &mut MovingScratch,
    ) -> MovingShadow {
        self.moving
            .as_ref()
            .map_or(MovingShadow::Clear, |m| m.blocks(ray, t_max, from, scratch))
    }

    /// Per material of `scene` (whose geometry this is): whether some primitive draws with
    /// it.
    pub(crate) fn used_materials(&self, scene: &Scene) -> Vec<bool> {
        let mut used = vec![false; scene.materials.len()];
        let prototype_materials = scene
            .instanced
            .prototypes
            .iter()
            .flat_map(|p| p.leaves.iter().map(|l| l.material as u32));
        let top_materials = self
            .material
            .iter()
            .zip(&self.kind)
            .filter(|&(_, k)| !matches!(k.kind(), Kind::Instance(_)))
            .map(|(&m, _)| m);
        for m in top_materials.chain(prototype_materials) {
            if let Some(u) = used.get_mut(m as usize) {
                *u = true;
            }
        }
        used
    }

    /// Bytes the geometry holds (primitives and hierarchy).
    pub(crate) fn memory_bytes(&self) -> usize {
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
    }
}

/// The table's bounds in the hierarchy's `order`, each with its kind's tag in `w` and padded
/// by `LANES - 1` NaN entries (none when the leaves test packed spheres alone).
fn packed_bounds(table: &Table, order: &[u32], spheres_only: bool) -> (Vec<Vec4>, Vec<Vec4>) {
    if spheres_only {
        return (Vec::new(), Vec::new());
    }
    let (mut min, mut max): (Vec<Vec4>, Vec<Vec4>) = order
        .iter()
        .map(|&i| {
            let (b, tag) = (table.bounds[i as usize], table.tags[i as usize]);
            (b.min.extend(tag), b.max.extend(tag))
        })
        .unzip();
    min.resize(order.len() + LANES - 1, Vec4::NAN);
    max.resize(order.len() + LANES - 1, Vec4::NAN);
    (min, max)
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
