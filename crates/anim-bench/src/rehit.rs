//! Self-intersections of spawned rays, counted exactly for the stress table.
//!
//! A ray spawned from a surface hit (`math::spawn_ray`: reflected, refracted, shadow, or any
//! other direction) *re-hits* when it meets the primitive it left in a way exact arithmetic
//! never allows. Every primitive is convex (spheres, boxes, capped cylinders and cones) or
//! flat (planes, triangles), so:
//! - leaving a flat primitive, the ray must not meet it again at all;
//! - leaving a closed primitive outwards (direction on the side of the outward normal), the
//!   ray must not meet it again at all;
//! - going into a closed primitive, its first meeting with it must be the exit through the far
//!   side (hit normal along the ray); a first meeting that *enters* the primitive means the
//!   origin was left on the outside, a hit at t ≈ 0 on the surface just left.
//!
//! Each spawned ray is tested against its own primitive alone (not the whole scene), so a
//! re-hit hidden behind a nearer object is counted too. The walk spawns what the renderer
//! spawns (a shadow ray to every light above the surface, the mirror direction, the refracted
//! direction of glass, recursively up to the depth limit, without the renderer's cut-off of
//! negligible rays) plus two directions drawn at random on each side of the surface, so that
//! rays leave at every angle, grazing ones included.

use anim_core::math::{reflect, Ray};
use anim_core::render::camera::PinholeCamera;
use anim_core::render::compile::{RayHint, RenderScene, Scratch, SurfaceHit};
use anim_core::render::integrator::fresnel;
use anim_core::scene::RenderJob;
use anim_core::shape::Shape;
use anim_core::util::SplitMix64;
use glam::Vec3A;
use rayon::prelude::*;
use std::cell::RefCell;

/// The kind of a primitive's shape (`None`: a packed world-space sphere), as an index of
/// `Shape::KINDS`; `None` for a kind that is not judged: one neither convex nor one flat
/// face (a mesh), which a ray leaving one of its faces may rightly meet again.
fn kind_index(shape: Option<&Shape>) -> Option<usize> {
    match shape {
        // A packed sphere: `Shape::KINDS` lists spheres first.
        None => Some(0),
        Some(s) if s.is_convex() || s.is_flat() => Some(s.kind_index()),
        Some(_) => None,
    }
}

/// Spawned rays and re-hits, per primitive kind (indices of `Shape::KINDS`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RehitCount {
    pub by_kind: [(u64, u64); Shape::KINDS.len()],
}

impl RehitCount {
    pub fn spawned(&self) -> u64 {
        self.by_kind.iter().map(|k| k.0).sum()
    }

    pub fn rehits(&self) -> u64 {
        self.by_kind.iter().map(|k| k.1).sum()
    }

    pub fn add(&mut self, o: &RehitCount) {
        for (a, b) in self.by_kind.iter_mut().zip(o.by_kind.iter()) {
            a.0 += b.0;
            a.1 += b.1;
        }
    }
}

/// Uniform on the hemisphere around unit `axis`, drawn from `rng`: each pixel has its own
/// fixed stream, so the count does not depend on the thread count.
fn hemisphere(rng: &mut SplitMix64, axis: Vec3A) -> Vec3A {
    let z = rng.unit_f32();
    let phi = std::f32::consts::TAU * rng.unit_f32();
    let s = (1.0 - z * z).max(0.0).sqrt();
    let (u, v) = axis.any_orthonormal_pair();
    (u * (s * phi.cos()) + v * (s * phi.sin()) + axis * z).normalize()
}

struct Walk<'a> {
    scene: &'a RenderScene,
    max_depth: u32,
    scratch: RefCell<Scratch>,
}

