//! The geometry contract: every strategy that answers a ray (the 4-wide hierarchy, the flat
//! leaf, packed spheres, packets, instanced composites, moving shapes, direction cells and
//! image tiles) gives brute force's answer over real primitives, to the bit: random scenes of
//! spheres, boxes, triangles and the other kinds (some transformed, so kept in object space);
//! the closest hit's distance, primitive and surface, and any-hit answers.
//!
//! - `hierarchy`: the hierarchy alone, over primitives.
//! - `render_scene`: the compiled scene's queries, instanced composites against their
//!   flattened trees, packets against single rays.
//! - `lookups`: camera and shadow rays through the eye's and the lights' direction cells and
//!   image tiles, in still and moving frames.
//! - `shadows`: how much of a light passes the glass before it (`RenderScene::transmittance`),
//!   with and without lookups, and through instanced composites.
//! - `light_cones`: what a point sees of a spherical light as a whole
//!   (`RenderScene::whole_light`) against shadow rays over its disc.

mod hierarchy;
mod light_cones;
mod lookups;
mod render_scene;
mod shadows;

#[path = "../common/composites.rs"]
mod composites;

use anim_core::math::{Ray, Transform};
use anim_core::render::camera::PinholeCamera;
use anim_core::render::compile::{Occlusion, RayHint, RenderScene, Scratch, ShadowRay, SurfaceHit};
use anim_core::render::geometry::{Dropped, MovingScratch, Primitive};
use anim_core::render::shading::PointLight;
use anim_core::render::view::Viewpoint;
use anim_core::scene::{Camera, Instance, Material, Scene};
use anim_core::shape::Geometry;
use anim_core::util::SplitMix64;
use glam::{DVec3, Vec3, Vec3A};
use std::cell::RefCell;

/// A compiled scene with a scratch of its own, asked what the renderer asks it: each helper
/// is named after the question of the facade (`RenderScene`) or of its aggregate it asks.
struct Compiled {
    scene: RenderScene,
    scratch: RefCell<Scratch>,
    /// For the aggregate's own queries.
    moving: RefCell<MovingScratch>,
}

impl Compiled {
    fn new(scene: &Scene, viewpoint: Option<&Viewpoint>) -> (Compiled, Vec<Dropped>) {
        let (scene, dropped) = RenderScene::compile(scene, viewpoint);
        let compiled = Compiled {
            scene,
            scratch: RefCell::default(),
            moving: RefCell::default(),
        };
        (compiled, dropped)
    }

    fn len(&self) -> usize {
        self.scene.aggregate().len()
    }

    fn material_of(&self, id: u32) -> u32 {
        self.scene.aggregate().material_of(id)
    }

    /// `RenderScene::intersect` as a reflected ray asks it: through the hierarchy.
    fn intersect(&self, ray: &Ray, t_max: f32) -> Option<(u32, SurfaceHit)> {
        let scratch = &mut self.scratch.borrow_mut();
        self.scene
            .intersect(ray, t_max, RayHint::Secondary, scratch)
    }

    /// `RenderScene::intersect` as a camera ray asks it: through the eye's lookup where it
    /// answers.
    fn intersect_camera(&self, ray: &Ray) -> Option<(u32, SurfaceHit)> {
        let scratch = &mut self.scratch.borrow_mut();
        self.scene
            .intersect(ray, f32::INFINITY, RayHint::Camera, scratch)
    }

    /// `RenderScene::intersect_camera_packet`.
    fn intersect_camera_packet<const N: usize>(
        &self,
        rays: &[Ray; N],
    ) -> [Option<(u32, SurfaceHit)>; N] {
        let scratch = &mut self.scratch.borrow_mut();
        self.scene.intersect_camera_packet(rays, scratch)
    }

    /// `Aggregate::closest_packet`: the packet walk over every primitive, up to `t_max`.
    fn closest_packet<const N: usize>(
        &self,
        rays: &[Ray; N],
        t_max: f32,
    ) -> [Option<(u32, SurfaceHit)>; N] {
        let moving = &mut self.moving.borrow_mut();
        self.scene.aggregate().closest_packet(rays, t_max, moving)
    }

