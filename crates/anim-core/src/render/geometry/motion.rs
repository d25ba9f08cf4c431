//! The moving part of a compiled scene's geometry (docs/scene-language.md §10): shapes whose
//! transform slot moves during the exposure, each a primitive of the geometry's table
//! (`Kind::Moving`, pbrt's `AnimatedPrimitive`) bounded over the whole exposure and placed at
//! the time of the ray that tests it. Moving lights are shading data
//! (`crate::render::shading`).
//!
//! Motion, one home per layer: `crate::math::motion` (keys and their interpolation),
//! `crate::sdf::parse::motion` (the `motion` lines), `crate::scene::motion` (what moves in a
//! scene) with `crate::scene::builder::motion` (made from the lines),
//! `crate::render::geometry::motion` (moving shapes as primitives), `crate::render::motion`
//! (the exposure: the camera at an instant), `crate::render::sampler::motion` (what adaptive
//! sampling asks of the motion), and the animation pipeline's `keyframe::motion` (the lines
//! a spec with a `shutter` writes). The instants of the exposure are `crate::limits`'s
//! (`MOTION_TIME_STEPS`, `quantized_time`).
//!
//! Static geometry pays nothing: its primitives and their tests are those of a frame without
//! motion. A moving shape is placed by `Motion::slot_matrix` at the ray's time, a function of
//! that time alone, so every ray of one camera sample (primary, shadow, reflected) meets the
//! same floats, and the spawn bounds of `Primitive::surface` hold between them as for a
//! static shape.

use super::Primitive;
use crate::limits::{motion_step, motion_step_middle, MOTION_MAX_PLACED, MOTION_TIME_STEPS};
use crate::math::{Aabb, Ray, Transform};
use crate::scene::motion::Motion;
use crate::scene::{Instance, Scene};
use crate::shape::{BoxRay, Geometry};
use glam::{Affine3A, DVec3, Vec3A, Vec4};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};

/// Instants, evenly spread over the exposure, at which a moving shape's bounds are taken
/// (besides its keys' instants): between two of them its corners move along paths so little
/// curved that twice the longest chord bounds how far they stray (see [`swept_bounds`]).
const BOUND_STEPS: usize = 64;

/// Parts of the exposure in each of which a moving shape has one pose ([`Pose`]): what
/// adaptive sampling's first pass asks a ray about, to tell the pixels that see the motion
/// from those that only look through its bounds over the whole exposure.
const POSE_PARTS: usize = 32;

/// Steps per half part over which a pose's drift is measured (and at the keys' instants).
const DRIFT_STEPS: usize = 2;
/// Boxes slab-tested at once by [`Moving::blocks`].
const LANES: usize = 4;

/// A moving shape over one part of the exposure: the map into its own space at the part's
/// middle, and there its own bounds, and for a sphere the sphere, grown by how far any of its
/// points drifts within the part (in its own units). A ray that misses what is grown misses
/// the shape all through the part.
#[derive(Clone, Copy, Debug)]
struct Pose {
    object_from_world: Affine3A,
    grown: Aabb,
    /// World bounds of `grown` placed at the part's middle: the shape stays inside all
    /// through the part.
    world: Aabb,
    /// Centre and grown radius, when the shape is a sphere in its own space.
    sphere: Option<Vec4>,
}

impl Pose {
    #[inline]
    fn met_by(&self, ray: &Ray) -> bool {
        let origin = self.object_from_world.transform_point3a(ray.origin);
        let dir = self.object_from_world.transform_vector3a(ray.dir);
        if self
            .grown
            .hit_range(&Ray::new(origin, dir), dir.recip(), 0.0, f32::INFINITY)
            .is_none()
        {
            return false;
        }
        // Whether the line comes within the radius, and not wholly behind the origin: the
        // closest approach of the line to the centre, clamped to the ray.
        self.sphere.is_none_or(|s| {
            let to_centre = Vec3A::from(s.truncate()) - origin;
            let along = (to_centre.dot(dir) / dir.length_squared()).max(0.0);
            let miss = to_centre - dir * along;
            // NaN (a degenerate map) counts as met.
            miss.length_squared().partial_cmp(&(s.w * s.w)) != Some(std::cmp::Ordering::Greater)
        })
    }
}

/// Numbers the moving parts made, so that a worker's scratch knows whose entries it holds.
static NEXT_ID: AtomicU64 = AtomicU64::new(1);

#[derive(Default)]
struct Placed {
    /// The moving part and the time (bits) the entries were placed for.
    owner: u64,
    time: u32,
    /// Bumped when the owner or time changes: an entry is valid for its own generation only.
    generation: u64,
    entries: Vec<(u64, Option<Primitive>)>,
}

