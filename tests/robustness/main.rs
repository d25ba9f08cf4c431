//! Numerical robustness of every primitive, tested through the same `Primitive` the renderer
//! uses (world transforms, baking, object-space matrices and all):
//!
//! - re-intersection: rays spawned with `SurfaceHit::spawn_ray` from surface points never hit the surface
//!   they leave (10⁶ rays per primitive kind, scales 1e-4 … 1e5, random transforms);
//! - contact: the spawn offset is small enough that a sphere resting on a plane or a box still
//!   shadows the surface right next to the contact point;
//! - watertightness: rays through the shared edges and vertices of closed triangle meshes,
//!   and through the cone's apex and the quadrics' rims, never slip through;
//! - accuracy: cone and cylinder hit points lie on the surface to 1e-5 (relative) against f64,
//!   including rays along the axis and along a cone generator;
//! - no primitive ever returns a NaN or infinite t, point or normal (proptest).
//!
//! Randomness is the seeded `SplitMix64` of `anim_core::util`, so every failure message (kind, seed, object, ray)
//! reproduces exactly.

use anim_core::math::{Ray, Transform};
use anim_core::render::geometry::{Primitive, SurfaceHit};
use anim_core::scene::Geometry;
use anim_core::util::SplitMix64;
use glam::{DVec3, Vec3A};
use proptest::prelude::*;
use std::collections::HashMap;
use std::f64::consts::{PI, TAU};
use std::sync::OnceLock;
use std::time::Instant;

mod accuracy;
mod contact;
mod finite;
mod lift;
mod reintersection;
mod watertight;

// ------------------------------------------------------------------------------------------
// Deterministic randomness and helpers
// ------------------------------------------------------------------------------------------

/// The draws these tests make, from the one test generator (SplitMix64, so a failure message
/// that names its seed reproduces exactly).
trait Draws {
    /// Log-uniform in [`lo`, `hi`).
    fn log_uniform(&mut self, lo: f64, hi: f64) -> f64;
    /// Uniform on the unit sphere.
    fn direction(&mut self) -> DVec3;
    /// Uniform in the unit ball.
    fn in_ball(&mut self) -> DVec3;
    /// A direction in the hemisphere around unit `axis`. Mostly uniform, but one in five is
    /// grazing (cos θ log-uniform in 1e-6 … 0.1), where offsets are most likely to fail.
    fn hemisphere(&mut self, axis: DVec3) -> DVec3;
}

impl Draws for SplitMix64 {
    fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + (hi.ln() - lo.ln()) * self.unit_f64()).exp()
    }

    fn direction(&mut self) -> DVec3 {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, TAU);
        let s = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(s * phi.cos(), s * phi.sin(), z)
    }

    fn in_ball(&mut self) -> DVec3 {
        self.direction() * self.unit_f64().cbrt()
    }

    fn hemisphere(&mut self, axis: DVec3) -> DVec3 {
        let cos = if self.below(5) == 0 {
            self.log_uniform(1e-6, 0.1)
        } else {
            self.unit_f64()
        };
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let phi = self.range(0.0, TAU);
        let (u, v) = axis.any_orthonormal_pair();
        axis * cos + (u * phi.cos() + v * phi.sin()) * sin
    }
}

/// Seeds are fixed, so a failure reproduces. For soak runs, `ROBUSTNESS_SOAK=<n>` mixes `n`
/// into every seed (different rays, equally reproducible with the same `n`).
fn soak() -> u64 {
    std::env::var("ROBUSTNESS_SOAK")
        .ok()
        .and_then(|v| v.parse::<u64>().ok())
        .map_or(0, |n| n.wrapping_mul(0x9E37_79B9_7F4A_7C15))
}

fn v32(v: DVec3) -> Vec3A {
    v.as_vec3().into()
}

fn world_ray(o: DVec3, d: DVec3) -> Ray {
    Ray::new(v32(o), v32(d))
}

