//! Watertight ray/triangle intersection (Woop, Benthin & Wald, "Watertight Ray/Triangle
//! Intersection", JCGT 2013), in the form pbrt-v4 uses (`IntersectTriangle`, shapes.h).
//!
//! The ray is translated to the origin, its axes permuted so that its largest direction
//! component becomes z, and the vertices sheared so that the ray runs along +z. The hit test
//! then reduces to the signs of three 2D edge functions. Every quantity that decides a sign is
//! computed from per-vertex values that do not depend on which triangle the vertex belongs to,
//! so two triangles sharing an edge evaluate that edge's function to exactly opposite values:
//! a ray can never slip between them.

use super::ShapeHit;
use crate::math::{Aabb, Ray};
use glam::{DVec3, Vec3A};

/// Triangle with corners `v0`, `v1` and `v2`, hit from both sides.
#[derive(Clone, Debug)]
pub struct Triangle {
    /// The first corner.
    pub v0: Vec3A,
    /// The second corner.
    pub v1: Vec3A,
    /// The third corner.
    pub v2: Vec3A,
    /// Unit geometric normal along `(v1 − v0) × (v2 − v0)`, computed once in f64.
    pub normal: Vec3A,
}

/// pbrt's γ(n) = nε/(1 − nε) with ε the unit round-off of f32: the relative bound on the
/// error of n chained f32 operations.
const fn gamma(n: i32) -> f32 {
    let e = f32::EPSILON * 0.5;
    (n as f32 * e) / (1.0 - n as f32 * e)
}

impl Triangle {
    /// `None` for non-finite or collinear vertices (including repeated ones). The normal is
    /// taken in f64, where the differences of f32 coordinates are exact and the cross product
    /// is zero only for (numerically) collinear vertices.
    pub fn new(v0: Vec3A, v1: Vec3A, v2: Vec3A) -> Option<Self> {
        if !(v0.is_finite() && v1.is_finite() && v2.is_finite()) {
            return None;
        }
        let (a, b, c) = (v0.as_dvec3(), v1.as_dvec3(), v2.as_dvec3());
        let n: DVec3 = (b - a).cross(c - a);
        let len = n.length();
        if !(len > 0.0 && len.is_finite()) {
            return None;
        }
        Some(Triangle {
            v0,
            v1,
            v2,
            normal: (n / len).as_vec3().into(),
        })
    }

    /// The smallest box holding the three corners.
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points([self.v0, self.v1, self.v2])
    }

    /// Two-sided; the normal is the geometric one whatever side the ray comes from.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        let h = RaySpace::new(ray)?.hit(self.v0, self.v1, self.v2, t_max)?;
        Some(ShapeHit {
            t: h.t,
            point: h.point,
            normal: self.normal,
        })
    }
}

/// A hit of [`RaySpace::hit`]: the distance, the barycentric weights of the three vertices
/// and the point they give.
#[derive(Clone, Copy, Debug)]
pub struct TriangleHit {
    pub t: f32,
    pub barycentric: [f32; 3],
    pub point: Vec3A,
}

/// The ray's half of the watertight test: the axis permutation and shear that make the ray
/// run along +z. It depends on the ray alone, so a mesh computes it once per ray and tests
/// every candidate triangle against it.
#[derive(Clone, Copy, Debug)]
pub struct RaySpace {
    origin: Vec3A,
    kx: usize,
    ky: usize,
    kz: usize,
    sx: f32,
    sy: f32,
    sz: f32,
}

impl RaySpace {
    /// `None` for a zero (or unusable) direction: no line to intersect with.
    #[inline]
    pub fn new(ray: &Ray) -> Option<RaySpace> {
        let d = ray.dir;
        // Permute so that the largest |component| of the direction is z (kz); this keeps the
        // shear factors Sx, Sy within [-1, 1].
        let ad = d.abs();
        let kz = if ad.x >= ad.y && ad.x >= ad.z {
            0
        } else if ad.y >= ad.z {
            1
        } else {
            2
        };
        if d[kz] == 0.0 || !d[kz].is_finite() {
            return None;
        }
        let kx = if kz == 2 { 0 } else { kz + 1 };
        let ky = if kx == 2 { 0 } else { kx + 1 };
        Some(RaySpace {
            origin: ray.origin,
            kx,
            ky,
            kz,
            sx: -d[kx] / d[kz],
            sy: -d[ky] / d[kz],
            sz: 1.0 / d[kz],
        })
    }