/// What one worker's queries keep of the moving shapes between rays: owned by the worker
/// (inside the facade's `Scratch`) and handed to every query, so nothing flows between
/// layers behind the callers' backs.
pub struct MovingScratch {
    /// While a camera sample's sweep is measured ([`MovingScratch::measure_sweep`]): the
    /// largest angle (radians, as the eye sees it) swept by the moving shapes its rays may
    /// have met at some instant of the exposure. NaN otherwise, so that the test in
    /// [`Moving::with`] is one comparison that fails.
    swept: f32,
    /// The moving entries placed at the time of the worker's latest ray: every ray of a
    /// camera sample (primary, shadow, reflected) has that sample's time, so each entry is
    /// placed once per sample, not once per test. Only saves work: an entry placed again at
    /// the same time is the same floats.
    placed: Placed,
}

impl Default for MovingScratch {
    fn default() -> Self {
        MovingScratch {
            swept: f32::NAN,
            placed: Placed::default(),
        }
    }
}

impl MovingScratch {
    /// Starts measuring the largest angle swept by the moving shapes the queries given this
    /// scratch may meet ([`MovingScratch::take_sweep`]).
    #[inline]
    pub fn measure_sweep(&mut self) {
        self.swept = 0.0;
    }

    /// The largest angle (radians) swept, as the eye sees it, by the moving shapes that the
    /// queries may have met at some instant since [`MovingScratch::measure_sweep`] (see
    /// `Moving::met_by`); 0 when they met none, or nothing was measured. Stops measuring.
    #[inline]
    pub fn take_sweep(&mut self) -> f32 {
        std::mem::replace(&mut self.swept, f32::NAN).max(0.0)
    }
}

/// What the moving shapes do to a shadow ray, at its instant (`Moving::blocks`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MovingShadow {
    /// No moving shape meets it before its end (or nothing moves).
    Clear,
    /// A moving shape blocks it, wholly or in part.
    Blocked,
    /// The scene's moving shapes are too many to ask one by one (`GeometryPlan::ask_moving`):
    /// only the whole shadow ray can tell.
    Unasked,
}

/// The moving shapes of a scene.
#[derive(Clone, Debug)]
pub struct Moving {
    id: u64,
    motion: Arc<Motion>,
    instances: Arc<Vec<Instance>>,
    /// Per moving entry: its instance.
    entries: Vec<u32>,
    /// Per moving entry: the angle (radians) its motion sweeps as the eye sees it, at most.
    sweep: Vec<f32>,
    /// Per moving entry: its bounds over the exposure.
    bounds: Vec<Aabb>,
    /// Per moving entry: whether its shape is convex.
    convex: Vec<bool>,
    /// Entry `k`'s pose in part `i` of the exposure in cell `k·POSE_PARTS + i`; `None` where
    /// it cannot be told (degenerate or unbounded), which counts as met.
    poses: Vec<Option<Pose>>,
    /// Per moving entry: all its poses at once, as one box in the space of one of them
    /// (`reach_of`); `None` where a pose cannot be told.
    reach: Vec<Option<Pose>>,
    /// Entry `k` placed at instant `i` (of `MOTION_TIME_STEPS`) in cell `k·steps + i`, made
    /// by the first ray that needs it; empty when the scene has too many moving shapes for
    /// it (each worker then places them per camera sample).
    placed: Vec<OnceLock<Option<Primitive>>>,
    /// Where [`Moving::blocks`] answers: per part of the exposure, the world box of each
    /// entry's pose there (its bounds over the exposure where it has none), in groups of
    /// four (`[min, max]`; NaN past the last entry), for [`BoxRay::slabs4`]: part `i`'s
    /// groups are cells `i·groups` to `(i+1)·groups − 1`.
    part_boxes: Vec<[[Vec4; LANES]; 2]>,
    /// Per part of the exposure: the union of its `part_boxes`, which a ray that meets none
    /// of them may miss in one test (`Moving::blocks`).
    part_union: Vec<Aabb>,
    /// Whether shadow rays ask the moving shapes one by one ([`Moving::blocks`]), as the
    /// geometry's plan decides (`GeometryPlan::ask_moving`).
    asked: bool,
}

impl Moving {
    /// The moving part of `scene`, if a shape in it moves.
    pub fn new(scene: &Scene) -> Option<Moving> {
        let motion = scene.motion.as_ref()?;
        if !motion.moves_geometry() {
            return None;
        }
        Some(Moving {
            id: NEXT_ID.fetch_add(1, Ordering::Relaxed),
            motion: motion.clone(),
            instances: scene.instances.clone(),
            entries: Vec::new(),
            sweep: Vec::new(),
            bounds: Vec::new(),
            poses: Vec::new(),
            reach: Vec::new(),
            convex: Vec::new(),
            part_boxes: Vec::new(),
            part_union: Vec::new(),
            placed: Vec::new(),
            asked: false,
        })
    }

