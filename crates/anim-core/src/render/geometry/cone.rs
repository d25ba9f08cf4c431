//! What may meet a cone of shadow rays: the segments from a point to every point of a disc
//! across the line to its centre (a spherical light as the point sees it,
//! `crate::render::shading::LightDisc`). The answer is conservative: every primitive a
//! segment of the cone meets is offered, and some that none meets may be (bounds stand in for
//! shapes but for spheres, planes and triangles). The facade proves a light wholly visible
//! where nothing is offered (`RenderScene::whole_light`).

use super::{Aggregate, Kind, PrimId};
use crate::math::Aabb;
use crate::shape::Shape;
use glam::{Vec3A, Vec4};
use std::cmp::Ordering;

/// The solid cone of segments from `apex` to the disc of `radius` about `apex + axis·length`,
/// across `axis`.
#[derive(Clone, Copy, Debug)]
pub struct Cone {
    apex: Vec3A,
    /// Unit.
    axis: Vec3A,
    length: f32,
    radius: f32,
    /// The box around it.
    bounds: Aabb,
}

impl Cone {
    /// The cone from `apex` to the disc of `radius` about `centre`, across the line between
    /// them; `None` when they coincide.
    pub fn new(apex: Vec3A, centre: Vec3A, radius: f32) -> Option<Cone> {
        let to = centre - apex;
        let length = to.length();
        if length.partial_cmp(&0.0) != Some(Ordering::Greater) || !radius.is_finite() {
            return None;
        }
        let axis = to / length;
        // The disc reaches `radius·√(1 − a²)` along each world axis `a` of the unit axis.
        let across = (Vec3A::ONE - axis * axis).max(Vec3A::ZERO);
        let reach = Vec3A::new(across.x.sqrt(), across.y.sqrt(), across.z.sqrt()) * radius;
        let bounds = Aabb::new(apex.min(centre - reach), apex.max(centre + reach));
        Some(Cone {
            apex,
            axis,
            length,
            radius,
            bounds,
        })
    }

    /// The distance from `p` to the cone (0 inside it), less a bound of its rounding error:
    /// never more than the true distance.
    pub fn distance(&self, p: Vec3A) -> f32 {
        let v = p - self.apex;
        let t = v.dot(self.axis);
        // From the difference of vectors, not of squares, which cancel along a long cone.
        let q = (v - self.axis * t).length();
        let slack = ROUNDING * (v.abs().max_element() + self.length + self.radius);
        (self.exact_distance(t, q) - slack).max(0.0)
    }

    /// The distance from the point `t` along the axis and `q` away from it to the cone.
    fn exact_distance(&self, t: f32, q: f32) -> f32 {
        let (h, r) = (self.length, self.radius);
        // In the half-plane of the axis and `p`, the cone is the triangle (0,0) (h,0) (h,r).
        if (0.0..=h).contains(&t) && q * h <= t * r {
            return 0.0;
        }
        let to_axis = (t - t.clamp(0.0, h)).hypot(q);
        let to_disc = (t - h).hypot(q - q.clamp(0.0, r));
        // The slant side, from the apex to (h, r).
        let len2 = h * h + r * r;
        let s = ((t * h + q * r) / len2).clamp(0.0, 1.0);
        let to_side = (t - s * h).hypot(q - s * r);
        to_axis.min(to_disc).min(to_side)
    }

    /// Whether the box from `min` to `max` may meet the cone: neither the cone's box nor the
    /// sphere around the box keeps them apart.
    pub fn may_meet_box(&self, min: Vec3A, max: Vec3A) -> bool {
        let b = &self.bounds;
        if max.cmplt(b.min).any() || min.cmpgt(b.max).any() {
            return false;
        }
        let (centre, half) = ((min + max) * 0.5, (max - min) * 0.5);
        // Infinite or NaN bounds (a lane no child fills) compare false above; keep them.
        self.distance(centre).partial_cmp(&half.length()) != Some(Ordering::Greater)
    }

    /// Whether the plane through `point` with unit `normal` may cut the cone: its apex and
    /// some point of its disc lie on different sides, touch it, or lie within rounding of it.
    pub fn crosses_plane(&self, point: Vec3A, normal: Vec3A) -> bool {
        let apex = (self.apex - point).dot(normal);
        let centre = apex + self.length * self.axis.dot(normal);
        let reach = self.radius * (1.0 - self.axis.dot(normal).powi(2)).max(0.0).sqrt();
        let (lo, hi) = (apex.min(centre - reach), apex.max(centre + reach));
        let slack =
            ROUNDING * ((self.apex - point).abs().max_element() + self.length + self.radius);
        !(lo > slack || hi < -slack)
    }

    /// Whether the whole disc lies on the side of the plane through the apex that unit
    /// `normal` points to, clear of it by more than rounding: segments leaving a convex
    /// surface there never come back to it.
    pub fn above(&self, normal: Vec3A) -> bool {
        let cos = self.axis.dot(normal);
        let lowest = self.length * cos - self.radius * (1.0 - cos * cos).max(0.0).sqrt();
        lowest > ROUNDING * (self.length + self.radius)
    }
}

/// A bound of the relative rounding error of the few f32 operations a cone's tests take,
/// times the magnitudes involved (eight units in the last place).
const ROUNDING: f32 = 8.0 * f32::EPSILON;

impl Aggregate {
    /// Offers to `stop` every primitive that may meet `cone` (see the module doc), until it
    /// returns true (then true). The shapes of an instanced composite and the moving shapes
    /// are offered as their entry (by its bounds over the exposure).
    pub(crate) fn cone_candidates(
        &self,
        cone: &Cone,
        mut stop: impl FnMut(PrimId) -> bool,
    ) -> bool {
        let mut offer = |i: PrimId| self.may_meet(cone, i) && stop(i);
        (self.unbounded..self.len() as u32).any(&mut offer)
            || self.bvh.any_meeting(
                |min: Vec4, max: Vec4| {
                    cone.may_meet_box(min.truncate().into(), max.truncate().into())
                },
                |leaf| leaf.iter().any(|&i| offer(i)),
            )
    }

