//! A scene description compiled for rendering, and the facade every ray question passes
//! through: the closest hit along a ray ([`RenderScene::intersect`], and
//! [`RenderScene::intersect_camera_packet`] for a block of camera rays), what lies before a
//! light ([`RenderScene::occlusion`]), how much of a light passes the glass on the way
//! ([`RenderScene::transmittance`], pbrt's `Integrator::Tr`, Mitsuba's `ray_test` with its
//! transmission), what the moving shapes do to a shadow ray
//! ([`RenderScene::moving_shadow`]), and what a point sees of a spherical light as a whole
//! ([`RenderScene::whole_light`]). Each takes a hint of what the ray is ([`RayHint`], in the
//! manner of Mitsuba's `coherent` flag), which lets the scene answer it from the structure
//! that serves it best, and the worker's [`Scratch`].
//!
//! A compiled scene has three parts, none of them public: the [`Aggregate`] (camera-free,
//! immutable, shared by an `Arc`), the [`View`] (built with the camera) and the [`Shading`]
//! data. The integrator and the samplers ask this facade only; the types they read of a hit
//! are re-exported here.

use super::counts::RayCounts;
use super::geometry::{Aggregate, Candidates, Cone, Dropped, MovingScratch};
use super::policy::{GeometryPlan, ViewPlan};
use super::shading::{LightDisc, ShadeMaterial, Shading};
use super::view::{View, Viewpoint};
use crate::math::Ray;
use crate::scene::Scene;
use glam::Vec3A;
use std::sync::Arc;

pub use super::geometry::{MovingShadow, PrimId, SurfaceHit};

/// What a ray is, for the scene to choose what answers it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayHint {
    /// A camera ray from the eye the scene was compiled for (any other camera ray is
    /// answered as a secondary one).
    Camera,
    /// A shadow ray towards light `k`, ending there.
    Shadow(usize),
    /// Any other ray.
    Secondary,
}

/// What a shadow ray meets ([`RenderScene::occlusion`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Occlusion {
    /// Nothing.
    Clear,
    /// This opaque primitive (and maybe more).
    Blocked(PrimId),
    /// This transparent primitive, maybe more than once, and nothing else.
    Through(PrimId),
    /// Transparent primitives only, but more than one, or some inside an instanced
    /// composite: which of them it crosses, and how often, is for the caller to find out.
    Walk,
}

/// What a point sees of a spherical light as a whole ([`RenderScene::whole_light`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WholeLight {
    /// All of it: nothing may meet a shadow ray towards any point of it.
    Visible,
    /// None of it: one opaque primitive meets every shadow ray towards it.
    Hidden,
    /// Neither is proven: its shadow rays are sampled.
    Partial,
}

/// A point asking about a whole spherical light ([`RenderScene::whole_light`]).
#[derive(Clone, Copy, Debug)]
pub struct LightSight<'a> {
    /// The surface point, as its closest hit found it.
    pub hit: &'a SurfaceHit,
    /// The primitive it lies on.
    pub leaving: PrimId,
    /// The shading normal there (turned to the incoming ray).
    pub normal: Vec3A,
    /// The light's number.
    pub light: usize,
    /// Its centre, at `time`.
    pub centre: Vec3A,
    /// Its radius.
    pub radius: f32,
    /// The instant of the exposure the question is asked at.
    pub time: f32,
}

/// Convex opaque primitives among a light cone's candidates tried as the one that hides all
/// of the light: the blocker that casts an umbra is mostly the first or the light's last
/// blocker, and each try costs four ray tests.
const HIDING_TRIES: usize = 2;

/// Bound on surfaces a shadow ray may pass through (glass behind glass behind glass ...).
const MAX_SHADOW_CROSSINGS: usize = 64;

/// Lights whose last blocker a [`Scratch`] remembers (the others go without).
const CACHED_LIGHTS: usize = 8;

/// Shadow rays towards a light found clear in a row after which its last blocker is no
/// longer tried first (see [`LastBlocker`]).
const CLEAR_RUN_SKIP: u8 = 8;

/// No primitive: what a ray that meets nothing reports, and a light's last blocker before
/// any.
pub const NO_HIT: PrimId = PrimId::MAX;

