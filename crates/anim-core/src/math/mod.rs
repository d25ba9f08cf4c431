//! Rays, bounding boxes, transforms, the one place where secondary rays are offset, and the
//! maps sampled integrals draw their points with (`sampling`).

pub(crate) mod aabb;
pub mod motion;
pub mod sampling;
mod transform;

pub use aabb::{Aabb, SLAB_WIDEN};
pub use transform::Transform;

use glam::Vec3A;

/// A ray `origin + t·dir`. `dir` is not necessarily unit length: rays moved into object space
/// keep the world-space parameter `t`, so hits from differently transformed shapes compare.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Where the ray starts: in world space, or in a shape's object space once moved there.
    pub origin: Vec3A,
    /// The direction of travel: `t` counts multiples of it.
    pub dir: Vec3A,
    /// The instant of the exposure the ray belongs to (0 at shutter open, 1 at close): its
    /// camera sample's, inherited by every ray spawned from it. Only moving things read it.
    pub time: f32,
}

impl Ray {
    /// A ray at the middle of the exposure, the instant a frame's statements describe.
    pub fn new(origin: Vec3A, dir: Vec3A) -> Self {
        Ray {
            origin,
            dir,
            time: 0.5,
        }
    }

    /// The same ray at instant `time` of the exposure.
    #[inline]
    pub fn at_time(self, time: f32) -> Self {
        Ray { time, ..self }
    }

    /// The point at parameter `t` along the ray.
    pub fn at(&self, t: f32) -> Vec3A {
        self.origin + self.dir * t
    }
}

/// Relative size of the offset that lifts a spawned ray's origin off the surface it leaves.
/// Intersection arithmetic in f32 leaves a hit point within a few ulps of the true surface *in
/// every coordinate*, so the error scales with the largest coordinate magnitude of the point
/// (Wächter & Binder, "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing
/// Gems ch. 6). Transformed shapes add the error of the matrix product, hence the margin.
///
/// Measured, not guessed (tests/robustness/; `offset_margin_sweep` spawns 2·10⁵ rays per
/// shape kind with this offset scaled by 2⁻ᵏ, scales 1e-4…1e5, anisotropy ≤ 4, translations up
/// to 30× the object size): the first self-intersections appear at 1/8 of this offset for
/// spheres (so a 4× margin, the tightest), 1/16 for cylinders, 1/32 for boxes, planes and
/// cones, 1/64 for triangles; at full size 6·10⁶ rays (10⁶ per kind) re-hit nothing. In the
/// other direction, a sphere resting on a plane or box lies ≥ 5.3× this offset above the
/// surface 2 % of its radius from the contact point (`contact_shadows_reach_the_resting_sphere`),
/// so contact shadows stay closed. Hence left as it is.
const ORIGIN_ERROR_SCALE: f32 = 1.0 / 4096.0 * (1.0 / 32.0);
/// Floor for points at the origin itself, where a relative bound would be exactly zero.
/// Rendering is camera-relative (the eye at the origin), so `|p|` is about the distance from
/// the eye and the relative bound is right for every visible point; a fixed floor of any
/// size in world units would break scale invariance (`anim bench --stress`): the earlier
/// 2⁻²⁶ outweighed the relative bound in a scene scaled by 1e-4, so contact shadows and
/// acute cone rims saw an offset 3× too long (99.88 % of pixels within 1 LSB, and re-hits at
/// the rims of non-uniformly scaled cones). 2⁻¹⁰⁰ stays far above f32's smallest normal
/// number and below any coordinate a scene can hold.
const ORIGIN_ERROR_FLOOR: f32 = 7.888_609e-31;

/// Origin for a ray leaving surface point `p` with geometric normal `n` in direction `dir`:
/// pushed to the side of the surface that `dir` points into. The only place in the renderer
/// where ray origins are offset.
#[inline]
pub fn spawn_origin(p: Vec3A, n: Vec3A, dir: Vec3A) -> Vec3A {
    let offset = relative_offset(p);
    let side = if n.dot(dir) >= 0.0 { 1.0 } else { -1.0 };
    p + n * (offset * side)
}