impl Walk<'_> {
    /// Spawns one ray from `hit` of primitive `prim` towards `dir`, as the renderer does
    /// (`SurfaceHit::spawn_ray`), and judges it.
    fn spawn(&self, prim: u32, hit: &SurfaceHit, dir: Vec3A, out: &mut RehitCount) {
        let shape = self.scene.aggregate().object_shape(prim);
        let Some(kind) = kind_index(shape) else {
            return;
        };
        let normal = hit.normal;
        let ray = hit.spawn_ray(dir);
        out.by_kind[kind].0 += 1;
        let mut scratch = self.scratch.borrow_mut();
        let again = self
            .scene
            .intersect_primitive(prim, &ray, f32::INFINITY, &mut scratch);
        let Some(again) = again else {
            return;
        };
        let outward = normal.dot(dir) >= 0.0;
        let flat = shape.is_some_and(Shape::is_flat);
        if flat || outward || again.normal.dot(dir) < 0.0 {
            out.by_kind[kind].1 += 1;
        }
    }

    fn trace(&self, ray: &Ray, depth: u32, rng: &mut SplitMix64, out: &mut RehitCount) {
        let hint = RayHint::Secondary;
        let Some((prim, hit)) =
            self.scene
                .intersect(ray, f32::INFINITY, hint, &mut self.scratch.borrow_mut())
        else {
            return;
        };
        if hit.normal == Vec3A::ZERO {
            return;
        }
        let scene = self.scene;
        let mat = scene.material(prim);
        let entering = hit.normal.dot(ray.dir) < 0.0;
        let n = if entering { hit.normal } else { -hit.normal };
        for light in &scene.shading().lights {
            let l = (light.position - hit.point).normalize_or_zero();
            if n.dot(l) > 0.0 {
                self.spawn(prim, &hit, l, out);
            }
        }
        for side in [1.0, -1.0] {
            let dir = hemisphere(rng, hit.normal * side);
            self.spawn(prim, &hit, dir, out);
        }
        let mirror = reflect(ray.dir, n);
        self.spawn(prim, &hit, mirror, out);
        let recurse = depth < self.max_depth;
        if mat.reflectivity > 0.0 && recurse {
            self.trace(&hit.spawn_ray(mirror), depth + 1, rng, out);
        }
        if mat.is_transparent() {
            let eta = if entering { 1.0 / mat.ior } else { mat.ior };
            let cos_i = -ray.dir.dot(n);
            let (f, cos_t) = fresnel(cos_i, eta);
            if f < 1.0 {
                let dir = (ray.dir * eta + n * (eta * cos_i - cos_t)).normalize();
                self.spawn(prim, &hit, dir, out);
                if recurse {
                    self.trace(&hit.spawn_ray(dir), depth + 1, rng, out);
                }
            }
        }
    }
}

/// Counts re-hits over one ray through each pixel centre of `job` at `width`×`height`.
/// `job` must already be camera-relative (eye at the origin), as the renderer makes it.
pub fn count(
    job: &RenderJob,
    width: u32,
    height: u32,
    max_depth: u32,
) -> Result<RehitCount, String> {
    let camera = PinholeCamera::new(&job.camera, width, height)
        .map_err(|e| format!("camera '{}': {e:?}", job.camera.name))?;
    let (scene, _) = RenderScene::compile(&job.scene, None);
    let rows: Vec<RehitCount> = (0..height)
        .into_par_iter()
        .map(|y| {
            let walk = Walk {
                scene: &scene,
                max_depth,
                scratch: RefCell::default(),
            };
            let mut out = RehitCount::default();
            for x in 0..width {
                let mut rng = SplitMix64::new(u64::from(y) << 32 | u64::from(x));
                let ray = camera.ray(x as f32 + 0.5, y as f32 + 0.5);
                walk.trace(&ray, 0, &mut rng, &mut out);
            }
            out
        })
        .collect();
    let mut total = RehitCount::default();
    for r in &rows {
        total.add(r);
    }
    Ok(total)
}

#[cfg(test)]
mod tests {
    use super::*;
    use anim_core::load::load_str;
    use anim_core::sdf::LoadOptions;
    use std::path::Path;

    fn job(text: &str) -> RenderJob {
        load_str(text, Path::new("t.sdf"), &LoadOptions::default())
            .unwrap()
            .jobs
            .remove(0)
    }

    #[test]
    fn spawned_rays_are_counted_and_a_sphere_does_not_rehit() {
        let j = job("define material m 0.2 0.2 0.2 0.6 0.6 0.6 0.2 0.2 0.2 10\n\
            define shape sphere s 0 0 -5 2 m\n\
            define light l 3 3 0 1 1 1\n\
            define camera c 40\n\
            render c x.png 16 16\n");
        let c = count(&j, 16, 16, 1).unwrap();
        // Every pixel sees the sphere: three rays each at least (two random, the mirror).
        assert!(c.by_kind[0].0 >= 3 * 256, "{c:?}");
        assert_eq!(c.rehits(), 0);
    }

    #[test]
    fn a_ray_left_on_the_surface_is_a_rehit() {
        // Without an offset a ray leaving outward from an exact-looking surface point of a
        // sphere may or may not meet it; from a point inside it surely does: what the judge
        // must call a re-hit.
        let j = job("define material m 0.2 0.2 0.2 0.6 0.6 0.6 0.2 0.2 0.2 10\n\
            define shape sphere s 0 0 -5 2 m\n\
            define camera c 40\n\
            render c x.png 4 4\n");
        let (scene, _) = RenderScene::compile(&j.scene, None);
        let walk = Walk {
            scene: &scene,
            max_depth: 0,
            scratch: RefCell::default(),
        };
        let mut out = RehitCount::default();
        // A "surface point" 1 % inside, claimed to leave outwards.
        let p = Vec3A::new(0.0, 0.0, -3.02);
        walk.spawn(
            0,
            &SurfaceHit::on_face(1.0, p, Vec3A::Z),
            Vec3A::Z,
            &mut out,
        );
        assert_eq!(out.by_kind[0], (1, 1));
    }
}