    /// `RenderScene::occlusion` of a ray of kind `hint`.
    fn occlusion(&self, ray: &Ray, t_max: f32, hint: RayHint) -> Occlusion {
        let scratch = &mut self.scratch.borrow_mut();
        self.scene.occlusion(ray, t_max, hint, scratch)
    }

    /// `RenderScene::transmittance`.
    fn transmittance(&self, shadow: &ShadowRay) -> f32 {
        self.scene
            .transmittance(shadow, &mut self.scratch.borrow_mut())
    }

    /// `RenderScene::intersect_primitive`.
    fn intersect_primitive(&self, id: u32, ray: &Ray, t_max: f32) -> Option<SurfaceHit> {
        let scratch = &mut self.scratch.borrow_mut();
        self.scene.intersect_primitive(id, ray, t_max, scratch)
    }

    fn lights(&self) -> &[PointLight] {
        &self.scene.shading().lights
    }
}

/// White point lights of intensity 1 at `positions`.
fn white_lights(positions: &[DVec3]) -> Vec<anim_core::scene::Light> {
    positions
        .iter()
        .map(|&position| anim_core::scene::Light {
            name: "l".into(),
            position,
            intensity: Vec3::ONE,
            radius: 0.0,
            spot: None,
        })
        .collect()
}

/// A view from `camera` of a `width`×`height` image, as a render traces it (with more camera
/// rays than any scene has shapes, so that every lookup the plan allows is built).
fn viewpoint(camera: &Camera, (width, height): (u32, u32), motion: bool) -> Viewpoint {
    let rays = PinholeCamera::new(camera, width, height).unwrap();
    Viewpoint {
        view: rays.view(),
        size: (width, height),
        camera_rays: u64::MAX,
        motion,
    }
}

/// A view from `eye` (looking down −z; cells around the eye do not depend on where it looks).
fn viewpoint_at(eye: Vec3A, motion: bool) -> Viewpoint {
    let mut camera = Camera::default_with_fov("eye", 60.0);
    camera.eye = eye.as_dvec3();
    viewpoint(&camera, (64, 48), motion)
}

/// Test points from the one test generator.
trait Points {
    /// A point in the cube [0, `scale`)³.
    fn vec(&mut self, scale: f64) -> DVec3;
}

impl Points for SplitMix64 {
    fn vec(&mut self, scale: f64) -> DVec3 {
        DVec3::new(self.unit_f64(), self.unit_f64(), self.unit_f64()) * scale
    }
}

fn random_ray(rng: &mut SplitMix64, i: usize) -> Ray {
    let o = rng.vec(80.0) - DVec3::splat(15.0);
    let mut dir = (rng.vec(50.0) - o).normalize();
    if i.is_multiple_of(4) {
        // Axis-parallel: direction components of exactly zero.
        dir = DVec3::ZERO;
        dir[i / 4 % 3] = if rng.unit_f64() < 0.5 { 1.0 } else { -1.0 };
    }
    Ray::new(Vec3A::from(o.as_vec3()), Vec3A::from(dir.as_vec3()))
}

/// Every third ray is bounded, so that the `t_max` paths are exercised too.
fn t_limit_of(i: usize) -> f32 {
    if i.is_multiple_of(3) {
        40.0
    } else {
        f32::INFINITY
    }
}

/// The nearest hit by testing every primitive in order (the first of equal distances wins).
fn brute_closest(prims: &[Primitive], ray: &Ray, t_limit: f32) -> Option<(usize, f32)> {
    let mut best: Option<(usize, f32)> = None;
    for (k, p) in prims.iter().enumerate() {
        let t_max = best.map_or(t_limit, |(_, t)| t);
        if let Some(h) = p.hit(ray, t_max) {
            best = Some((k, h.t));
        }
    }
    best
}