/// What a worker's latest shadow rays towards one light found: the opaque primitive that
/// last blocked one, tried first by the next (neighbouring points mostly lie in the same
/// shadow), and how many in a row have since found the light clear. Out of shadow, trying
/// a blocker that blocks nothing is a wasted test per ray; but where shadowed and lit points
/// alternate (a packet of camera rays crossing gaps between spheres), the blocker of two
/// rays ago is often the next one's too. So it is tried until a few clear rays in a row.
/// Rays that cross only glass neither count nor break the run: making them break it cost
/// the glass scenes more than it saved (docs/benchmarks-history.md §9.7).
#[derive(Clone, Copy, Debug)]
struct LastBlocker {
    prim: PrimId,
    clear_run: u8,
}

impl LastBlocker {
    const NONE: LastBlocker = LastBlocker {
        prim: NO_HIT,
        clear_run: 0,
    };

    /// The primitive to try first, if any.
    #[inline]
    fn guess(&self) -> Option<PrimId> {
        (self.prim != NO_HIT && self.clear_run < CLEAR_RUN_SKIP).then_some(self.prim)
    }

    #[inline]
    fn blocked_by(&mut self, prim: PrimId) {
        *self = LastBlocker { prim, clear_run: 0 };
    }
}

/// What one worker keeps between the rays it asks the scene about, handed to every query:
/// its ray counts, per light the opaque primitive that last blocked a shadow ray (tried
/// first by the next, [`RenderScene::transmittance`]), and what the geometry keeps between
/// rays (the moving shapes placed at the current instant). The caches only save work, never
/// change a value, so images do not depend on which worker traced which pixel.
pub struct Scratch {
    /// Rays traced so far, counted by whoever asks them.
    pub counts: RayCounts,
    last_blockers: [LastBlocker; CACHED_LIGHTS],
    moving: MovingScratch,
}

impl Default for Scratch {
    fn default() -> Self {
        Scratch {
            counts: RayCounts::default(),
            last_blockers: [LastBlocker::NONE; CACHED_LIGHTS],
            moving: MovingScratch::default(),
        }
    }
}

impl Scratch {
    /// Starts measuring the largest angle, as the eye sees it, swept by the moving shapes
    /// the queries given this scratch may meet ([`Scratch::take_sweep`]).
    #[inline]
    pub fn measure_sweep(&mut self) {
        self.moving.measure_sweep();
    }

    /// The largest angle (radians) swept by the moving shapes that the queries may have met
    /// at some instant of the exposure since [`Scratch::measure_sweep`]; 0 when they met
    /// none. Stops measuring.
    #[inline]
    pub fn take_sweep(&mut self) -> f32 {
        self.moving.take_sweep()
    }
}

/// A shadow ray: from a surface point towards a point `to` on light `light`, ending there.
#[derive(Clone, Copy, Debug)]
pub struct ShadowRay {
    /// The ray, leaving the surface (unit direction), at its camera sample's instant.
    pub ray: Ray,
    /// The point on the light it aims for.
    pub to: Vec3A,
    /// Its length to `to`.
    pub t_max: f32,
    /// The light's number.
    pub light: usize,
}

impl ShadowRay {
    /// The shadow ray leaving `hit` along unit direction `dir` at instant `time`, towards the
    /// point `dist` away on light `light`.
    #[inline]
    pub fn new(hit: &SurfaceHit, dir: Vec3A, dist: f32, time: f32, light: usize) -> ShadowRay {
        let ray = hit.spawn_ray(dir).at_time(time);
        let to = hit.point + dir * dist;
        ShadowRay {
            ray,
            to,
            t_max: (to - ray.origin).dot(dir),
            light,
        }
    }
}

/// A scene compiled for rendering: what rays meet, where they start, and how what they meet
/// is shaded.
#[derive(Clone, Debug)]
pub struct RenderScene {
    /// What rays meet: the primitives and their hierarchy (camera-free, shared).
    geometry: Arc<Aggregate>,
    /// Where the rays whose start is known look their candidates up.
    view: View,
    /// How what rays meet is shaded.
    shading: Shading,
}

impl RenderScene {
    /// Compiles `scene` as seen from `viewpoint` (`None`: no camera, as for tools and tests
    /// of the geometry alone); the shapes that stay degenerate once transformed are left out
    /// and returned.
    pub fn compile(scene: &Scene, viewpoint: Option<&Viewpoint>) -> (RenderScene, Vec<Dropped>) {
        let (geometry, dropped) = Aggregate::build(scene);
        (
            Self::with_geometry(Arc::new(geometry), scene, viewpoint),
            dropped,
        )
    }

    /// The scene `scene` whose geometry was built already (`Aggregate::build` of it), as
    /// seen from `viewpoint`.
    pub(crate) fn with_geometry(
        geometry: Arc<Aggregate>,
        scene: &Scene,
        viewpoint: Option<&Viewpoint>,
    ) -> RenderScene {
        let shading = Shading::new(scene, &geometry.used_materials(scene));
        let view = View::new(&geometry, &shading.lights, shading.lights_move(), viewpoint);
        RenderScene {
            geometry,
            view,
            shading,
        }
    }