    /// The number of moving entries.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Makes room for the placed entries, once they are all added, if they fit; and, where
    /// shadow rays ask the moving shapes one by one (`ask`: the geometry's plan), the boxes
    /// they ask.
    pub fn finish(&mut self, ask: bool) {
        let cells = self.entries.len() * MOTION_TIME_STEPS as usize;
        if cells <= MOTION_MAX_PLACED {
            self.placed = (0..cells).map(|_| OnceLock::new()).collect();
        }
        self.asked = ask;
        if ask {
            let groups = self.entries.len().div_ceil(LANES);
            let unused = Vec4::splat(f32::NAN);
            let world = |part: usize, k: usize| match self.poses.get(k * POSE_PARTS + part) {
                _ if k >= self.entries.len() => (unused, unused),
                Some(Some(pose)) => (pose.world.min.extend(0.0), pose.world.max.extend(0.0)),
                _ => (
                    self.bounds[k].min.extend(0.0),
                    self.bounds[k].max.extend(0.0),
                ),
            };
            self.part_boxes = (0..POSE_PARTS)
                .flat_map(|part| (0..groups).map(move |g| (part, g)))
                .map(|(part, g)| {
                    let lanes: [(Vec4, Vec4); LANES] =
                        std::array::from_fn(|lane| world(part, g * LANES + lane));
                    [lanes.map(|(min, _)| min), lanes.map(|(_, max)| max)]
                })
                .collect();
            self.part_union = (0..POSE_PARTS)
                .map(|part| {
                    (0..self.entries.len()).fold(Aabb::EMPTY, |union, k| {
                        let (min, max) = world(part, k);
                        union.union(Aabb::new(min.truncate().into(), max.truncate().into()))
                    })
                })
                .collect();
        }
    }

    /// Whether `inst` moves (it is then added with [`Moving::add`], not as a primitive).
    #[inline]
    pub fn moves(&self, inst: &Instance) -> bool {
        self.motion.moves_slot(inst.transform)
    }

    /// Adds instance `index` as a moving entry; its number and its bounds over the exposure.
    pub fn add(&mut self, index: usize) -> (u32, Aabb) {
        let k = self.entries.len() as u32;
        self.entries.push(index as u32);
        let swept = self.swept(k);
        // Seen from the eye (at the origin: rendering is camera-relative), the angle its
        // corners sweep, at most: their path over the distance to the nearest point of the
        // bounds.
        let b = swept.bounds;
        let nearest = Vec3A::ZERO.clamp(b.min, b.max).length() as f64;
        let angle = if swept.path == 0.0 {
            0.0
        } else {
            (swept.path / nearest) as f32
        };
        self.sweep
            .push(if angle.is_nan() { f32::INFINITY } else { angle });
        self.bounds.push(b);
        let convex = self
            .instance(k)
            .is_some_and(|inst| !matches!(inst.geometry, Geometry::Mesh(_)));
        self.convex.push(convex);
        let poses = self.poses_of(k);
        self.reach.push(reach_of(&poses));
        self.poses.extend(poses);
        (k, swept.bounds)
    }

    /// Whether `ray` (from its origin on, however far) may meet entry `k` at some instant of
    /// the exposure: `false` only where its poses say it surely does not.
    fn met_by(&self, k: u32, ray: &Ray) -> bool {
        let k = k as usize;
        if self.bounds.get(k).is_some_and(|b| {
            b.hit_range(ray, ray.dir.recip(), 0.0, f32::INFINITY)
                .is_none()
        }) {
            return false;
        }
        // A ray that misses all the poses at once misses each: most of those that get here,
        // inside the bounds over the exposure, for one test instead of one per pose.
        if self
            .reach
            .get(k)
            .is_some_and(|r| r.is_some_and(|r| !r.met_by(ray)))
        {
            return false;
        }
        self.poses
            .get(k * POSE_PARTS..(k + 1) * POSE_PARTS)
            .is_none_or(|poses| poses.iter().any(|p| p.is_none_or(|p| p.met_by(ray))))
    }

    /// Entry `k` placed at instant `step` (of `MOTION_TIME_STEPS`), from the table that keeps
    /// them; `None` when the scene has too many moving shapes for the table. The inner `None`:
    /// degenerate at that instant.
    #[inline]
    fn placed_at(&self, k: u32, step: u32) -> Option<Option<&Primitive>> {
        let cell = self
            .placed
            .get(k as usize * MOTION_TIME_STEPS as usize + step as usize)?;
        Some(
            cell.get_or_init(|| self.place(k, motion_step_middle(step)))
                .as_ref(),
        )
    }

