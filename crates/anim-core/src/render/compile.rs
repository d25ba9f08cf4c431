//! A scene description compiled for rendering, and the one query surface the integrator
//! asks: the closest hit along a ray ([`RenderScene::intersect`]) and what lies between a
//! point and a light ([`RenderScene::occlusion`]), each with a hint of what the ray is
//! ([`RayHint`], in the manner of Mitsuba's `coherent` flag) that lets the scene answer it
//! from the structure that serves it best.
//!
//! A compiled scene has three parts: the [`Aggregate`] (camera-free, immutable, shared by an
//! `Arc`), the [`View`] (built with the camera) and the [`Shading`] data.

use super::geometry::{Aggregate, Dropped, PrimId, Scratch, SurfaceHit};
use super::policy::{GeometryPlan, ViewPlan};
use super::shading::Shading;
use super::view::{View, Viewpoint};
use crate::math::Ray;
use crate::scene::Scene;
use std::sync::Arc;

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

/// A scene compiled for rendering: what rays meet, where they start, and how what they meet
/// is shaded.
#[derive(Clone, Debug)]
pub struct RenderScene {
    /// What rays meet: the primitives and their hierarchy (camera-free, shared).
    pub geometry: Arc<Aggregate>,
    /// Where the rays whose start is known look their candidates up.
    pub view: View,
    /// How what rays meet is shaded.
    pub shading: Shading,
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
    pub fn with_geometry(
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

    /// The nearest surface along `ray` with `t < t_max`. Of equally close hits, an unbounded
    /// primitive's wins (the first of them), else the first in the flattened composite tree.
    #[inline]
    pub fn intersect(
        &self,
        ray: &Ray,
        t_max: f32,
        hint: RayHint,
        scratch: &Scratch,
    ) -> Option<(PrimId, SurfaceHit)> {
        let candidates = match hint {
            RayHint::Camera => self.view.camera(ray),
            _ => super::geometry::Candidates::All,
        };
        self.geometry.closest(ray, t_max, candidates, scratch)
    }

    /// [`RenderScene::intersect`] of each of a packet of camera rays without limit, which
    /// lie on the image within the rectangle that the first and the last span (a block of
    /// pixels, or a run of a row).
    pub fn intersect_camera_packet<const N: usize>(
        &self,
        rays: &[Ray; N],
        scratch: &Scratch,
    ) -> [Option<(PrimId, SurfaceHit)>; N] {
        let geometry = &self.geometry;
        let Some(tiles) = self.view.eye_tiles() else {
            return geometry.closest_packet(rays, f32::INFINITY, scratch);
        };
        // Rays of one tile in a scene of packed spheres alone: each group of four spheres is
        // put in lanes once for them all. The rays between the first and the last on the
        // image lie in the tile of both (up to round-off, which the tiles' widening covers).
        let ends = [&rays[0], &rays[N - 1]].map(|r| tiles.candidates(r.origin, r.dir));
        match ends {
            [Some(first), Some(last)]
                if geometry.plan().spheres_only && std::ptr::eq(first.0, last.0) =>
            {
                geometry.closest_in_tile(rays, first, scratch)
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
    pub fn occlusion(&self, ray: &Ray, t_max: f32, hint: RayHint, scratch: &Scratch) -> Occlusion {
        let candidates = match hint {
            RayHint::Shadow(light) => self.view.shadow(ray, t_max, light),
            _ => super::geometry::Candidates::All,
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
        let shading = &self.shading;
        let geometry = &*self.geometry;
        // As the walk of `Integrator::visibility` tells them apart.
        if !shading.any_transparent
            || shading.materials[geometry.material_of(i) as usize].opacity >= 1.0
        {
            *seen = Occlusion::Blocked(i);
            return true;
        }
        *seen = match *seen {
            // Inside an instanced composite, what lies past `i` is not looked at.
            Occlusion::Clear if i < geometry.len() as u32 => Occlusion::Through(i),
            Occlusion::Through(j) if j == i => Occlusion::Through(i),
            _ => Occlusion::Walk,
        };
        false
    }

    /// Bytes the scene's geometry and lookups hold (not materials or lights).
    pub fn memory_bytes(&self) -> usize {
        self.geometry.memory_bytes() + self.view.memory_bytes()
    }
}