// ------------------------------------------------------------------------------------------
// Random objects and placements
// ------------------------------------------------------------------------------------------

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Sphere,
    Box,
    Plane,
    Triangle,
    Cylinder,
    Cone,
}

impl Kind {
    /// Every kind of primitive a scene statement writes with numbers (meshes, read from
    /// files, have their own tests); `every_kind_of_primitive_is_generated` holds it to the
    /// renderer's list, so a new primitive cannot miss these tests.
    const ALL: [Kind; 6] = [
        Kind::Sphere,
        Kind::Box,
        Kind::Plane,
        Kind::Triangle,
        Kind::Cylinder,
        Kind::Cone,
    ];

    fn is_closed(self) -> bool {
        !matches!(self, Kind::Plane | Kind::Triangle)
    }
}

/// An object-space geometry of size about 1, with what the tests need to aim at it.
#[derive(Clone, Debug)]
struct Object {
    kind: Kind,
    geometry: Geometry,
    /// Thinnest object-space dimension (for closed shapes).
    min_dim: f64,
}

fn random_object(kind: Kind, rng: &mut SplitMix64) -> Object {
    // Axis length and radius for cylinders and cones: slender to flat (ratio 1:20 … 5:1).
    let axis = |rng: &mut SplitMix64| {
        let len = rng.range(0.5, 2.0);
        let radius = len * rng.log_uniform(0.05, 5.0) * 0.5;
        let from = rng.in_ball() * 0.3;
        (
            from,
            from + rng.direction() * len,
            radius,
            len.min(2.0 * radius),
        )
    };
    let (geometry, min_dim) = match kind {
        Kind::Sphere => {
            let radius = rng.range(0.5, 1.5);
            (
                Geometry::Sphere {
                    center: rng.in_ball() * 0.5,
                    radius,
                },
                2.0 * radius,
            )
        }
        Kind::Box => {
            let p1 = -DVec3::new(
                rng.range(0.5, 1.5),
                rng.range(0.5, 1.5),
                rng.range(0.5, 1.5),
            );
            let p2 = DVec3::new(
                rng.range(0.5, 1.5),
                rng.range(0.5, 1.5),
                rng.range(0.5, 1.5),
            );
            (Geometry::Box { p1, p2 }, (p2 - p1).min_element())
        }
        Kind::Plane => (
            Geometry::Plane {
                point: rng.in_ball(),
                normal: rng.direction(),
            },
            1.0,
        ),
        Kind::Triangle => (
            Geometry::Triangle {
                vertices: [
                    rng.in_ball() * 1.5,
                    rng.in_ball() * 1.5,
                    rng.in_ball() * 1.5,
                ],
            },
            1.0,
        ),
        Kind::Cylinder => {
            let (p1, p2, radius, min_dim) = axis(rng);
            (Geometry::Cylinder { p1, p2, radius }, min_dim)
        }
        Kind::Cone => {
            let (base, tip, radius, min_dim) = axis(rng);
            (Geometry::Cone { base, tip, radius }, min_dim)
        }
    };
    Object {
        kind,
        geometry,
        min_dim,
    }
}

/// A point strictly inside a closed object (object space).
fn interior_point(obj: &Object, rng: &mut SplitMix64) -> DVec3 {
    match obj.geometry {
        Geometry::Sphere { center, radius } => center + rng.in_ball() * (0.8 * radius),
        Geometry::Box { p1, p2 } => {
            let c = (p1 + p2) * 0.5;
            let half = (p2 - p1).abs() * 0.5;
            c + half
                * DVec3::new(
                    rng.range(-0.9, 0.9),
                    rng.range(-0.9, 0.9),
                    rng.range(-0.9, 0.9),
                )
        }
        Geometry::Cylinder { p1, p2, radius } => {
            let w = (p2 - p1).normalize();
            let (u, v) = w.any_orthonormal_pair();
            let disc = rng.in_ball().truncate() * (0.9 * radius);
            p1 + (p2 - p1) * rng.range(0.05, 0.95) + u * disc.x + v * disc.y
        }
        Geometry::Cone { base, tip, radius } => {
            // Up to half way to the tip the radius is at least r/2.
            let w = (tip - base).normalize();
            let (u, v) = w.any_orthonormal_pair();
            let disc = rng.in_ball().truncate() * (0.45 * radius);
            base + (tip - base) * rng.range(0.05, 0.5) + u * disc.x + v * disc.y
        }
        Geometry::Plane { .. } | Geometry::Triangle { .. } | Geometry::Mesh(_) => {
            unreachable!("not closed (or not made here)")
        }
    }
}

