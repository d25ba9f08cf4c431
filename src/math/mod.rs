//! Rays, bounding boxes, transforms and the one place where secondary rays are offset.

pub(crate) mod aabb;
mod transform;

pub use aabb::{Aabb, SLAB_WIDEN};
pub use transform::Transform;

use glam::Vec3A;

/// A ray `origin + t·dir`. `dir` is not necessarily unit length: rays moved into object space
/// keep the world-space parameter `t`, so hits from differently transformed shapes compare.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3A,
    pub dir: Vec3A,
}

impl Ray {
    pub fn new(origin: Vec3A, dir: Vec3A) -> Self {
        Ray { origin, dir }
    }

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
/// Measured, not guessed (tests/robustness.rs; `offset_margin_sweep` spawns 2·10⁵ rays per
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
    let magnitude = p.abs().max_element();
    let offset = ORIGIN_ERROR_FLOOR + magnitude * ORIGIN_ERROR_SCALE;
    let side = if n.dot(dir) >= 0.0 { 1.0 } else { -1.0 };
    p + n * (offset * side)
}

/// A ray from surface point `p` (geometric normal `n`) towards `dir`, offset off the surface.
#[inline]
pub fn spawn_ray(p: Vec3A, n: Vec3A, dir: Vec3A) -> Ray {
    Ray::new(spawn_origin(p, n, dir), dir)
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
    fn reflect_about_normal() {
        let r = reflect(Vec3A::new(1.0, -1.0, 0.0), Vec3A::Y);
        assert_eq!(r, Vec3A::new(1.0, 1.0, 0.0));
    }
}
