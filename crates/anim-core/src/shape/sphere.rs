use super::ShapeHit;
use crate::math::{Aabb, Ray};
use glam::{Mat4, Vec3A, Vec4};

/// Sphere of `radius` around `center`.
#[derive(Clone, Debug)]
pub struct Sphere {
    /// The centre.
    pub center: Vec3A,
    /// The radius, positive and finite.
    pub radius: f32,
}

impl Sphere {
    /// `None` unless the radius is positive and everything is finite.
    pub fn new(center: Vec3A, radius: f32) -> Option<Self> {
        (radius > 0.0 && radius.is_finite() && center.is_finite())
            .then_some(Sphere { center, radius })
    }

    /// The cube that holds the sphere, touching it at the middle of every face.
    pub fn bounds(&self) -> Aabb {
        Aabb::new(
            self.center - Vec3A::splat(self.radius),
            self.center + Vec3A::splat(self.radius),
        )
    }

    /// Discriminant in the form of Haines et al. (Ray Tracing Gems ch. 7): the distance from
    /// the centre to the ray line is computed directly, so there is no cancellation between
    /// `b²` and `4ac` for small spheres far away; the roots use the stable `q` form.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        let f = ray.origin - self.center;
        let a = ray.dir.length_squared();
        let beta = f.dot(ray.dir);
        let perp = f - ray.dir * (beta / a);
        let r2 = self.radius * self.radius;
        let disc = a * (r2 - perp.length_squared());
        if disc < 0.0 {
            return None;
        }
        let c = f.length_squared() - r2;
        let q = -(beta + disc.sqrt().copysign(beta));
        let (t0, t1) = {
            let x = q / a;
            let y = c / q;
            if x <= y {
                (x, y)
            } else {
                (y, x)
            }
        };
        let t = if t0 > 0.0 { t0 } else { t1 };
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        Some(self.hit_at(ray, t))
    }

    /// The hit at `t` (found by `intersect` or [`SphereRay::hit4`]): the point re-projected
    /// onto the surface, so its error is a few ulps of its magnitude.
    #[inline]
    pub fn hit_at(&self, ray: &Ray, t: f32) -> ShapeHit {
        let offset = ray.at(t) - self.center;
        let normal = offset.normalize_or_zero();
        let point = self.center + normal * self.radius;
        ShapeHit { t, point, normal }
    }

    /// The sphere packed for [`SphereRay::hit4`]: centre in `xyz`, radius in `w`.
    pub fn packed(&self) -> Vec4 {
        self.center.extend(self.radius)
    }
}

/// One ray splatted over four lanes, to test four spheres at once.
pub struct SphereRay {
    origin: [Vec4; 3],
    dir: [Vec4; 3],
    /// `|dir|²`, as `Sphere::intersect` computes it.
    a: Vec4,
}

impl SphereRay {
    /// `ray`, ready to be tested against four spheres at once.
    #[inline]
    pub fn new(ray: &Ray) -> SphereRay {
        SphereRay {
            origin: crate::math::splat3(ray.origin),
            dir: crate::math::splat3(ray.dir),
            a: Vec4::splat(ray.dir.length_squared()),
        }
    }

    /// `Sphere::intersect`'s distance for four packed spheres (see [`Sphere::packed`]), lane
    /// by lane the same operations in the same order, so the same floats: `(mask, t)` with
    /// bit `i` of the mask set when sphere `i` is hit at `0 < t[i] < t_max`. A lane holding
    /// NaN is never hit.
    #[inline(always)]
    pub fn hit4(&self, spheres: [Vec4; 4], t_max: f32) -> (u32, Vec4) {
        self.hit_lanes(&SphereRay::lanes(spheres), t_max)
    }

    /// Four packed spheres as lanes: centres' `x`, `y`, `z`, then radii (what
    /// [`SphereRay::hit_lanes`] takes; rays of a packet share them).
    #[inline(always)]
    pub fn lanes(spheres: [Vec4; 4]) -> [Vec4; 4] {
        let m = Mat4::from_cols(spheres[0], spheres[1], spheres[2], spheres[3]).transpose();
        [m.x_axis, m.y_axis, m.z_axis, m.w_axis]
    }