    /// The hit of the triangle `v0 v1 v2` with `0 < t < t_max`, from either side.
    #[inline]
    pub fn hit(&self, v0: Vec3A, v1: Vec3A, v2: Vec3A, t_max: f32) -> Option<TriangleHit> {
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        let (sx, sy, sz) = (self.sx, self.sy, self.sz);
        // Ray-space vertices. The x and y shear is applied per vertex, so a vertex shared by
        // two triangles gets bit-identical ray-space coordinates in both.
        let to_ray_space = |v: Vec3A| {
            let p = v - self.origin;
            let (x, y, z) = (p[kx], p[ky], p[kz]);
            (x + sx * z, y + sy * z, z)
        };
        let (x0, y0, z0) = to_ray_space(v0);
        let (x1, y1, z1) = to_ray_space(v1);
        let (x2, y2, z2) = to_ray_space(v2);

        // Edge functions. Rounding is monotonic, so `a·b − c·d` in f32 either has the exact
        // sign or is 0, and swapping the edge's vertices negates it exactly.
        let mut e0 = x1 * y2 - y1 * x2;
        let mut e1 = x2 * y0 - y2 * x0;
        let mut e2 = x0 * y1 - y0 * x1;
        if e0 == 0.0 || e1 == 0.0 || e2 == 0.0 {
            // Products of two f32 are exact in f64, so the f64 difference has the exact sign:
            // a ray through an edge or vertex is decided exactly, as pbrt-v4 does.
            let ef = |xa: f32, ya: f32, xb: f32, yb: f32| {
                (xa as f64 * yb as f64 - ya as f64 * xb as f64) as f32
            };
            e0 = ef(x1, y1, x2, y2);
            e1 = ef(x2, y2, x0, y0);
            e2 = ef(x0, y0, x1, y1);
        }
        // Outside unless all edge functions agree in sign (zeros count as inside, so a ray
        // through a shared edge hits both triangles rather than neither).
        if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) && (e0 > 0.0 || e1 > 0.0 || e2 > 0.0) {
            return None;
        }
        let det = e0 + e1 + e2;
        if det == 0.0 || !det.is_finite() {
            // Seen edge-on (or overflowed): no area to hit.
            return None;
        }

        let (z0, z1, z2) = (z0 * sz, z1 * sz, z2 * sz);
        let t_scaled = e0 * z0 + e1 * z1 + e2 * z2;
        // Compare before dividing, as the paper does; written so that NaN falls through to
        // `None`.
        let in_range = if det < 0.0 {
            t_scaled < 0.0 && t_scaled > t_max * det
        } else {
            t_scaled > 0.0 && t_scaled < t_max * det
        };
        if !in_range {
            return None;
        }
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;