    /// What the moving shapes do to a ray before `t_max`, at the ray's time, leaving the
    /// surface of entry `from` (if any) outwards: whether one blocks it (wholly or in part),
    /// or `Unasked` when there are more moving shapes than it pays to ask one by one.
    /// For shadow rays whose light no static shape blocks (adaptive sampling's known-clear
    /// lights in frames with motion), which need not walk the whole hierarchy.
    pub fn blocks(
        &self,
        ray: &Ray,
        t_max: f32,
        from: Option<u32>,
        scratch: &mut MovingScratch,
    ) -> MovingShadow {
        if !self.asked {
            return MovingShadow::Unasked;
        }
        // The part of the exposure the ray's instant lies in: the shapes' bounds in it are
        // much tighter than over the whole exposure.
        let part = ((ray.time * POSE_PARTS as f32) as usize).min(POSE_PARTS - 1);
        // Most shadow rays pass far from every moving shape: one test of the box around them
        // all says so. It misses only where every box inside it misses (the slab test is the
        // same arithmetic, and monotone in the box), so the answer is the one below.
        let Some(union) = self.part_union.get(part) else {
            return MovingShadow::Unasked;
        };
        if union.hit_range(ray, ray.dir.recip(), 0.0, t_max).is_none() {
            return MovingShadow::Clear;
        }
        let boxes = BoxRay::new(ray);
        let n = self.entries.len();
        let groups = n.div_ceil(LANES);
        let Some(cells) = self.part_boxes.get(part * groups..(part + 1) * groups) else {
            return MovingShadow::Unasked;
        };
        for (g, [min, max]) in cells.iter().enumerate() {
            let group = g * LANES;
            let live = (1u32 << (n - group).min(LANES)) - 1;
            let slabs = boxes.slabs4(*min, *max);
            let mut near = slabs.overlaps(t_max) & live;
            while near != 0 {
                let k = group + near.trailing_zeros() as usize;
                near &= near - 1;
                // A ray leaving the surface of a convex shape (every kind but a mesh) outwards,
                // as a shadow ray towards a light on its lit side does, cannot meet it again.
                if from == Some(k as u32) && self.convex[k] {
                    continue;
                }
                let hit = |p: &Primitive| p.hit(ray, t_max).is_some();
                if self.with(k as u32, ray, scratch, hit) == Some(true) {
                    return MovingShadow::Blocked;
                }
            }
        }
        MovingShadow::Clear
    }

    /// Entry `k`'s poses, one per part of the exposure (see [`Pose`]).
    ///
    /// Why a grown box holds the shape through its part: a point of the shape is an affine
    /// combination of its own bounds' corners, so it drifts from where it is at the part's
    /// middle by at most the longest way a corner travels from there to either end of the part.
    /// That way is measured as twice the sum of the chords between instants 1/128 of the
    /// exposure apart (and the keys' instants), as in [`swept_bounds`]. A drift `d` in the world
    /// is at most `d·|M⁻¹|` in the shape's own space, `M⁻¹` the map into it, whose Frobenius
    /// norm bounds its stretch.
    fn poses_of(&self, k: u32) -> Vec<Option<Pose>> {
        let unknown = vec![None; POSE_PARTS];
        let Some((inst, local)) = self.own(k) else {
            return unknown;
        };
        let sphere = local.world_sphere().map(|s| s.packed());
        let local = local.bounds;
        if !local.is_finite() || local.is_empty() {
            return unknown;
        }
        let steps = 2 * POSE_PARTS * DRIFT_STEPS;
        let mut instants: Vec<f64> = (0..=steps).map(|s| s as f64 / steps as f64).collect();
        instants.extend(
            self.motion
                .slot_instants(inst.transform)
                .into_iter()
                .filter(|u| (0.0..=1.0).contains(u)),
        );
        instants.sort_by(f64::total_cmp);
        instants.dedup();
        let corners: Vec<[DVec3; 8]> = instants
            .iter()
            .map(|&u| {
                let m = self.motion.slot_matrix(inst.transform, u);
                local.corners().map(|c| m.transform_point3(c.as_dvec3()))
            })
            .collect();
        // The longest way a corner travels between instants `a` and `b` (indices), chord by chord.
        let way = |a: usize, b: usize| -> f64 {
            let (a, b) = (a.min(b), a.max(b));
            (0..8)
                .map(|c| {
                    (a..b)
                        .map(|i| corners[i][c].distance(corners[i + 1][c]))
                        .sum::<f64>()
                })
                .fold(0.0, f64::max)
        };
        let at = |u: f64| instants.partition_point(|&v| v < u).min(instants.len() - 1);
        (0..POSE_PARTS)
            .map(|i| {
                let middle = (i as f64 + 0.5) / POSE_PARTS as f64;
                let (lo, mid, hi) = (
                    at(i as f64 / POSE_PARTS as f64),
                    at(middle),
                    at((i + 1) as f64 / POSE_PARTS as f64),
                );
                let drift = 2.0 * way(lo, mid).max(way(mid, hi));
                let xf = self.motion.slot_at(inst.transform, instants[mid]);
                let inverse = xf.object_from_world;
                let stretch = (inverse.x_axis.truncate().length_squared()
                    + inverse.y_axis.truncate().length_squared()
                    + inverse.z_axis.truncate().length_squared())
                .sqrt();
                let grow = drift * stretch;
                if !(grow.is_finite() && inverse.is_finite()) {
                    return None;
                }
                // And a relative margin for the f32 rounding of the ray's map.
                let pad = Vec3A::splat(grow as f32)
                    + (local.min.abs().max(local.max.abs()) + local.extent()) * 1e-4;
                let grown = Aabb::new(local.min - pad, local.max + pad);
                let world = Aabb::from_points(grown.corners().map(|c| {
                    Vec3A::from(
                        xf.world_from_object
                            .transform_point3(c.as_dvec3())
                            .as_vec3(),
                    )
                }));
                // The f32 rounding of the corners, outwards.
                let slack = (world.min.abs().max(world.max.abs()) + world.extent()) * 1e-4;
                let world = Aabb::new(world.min - slack, world.max + slack);
                if !world.is_finite() {
                    return None;
                }
                Some(Pose {
                    object_from_world: Affine3A::from_mat4(inverse.as_mat4()),
                    grown,
                    world,
                    sphere: sphere.map(|s| s.truncate().extend(s.w + pad.max_element())),
                })
            })
            .collect()
    }

