use super::ShapeHit;
use crate::math::{Aabb, Ray};
use glam::Vec3A;

#[derive(Clone, Debug)]
pub struct Sphere {
    pub center: Vec3A,
    pub radius: f32,
}

impl Sphere {
    /// `None` unless the radius is positive and everything is finite.
    pub fn new(center: Vec3A, radius: f32) -> Option<Self> {
        (radius > 0.0 && radius.is_finite() && center.is_finite())
            .then_some(Sphere { center, radius })
    }

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
        let offset = ray.at(t) - self.center;
        // Re-project onto the surface so the hit point's error is a few ulps of its magnitude.
        let normal = offset.normalize_or_zero();
        let point = self.center + normal * self.radius;
        Some(ShapeHit { t, point, normal })
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
}
