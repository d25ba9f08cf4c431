use super::{NearFaces, ShapeHit};
use crate::math::aabb::slabs;
use crate::math::{Aabb, Ray};
use glam::Vec3A;

/// Axis-aligned box; a zero extent on one axis is allowed and renders as a rectangle.
#[derive(Clone, Debug)]
pub struct AaBox {
    pub min: Vec3A,
    pub max: Vec3A,
}

impl AaBox {
    /// Corners may be given in any order. `None` if any coordinate is not finite.
    pub fn new(a: Vec3A, b: Vec3A) -> Option<Self> {
        (a.is_finite() && b.is_finite()).then(|| AaBox {
            min: a.min(b),
            max: a.max(b),
        })
    }

    pub fn bounds(&self) -> Aabb {
        Aabb::new(self.min, self.max)
    }

    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        let inv = ray.dir.recip();
        let (near, far) = slabs(self.min, self.max, ray.origin, inv);
        let enter = near.max_element();
        let exit = far.min_element();
        if enter > exit || exit <= 0.0 {
            return None;
        }
        let (t, axis, outward_sign) = if enter > 0.0 {
            (enter, max_axis(near), -1.0)
        } else {
            (exit, min_axis(far), 1.0)
        };
        if t >= t_max {
            return None;
        }
        let mut normal = Vec3A::ZERO;
        normal[axis] = outward_sign * ray.dir[axis].signum();
        let mut point = ray.at(t).clamp(self.min, self.max);
        // Snap the hit coordinate onto the face plane it lies on.
        point[axis] = if normal[axis] > 0.0 {
            self.max[axis]
        } else {
            self.min[axis]
        };
        Some(ShapeHit { t, point, normal })
    }
}

impl AaBox {
    /// The face `hit` lies on and, on each other axis, the nearer of the two faces with the
    /// hit point's distance from it: at an edge or corner, a ray spawned inwards along the
    /// hit face's normal alone can start outside a neighbour that a shear made acute.
    pub fn faces_near(&self, hit: &ShapeHit) -> NearFaces {
        let mut out = NearFaces {
            len: 3,
            ..NearFaces::default()
        };
        for axis in 0..3 {
            let mut n = Vec3A::ZERO;
            if hit.normal[axis] != 0.0 {
                n[axis] = hit.normal[axis].signum();
            } else {
                let below = hit.point[axis] - self.min[axis];
                let above = self.max[axis] - hit.point[axis];
                n[axis] = if above <= below { 1.0 } else { -1.0 };
                out.distances[axis] = below.min(above).max(0.0);
            }
            out.normals[axis] = n;
        }
        out
    }
}

fn max_axis(v: Vec3A) -> usize {
    if v.x >= v.y && v.x >= v.z {
        0
    } else if v.y >= v.z {
        1
    } else {
        2
    }
}

fn min_axis(v: Vec3A) -> usize {
    if v.x <= v.y && v.x <= v.z {
        0
    } else if v.y <= v.z {
        1
    } else {
        2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corners_in_any_order() {
        let b = AaBox::new(Vec3A::new(1.0, -1.0, 1.0), Vec3A::new(-1.0, 1.0, -1.0)).unwrap();
        assert_eq!(b.min, Vec3A::splat(-1.0));
        assert_eq!(b.max, Vec3A::splat(1.0));
    }

    #[test]
    fn front_face_normal_and_inside_exit() {
        let b = AaBox::new(Vec3A::splat(-1.0), Vec3A::splat(1.0)).unwrap();
        let h = b
            .intersect(
                &Ray::new(Vec3A::new(0.2, 0.3, 5.0), -Vec3A::Z),
                f32::INFINITY,
            )
            .unwrap();
        assert_eq!(h.t, 4.0);
        assert_eq!(h.normal, Vec3A::Z);
        assert_eq!(h.point.z, 1.0);
        let inside = b
            .intersect(&Ray::new(Vec3A::ZERO, Vec3A::X), f32::INFINITY)
            .unwrap();
        assert_eq!(inside.t, 1.0);
        assert_eq!(inside.normal, Vec3A::X);
    }

    #[test]
    fn flat_box_is_a_rectangle() {
        let b = AaBox::new(Vec3A::new(-1.0, -1.0, 0.0), Vec3A::new(1.0, 1.0, 0.0)).unwrap();
        let h = b
            .intersect(
                &Ray::new(Vec3A::new(0.5, 0.5, 3.0), -Vec3A::Z),
                f32::INFINITY,
            )
            .unwrap();
        assert_eq!(h.t, 3.0);
        assert_eq!(h.normal, Vec3A::Z);
        let below = b
            .intersect(
                &Ray::new(Vec3A::new(0.5, 0.5, -3.0), Vec3A::Z),
                f32::INFINITY,
            )
            .unwrap();
        assert_eq!(below.normal, -Vec3A::Z);
    }
}