/// A ray from surface point `p` (geometric normal `n`) towards `dir`, offset off the surface.
#[inline]
pub fn spawn_ray(p: Vec3A, n: Vec3A, dir: Vec3A) -> Ray {
    Ray::new(spawn_origin(p, n, dir), dir)
}

/// The spawn offset `spawn_origin` applies at `p`: the relative bound, before any per-hit
/// bound raises it.
#[inline]
pub fn relative_offset(p: Vec3A) -> f32 {
    ORIGIN_ERROR_FLOOR + p.abs().max_element() * ORIGIN_ERROR_SCALE
}

/// `spawn_origin` for a hit that carries its own error bound (`crate::render::primitive`'s
/// `SurfaceHit`). The side is chosen by the reported normal `n`, as `spawn_origin` does.
/// Outwards (`n · dir ≥ 0`) the origin moves along `n`: the half-space `n` bounds holds the
/// solid (on an edge too: `n` is then in the edge's cone of normals), so a ray leaving it
/// never comes back, and only the distance matters. Inwards it moves along `−lift.inward`,
/// a unit direction into *every* face meeting at or passing near `p`, so that the ray starts
/// inside whichever face it leaves by. Each way by at least the hit's own bound on how far
/// its point and the next ray's view of it can be from the true surface, over the fraction
/// of the move the most oblique face sees (see `Lift`).
#[inline]
pub fn spawn_origin_lifted(p: Vec3A, n: Vec3A, lift: Lift, dir: Vec3A) -> Vec3A {
    let rel = relative_offset(p);
    if n.dot(dir) >= 0.0 {
        p + n * rel.max(lift.outward_min)
    } else {
        p - lift.inward * rel.max(lift.inward_min)
    }
}

/// How spawned origins leave a surface point (see `spawn_origin_lifted`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lift {
    /// Least offset along the normal for rays leaving outwards, in world units: the point's
    /// error bound. 0 when the relative bound alone is enough.
    pub outward_min: f32,
    /// Unit direction (into the surface along its opposite) for rays leaving inwards: the
    /// normal on a face, the bisector of the faces' normals on an edge.
    pub inward: Vec3A,
    /// Least offset along it: the error bound over the fraction of the move that the most
    /// oblique face sees (1 on a face, cos(θ/2) on an edge whose face normals are θ apart).
    pub inward_min: f32,
}

impl Lift {
    /// Along the normal both ways, with the relative bound: a hit on one face computed in
    /// world space.
    #[inline]
    pub fn normal(n: Vec3A) -> Lift {
        Lift {
            outward_min: 0.0,
            inward: n,
            inward_min: 0.0,
        }
    }
}

/// f32 unit round-off, 2⁻²⁴.
pub const UNIT_ROUNDOFF: f32 = f32::EPSILON * 0.5;

/// Each coordinate of `v` across the four lanes of a vector, as four-at-a-time tests take a
/// ray. Written out: an array `map` here is left as a call in the hottest loops.
#[inline(always)]
pub fn splat3(v: Vec3A) -> [glam::Vec4; 3] {
    [
        glam::Vec4::splat(v.x),
        glam::Vec4::splat(v.y),
        glam::Vec4::splat(v.z),
    ]
}

/// Higham's γₙ = n·u / (1 − n·u): the relative error bound of n chained f32 operations (a
/// sum of n terms, a dot product of length n), taken against the sum of the terms' absolute
/// values (Higham, "Accuracy and Stability of Numerical Algorithms", §3.1; pbrt-v4 §6.8).
#[inline]
pub fn gamma(n: u32) -> f32 {
    let nu = n as f32 * UNIT_ROUNDOFF;
    nu / (1.0 - nu)
}

/// Mirror `d` about the plane with unit normal `n`.
#[inline]
pub fn reflect(d: Vec3A, n: Vec3A) -> Vec3A {
    d - n * (2.0 * d.dot(n))
}