    /// [`SphereRay::hit4`] of spheres already in lanes ([`SphereRay::lanes`]).
    #[inline(always)]
    pub fn hit_lanes(&self, spheres: &[Vec4; 4], t_max: f32) -> (u32, Vec4) {
        let (r, [dx, dy, dz]) = (spheres[3], self.dir);
        let fx = self.origin[0] - spheres[0];
        let fy = self.origin[1] - spheres[1];
        let fz = self.origin[2] - spheres[2];
        // Vec3A's dot product adds (x + y) + z.
        let beta = fx * dx + fy * dy + fz * dz;
        let r2 = r * r;
        let c = (fx * fx + fy * fy + fz * fz) - r2;
        // A lane with `beta > 0` (or NaN) has `q < 0` (or NaN), so `x = q / a` is not above
        // 0, and with `c > 0` (or NaN: then `t` falls to `x`) neither is `t`: a miss, the
        // origin outside and the sphere behind it. When every lane is one (a shadow ray
        // leaving its own sphere, mostly), the rest is skipped; `t` matters only where hit.
        let may_hit = beta.cmple(Vec4::ZERO) | c.cmple(Vec4::ZERO);
        if may_hit.bitmask() == 0 {
            return (0, Vec4::ZERO);
        }
        let k = beta / self.a;
        let (px, py, pz) = (fx - dx * k, fy - dy * k, fz - dz * k);
        let disc = self.a * (r2 - (px * px + py * py + pz * pz));
        // A negative discriminant gives NaN here, and NaN fails every comparison below: a
        // miss in every lane where it is negative (or NaN) needs nothing more.
        if (disc.cmpge(Vec4::ZERO) & may_hit).bitmask() == 0 {
            return (0, Vec4::ZERO);
        }
        let q = -(beta + disc.map(f32::sqrt).copysign(beta));
        let x = q / self.a;
        let y = c / q;
        let ordered = x.cmple(y);
        let t0 = Vec4::select(ordered, x, y);
        let t1 = Vec4::select(ordered, y, x);
        let t = Vec4::select(t0.cmpgt(Vec4::ZERO), t0, t1);
        let hit = t.cmpgt(Vec4::ZERO) & t.cmplt(Vec4::splat(t_max));
        (hit.bitmask(), t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_front_and_from_inside() {
        let s = Sphere::new(Vec3A::new(0.0, 0.0, -5.0), 1.0).unwrap();
        let h = s
            .intersect(&Ray::new(Vec3A::ZERO, -Vec3A::Z), f32::INFINITY)
            .unwrap();
        assert!((h.t - 4.0).abs() < 1e-6);
        assert!((h.normal - Vec3A::Z).length() < 1e-6);
        let inside = s
            .intersect(
                &Ray::new(Vec3A::new(0.0, 0.0, -5.0), -Vec3A::Z),
                f32::INFINITY,
            )
            .unwrap();
        assert!((inside.t - 1.0).abs() < 1e-6);
        assert!(
            (inside.normal + Vec3A::Z).length() < 1e-6,
            "outward normal from inside"
        );
    }

    #[test]
    fn t_is_in_units_of_a_non_unit_direction() {
        let s = Sphere::new(Vec3A::new(0.0, 0.0, -5.0), 1.0).unwrap();
        let h = s
            .intersect(
                &Ray::new(Vec3A::ZERO, Vec3A::new(0.0, 0.0, -2.0)),
                f32::INFINITY,
            )
            .unwrap();
        assert!((h.t - 2.0).abs() < 1e-6);
    }

    #[test]
    fn tiny_far_sphere_is_still_hit() {
        // The textbook discriminant cancels to zero or below here in f32.
        let s = Sphere::new(Vec3A::new(0.0, 0.0, -1.0e4), 1.0e-2).unwrap();
        let h = s
            .intersect(&Ray::new(Vec3A::ZERO, -Vec3A::Z), f32::INFINITY)
            .unwrap();
        assert!((h.t - (1.0e4 - 1.0e-2)).abs() < 1e-2);
    }

    #[test]
    fn miss_and_t_max() {
        let s = Sphere::new(Vec3A::new(0.0, 0.0, -5.0), 1.0).unwrap();
        assert!(s
            .intersect(
                &Ray::new(Vec3A::new(2.0, 0.0, 0.0), -Vec3A::Z),
                f32::INFINITY
            )
            .is_none());
        assert!(s
            .intersect(&Ray::new(Vec3A::ZERO, -Vec3A::Z), 3.9)
            .is_none());
        assert!(Sphere::new(Vec3A::ZERO, 0.0).is_none());
    }

    /// The four-lane test gives `intersect`'s distance bit for bit, hit or miss, for rays
    /// from near and far, inside and outside, grazing and non-unit.
    #[test]
    fn four_lanes_equal_the_scalar_test() {
        let mut rng = crate::util::SplitMix64::new(0x9E37_79B9_7F4A_7C15);
        let mut next = move || rng.unit_f32();
        let mut v = move || {
            let x = [next(), next(), next(), next()];
            (Vec3A::new(x[0], x[1], x[2]) * 2.0 - Vec3A::ONE, x[3])
        };
        let mut hits = 0;
        for i in 0..20_000 {
            let scale = [1e-3f32, 1.0, 1e3][i % 3];
            let spheres: Vec<Sphere> = (0..4)
                .map(|_| {
                    let (c, r) = v();
                    Sphere::new(c * scale, (r * 0.6 + 0.01) * scale).unwrap()
                })
                .collect();
            let (o, limit) = v();
            let origin = o * scale * [1.0, 0.5, 30.0][i % 3];
            let target = spheres[i % 4].center + v().0 * spheres[i % 4].radius;
            let ray = Ray::new(origin, (target - origin) * [1.0, 0.3, 7.0][i / 3 % 3]);
            let t_max = if i % 5 == 0 {
                limit * scale * 30.0
            } else {
                f32::INFINITY
            };
            let (mask, t) =
                SphereRay::new(&ray).hit4([0, 1, 2, 3].map(|k| spheres[k].packed()), t_max);
            for (k, s) in spheres.iter().enumerate() {
                let scalar = s.intersect(&ray, t_max).map(|h| h.t.to_bits());
                let lane = (mask & (1 << k) != 0).then(|| t[k].to_bits());
                assert_eq!(scalar, lane, "ray {i} sphere {k}");
                hits += usize::from(scalar.is_some());
            }
        }
        assert!(hits > 10_000, "{hits} hits");
    }
}
