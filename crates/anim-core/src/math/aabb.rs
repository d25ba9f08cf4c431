use super::Ray;
use glam::Vec3A;

/// Axis-aligned bounding box. The empty box has `min = +inf`, `max = -inf`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// The lowest corner: the smallest x, y and z the box holds.
    pub min: Vec3A,
    /// The highest corner: the largest x, y and z the box holds.
    pub max: Vec3A,
}

/// Slab-test widening so that round-off never rejects a box the ray grazes
/// (Ize, "Robust BVH Ray Traversal", JCGT 2013: 1 + 2·gamma(3)).
pub const SLAB_WIDEN: f32 =
    1.0 + 2.0 * (3.0 * f32::EPSILON * 0.5) / (1.0 - 3.0 * f32::EPSILON * 0.5);

impl Aabb {
    /// The box that holds nothing, which any union leaves unchanged.
    pub const EMPTY: Aabb = Aabb {
        min: Vec3A::splat(f32::INFINITY),
        max: Vec3A::splat(f32::NEG_INFINITY),
    };

    /// The box with opposite corners `a` and `b`, given in either order.
    pub fn new(a: Vec3A, b: Vec3A) -> Self {
        Aabb {
            min: a.min(b),
            max: a.max(b),
        }
    }

    /// The smallest box holding every point; [`Aabb::EMPTY`] when there is none.
    pub fn from_points(points: impl IntoIterator<Item = Vec3A>) -> Self {
        points
            .into_iter()
            .fold(Aabb::EMPTY, |acc, p| acc.union_point(p))
    }

    /// The smallest box holding both boxes.
    pub fn union(self, o: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    /// The smallest box holding this box and the point `p`.
    pub fn union_point(self, p: Vec3A) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// Whether the box holds no point: `min` lies above `max` on some axis. A flat box, with
    /// `min == max` on an axis, is not empty.
    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    /// Whether both corners are finite. False for the empty box and for the bounds of an
    /// unbounded shape such as a plane.
    pub fn is_finite(&self) -> bool {
        self.min.is_finite() && self.max.is_finite()
    }

    /// The point half-way between the corners. Not a point for the empty box.
    pub fn centroid(&self) -> Vec3A {
        (self.min + self.max) * 0.5
    }

    /// The size along each axis, `max - min`; negative for the empty box.
    pub fn extent(&self) -> Vec3A {
        self.max - self.min
    }

    /// The total area of the six faces; 0 for the empty box.
    pub fn surface_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// The eight corners. Bit 0 of an index picks the high x, bit 1 the high y, bit 2 the
    /// high z.
    pub fn corners(&self) -> [Vec3A; 8] {
        let (a, b) = (self.min, self.max);
        [
            Vec3A::new(a.x, a.y, a.z),
            Vec3A::new(b.x, a.y, a.z),
            Vec3A::new(a.x, b.y, a.z),
            Vec3A::new(b.x, b.y, a.z),
            Vec3A::new(a.x, a.y, b.z),
            Vec3A::new(b.x, a.y, b.z),
            Vec3A::new(a.x, b.y, b.z),
            Vec3A::new(b.x, b.y, b.z),
        ]
    }

    /// Entry and exit parameters of the ray against the box, clipped to `[t_min, t_max]`.
    /// `inv_dir` is `1 / ray.dir` per component (±inf for zero components).
    #[inline]
    pub fn hit_range(
        &self,
        ray: &Ray,
        inv_dir: Vec3A,
        t_min: f32,
        t_max: f32,
    ) -> Option<(f32, f32)> {
        let (near, far) = slabs(self.min, self.max, ray.origin, inv_dir);
        let enter = near.max_element().max(t_min);
        let exit = (far.min_element() * SLAB_WIDEN).min(t_max);
        (enter <= exit).then_some((enter, exit))
    }
}

/// Per-axis entry and exit parameters of the slabs `[min, max]`. A ray parallel to a slab
/// whose origin lies exactly on one of its planes gives `0 · inf = NaN`; such a ray is
/// inside that slab, so NaN becomes the unbounded interval (SSE min/max would not drop it).
#[inline]
pub(crate) fn slabs(min: Vec3A, max: Vec3A, origin: Vec3A, inv_dir: Vec3A) -> (Vec3A, Vec3A) {
    let t0 = (min - origin) * inv_dir;
    let t1 = (max - origin) * inv_dir;
    let on_plane = t0.is_nan_mask() | t1.is_nan_mask();
    (
        Vec3A::select(on_plane, Vec3A::NEG_INFINITY, t0.min(t1)),
        Vec3A::select(on_plane, Vec3A::INFINITY, t0.max(t1)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grazing_ray_along_a_face_is_not_rejected() {
        let b = Aabb::new(Vec3A::ZERO, Vec3A::ONE);
        // Travels exactly in the plane x = 0, parallel to the x slab.
        let ray = Ray::new(Vec3A::new(0.0, 0.5, -1.0), Vec3A::Z);
        assert!(b
            .hit_range(&ray, ray.dir.recip(), 0.0, f32::INFINITY)
            .is_some());
    }

    #[test]
    fn miss_beside_the_box() {
        let b = Aabb::new(Vec3A::ZERO, Vec3A::ONE);
        let ray = Ray::new(Vec3A::new(2.0, 0.5, -1.0), Vec3A::Z);
        assert!(b
            .hit_range(&ray, ray.dir.recip(), 0.0, f32::INFINITY)
            .is_none());
    }

    #[test]
    fn surface_area_of_unit_cube() {
        assert_eq!(Aabb::new(Vec3A::ZERO, Vec3A::ONE).surface_area(), 6.0);
    }
}