/// Object-space centre (for aiming from outside).
fn centre(obj: &Object) -> DVec3 {
    match obj.geometry {
        Geometry::Sphere { center, .. } => center,
        Geometry::Box { p1, p2 } => (p1 + p2) * 0.5,
        Geometry::Plane { point, .. } => point,
        Geometry::Triangle {
            vertices: [a, b, c],
        } => (a + b + c) / 3.0,
        Geometry::Cylinder { p1, p2, .. } => (p1 + p2) * 0.5,
        Geometry::Cone { base, tip, .. } => (base + tip) * 0.5,
        Geometry::Mesh(_) => unreachable!("the generated scenes hold no meshes"),
    }
}

#[derive(Clone, Debug)]
struct Placement {
    xf: Transform,
    /// Which of the four kinds of transform (see `random_placement`).
    mode: usize,
    /// Smallest per-axis scale factor (world units per object unit, at worst).
    s_min: f64,
}

/// `translate · rotate · scale`, in one of four modes so that every code path of
/// `Primitive::new` is exercised: (0) uniform scale, no rotation: everything baked; (1)
/// uniform scale and rotation: quadrics baked, box keeps its matrix; (2) non-uniform scale and
/// rotation: every closed shape keeps its matrix; (3) non-uniform scale, no rotation: box
/// baked, quadrics keep their matrix. Planes and triangles are always baked.
fn random_placement(
    rng: &mut SplitMix64,
    scale: f64,
    max_anisotropy: f64,
    max_shift: f64,
) -> Placement {
    let mode = rng.below(4);
    let factors = if mode < 2 {
        DVec3::ONE
    } else {
        let mut f = || rng.log_uniform(1.0 / max_anisotropy, max_anisotropy);
        DVec3::new(f(), f(), f())
    };
    let rotation = if mode == 1 || mode == 2 {
        Transform::rotate(rng.range(-180.0, 180.0), rng.direction()).unwrap()
    } else {
        Transform::IDENTITY
    };
    let shift = rng.direction() * rng.log_uniform(0.01, max_shift) * scale;
    let xf = Transform::translate(shift)
        .then_after(&rotation)
        .then_after(&Transform::scale(factors * scale).unwrap());
    Placement {
        xf,
        mode,
        s_min: scale * factors.min_element(),
    }
}

fn to_object(xf: &Transform, ray: &Ray) -> (DVec3, DVec3) {
    (
        xf.object_from_world.transform_point3(ray.origin.as_dvec3()),
        xf.object_from_world.transform_vector3(ray.dir.as_dvec3()),
    )
}

// ------------------------------------------------------------------------------------------
// f64 reference intersections (object space), in textbook formulations independent of the
// frame-based ones the primitives use.
// ------------------------------------------------------------------------------------------

/// Real roots of a·t² + b·t + c = 0 (stable form; linear when a = 0).
fn roots(a: f64, b: f64, c: f64) -> [Option<f64>; 2] {
    if a == 0.0 {
        return [(b != 0.0).then(|| -c / b), None];
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return [None, None];
    }
    let q = -0.5 * (b + disc.sqrt().copysign(b));
    if q == 0.0 {
        return [Some(0.0), None];
    }
    [Some(q / a), Some(c / q)]
}