/// Mostly world-space spheres (so leaves of four spheres, and leaves mixing spheres with other
/// kinds), with boxes, triangles, rotated and stretched shapes, an exact duplicate sphere (a
/// tie) and a plane. Instance `i` has material `i`, which names it after renumbering.
/// Each instance has its own transform slot, with the same index.
fn mixed_instances(rng: &mut SplitMix64, n: usize) -> (Vec<Instance>, Vec<Transform>) {
    let mut transforms = Vec::new();
    let mut push = |out: &mut Vec<Instance>, geometry: Geometry, transform: Transform| {
        let material = out.len();
        let mut instance = Instance::new(geometry, material);
        instance.transform = transforms.len() as u32;
        transforms.push(transform);
        out.push(instance);
    };
    let mut out = Vec::new();
    for i in 0..n {
        let c = rng.vec(50.0);
        let spin = |rng: &mut SplitMix64| {
            let turn = Transform::rotate(10.0 + rng.unit_f64() * 70.0, DVec3::Y).unwrap();
            Transform::translate(c).then_after(&turn.then_after(&Transform::translate(-c)))
        };
        match i % 10 {
            0 => push(
                &mut out,
                Geometry::Triangle {
                    vertices: [c, c + rng.vec(4.0), c + rng.vec(4.0)],
                },
                Transform::IDENTITY,
            ),
            1 => push(
                &mut out,
                Geometry::Box {
                    p1: c,
                    p2: c + rng.vec(3.0) + DVec3::splat(0.05),
                },
                spin(rng),
            ),
            2 => {
                let stretch = Transform::scale(DVec3::new(2.0, 0.5, 1.0)).unwrap();
                push(
                    &mut out,
                    Geometry::Sphere {
                        center: DVec3::ZERO,
                        radius: 0.5 + rng.unit_f64(),
                    },
                    Transform::translate(c).then_after(&stretch),
                )
            }
            _ => push(
                &mut out,
                Geometry::Sphere {
                    center: c,
                    radius: 0.2 + rng.unit_f64() * 2.0,
                },
                Transform::IDENTITY,
            ),
        }
    }
    let twin = out[3].geometry.clone();
    push(&mut out, twin, Transform::IDENTITY);
    push(
        &mut out,
        Geometry::Plane {
            point: DVec3::new(0.0, -5.0, 0.0),
            normal: DVec3::new(0.1, 1.0, 0.05),
        },
        Transform::IDENTITY,
    );
    (out, transforms)
}

/// World-space axis-aligned boxes (tested by distance alone, the surface built for the
/// winner): small ones, an exact duplicate (a tie), and rooms enclosing every ray origin,
/// so that rays start inside boxes and leave through them.
fn world_boxes(rng: &mut SplitMix64, n: usize) -> (Vec<Instance>, Vec<Transform>) {
    let mut geometry: Vec<Geometry> = (0..n)
        .map(|_| {
            let c = rng.vec(50.0);
            Geometry::Box {
                p1: c,
                p2: c + rng.vec(6.0),
            }
        })
        .collect();
    geometry.push(geometry[1].clone());
    for half in [300.0, 400.0] {
        geometry.push(Geometry::Box {
            p1: DVec3::splat(-half),
            p2: DVec3::new(half, half, half * 0.9),
        });
    }
    let instances = geometry
        .into_iter()
        .enumerate()
        .map(|(k, g)| Instance::new(g, k))
        .collect();
    (instances, vec![Transform::IDENTITY])
}

/// With `spheres_only`, the world-space spheres alone, renumbered.
fn instances_only(
    mut instances: Vec<Instance>,
    transforms: &[Transform],
    spheres_only: bool,
) -> Vec<Instance> {
    if spheres_only {
        instances.retain(|i| {
            matches!(i.geometry, Geometry::Sphere { .. })
                && transforms[i.transform as usize] == Transform::IDENTITY
        });
        for (k, i) in instances.iter_mut().enumerate() {
            i.material = k;
        }
    }
    instances
}

/// The render scene of a file's first job.
fn loaded_scene(text: &str) -> Scene {
    let loaded = anim_core::load::load_str(
        text,
        std::path::Path::new("scene.sdf"),
        // A small budget: the composites are then worth instancing.
        &anim_core::sdf::LoadOptions {
            max_memory: 1 << 20,
            ..anim_core::sdf::LoadOptions::default()
        },
    )
    .unwrap_or_else(|d| panic!("{d:?}"));
    loaded.jobs[0].scene.clone()
}
