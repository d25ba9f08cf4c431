use super::ShapeHit;
use crate::math::Ray;
use glam::Vec3A;

/// Infinite plane through `point` with unit `normal`.
#[derive(Clone, Debug)]
pub struct Plane {
    /// A point the plane passes through.
    pub point: Vec3A,
    /// The unit normal, reported for every hit whichever side the ray comes from.
    pub normal: Vec3A,
}

impl Plane {
    /// The plane through `point` perpendicular to `normal`, which is made unit length.
    /// `None` when `normal` cannot be normalised (zero or not finite) or `point` is not
    /// finite.
    pub fn new(point: Vec3A, normal: Vec3A) -> Option<Self> {
        let normal = normal.try_normalize()?;
        point.is_finite().then_some(Plane { point, normal })
    }

    /// The hit with `0 < t < t_max`, from either side. `None` as well for a ray parallel to
    /// the plane, and for a hit point too far out to be held in f32.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        let denom = ray.dir.dot(self.normal);
        if denom == 0.0 {
            return None;
        }
        let t = (self.point - ray.origin).dot(self.normal) / denom;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let p = ray.at(t);
        // Remove the error along the normal: the point lies on the plane to f32 rounding.
        let point = p - self.normal * (p - self.point).dot(self.normal);
        // Origins near f32::MAX overflow o + t·d; such a hit has no usable position.
        if !point.is_finite() {
            return None;
        }
        Some(ShapeHit {
            t,
            point,
            normal: self.normal,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hit_from_either_side_and_parallel_miss() {
        let p = Plane::new(Vec3A::new(0.0, -1.0, 0.0), Vec3A::new(0.0, 2.0, 0.0)).unwrap();
        let h = p
            .intersect(&Ray::new(Vec3A::ZERO, -Vec3A::Y), f32::INFINITY)
            .unwrap();
        assert_eq!(h.t, 1.0);
        assert_eq!(h.normal, Vec3A::Y);
        assert!(p
            .intersect(
                &Ray::new(Vec3A::new(0.0, -2.0, 0.0), Vec3A::Y),
                f32::INFINITY
            )
            .is_some());
        assert!(p
            .intersect(&Ray::new(Vec3A::ZERO, Vec3A::X), f32::INFINITY)
            .is_none());
        assert!(Plane::new(Vec3A::ZERO, Vec3A::ZERO).is_none());
    }

    #[test]
    fn overflowing_hit_point_is_no_hit() {
        let p = Plane::new(Vec3A::ZERO, Vec3A::new(0.3, 1.0, 0.0)).unwrap();
        let ray = Ray::new(Vec3A::new(0.0, 0.0, 2.23e38), Vec3A::new(0.0, -1.79, 0.0));
        assert!(p
            .intersect(&ray, f32::INFINITY)
            .is_none_or(|h| h.point.is_finite()));
    }
}