    /// Entry `k`'s instance.
    fn instance(&self, k: u32) -> Option<&Instance> {
        self.instances.get(*self.entries.get(k as usize)? as usize)
    }

    /// Whether entry `k`'s shape encloses a solid (`Shape::is_closed`).
    pub fn is_closed(&self, k: u32) -> bool {
        self.own(k).is_some_and(|(_, p)| p.shape.is_closed())
    }

    /// Entry `k`'s instance and its shape in its own space (where its motion places it from).
    fn own(&self, k: u32) -> Option<(&Instance, Primitive)> {
        let inst = self.instance(k)?;
        let shape = Primitive::new(&inst.geometry, &Transform::IDENTITY, 0).ok()?;
        Some((inst, shape))
    }

    /// Entry `k` at time `u`: its transform.
    fn transform(&self, k: u32, u: f64) -> Option<(&Instance, Transform)> {
        let inst = self.instance(k)?;
        Some((inst, self.motion.slot_at(inst.transform, u)))
    }

    /// Entry `k` placed at `time` (`None` where it is degenerate then).
    fn place(&self, k: u32, time: f32) -> Option<Primitive> {
        let (inst, xf) = self.transform(k, time as f64)?;
        Primitive::new(&inst.geometry, &xf, inst.material as u32).ok()
    }

    /// `f` of entry `k` placed at the ray's time; `None` where it is degenerate then.
    #[inline]
    pub fn with<R>(
        &self,
        k: u32,
        ray: &Ray,
        scratch: &mut MovingScratch,
        f: impl FnOnce(&Primitive) -> R,
    ) -> Option<R> {
        let time = ray.time;
        let swept = self.sweep.get(k as usize).copied().unwrap_or(f32::INFINITY);
        // Asked also outside a traversal (a shadow ray tries the last blocker first): only a
        // ray that meets the shape at some instant counts.
        if scratch.swept < swept && self.met_by(k, ray) {
            scratch.swept = swept;
        }
        self.placed_with(k, time, scratch, f)
    }

    /// `f` of entry `k` placed at `time`, as [`Moving::with`] gives it to a ray of that time,
    /// without noting it as met: for a shape a ray already met (its surface).
    #[inline]
    pub fn placed_with<R>(
        &self,
        k: u32,
        time: f32,
        scratch: &mut MovingScratch,
        f: impl FnOnce(&Primitive) -> R,
    ) -> Option<R> {
        if !self.placed.is_empty() {
            return self.placed_at(k, motion_step(time))?.map(f);
        }
        let c = &mut scratch.placed;
        if c.owner != self.id || c.time != time.to_bits() {
            c.owner = self.id;
            c.time = time.to_bits();
            c.generation += 1;
            if c.entries.len() != self.entries.len() {
                c.entries.clear();
                c.entries.resize_with(self.entries.len(), || (0, None));
            }
        }
        let generation = c.generation;
        let slot = c.entries.get_mut(k as usize)?;
        if slot.0 != generation {
            *slot = (generation, self.place(k, time));
        }
        slot.1.as_ref().map(f)
    }