/// First crossing with t > 0 of the closed object-space shape: (t, outward normal).
fn reference_hit(g: &Geometry, o: DVec3, d: DVec3) -> Option<(f64, DVec3)> {
    let mut best: Option<(f64, DVec3)> = None;
    let mut offer = |t: f64, n: DVec3| {
        if t > 0.0 && best.is_none_or(|(b, _)| t < b) {
            best = Some((t, n));
        }
    };
    match *g {
        Geometry::Sphere { center, radius } => {
            let oc = o - center;
            for t in roots(d.dot(d), 2.0 * oc.dot(d), oc.dot(oc) - radius * radius)
                .into_iter()
                .flatten()
            {
                offer(t, (oc + d * t) / radius);
            }
        }
        Geometry::Box { p1, p2 } => {
            let (lo, hi) = (p1.min(p2), p1.max(p2));
            let (mut enter, mut exit) = ((f64::NEG_INFINITY, 0), (f64::INFINITY, 0));
            for i in 0..3 {
                if d[i] == 0.0 {
                    if o[i] < lo[i] || o[i] > hi[i] {
                        return None;
                    }
                    continue;
                }
                let (t0, t1) = ((lo[i] - o[i]) / d[i], (hi[i] - o[i]) / d[i]);
                if t0.min(t1) > enter.0 {
                    enter = (t0.min(t1), i);
                }
                if t0.max(t1) < exit.0 {
                    exit = (t0.max(t1), i);
                }
            }
            if enter.0 <= exit.0 {
                let mut n = DVec3::ZERO;
                n[enter.1] = -d[enter.1].signum();
                offer(enter.0, n);
                let mut n = DVec3::ZERO;
                n[exit.1] = d[exit.1].signum();
                offer(exit.0, n);
            }
        }
        Geometry::Cylinder { p1, p2, radius } => {
            cylinder_crossings(p1, p2, radius, o, d, &mut offer)
        }
        Geometry::Cone { base, tip, radius } => cone_crossings(base, tip, radius, o, d, &mut offer),
        Geometry::Plane { .. } | Geometry::Triangle { .. } | Geometry::Mesh(_) => {
            unreachable!("not closed (or not made here)")
        }
    }
    best
}

/// Offers each crossing of the ray `o + t·d` with the closed cylinder of `radius` about
/// `p1 → p2` to `offer`: (t, outward normal).
fn cylinder_crossings(
    p1: DVec3,
    p2: DVec3,
    radius: f64,
    o: DVec3,
    d: DVec3,
    offer: &mut impl FnMut(f64, DVec3),
) {
    let h = (p2 - p1).length();
    let w = (p2 - p1) / h;
    let oc = o - p1;
    let (oz, dz) = (oc.dot(w), d.dot(w));
    let a = d.dot(d) - dz * dz;
    let b = 2.0 * (oc.dot(d) - oz * dz);
    let c = oc.dot(oc) - oz * oz - radius * radius;
    if a > 0.0 {
        for t in roots(a, b, c).into_iter().flatten() {
            let z = oz + t * dz;
            if (0.0..=h).contains(&z) {
                let q = oc + d * t;
                offer(t, (q - w * z).normalize());
            }
        }
    }
    if dz != 0.0 {
        for (zc, n) in [(0.0, -w), (h, w)] {
            let t = (zc - oz) / dz;
            let q = oc + d * t;
            if q.dot(q) - zc * zc <= radius * radius {
                offer(t, n);
            }
        }
    }
}