        // Conservative bound on the error of t (pbrt-v4 §6.8.7): a t that round-off alone
        // could have made positive is rejected, so a ray leaving the triangle's plane never
        // hits the triangle it left.
        let max_z = z0.abs().max(z1.abs()).max(z2.abs());
        let max_x = x0.abs().max(x1.abs()).max(x2.abs());
        let max_y = y0.abs().max(y1.abs()).max(y2.abs());
        let delta_z = gamma(3) * max_z;
        let delta_x = gamma(5) * (max_x + max_z);
        let delta_y = gamma(5) * (max_y + max_z);
        let delta_e = 2.0 * (gamma(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
        let max_e = e0.abs().max(e1.abs()).max(e2.abs());
        let delta_t =
            3.0 * (gamma(3) * max_e * max_z + delta_e * max_z + delta_z * max_e) * inv_det.abs();
        if !(t > delta_t && t < t_max) {
            return None;
        }

        // The point as a barycentric combination of the vertices: its error is a few ulps of
        // the vertex magnitudes, independent of how far the ray travelled (o + t·d is not).
        let (b0, b1, b2) = (e0 * inv_det, e1 * inv_det, e2 * inv_det);
        let point = v0 * b0 + v1 * b1 + v2 * b2;
        if !point.is_finite() {
            return None;
        }
        Some(TriangleHit {
            t,
            barycentric: [b0, b1, b2],
            point,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> Triangle {
        Triangle::new(
            Vec3A::new(0.0, 0.0, 0.0),
            Vec3A::new(1.0, 0.0, 0.0),
            Vec3A::new(0.0, 1.0, 0.0),
        )
        .unwrap()
    }

    #[test]
    fn hit_from_both_sides_with_the_geometric_normal() {
        let t = tri();
        let front = t
            .intersect(
                &Ray::new(Vec3A::new(0.25, 0.25, 2.0), -Vec3A::Z),
                f32::INFINITY,
            )
            .unwrap();
        assert_eq!(front.t, 2.0);
        assert_eq!(front.normal, Vec3A::Z);
        assert!((front.point - Vec3A::new(0.25, 0.25, 0.0)).length() < 1e-7);
        let back = t
            .intersect(
                &Ray::new(Vec3A::new(0.25, 0.25, -3.0), Vec3A::Z),
                f32::INFINITY,
            )
            .unwrap();
        assert_eq!(back.t, 3.0);
        assert_eq!(back.normal, Vec3A::Z, "not flipped towards the ray");
    }

    #[test]
    fn misses_outside_behind_and_beyond_t_max() {
        let t = tri();
        let outside = Ray::new(Vec3A::new(0.75, 0.75, 1.0), -Vec3A::Z);
        assert!(t.intersect(&outside, f32::INFINITY).is_none());
        let behind = Ray::new(Vec3A::new(0.25, 0.25, 1.0), Vec3A::Z);
        assert!(t.intersect(&behind, f32::INFINITY).is_none());
        let short = Ray::new(Vec3A::new(0.25, 0.25, 1.0), -Vec3A::Z);
        assert!(t.intersect(&short, 1.0).is_none(), "t_max is exclusive");
        assert!(t.intersect(&short, 1.5).is_some());
        let parallel = Ray::new(Vec3A::new(-1.0, 0.25, 0.0), Vec3A::X);
        assert!(t.intersect(&parallel, f32::INFINITY).is_none(), "edge-on");
        let zero = Ray::new(Vec3A::new(0.25, 0.25, 1.0), Vec3A::ZERO);
        assert!(t.intersect(&zero, f32::INFINITY).is_none());
    }

    #[test]
    fn t_is_in_units_of_a_non_unit_direction() {
        let h = tri()
            .intersect(
                &Ray::new(Vec3A::new(0.25, 0.25, 4.0), Vec3A::new(0.0, 0.0, -2.0)),
                f32::INFINITY,
            )
            .unwrap();
        assert_eq!(h.t, 2.0);
    }

    #[test]
    fn shared_edge_and_vertex_are_hit_by_one_of_the_pair() {
        // Two triangles forming the unit square, sharing the diagonal (1,0)–(0,1).
        let a = tri();
        let b = Triangle::new(
            Vec3A::new(1.0, 0.0, 0.0),
            Vec3A::new(1.0, 1.0, 0.0),
            Vec3A::new(0.0, 1.0, 0.0),
        )
        .unwrap();
        for i in 0..=1000 {
            let s = i as f32 / 1000.0;
            // Slanted rays whose f32 arithmetic does not land exactly on the diagonal.
            let target = Vec3A::new(1.0 - s, s, 0.0);
            let origin = Vec3A::new(0.3, -0.7, 1.3);
            let ray = Ray::new(origin, target - origin);
            let hit = a.intersect(&ray, f32::INFINITY).is_some()
                || b.intersect(&ray, f32::INFINITY).is_some();
            assert!(hit, "slipped through the shared edge at s = {s}");
        }
    }

    #[test]
    fn barycentric_point_lies_in_the_plane_far_from_the_origin() {
        let t = Triangle::new(
            Vec3A::new(1.0e4, 0.0, 1.0e4),
            Vec3A::new(1.0e4 + 1.0, 0.0, 1.0e4),
            Vec3A::new(1.0e4, 1.0, 1.0e4 + 1.0),
        )
        .unwrap();
        let origin = Vec3A::new(-3.0e4, 2.0e4, -1.0e4);
        let target = Vec3A::new(1.0e4 + 0.3, 0.3, 1.0e4 + 0.3);
        let h = t
            .intersect(&Ray::new(origin, target - origin), f32::INFINITY)
            .unwrap();
        // Plane: y = z − 1e4. The barycentric point is within an ulp or two of it.
        assert!(
            (h.point.y - (h.point.z - 1.0e4)).abs() <= 2.0e-3,
            "{:?}",
            h.point
        );
        let expected_n = Vec3A::new(0.0, -1.0, 1.0).normalize(); // (1,0,0) × (0,1,1)
        assert!((h.normal - expected_n).length() < 1e-6);
    }

    #[test]
    fn degenerate_triangles_are_rejected() {
        let o = Vec3A::ZERO;
        assert!(
            Triangle::new(o, Vec3A::X, Vec3A::X * 2.0).is_none(),
            "collinear"
        );
        assert!(Triangle::new(o, o, Vec3A::Y).is_none(), "repeated vertex");
        assert!(Triangle::new(o, Vec3A::X, Vec3A::new(f32::NAN, 1.0, 0.0)).is_none());
        assert!(Triangle::new(o, Vec3A::X, Vec3A::new(f32::INFINITY, 1.0, 0.0)).is_none());
        // Tiny but genuine triangles are kept.
        assert!(Triangle::new(o, Vec3A::X * 1e-20, Vec3A::Y * 1e-20).is_some());
    }

    #[test]
    fn bounds_cover_the_vertices() {
        let b = tri().bounds();
        assert_eq!(b.min, Vec3A::ZERO);
        assert_eq!(b.max, Vec3A::new(1.0, 1.0, 0.0));
    }
}
