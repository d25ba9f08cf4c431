//! The camera-dependent part of a compiled scene: for rays that start at a known point (camera
//! rays at the eye, shadow rays towards a light), the few primitives each may meet, looked up
//! by where it goes (direction cells in a scene of a few primitives, image tiles in a larger
//! one: `crate::accel::DirectionCells`, `crate::accel::ImageTiles`). Built with the camera,
//! once, when the scene is compiled; never patched afterwards. [`super::policy::view_plan`]
//! decides which structure serves which point.

use super::geometry::{Aggregate, Candidates};
use super::policy::{self, Lookup, ViewFacts, ViewPlan};
use super::shading::PointLight;
use crate::accel::{DirectionCells, ImageTiles, ImageView};
use crate::math::{Aabb, Ray};

/// Where the camera rays of a render come from: the eye and the image they cross, and how
/// many of them the render traces at least.
#[derive(Clone, Copy, Debug)]
pub struct Viewpoint {
    /// The camera's image plane (the eye included).
    pub view: ImageView,
    /// The image's size in pixels.
    pub size: (u32, u32),
    /// Camera rays the render traces at least (pixels times the fewest samples a pixel takes).
    pub camera_rays: u64,
    /// Whether something moves during the exposure (a shape, a light or the camera).
    pub motion: bool,
}

/// The candidates of rays from one known point.
#[derive(Clone, Debug)]
enum Candidacy {
    Cells(DirectionCells),
    Tiles(ImageTiles),
}

/// Candidate lists for the rays whose start a compiled scene knows.
#[derive(Clone, Debug)]
pub struct View {
    plan: ViewPlan,
    /// Around the eye, for camera rays.
    eye: Option<Candidacy>,
    /// Around each light, for shadow rays (empty when no light keeps any).
    lights: Vec<Option<Candidacy>>,
}

impl View {
    /// The view of `geometry` from `viewpoint` (`None`: no camera), lit by `lights`.
    pub(crate) fn new(
        geometry: &Aggregate,
        lights: &[PointLight],
        lights_move: bool,
        viewpoint: Option<&Viewpoint>,
    ) -> View {
        let n = geometry.bounded();
        let plan = policy::view_plan(ViewFacts {
            bounded: n,
            hierarchy_nodes: geometry.hierarchy_nodes(),
            camera_rays: viewpoint.map(|v| v.camera_rays),
            motion: viewpoint.is_some_and(|v| v.motion),
            lights_move,
        });
        let bound = |i| geometry.bound(i);
        // Past the last primitive, every packed array holds NaN: never hit.
        let pad = geometry.len() as u32;
        let cells = |centre| {
            let bounds: Vec<Aabb> = (0..n).map(bound).collect();
            DirectionCells::new(centre, &bounds, pad)
        };
        let eye = viewpoint.and_then(|v| match plan.eye {
            Lookup::None => None,
            Lookup::Cells => Some(Candidacy::Cells(cells(v.view.eye))),
            Lookup::Tiles => ImageTiles::new(v.view, v.size, n, bound, pad).map(Candidacy::Tiles),
        });
        // A spherical light's shadow rays end all over its disc, away from the centre the
        // lookups are built around: the geometry's own strategy answers them.
        let point = |l: &&PointLight| l.radius == 0.0;
        let lights = match plan.lights {
            Lookup::None => Vec::new(),
            Lookup::Cells => lights
                .iter()
                .map(|l| {
                    Some(l)
                        .filter(point)
                        .map(|l| Candidacy::Cells(cells(l.position)))
                })
                .collect(),
            Lookup::Tiles => {
                let all = (0..n).fold(Aabb::EMPTY, |all, i| all.union(bound(i)));
                lights
                    .iter()
                    .map(|l| {
                        let tiles = Some(l).filter(point);
                        tiles.and_then(|l| ImageTiles::around(l.position, &all, n, bound, pad))
                    })
                    .map(|t| t.map(Candidacy::Tiles))
                    .collect()
            }
        };
        View { plan, eye, lights }
    }

    /// The strategies chosen.
    pub fn plan(&self) -> ViewPlan {
        self.plan
    }

    /// The candidates of a camera ray (from the eye; a ray from elsewhere, or one the eye's
    /// lookup does not answer, gets every primitive).
    #[inline(always)]
    pub(crate) fn camera(&self, ray: &Ray) -> Candidates<'_> {
        let listed = match &self.eye {
            Some(Candidacy::Cells(cells)) => cells
                .candidates(ray.origin, ray.dir, f32::INFINITY)
                .map(|ids| (ids, None)),
            Some(Candidacy::Tiles(tiles)) => tiles
                .candidates(ray.origin, ray.dir)
                .map(|(ids, near)| (ids, Some(near))),
            None => None,
        };
        listed.map_or(Candidates::All, |(ids, near)| Candidates::Listed {
            ids,
            near,
        })
    }

    /// The image tiles of camera rays, when the eye keeps them (camera packets share a
    /// tile's list).
    #[inline]
    pub(crate) fn eye_tiles(&self) -> Option<&ImageTiles> {
        match &self.eye {
            Some(Candidacy::Tiles(tiles)) => Some(tiles),
            _ => None,
        }
    }

    /// The candidates of a shadow ray towards light `light` that ends there after `t_max`.
    #[inline(always)]
    pub(crate) fn shadow(&self, ray: &Ray, t_max: f32, light: usize) -> Candidates<'_> {
        let listed = match self.lights.get(light) {
            Some(Some(Candidacy::Cells(cells))) => cells
                .candidates(ray.origin, ray.dir, t_max)
                .map(|ids| (ids, None)),
            Some(Some(Candidacy::Tiles(tiles))) => tiles
                .towards(ray.origin)
                .map(|(ids, near)| (ids, Some(near))),
            _ => None,
        };
        listed.map_or(Candidates::All, |(ids, near)| Candidates::Listed {
            ids,
            near,
        })
    }

    /// How many lights keep candidates, and whether the eye does: for tests and tools that
    /// report what a scene was given.
    pub fn kept(&self) -> (usize, bool) {
        (self.lights.iter().flatten().count(), self.eye.is_some())
    }

    /// Bytes the lookups hold.
    pub fn memory_bytes(&self) -> usize {
        self.lights
            .iter()
            .flatten()
            .chain(&self.eye)
            .map(|c| match c {
                Candidacy::Cells(cells) => cells.memory_bytes(),
                Candidacy::Tiles(tiles) => tiles.memory_bytes(),
            })
            .sum()
    }
}