/// Offers each crossing of the ray `o + t·d` with the closed cone of `radius` at `base` and
/// apex `tip` to `offer`: (t, outward normal).
fn cone_crossings(
    base: DVec3,
    tip: DVec3,
    radius: f64,
    o: DVec3,
    d: DVec3,
    offer: &mut impl FnMut(f64, DVec3),
) {
    // With P = o − tip: on the side, |P|² = (1 + k²)·z², z = P·w, 0 ≤ z ≤ h.
    let h = (base - tip).length();
    let w = (base - tip) / h;
    let k = radius / h;
    let m = 1.0 + k * k;
    let oc = o - tip;
    let (oz, dz) = (oc.dot(w), d.dot(w));
    let a = d.dot(d) - m * dz * dz;
    let b = 2.0 * (oc.dot(d) - m * oz * dz);
    let c = oc.dot(oc) - m * oz * oz;
    for t in roots(a, b, c).into_iter().flatten() {
        let q = oc + d * t;
        let z = q.dot(w);
        if (0.0..=h).contains(&z) {
            // Gradient of |P|² − m z²: 2P − 2m z w.
            offer(t, (q - w * (m * z)).normalize_or_zero());
        }
    }
    if dz != 0.0 {
        let t = (h - oz) / dz;
        let q = oc + d * t;
        if q.dot(q) - h * h <= radius * radius {
            offer(t, w);
        }
    }
}

// ------------------------------------------------------------------------------------------
// Spawning rays and judging them (re-intersection, watertightness)
// ------------------------------------------------------------------------------------------

/// An inward ray is held to "hit the far side" when the exact exit is farther than this
/// fraction of the object's thinnest world dimension. Closer exits (grazing rays, points next
/// to an edge or rim) are legitimate and make no claim either way.
const FAR_SIDE: f64 = 1e-3;

#[derive(Debug, Default)]
struct Stats {
    rays: u64,
    outward: u64,
    inward_checked: u64,
    /// Inward rays whose far side lies within the lift (see `spawn_and_check`): no claim.
    within_lift: u64,
    failures: u64,
    messages: Vec<String>,
    /// Smallest (reported t) / (exact exit t) over checked inward rays.
    min_exit_ratio: f64,
    /// Largest |reported t − exact exit t| / size over checked inward rays whose exit is not
    /// grazing (|cos| > 0.1 against the exit normal); grazing exits are ill-conditioned.
    max_exit_error: f64,
    /// The same over all checked inward rays, grazing exits included.
    max_exit_error_grazing: f64,
}

impl Stats {
    fn fail(&mut self, msg: String) {
        self.failures += 1;
        if self.messages.len() < 8 {
            self.messages.push(msg);
        }
    }
}

/// A ray from somewhere towards the object, so that its hit is a surface point on any part.
fn aim(obj: &Object, xf: &Transform, rng: &mut SplitMix64) -> Ray {
    let (o, target) = match (&obj.geometry, obj.kind.is_closed()) {
        (_, true) => {
            if rng.below(2) == 0 {
                // From outside through the interior: entry points.
                let c = centre(obj);
                (c + rng.direction() * 6.0, interior_point(obj, rng))
            } else {
                // From inside: exit points (the far root of the quadrics).
                let p = interior_point(obj, rng);
                (p, p + rng.direction())
            }
        }
        (Geometry::Plane { point, normal }, false) => {
            let (u, v) = normal.normalize().any_orthonormal_pair();
            let t = *point + u * rng.range(-2.0, 2.0) + v * rng.range(-2.0, 2.0);
            (t + rng.direction() * rng.range(0.5, 4.0), t)
        }
        (
            Geometry::Triangle {
                vertices: [a, b, c],
            },
            false,
        ) => {
            let (mut s, mut t) = (rng.unit_f64(), rng.unit_f64());
            if s + t > 1.0 {
                (s, t) = (1.0 - s, 1.0 - t);
            }
            let target = *a + (*b - *a) * s + (*c - *a) * t;
            (target + rng.direction() * rng.range(0.5, 4.0), target)
        }
        _ => unreachable!(),
    };
    let (wo, wt) = (xf.point(o), xf.point(target));
    world_ray(wo, (wt - wo).normalize())
}