/// Solves `a·t² + b·t + c = 0` in f64 without catastrophic cancellation; roots ascending.
/// Returns `None` when there is no real root. `a` must not be zero.
#[inline]
pub fn solve_quadratic(a: f64, b: f64, c: f64) -> Option<(f64, f64)> {
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 || !disc.is_finite() {
        return None;
    }
    let q = -0.5 * (b + disc.sqrt().copysign(b));
    let (t0, t1) = if q == 0.0 {
        // b = 0 and c = 0: a double root at 0.
        (0.0, 0.0)
    } else {
        (q / a, c / q)
    };
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadratic_is_stable_when_b_dominates() {
        // Roots 1e-8 and 1e8: the naive formula loses the small root entirely in f64.
        let (t0, t1) = solve_quadratic(1.0, -(1e8 + 1e-8), 1.0).unwrap();
        assert!((t0 - 1e-8).abs() / 1e-8 < 1e-12, "{t0}");
        assert!((t1 - 1e8).abs() / 1e8 < 1e-12, "{t1}");
    }

    #[test]
    fn quadratic_without_real_roots() {
        assert!(solve_quadratic(1.0, 0.0, 1.0).is_none());
    }

    #[test]
    fn spawn_origin_moves_to_the_side_of_the_direction() {
        let p = Vec3A::new(1000.0, 0.0, 0.0);
        let n = Vec3A::X;
        assert!(spawn_origin(p, n, Vec3A::X).x > 1000.0);
        assert!(spawn_origin(p, n, -Vec3A::X).x < 1000.0);
    }

    #[test]
    fn lifted_origin_matches_the_plain_one_on_a_face() {
        let p = Vec3A::new(3.0, -2.0, 7.5);
        let n = Vec3A::new(0.6, 0.0, 0.8);
        for dir in [n, -n, Vec3A::X, -Vec3A::Z] {
            assert_eq!(
                spawn_origin_lifted(p, n, Lift::normal(n), dir),
                spawn_origin(p, n, dir)
            );
        }
    }

    #[test]
    fn lifted_origin_moves_along_the_normal_out_and_the_lift_in() {
        let p = Vec3A::new(1.0, 1.0, 0.0);
        let n = Vec3A::X;
        let lift = Lift {
            outward_min: 2e-3,
            inward: Vec3A::new(1.0, 1.0, 0.0).normalize(),
            inward_min: 1e-3,
        };
        // The side follows the reported normal; outwards the move follows it too, inwards
        // the lift.
        let out = spawn_origin_lifted(p, n, lift, Vec3A::new(0.1, -5.0, 0.0));
        let inward = spawn_origin_lifted(p, n, lift, Vec3A::new(-0.1, 5.0, 0.0));
        assert!(((out - p).length() - 2e-3).abs() < 1e-6, "{out:?}");
        assert!((out - p).normalize().dot(n) > 0.999_999);
        assert!(((inward - p).length() - 1e-3).abs() < 1e-6, "{inward:?}");
        assert!((inward - p).normalize().dot(lift.inward) < -0.999_999);
        // Bounds below the relative one change nothing.
        let small = Lift {
            outward_min: relative_offset(p) * 0.5,
            inward: n,
            inward_min: relative_offset(p) * 0.5,
        };
        for dir in [n, -n] {
            assert_eq!(
                spawn_origin_lifted(p, n, small, dir),
                spawn_origin(p, n, dir)
            );
        }
    }

    #[test]
    fn gamma_bounds_chained_rounding() {
        assert_eq!(gamma(0), 0.0);
        assert!(gamma(1) > UNIT_ROUNDOFF && gamma(1) < 1.000_001 * UNIT_ROUNDOFF);
        // The sum of 4 terms in f32 against the exact sum, at its worst over many draws.
        let mut worst = 0.0f64;
        let mut rng = crate::util::SplitMix64::new(0x1234_5678);
        for _ in 0..10_000 {
            let mut next = || (rng.unit_f32() - 0.5) * 1e3;
            let t = [next(), next(), next(), next()];
            let sum32 = ((t[0] + t[1]) + t[2]) + t[3];
            let exact: f64 = t.iter().map(|&v| v as f64).sum();
            let abs: f64 = t.iter().map(|&v| (v as f64).abs()).sum();
            worst = worst.max((sum32 as f64 - exact).abs() / abs);
        }
        assert!(worst > 0.0 && worst <= gamma(3) as f64, "{worst:e}");
    }

    #[test]
    fn reflect_about_normal() {
        let r = reflect(Vec3A::new(1.0, -1.0, 0.0), Vec3A::Y);
        assert_eq!(r, Vec3A::new(1.0, 1.0, 0.0));
    }
}