    /// Entry `k`'s bounds over the whole exposure.
    fn swept(&self, k: u32) -> Swept {
        let Some((inst, local)) = self.own(k) else {
            return Swept {
                bounds: Aabb::EMPTY,
                path: 0.0,
            };
        };
        let mut instants: Vec<f64> = (0..=BOUND_STEPS)
            .map(|s| s as f64 / BOUND_STEPS as f64)
            .collect();
        instants.extend(self.motion.slot_instants(inst.transform));
        swept_bounds(&instants, |u| {
            Some((local.bounds, self.motion.slot_at(inst.transform, u)))
        })
    }

    /// Bytes the moving part holds.
    pub fn memory_bytes(&self) -> usize {
        self.entries.capacity() * 4
            + self.sweep.capacity() * 4
            + self.bounds.capacity() * std::mem::size_of::<Aabb>()
            + self.poses.capacity() * std::mem::size_of::<Option<Pose>>()
            + self.reach.capacity() * std::mem::size_of::<Option<Pose>>()
            + self.placed.capacity() * std::mem::size_of::<OnceLock<Option<Primitive>>>()
            + self.part_boxes.capacity() * std::mem::size_of::<[[Vec4; LANES]; 2]>()
            + self.part_union.capacity() * std::mem::size_of::<Aabb>()
    }
}

/// Bounds of a moving box over the exposure: `placed(u)` gives the box in its own space and
/// its transform at `u` (`None` where degenerate). The union of the boxes at `instants`
/// (0 and 1 among them), each widened by twice the longest path a corner takes between two
/// neighbouring instants (its chord).
///
/// Why it holds: a point of the shape is an affine combination of the box's corners, so
/// between two instants it strays from where it was at the nearer one by at most the longest
/// path a corner takes in that span. Between instants 1/64 of the exposure apart (and every
/// key instant), a corner's path is a smooth curve (a constant-speed turn combined with a
/// straight slide and a steady stretch) that turns far less than a half circle, and the path
/// of a curve turning by less than 180° is at most π/2 times its chord: twice the chord
/// covers it with room to spare. `motion_bounds_hold` (proptest) checks it.
pub fn swept_bounds(instants: &[f64], placed: impl Fn(f64) -> Option<(Aabb, Transform)>) -> Swept {
    let mut instants: Vec<f64> = instants
        .iter()
        .copied()
        .filter(|u| (0.0..=1.0).contains(u))
        .collect();
    instants.extend([0.0, 1.0]);
    instants.sort_by(f64::total_cmp);
    instants.dedup();
    let mut all = Aabb::EMPTY;
    let mut margin = 0.0f64;
    let mut paths = [0.0f64; 8];
    let mut previous: Option<[DVec3; 8]> = None;
    for &u in &instants {
        let Some((local, xf)) = placed(u) else {
            previous = None;
            continue;
        };
        if !local.is_finite() {
            return Swept {
                bounds: Aabb::new(Vec3A::NEG_INFINITY, Vec3A::INFINITY),
                path: f64::INFINITY,
            };
        }
        let corners = local.corners().map(|c| xf.point(c.as_dvec3()));
        for c in corners {
            all = all.union_point(Vec3A::from(c.as_vec3()));
        }
        if let Some(before) = previous {
            for ((a, b), path) in before.iter().zip(&corners).zip(&mut paths) {
                margin = margin.max(a.distance(*b));
                *path += a.distance(*b);
            }
        }
        previous = Some(corners);
    }
    let path = paths.into_iter().fold(0.0, f64::max);
    if all.is_empty() {
        return Swept { bounds: all, path };
    }
    // Twice the longest chord, and a relative margin for the f32 rounding of the corners.
    let pad = Vec3A::splat((2.0 * margin) as f32)
        + (all.min.abs().max(all.max.abs()) + all.extent()) * 1e-5;
    Swept {
        bounds: Aabb::new(all.min - pad, all.max + pad),
        path,
    }
}

/// A moving entry's `poses` as one: the box, in the space of the middle pose, around every
/// pose's grown box (its corners mapped through the world), widened by a thousandth for the
/// f32 rounding of the maps. A ray that misses it misses every pose: the poses' boxes lie
/// inside it, each mapped to that space. `None` where a pose cannot be told.
fn reach_of(poses: &[Option<Pose>]) -> Option<Pose> {
    let poses: Vec<&Pose> = poses.iter().map(Option::as_ref).collect::<Option<_>>()?;
    let frame = poses.get(poses.len() / 2)?.object_from_world;
    let mut all = Aabb::EMPTY;
    for p in &poses {
        let to_frame = frame * p.object_from_world.inverse();
        for c in p.grown.corners() {
            all = all.union_point(to_frame.transform_point3a(c));
        }
    }
    let slack = (all.min.abs().max(all.max.abs()) + all.extent()) * 1e-3;
    let all = Aabb::new(all.min - slack, all.max + slack);
    (all.is_finite() && frame.is_finite()).then_some(Pose {
        object_from_world: frame,
        grown: all,
        world: Aabb::EMPTY,
        sphere: None,
    })
}