/// A placed primitive under test, with what the checks need to judge it.
struct Target<'a> {
    prim: &'a Primitive,
    obj: &'a Object,
    xf: &'a Transform,
    /// The object's thinnest world dimension.
    size: f64,
}

/// Spawns one ray from `hit` towards `dir`, with the offset `SurfaceHit::spawn_origin` applies
/// scaled by `offset_factor` (1 = the renderer's own `SurfaceHit::spawn_ray`), and records in `stats` whether it
/// behaves: leaving a planar shape, or a closed (convex) one outwards, it must hit nothing;
/// going into a closed shape it must reach the far side, judged against the exact f64 exit.
fn spawn_and_check(
    target: &Target,
    hit: &SurfaceHit,
    dir: Vec3A,
    offset_factor: f32,
    stats: &mut Stats,
    what: &dyn Fn() -> String,
) {
    let (p, n) = (hit.point, hit.normal);
    let ray = if offset_factor == 1.0 {
        hit.spawn_ray(dir)
    } else {
        Ray::new(p + (hit.spawn_origin(dir) - p) * offset_factor, dir)
    };
    stats.rays += 1;
    let again = target.prim.intersect(&ray, f32::INFINITY);
    let context = || {
        format!(
            "{}: p {p:?} n {n:?} dir {dir:?} origin {:?}",
            what(),
            ray.origin
        )
    };
    // The same classification `spawn_origin` makes.
    if !target.obj.kind.is_closed() || n.dot(dir) >= 0.0 {
        stats.outward += 1;
        if let Some(h) = again {
            stats.fail(format!(
                "{}: re-hit at t = {:e} ({:.2e} of the size)",
                context(),
                h.t,
                h.t as f64 / target.size
            ));
        }
        return;
    }
    let (o, d) = to_object(target.xf, &ray);
    let Some((t_ref, n_ref)) = reference_hit(&target.obj.geometry, o, d) else {
        return;
    };
    if t_ref <= FAR_SIDE * target.size {
        return;
    }
    // Nor when the far side passes closer to the spawned origin, measured across it, than the
    // origin was lifted off the hit: the lift is the hit's error bound, so a wall that thin
    // (next to a slender cone's apex) lies within it, on either side as far as f32 can tell.
    let n_world = target
        .xf
        .object_from_world
        .transpose()
        .transform_vector3(n_ref)
        .normalize();
    let across = t_ref * ray.dir.as_dvec3().normalize().dot(n_world).abs();
    if across <= (ray.origin - p).as_dvec3().length() {
        stats.within_lift += 1;
        return;
    }
    stats.inward_checked += 1;
    match again {
        None => stats.fail(format!(
            "{}: escaped; the exit is at t = {t_ref:e}",
            context()
        )),
        Some(h) if (h.t as f64) < 0.5 * t_ref => stats.fail(format!(
            "{}: re-hit at t = {:e}; the far side is at t = {t_ref:e}",
            context(),
            h.t
        )),
        Some(h) => {
            let err = (h.t as f64 - t_ref).abs() / target.size;
            stats.min_exit_ratio = stats.min_exit_ratio.min(h.t as f64 / t_ref);
            stats.max_exit_error_grazing = stats.max_exit_error_grazing.max(err);
            if n_ref.dot(d).abs() > 0.1 * n_ref.length() * d.length() {
                stats.max_exit_error = stats.max_exit_error.max(err);
            }
        }
    }
}

#[test]
fn every_kind_of_primitive_is_generated() {
    let generated: Vec<String> = Kind::ALL
        .iter()
        .map(|k| format!("{k:?}").to_lowercase())
        .collect();
    let drawn: Vec<&str> = anim_core::shape::Shape::KINDS
        .into_iter()
        .filter(|k| *k != "mesh")
        .collect();
    assert_eq!(
        generated, drawn,
        "a primitive the renderer draws has no generator in these tests (Kind, random_object, \
         interior_point, centre, reference_hit)"
    );
}