    /// The strategies chosen for this scene.
    pub fn plan(&self) -> (GeometryPlan, ViewPlan) {
        (self.geometry.plan(), self.view.plan())
    }

    /// The materials, lights, ambient light and background.
    #[inline(always)]
    pub fn shading(&self) -> &Shading {
        &self.shading
    }

    /// The material of primitive `prim`.
    #[inline(always)]
    pub fn material(&self, prim: PrimId) -> &ShadeMaterial {
        &self.shading.materials[self.geometry.material_of(prim) as usize]
    }

    /// The compiled primitive table itself, for tools and tests that look at it rather than
    /// ask rays (the blank-image probe, `tests/geometry`, the bench's re-hit count). The
    /// renderer's integrator and samplers never do.
    pub fn aggregate(&self) -> &Aggregate {
        &self.geometry
    }

    /// The lookups kept for rays from the eye and the lights.
    pub fn view(&self) -> &View {
        &self.view
    }

    /// The nearest surface along `ray` with `t < t_max`. Of equally close hits, an unbounded
    /// primitive's wins (the first of them), else the first in the flattened composite tree.
    #[inline]
    pub fn intersect(
        &self,
        ray: &Ray,
        t_max: f32,
        hint: RayHint,
        scratch: &mut Scratch,
    ) -> Option<(PrimId, SurfaceHit)> {
        let candidates = match hint {
            RayHint::Camera => self.view.camera(ray),
            _ => Candidates::All,
        };
        self.geometry
            .closest(ray, t_max, candidates, &mut scratch.moving)
    }

    /// The hit of primitive `prim` alone along `ray` with `0 < t < t_max` (a shape of an
    /// instanced composite too): for tools that judge the rays leaving a surface, and tests.
    pub fn intersect_primitive(
        &self,
        prim: PrimId,
        ray: &Ray,
        t_max: f32,
        scratch: &mut Scratch,
    ) -> Option<SurfaceHit> {
        self.geometry
            .intersect(prim, ray, t_max, &mut scratch.moving)
    }

    /// [`RenderScene::intersect`] of each of a packet of camera rays without limit, which
    /// lie on the image within the rectangle that the first and the last span (a block of
    /// pixels, or a run of a row).
    pub fn intersect_camera_packet<const N: usize>(
        &self,
        rays: &[Ray; N],
        scratch: &mut Scratch,
    ) -> [Option<(PrimId, SurfaceHit)>; N] {
        let geometry = &self.geometry;
        let Some(tiles) = self.view.eye_tiles() else {
            return geometry.closest_packet(rays, f32::INFINITY, &mut scratch.moving);
        };
        // Rays of one tile in a scene of packed spheres alone: each group of four spheres is
        // put in lanes once for them all. The rays between the first and the last on the
        // image lie in the tile of both (up to round-off, which the tiles' widening covers).
        let ends = [&rays[0], &rays[N - 1]].map(|r| tiles.candidates(r.origin, r.dir));
        match ends {
            [Some(first), Some(last)]
                if geometry.plan().spheres_only && std::ptr::eq(first.0, last.0) =>
            {
                geometry.closest_in_tile(rays, first, &mut scratch.moving)
            }
            _ => std::array::from_fn(|r| {
                self.intersect(&rays[r], f32::INFINITY, RayHint::Camera, scratch)
            }),
        }
    }

    /// What a shadow ray (`hint` names its light) meets before `t_max`, looking past
    /// transparent primitives for an opaque one (which one, of several, is left to the
    /// strategy that answers).
    #[inline(always)]
    pub fn occlusion(
        &self,
        ray: &Ray,
        t_max: f32,
        hint: RayHint,
        scratch: &mut Scratch,
    ) -> Occlusion {
        self.occlusion_in(ray, t_max, hint, &mut scratch.moving)
    }

    /// [`RenderScene::occlusion`] with the geometry's part of the scratch.
    #[inline(always)]
    fn occlusion_in(
        &self,
        ray: &Ray,
        t_max: f32,
        hint: RayHint,
        scratch: &mut MovingScratch,
    ) -> Occlusion {
        let candidates = match hint {
            RayHint::Shadow(light) => self.view.shadow(ray, t_max, light),
            _ => Candidates::All,
        };
        let mut seen = Occlusion::Clear;
        let stop = |i| self.stops_shadow(i, &mut seen);
        self.geometry.any(ray, t_max, candidates, scratch, stop);
        seen
    }