    /// Whether primitive `i` may meet `cone`: a sphere or a plane exactly, a triangle by its
    /// plane and its bounds, anything else by its bounds.
    fn may_meet(&self, cone: &Cone, i: PrimId) -> bool {
        match self.kind_of(i as usize) {
            Kind::Sphere => {
                let s = self.sphere(i as usize);
                cone.distance(s.center).partial_cmp(&s.radius) != Some(Ordering::Greater)
            }
            Kind::Shape(k) => {
                let p = &self.objects[k as usize];
                let flat = match p.world_shape() {
                    Some(Shape::Plane(plane)) => {
                        return cone.crosses_plane(plane.point, plane.normal)
                    }
                    Some(Shape::Triangle(t)) => Some((t.v0, t.normal)),
                    _ => None,
                };
                flat.is_none_or(|(point, normal)| cone.crosses_plane(point, normal))
                    && cone.may_meet_box(p.bounds.min, p.bounds.max)
            }
            Kind::Moving(_) | Kind::Instance(_) => {
                let b = self.bound(i as usize);
                cone.may_meet_box(b.min, b.max)
            }
        }
    }

    /// Whether primitive `i` is convex (a straight segment meets it in one piece at most,
    /// and one leaving its surface outwards never meets it again): any shape but a mesh,
    /// under any transform; not an instanced composite or a moving shape.
    pub(crate) fn is_convex(&self, i: PrimId) -> bool {
        match self.kind.get(i as usize).map(|k| k.kind()) {
            Some(Kind::Sphere) => true,
            Some(Kind::Shape(k)) => !matches!(self.objects[k as usize].shape, Shape::Mesh(_)),
            _ => false,
        }
    }

    /// Whether primitive `i` is flat (a plane or a triangle): a segment leaving its surface
    /// never meets it again, to either side.
    pub(crate) fn is_flat(&self, i: PrimId) -> bool {
        match self.kind.get(i as usize).map(|k| k.kind()) {
            Some(Kind::Shape(k)) => matches!(
                self.objects[k as usize].shape,
                Shape::Plane(_) | Shape::Triangle(_)
            ),
            _ => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::util::SplitMix64;

    /// The distance from `p` to the cone by brute force: to points of a fine grid of the
    /// cone's segments.
    fn brute_distance(cone: &Cone, p: Vec3A) -> f32 {
        let centre = cone.apex + cone.axis * cone.length;
        let [e1, e2] = crate::math::sampling::orthonormal_pair(cone.axis);
        let mut best = f32::INFINITY;
        for i in 0..=24 {
            for j in 0..48 {
                let (r, phi) = (
                    cone.radius * i as f32 / 24.0,
                    j as f32 / 48.0 * std::f32::consts::TAU,
                );
                let end = centre + (e1 * phi.cos() + e2 * phi.sin()) * r;
                for k in 0..=48 {
                    let q = cone.apex + (end - cone.apex) * (k as f32 / 48.0);
                    best = best.min(q.distance(p));
                }
            }
        }
        best
    }

    #[test]
    fn distance_to_the_cone_agrees_with_its_points() {
        let mut rng = SplitMix64::new(7);
        let mut unit = || rng.unit_f32() * 2.0 - 1.0;
        for _ in 0..20 {
            let apex = Vec3A::new(unit(), unit(), unit());
            let centre = apex + Vec3A::new(unit(), unit(), unit()) * 4.0;
            let cone = Cone::new(apex, centre, 0.2 + unit().abs()).unwrap();
            for _ in 0..10 {
                let p = apex + Vec3A::new(unit(), unit(), unit()) * 5.0;
                let (exact, brute) = (cone.distance(p), brute_distance(&cone, p));
                // The grid's points lie inside the cone: brute force is never nearer, and
                // its spacing bounds how much farther.
                assert!(exact <= brute + 1e-4, "{exact} {brute}");
                assert!(brute - exact < 0.1, "{exact} {brute}");
            }
        }
    }

    #[test]
    fn boxes_and_planes_apart_from_the_cone_are_not_offered() {
        // From the origin up to a disc of radius 1 at height 10.
        let cone = Cone::new(Vec3A::ZERO, Vec3A::new(0.0, 10.0, 0.0), 1.0).unwrap();
        // The floor it stands on, just below the apex.
        assert!(!cone.may_meet_box(Vec3A::new(-5.0, -1.0, -5.0), Vec3A::new(5.0, -1e-3, 5.0)));
        assert!(cone.above(Vec3A::Y));
        assert!(!cone.crosses_plane(Vec3A::new(0.0, -1e-3, 0.0), Vec3A::Y));
        // Beside the cone near its apex (where it is thin), and across it higher up.
        assert!(!cone.may_meet_box(Vec3A::new(0.5, 1.0, -0.1), Vec3A::new(0.7, 1.2, 0.1)));
        assert!(cone.may_meet_box(Vec3A::new(0.5, 8.0, -0.1), Vec3A::new(0.7, 8.2, 0.1)));
        assert!(cone.crosses_plane(Vec3A::new(0.0, 5.0, 0.0), Vec3A::Y));
        // Leaning over: the disc dips below the plane through the apex.
        let low = Cone::new(Vec3A::ZERO, Vec3A::new(10.0, 0.5, 0.0), 1.0).unwrap();
        assert!(!low.above(Vec3A::Y));
    }
}
