use super::{NearFaces, ShapeHit};
use crate::math::aabb::slabs;
use crate::math::{Aabb, Ray, SLAB_WIDEN};
use glam::{Mat4, Vec3A, Vec4};

/// Axis-aligned box; a zero extent on one axis is allowed and renders as a rectangle.
#[derive(Clone, Debug)]
pub struct AaBox {
    /// The lowest corner.
    pub min: Vec3A,
    /// The highest corner: at least `min` on every axis, equal to it where the box is flat.
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

    /// The box itself, as bounds.
    pub fn bounds(&self) -> Aabb {
        Aabb::new(self.min, self.max)
    }

    /// The nearest hit with `0 < t < t_max`: the face the ray enters by, or the face it
    /// leaves by when it starts inside. The normal is that face's outward unit normal.
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

/// One ray splatted over four lanes, to slab-test four boxes at once.
pub struct BoxRay {
    origin: [Vec4; 3],
    /// `1 / dir`, as `AaBox::intersect` computes it.
    inv: [Vec4; 3],
    /// Whether no slab test of this ray can make NaN: `(b − o) · (1/d)` is NaN only for
    /// `0 · ∞` (or `∞ − ∞`), never with a finite origin and every `1/d` finite and non-zero
    /// (box coordinates are finite; unused lanes may hold NaN, whose results are not read).
    nan_free: bool,
}

/// Four boxes against one ray ([`BoxRay::slabs4`]): per lane the largest entry and the
/// smallest exit over the three slabs, and the `w` of each box's `min`.
pub struct Slabs4 {
    /// Per box, the ray parameter at which the ray's line enters it (negative when the ray
    /// starts inside or past it).
    pub enter: Vec4,
    /// Per box, the ray parameter at which the ray's line leaves it. The ray misses a box
    /// whose `exit` is below its `enter` or not above 0.
    pub exit: Vec4,
    /// Per box, the `w` of its `min`, passed through untouched: a mark the caller stores
    /// there, such as what kind of primitive the box bounds.
    pub tag: Vec4,
}

impl BoxRay {
    /// `ray`, ready to be tested against four boxes at once.
    #[inline]
    pub fn new(ray: &Ray) -> BoxRay {
        let inv = ray.dir.recip();
        BoxRay {
            origin: crate::math::splat3(ray.origin),
            inv: crate::math::splat3(inv),
            nan_free: ray.origin.is_finite() && inv.is_finite() && inv.cmpne(Vec3A::ZERO).all(),
        }
    }

    /// The slabs of four boxes given by their corners (`xyz`; `min`'s `w` is passed through
    /// as `tag`), lane by lane the same operations as `AaBox::intersect` up to its `enter`
    /// and `exit`: the same floats, but for the sign of a zero, which decides nothing there.
    #[inline(always)]
    pub fn slabs4(&self, min: [Vec4; 4], max: [Vec4; 4]) -> Slabs4 {
        if self.nan_free {
            self.slabs::<true>(min, max)
        } else {
            self.slabs::<false>(min, max)
        }
    }

    /// `slabs4`; `NAN_FREE` skips the repair of NaN for rays that cannot make it, where it
    /// changes nothing.
    #[inline(always)]
    fn slabs<const NAN_FREE: bool>(&self, min: [Vec4; 4], max: [Vec4; 4]) -> Slabs4 {
        let lo = Mat4::from_cols(min[0], min[1], min[2], min[3]).transpose();
        let hi = Mat4::from_cols(max[0], max[1], max[2], max[3]).transpose();
        let (lo, hi) = (
            [lo.x_axis, lo.y_axis, lo.z_axis, lo.w_axis],
            [hi.x_axis, hi.y_axis, hi.z_axis],
        );
        let mut near = [Vec4::ZERO; 3];
        let mut far = [Vec4::ZERO; 3];
        for axis in 0..3 {
            let t0 = (lo[axis] - self.origin[axis]) * self.inv[axis];
            let t1 = (hi[axis] - self.origin[axis]) * self.inv[axis];
            if NAN_FREE {
                near[axis] = t0.min(t1);
                far[axis] = t0.max(t1);
                continue;
            }
            let on_plane = t0.is_nan_mask() | t1.is_nan_mask();
            near[axis] = Vec4::select(on_plane, Vec4::NEG_INFINITY, t0.min(t1));
            far[axis] = Vec4::select(on_plane, Vec4::INFINITY, t0.max(t1));
        }
        Slabs4 {
            enter: near[0].max(near[1]).max(near[2]),
            exit: far[0].min(far[1]).min(far[2]),
            tag: lo[3],
        }
    }
}

impl Slabs4 {
    /// `AaBox::intersect`'s distance: `(mask, t)` with bit `i` set when box `i` is hit at
    /// `0 < t[i] < t_max`.
    #[inline(always)]
    pub fn hits(&self, t_max: f32) -> (u32, Vec4) {
        let (enter, exit) = (self.enter, self.exit);
        let t = Vec4::select(enter.cmpgt(Vec4::ZERO), enter, exit);
        let missed = enter.cmpgt(exit) | exit.cmple(Vec4::ZERO);
        ((!missed & t.cmplt(Vec4::splat(t_max))).bitmask(), t)
    }

    /// Whether the ray meets each box within `[0, t_max]`, as a hierarchy's node test
    /// answers it (widened, so round-off never rejects a box the ray grazes): a shape whose
    /// bounds these are cannot be hit elsewhere.
    #[inline(always)]
    pub fn overlaps(&self, t_max: f32) -> u32 {
        let enter = self.enter.max(Vec4::ZERO);
        let exit = (self.exit * SLAB_WIDEN).min(Vec4::splat(t_max));
        enter.cmple(exit).bitmask()
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
    fn four_at_a_time_gives_the_scalar_distances() {
        // Rays from inside, outside, parallel to slabs and on their planes (NaN there).
        let boxes = [
            AaBox::new(Vec3A::splat(-1.0), Vec3A::splat(1.0)).unwrap(),
            AaBox::new(Vec3A::new(0.0, -2.0, 3.0), Vec3A::new(0.5, 2.0, 3.0)).unwrap(),
            AaBox::new(Vec3A::new(-6.0, 0.0, -14.0), Vec3A::new(6.0, 0.2, 4.0)).unwrap(),
            AaBox::new(Vec3A::new(2.0, 2.0, 2.0), Vec3A::new(4.0, 3.0, 2.5)).unwrap(),
        ];
        let min = boxes.each_ref().map(|b| b.min.extend(0.0));
        let max = boxes.each_ref().map(|b| b.max.extend(0.0));
        let coords = [-3.0f32, -1.0, 0.0, 0.25, 1.0, 3.0];
        let mut checked = 0;
        for (i, &ox) in coords.iter().enumerate() {
            for &oy in &coords {
                for (k, &dz) in coords.iter().enumerate() {
                    let o = Vec3A::new(ox, oy, coords[(i + k) % 6]);
                    let d = Vec3A::new(coords[k], dz - oy, 1.0 - ox);
                    let ray = Ray::new(o, d);
                    let (mask, t) = BoxRay::new(&ray).slabs4(min, max).hits(10.0);
                    for (lane, b) in boxes.iter().enumerate() {
                        let scalar = b.intersect(&ray, 10.0).map(|h| h.t);
                        let packed = (mask & (1 << lane) != 0).then_some(t[lane]);
                        assert_eq!(packed, scalar, "box {lane}, {ray:?}");
                        checked += usize::from(scalar.is_some());
                    }
                }
            }
        }
        assert!(checked > 100, "{checked} hits");
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