    /// Whether primitive `i`, which a shadow ray meets, ends the search: an opaque one does
    /// (`seen` becomes `Blocked`); a transparent one adds to what `seen` says, and the search
    /// goes on.
    #[inline(always)]
    fn stops_shadow(&self, i: PrimId, seen: &mut Occlusion) -> bool {
        // As the walk of `RenderScene::transmittance` tells them apart.
        if !self.shading.any_transparent || self.material(i).opacity >= 1.0 {
            *seen = Occlusion::Blocked(i);
            return true;
        }
        *seen = match *seen {
            // Inside an instanced composite, what lies past `i` is not looked at.
            Occlusion::Clear if i < self.geometry.len() as u32 => Occlusion::Through(i),
            Occlusion::Through(j) if j == i => Occlusion::Through(i),
            _ => Occlusion::Walk,
        };
        false
    }

    /// The fraction of its light's intensity that reaches the start of `shadow`: 0 behind an
    /// opaque primitive, attenuated by (1 − α) for every transparent surface crossed (shadow
    /// rays are not refracted). Any-hit either way: the first opaque blocker ends the query,
    /// and crossings of transparent primitives multiply in whatever order the hierarchy
    /// offers them.
    ///
    /// The opaque primitive that last blocked a shadow ray towards this light (kept in the
    /// worker's `scratch`) is tried first while it is likely to block again; an opaque hit
    /// means no light whatever else the ray crosses, so the answer is the same as without it.
    #[inline]
    pub fn transmittance(&self, shadow: &ShadowRay, scratch: &mut Scratch) -> f32 {
        let geometry = &self.geometry;
        let Scratch {
            last_blockers,
            moving,
            ..
        } = scratch;
        let (ray, remaining) = (&shadow.ray, shadow.t_max);
        let mut last = last_blockers.get_mut(shadow.light);
        if let Some(b) = last.as_deref().and_then(LastBlocker::guess) {
            if geometry.hit(b, ray, remaining, moving).is_some() {
                return 0.0;
            }
        }
        // Most shadow rays meet nothing at all, or one glass object: the any-hit query
        // (packed primitives four at a time) says so, looking past glass for an opaque
        // blocker, which means no light whatever else the ray crosses.
        let hint = RayHint::Shadow(shadow.light);
        match self.occlusion_in(ray, remaining, hint, moving) {
            Occlusion::Clear => {
                if let Some(last) = last {
                    last.clear_run = last.clear_run.saturating_add(1);
                }
                return 1.0;
            }
            Occlusion::Blocked(first) => {
                if let Some(last) = last {
                    last.blocked_by(first);
                }
                return 0.0;
            }
            // One object's crossings alone: the walk below would multiply the same factors
            // in the same order, and nothing else.
            Occlusion::Through(i) => return self.crossings(shadow, i, 1.0, moving),
            Occlusion::Walk => {}
        }
        // Glass of several objects: the walk tells glass from opaque, and names the blocker
        // for the next ray.
        let mut transmit = 1.0f32;
        let blocked = geometry.any_candidate(ray, remaining, |i| {
            if self.material(i).opacity >= 1.0 {
                let hit = geometry.hit(i, ray, remaining, moving).is_some();
                if let Some(last) = last.as_deref_mut().filter(|_| hit) {
                    last.blocked_by(i);
                }
                return hit;
            }
            transmit = self.crossings(shadow, i, transmit, moving);
            transmit == 0.0
        });
        if blocked {
            0.0
        } else {
            transmit
        }
    }

    /// `transmit` times `1 − α` for every crossing of transparent primitive `i` along
    /// `shadow` before its end, stepping past each.
    fn crossings(
        &self,
        shadow: &ShadowRay,
        i: PrimId,
        mut transmit: f32,
        scratch: &mut MovingScratch,
    ) -> f32 {
        let opacity = self.material(i).opacity;
        let (ray, l) = (&shadow.ray, shadow.ray.dir);
        let mut segment = *ray;
        let mut left = shadow.t_max;
        for _ in 0..MAX_SHADOW_CROSSINGS {
            let Some(hit) = self.geometry.intersect(i, &segment, left, scratch) else {
                break;
            };
            transmit *= 1.0 - opacity;
            if transmit == 0.0 {
                break;
            }
            segment = hit.spawn_ray(l).at_time(ray.time);
            left = (shadow.to - segment.origin).dot(l);
            if left <= 0.0 {
                break;
            }
        }
        transmit
    }