/// What [`swept_bounds`] finds of a moving box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Swept {
    /// A box that holds the shape over the whole exposure.
    pub bounds: Aabb,
    /// The longest way a corner of the box travels over the exposure (through the instants).
    pub path: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::motion::MotionKeys;
    use proptest::prelude::*;

    fn trs(t: [f64; 3], degrees: f64, axis: [f64; 3], s: [f64; 3]) -> Transform {
        Transform::translate(t.into())
            .then_after(&Transform::rotate(degrees, axis.into()).expect("axis"))
            .then_after(&Transform::scale(s.into()).expect("scale"))
    }

    proptest! {
        /// The swept bounds hold the box at every instant, turns of up to 180° between two
        /// keys and a parent's motion carrying the child included.
        #[test]
        fn motion_bounds_hold(
            t in prop::array::uniform3(prop::array::uniform3(-5.0f64..5.0)),
            d in prop::array::uniform3(-180.0f64..180.0),
            axis in prop::array::uniform3(0.1f64..1.0),
            s in prop::array::uniform3(0.5f64..2.0),
            parent_turn in -180.0f64..180.0,
            u in prop::collection::vec(0.0f64..1.0, 16),
        ) {
            let local = Aabb::new(Vec3A::new(-1.0, -0.5, -0.2), Vec3A::new(1.0, 0.5, 2.0));
            let keys = [0.0, 0.5, 1.0];
            let child: Vec<(f64, Transform)> = (0..3)
                .map(|k| (keys[k], trs(t[k], d[k], axis, [s[k], 1.0, s[(k + 1) % 3]])))
                .collect();
            let child = MotionKeys::new(DVec3::new(0.0, 0.0, 0.9), &child).expect("keys");
            let spin = |deg: f64| trs([3.0, 0.0, 0.0], deg, [0.0, 1.0, 0.0], [1.0; 3]);
            let parent = MotionKeys::new(
                DVec3::ZERO,
                &[(0.0, spin(0.0)), (1.0, spin(parent_turn))],
            )
            .expect("keys");
            let at = |u: f64| {
                let m = parent.matrix_at(u) * child.matrix_at(u);
                Transform { world_from_object: m, object_from_world: m.inverse() }
            };
            let instants: Vec<f64> = (0..=BOUND_STEPS).map(|k| k as f64 / BOUND_STEPS as f64).collect();
            let bounds = swept_bounds(&instants, |u| Some((local, at(u)))).bounds;
            for u in u {
                for c in local.corners() {
                    let p = Vec3A::from(at(u).point(c.as_dvec3()).as_vec3());
                    prop_assert!(
                        p.cmpge(bounds.min).all() && p.cmple(bounds.max).all(),
                        "{p} outside {bounds:?} at {u}"
                    );
                }
            }
        }
    }

    /// A bar spinning 60° about z through its centre, a ball shooting 20 units along x (rising a little), a tilted
    /// cylinder swinging: the moving part of the scene, every shape added.
    fn moving_things() -> Moving {
        let text = "define material m 1 1 1 0 0 0 0 0 0 1\n\
            define shape box bar -1 -0.2 -0.2 1 0.2 0.2 m\n\
            define shape sphere ball 3 0 0 0.5 m\n\
            define shape cylinder post -3 -1 0 -2.5 1 0.3 0.25 m\n\
            define camera eye 40 0 0 10 0 0 -1 0 1 0\n\
            motion bar 0 rotate -30 0 0 1\nmotion bar 0.5\nmotion bar 1 rotate 30 0 0 1\n\
            motion ball 0 translate -10 -0.5 0\nmotion ball 0.5\nmotion ball 1 translate 10 0.5 1\n\
            motion post 0 rotate -20 1 0 0\nmotion post 0.5\nmotion post 1 rotate 40 1 0 0\n\
            render eye m.ppm 8 8\n";
        let loaded = crate::load::load_str(
            text,
            std::path::Path::new("m.sdf"),
            &crate::sdf::LoadOptions::default(),
        )
        .expect("loads");
        let scene = &loaded.jobs[0].scene;
        let mut moving = Moving::new(scene).expect("things move");
        for (i, inst) in scene.instances.iter().enumerate() {
            if moving.moves(inst) {
                moving.add(i);
            }
        }
        moving.finish(true);
        assert_eq!(moving.entries.len(), 3);
        moving
    }

    proptest! {
        /// A ray that meets a moving shape at any instant rays are placed at is never told it
        /// does not ([`Moving::met_by`] is what adaptive sampling's first pass trusts): rays
        /// from all sides (across the path of the fast ball) through a point inside the shape
        /// at a random instant, most of them near its surface, where its motion carries it
        /// out of its poses soonest.
        #[test]
        fn a_ray_that_meets_a_moving_shape_is_seen_to(
            origin in prop::array::uniform3(-6.0f64..6.0),
            k in 0u32..3,
            step in 0..MOTION_TIME_STEPS,
            along in -1.0f64..1.0,
            across in prop::array::uniform2(-1.0f64..1.0),
        ) {
            let moving = moving_things();
            // A point of the shape in its own space: in the bar, in the ball, on the post's axis.
            let edge = |v: f64| v.signum() * v.abs().powf(0.1);
            let (along, across) = (edge(along), across.map(edge));
            let inside = match k {
                0 => DVec3::new(along, 0.19 * across[0], 0.19 * across[1]),
                1 => DVec3::new(3.0, 0.0, 0.0) + 0.49 * DVec3::new(along, across[0], across[1]) / 3f64.sqrt(),
                _ => DVec3::new(-3.0, -1.0, 0.0).lerp(DVec3::new(-2.5, 1.0, 0.3), 0.5 + 0.499 * along),
            };
            let u = (step as f64 + 0.5) / MOTION_TIME_STEPS as f64;
            let (_, xf) = moving.transform(k, u).expect("entry");
            let target = Vec3A::from(xf.point(inside).as_vec3());
            // Across the ball's path, so that a ray grazing it meets it for a moment only.
            let from = DVec3::from(origin);
            let from = if k == 1 { DVec3::new(0.0, from.y, from.z) } else { from };
            prop_assume!(from.length() > 1e-3);
            let origin = target + Vec3A::from((8.0 * from.normalize()).as_vec3());
            let ray = Ray::new(origin, (target - origin).normalize());
            let placed = moving.placed_at(k, step).flatten().expect("placed");
            prop_assume!(placed.hit(&ray, f32::INFINITY).is_some());
            prop_assert!(moving.met_by(k, &ray), "entry {k} hit at step {step}, not met");
            // And a shadow ray at that instant asks it (its bounds in that part hold it).
            let at = ray.at_time(u as f32);
            let blocks = moving.blocks(&at, f32::INFINITY, None, &mut MovingScratch::default());
            prop_assert_eq!(blocks, MovingShadow::Blocked, "entry {} at step {}", k, step);
        }
    }

    #[test]
    fn rays_through_the_swept_bounds_that_never_meet_the_shape_are_told_so() {
        let moving = moving_things();
        // Along z past the spinning bar, inside its bounds over the exposure (they reach
        // x = ±1, y = ±0.67) but 1.12 from its axis, beyond its reach of 1.02.
        let past = Ray::new(Vec3A::new(0.95, 0.6, 5.0), Vec3A::NEG_Z);
        assert!(moving.bounds[0]
            .hit_range(&past, past.dir.recip(), 0.0, f32::INFINITY)
            .is_some());
        assert!(!moving.met_by(0, &past));
        // Through the bar's centre, it meets it at every instant.
        let through = Ray::new(Vec3A::new(0.0, 0.0, 5.0), Vec3A::NEG_Z);
        assert!(moving.met_by(0, &through));
        // Through a corner of the ball's box over the exposure, far from its path.
        let b = moving.bounds[1];
        let corner = Ray::new(Vec3A::new(b.max.x - 0.05, b.max.y - 0.05, -5.0), Vec3A::Z);
        assert!(b
            .hit_range(&corner, corner.dir.recip(), 0.0, f32::INFINITY)
            .is_some());
        assert!(!moving.met_by(1, &corner));
    }

    #[test]
    fn a_shadow_ray_asks_the_moving_shapes_where_they_are_at_its_instant() {
        let moving = moving_things();
        // Down through the ball's centre at the middle of the exposure, (3, 0, 0).
        let at = |time: f32| Ray::new(Vec3A::new(3.0, 0.0, 5.0), Vec3A::NEG_Z).at_time(time);
        let blocks = |ray: Ray, t_max: f32, from: Option<u32>| {
            moving.blocks(&ray, t_max, from, &mut MovingScratch::default())
        };
        assert_eq!(blocks(at(0.5), f32::INFINITY, None), MovingShadow::Blocked);
        // Early on the ball is 8 units to the left; the bar and the post are never there.
        assert_eq!(blocks(at(0.1), f32::INFINITY, None), MovingShadow::Clear);
        // The light is nearer than the ball.
        assert_eq!(blocks(at(0.5), 4.0, None), MovingShadow::Clear);
        // A ray said to leave the ball's own surface (entry 1) does not ask the ball.
        assert_eq!(blocks(at(0.5), f32::INFINITY, Some(1)), MovingShadow::Clear);
        // Where the plan does not ask the moving shapes, neither do they answer.
        let mut unasked = moving.clone();
        unasked.asked = false;
        assert_eq!(
            unasked.blocks(&at(0.5), f32::INFINITY, None, &mut MovingScratch::default()),
            MovingShadow::Unasked
        );
    }
}