    /// What the moving shapes alone do to `shadow`, at its instant: for a shadow ray from a
    /// surface of primitive `leaving` towards a light that every shape holding still is known
    /// to leave clear (adaptive sampling's prior in a frame with motion), which then need not
    /// walk the whole hierarchy. A convex moving shape is not asked about a ray leaving its
    /// own surface outwards.
    #[inline]
    pub fn moving_shadow(
        &self,
        shadow: &ShadowRay,
        leaving: PrimId,
        scratch: &mut Scratch,
    ) -> MovingShadow {
        let from = self.geometry.moving_entry(leaving);
        let (ray, t_max) = (&shadow.ray, shadow.t_max);
        self.geometry
            .moving_blocks(ray, t_max, from, &mut scratch.moving)
    }

    /// What the point `sight.hit` sees of the spherical light `sight.light`, when that is
    /// cheap to prove: all of it when nothing may meet the cone of shadow rays towards its
    /// disc (docs/shading.md §2.1), none of it when one opaque convex primitive meets the
    /// rays to the four corners of a square around the disc (every segment to the disc then
    /// crosses the hull of those four hits, which lies inside the primitive). The light's last
    /// blocker is tried first. A light not wholly above the point's horizon is `Partial`.
    pub fn whole_light(&self, sight: &LightSight, scratch: &mut Scratch) -> WholeLight {
        let hit = sight.hit;
        let to = sight.centre - hit.point;
        let dist = to.length();
        if dist.partial_cmp(&sight.radius) != Some(std::cmp::Ordering::Greater) {
            return WholeLight::Partial;
        }
        let axis = to / dist;
        // Every shadow ray towards the disc leaves from here: it lies on one side.
        let apex = hit.spawn_origin(axis);
        let Some(cone) = Cone::new(apex, sight.centre, sight.radius) else {
            return WholeLight::Partial;
        };
        if !cone.above(sight.normal) {
            return WholeLight::Partial;
        }
        let geometry = &self.geometry;
        let outward = sight.normal.dot(hit.normal) > 0.0;
        let own = sight.leaving;
        let skip_own = geometry.is_flat(own) || (outward && geometry.is_convex(own));
        let disc = LightDisc::new(sight.centre, sight.radius, axis);
        let Scratch {
            last_blockers,
            moving,
            ..
        } = scratch;
        let mut last = last_blockers.get_mut(sight.light);
        let hides =
            |i: PrimId, moving: &mut MovingScratch| self.hides(i, apex, &disc, sight.time, moving);
        // Only a convex opaque primitive that all four corner rays meet meets every ray
        // between them.
        let solid = |i: PrimId| geometry.is_convex(i) && self.material(i).opacity >= 1.0;
        if let Some(b) = last.as_deref().and_then(LastBlocker::guess) {
            if solid(b) && hides(b, moving) {
                return WholeLight::Hidden;
            }
        }
        let (mut met, mut tries, mut hidden) = (false, 0, false);
        geometry.cone_candidates(&cone, |i| {
            if skip_own && i == own {
                return false;
            }
            met = true;
            if !solid(i) || tries == HIDING_TRIES {
                return tries == HIDING_TRIES;
            }
            tries += 1;
            hidden = hides(i, moving);
            if let Some(last) = last.as_deref_mut().filter(|_| hidden) {
                last.blocked_by(i);
            }
            hidden
        });
        match (met, hidden) {
            (false, _) => WholeLight::Visible,
            (true, true) => WholeLight::Hidden,
            (true, false) => WholeLight::Partial,
        }
    }

    /// Whether primitive `i` meets the rays from `apex` to the four corners of a square a
    /// little larger than the one around `disc` (sides along its two directions across),
    /// each before its corner: the margin keeps the disc's rim, where it touches the square,
    /// clear of rounding.
    fn hides(
        &self,
        i: PrimId,
        apex: Vec3A,
        disc: &LightDisc,
        time: f32,
        moving: &mut MovingScratch,
    ) -> bool {
        const C: f32 = 1.0 + 1.0 / 64.0;
        [(C, C), (C, -C), (-C, C), (-C, -C)]
            .into_iter()
            .all(|corner| {
                let to = disc.at(corner) - apex;
                let length = to.length();
                let ray = Ray::new(apex, to / length).at_time(time);
                self.geometry.hit(i, &ray, length, moving).is_some()
            })
    }

    /// Bytes the scene's geometry and lookups hold (not materials or lights).
    pub fn memory_bytes(&self) -> usize {
        self.geometry.memory_bytes() + self.view.memory_bytes()
    }
}
