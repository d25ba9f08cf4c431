//! Cone with its apex at `tip`, radius `radius` at `base`, closed by a disc at the base.
//!
//! Solved in f64 in the axis frame shared with the cylinder (see `cylinder.rs` for why the
//! ray is re-based first). In that frame, with the apex at the origin and z growing towards
//! the base, the side is x² + y² = k²z² for 0 ≤ z ≤ h, k = radius / h. The quadratic's
//! leading coefficient vanishes for rays parallel to a generator; the equation is then linear.

use super::cylinder::{
    conservative_aabb, discriminant_noise, quadratic_roots, AxisFrame, Nearest, Part, Rim, Side,
};
use super::{NearFaces, ShapeHit};
use crate::math::{Aabb, Ray};
use glam::{DVec3, Vec3A};

/// Cone with its apex at `tip` and a disc of `radius` at `base`, closed by that disc.
#[derive(Clone, Debug)]
pub struct Cone {
    /// The centre of the base disc.
    pub base: Vec3A,
    /// The apex.
    pub tip: Vec3A,
    /// The radius of the base disc, positive and finite.
    pub radius: f32,
    /// Origin at the tip, w towards the base.
    frame: AxisFrame,
    /// Radius per unit of height.
    slope: f64,
}

impl Cone {
    /// `None` if base and tip (nearly) coincide, the radius is not positive, or anything is
    /// not finite.
    pub fn new(base: Vec3A, tip: Vec3A, radius: f32) -> Option<Self> {
        if !(radius > 0.0 && radius.is_finite()) {
            return None;
        }
        let frame = AxisFrame::new(tip, base)?;
        let slope = radius as f64 / frame.height;
        slope.is_finite().then_some(Cone {
            base,
            tip,
            radius,
            frame,
            slope,
        })
    }

    /// A box holding the cone, padded so that rounding to f32 cannot cut it.
    pub fn bounds(&self) -> Aabb {
        let (lo, hi) = self
            .frame
            .disc_bounds(self.frame.height, self.radius as f64);
        let tip = self.tip.as_dvec3();
        conservative_aabb(lo.min(tip), hi.max(tip))
    }

    /// The nearest hit with `0 < t < t_max`, on the side or the base disc.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        let l = self.frame.to_local(ray)?;
        let (o, d) = (l.o, l.d);
        let h = self.frame.height;
        let k = self.slope;
        let k2 = k * k;
        let mut nearest = Nearest::new(t_max);
        let mut part = Part::Side;

        // Side of the double cone x² + y² − k²z² = 0; only the nappe 0 ≤ z ≤ h is ours.
        let a = d.x * d.x + d.y * d.y - k2 * d.z * d.z;
        let b = 2.0 * (o.x * d.x + o.y * d.y - k2 * o.z * d.z);
        let c = o.x * o.x + o.y * o.y - k2 * o.z * o.z;
        let roots = side_roots(a, b, c);
        let below_apex = below_apex_tolerance(a, b, c, d.z, h);
        for tl in roots.into_iter().flatten() {
            let z = o.z + tl * d.z;
            if (-below_apex..=h * (1.0 + 1e-12)).contains(&z) && nearest.offer(l.t_shift + tl) {
                part = Part::Side;
            }
        }

        // Base cap: the plane z = h, outward +w.
        if d.z != 0.0 {
            let tl = (h - o.z) / d.z;
            let x = o.x + tl * d.x;
            let y = o.y + tl * d.y;
            let r = self.radius as f64;
            if x * x + y * y <= r * r && nearest.offer(l.t_shift + tl) {
                part = Part::Cap { z: h, sign: 1.0 };
            }
        }

        let (t, t64) = nearest.best?;
        let p = o + d * (t64 - l.t_shift);
        let r = self.radius as f64;
        let rho = (p.x * p.x + p.y * p.y).sqrt();
        // Radial direction of the hit; `None` on the axis (only at the apex).
        let radial = (rho > 0.0).then(|| (p.x / rho, p.y / rho));
        let (cx, cy) = radial.unwrap_or((1.0, 0.0));
        let side_normal = DVec3::new(cx, cy, -k) / (1.0 + k2).sqrt();
        let band = self
            .frame
            .edge_band(DVec3::new(cx * rho, cy * rho, p.z), r.min(h));
        // Edges get the treatment explained at `AxisFrame::edge_band`: on the base rim, the
        // normal halfway between side and cap; at the apex, −w, whose plane through the apex
        // supports the whole cone.
        let rim = (
            DVec3::new(cx * r, cy * r, h),
            (side_normal + DVec3::Z).normalize(),
        );
        let apex = (DVec3::ZERO, DVec3::new(0.0, 0.0, -1.0));
        let (local, normal) = match part {
            Part::Side => {
                // Foot of the perpendicular from (ρ, z) onto the generator ρ = k·z in the
                // half-plane of the hit, kept between apex and base.
                let s = ((k * rho + p.z) / (1.0 + k2)).clamp(0.0, h);
                if s >= h - band {
                    rim
                } else if s <= band || radial.is_none() {
                    apex
                } else {
                    (DVec3::new(cx * k * s, cy * k * s, s), side_normal)
                }
            }
            Part::Cap { .. } if rho >= r - band => rim,
            Part::Cap { z, sign } => (DVec3::new(p.x, p.y, z), DVec3::new(0.0, 0.0, sign)),
        };
        // A hit snapped onto the rim or the apex keeps the edge's normal only while it tells
        // the crossing right: see `AxisFrame::crossing_normal`.
        let origin = o - d * l.t_shift;
        let inside = origin.x * origin.x + origin.y * origin.y < k2 * origin.z * origin.z
            && origin.z > 0.0
            && origin.z < h;
        let face = match part {
            Part::Side => side_normal,
            Part::Cap { sign, .. } => DVec3::new(0.0, 0.0, sign),
        };
        let normal = AxisFrame::crossing_normal(normal, face, d, inside);
        self.frame.shape_hit(t, local, normal)
    }
}

/// The side's crossings in local `t`: the roots of `a·t² + b·t + c = 0`, where `a` vanishes
/// for rays parallel to a generator and the equation is linear.
#[inline(always)]
fn side_roots(a: f64, b: f64, c: f64) -> [Option<f64>; 2] {
    if a != 0.0 {
        // Also right for |a| tiny (nearly parallel to a generator): the stable form yields
        // the linear root as c/q and the other one far away, on the other nappe or beyond
        // the base.
        match quadratic_roots(a, b, c) {
            Some((t0, t1)) => [Some(t0), Some(t1)],
            None => [None, None],
        }
    } else if b != 0.0 {
        // Exactly parallel to a generator: the line meets the cone once.
        [Some(-c / b), None]
    } else {
        // A generator itself (or parallel through the apex): no isolated crossing; the
        // base cap still catches it.
        [None, None]
    }
}

/// How far below the apex (z < 0, the mirrored nappe) a root of the side's quadratic
/// `a·t² + b·t + c` may be taken as the apex, for a local direction of height `dz` and a
/// cone of height `h`.
///
/// A ray steeper than the generators (a < 0) that passes near the apex goes from one nappe's
/// inside to the other's: it crosses our surface at the apex, by leaving the mirrored nappe
/// at z = −ε and entering ours at z = +ε. Those two roots merge as ε → 0 and are then known
/// only to √noise/|a| in t: the entry root (or the merged double root) can land at z < 0,
/// and dropping it would let the ray slip in or out through the apex unseen (pinned in
/// `tests::pinned_apex_*`). Within that bound the root is the apex itself, up to the same
/// uncertainty. Otherwise only a sliver of tolerance, as the cylinder has at both ends; at
/// the rim the side takes rays the cap test rounds away.
#[inline(always)]
fn below_apex_tolerance(a: f64, b: f64, c: f64, dz: f64, h: f64) -> f64 {
    (if a < 0.0 {
        dz.abs() * discriminant_noise(a, b, c).sqrt() / -a
    } else {
        0.0
    }) + 1e-12 * h
}

impl Cone {
    /// The side and the base around `point` (in the cone's space), with its distances from
    /// them; both at 0 on the base rim, where `intersect` snaps hits. At the apex, where hits
    /// are snapped too, no face but the axis into the solid, which clears every generator by
    /// sin(half-angle) per unit moved (`NearFaces::apex`). See `Cylinder::faces_near`.
    pub fn faces_near(&self, point: Vec3A) -> NearFaces {
        let local = self.frame.point_to_local(point.as_dvec3());
        let (r, h, k) = (self.radius as f64, self.frame.height, self.slope);
        let rho = (local.x * local.x + local.y * local.y).sqrt();
        let norm = (1.0 + k * k).sqrt();
        if rho == 0.0 {
            // The apex is at local z = 0, the base at z = h; the base's centre is one face.
            return NearFaces {
                apex: (local.z < 0.5 * h).then(|| self.apex_escape()),
                ..NearFaces::default()
            };
        }
        let side = DVec3::new(local.x / rho, local.y / rho, -k) / norm;
        // Distance from the generator's line ρ = k·z in the point's half-plane.
        let to_side = (k * local.z - rho) / norm;
        let side = Side {
            normal: side,
            distance: to_side,
        };
        let rim = Rim {
            z: h,
            cap: 1.0,
            radius: r,
        };
        self.frame.faces_near(local, side, rim, r.min(h))
    }

    /// The unit axis into the solid and the sine of the half-angle (`NearFaces::apex`).
    fn apex_escape(&self) -> (Vec3A, f32) {
        let k = self.slope;
        let inward: Vec3A = self.frame.vector_to_world(DVec3::Z).as_vec3().into();
        (inward, (k / (1.0 + k * k).sqrt()) as f32)
    }

    /// The apex escape for a side point `point` (in the cone's space) so close to the apex
    /// that the inward move `step` is as long as half the distance to the axis: the solid
    /// there is no thicker than the hit's error bound, and a move into the tangent plane
    /// (which a shear turns largely sideways) can come out through the curved side or the
    /// opposite one. A move along the axis cannot: the cone only widens that way, and the
    /// point's own generator recedes by sin(half-angle) per unit moved.
    pub fn apex_escape_near(&self, point: Vec3A, step: Vec3A) -> Option<(Vec3A, f32)> {
        let local = self.frame.point_to_local(point.as_dvec3());
        let rho = local.x.hypot(local.y);
        let thin = step.as_dvec3().length() >= 0.5 * rho;
        (local.z < 0.5 * self.frame.height && thin).then(|| self.apex_escape())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Base disc of radius 1 at y = 0, apex at y = 2.
    fn unit() -> Cone {
        Cone::new(Vec3A::ZERO, Vec3A::new(0.0, 2.0, 0.0), 1.0).unwrap()
    }

    fn close(a: Vec3A, b: Vec3A) -> bool {
        (a - b).length() < 1e-5
    }

    #[test]
    fn side_hit_with_outward_normal_tilted_towards_the_apex() {
        // At height y = 1 the radius is 0.5.
        let h = unit()
            .intersect(
                &Ray::new(Vec3A::new(5.0, 1.0, 0.0), -Vec3A::X),
                f32::INFINITY,
            )
            .unwrap();
        assert!((h.t - 4.5).abs() < 1e-6, "{}", h.t);
        assert!(close(h.point, Vec3A::new(0.5, 1.0, 0.0)));
        // Gradient of x² + z² − (1 − y/2)²: (2x, (1 − y/2), 2z) ∝ (1, 0.5, 0) at the hit.
        assert!(close(h.normal, Vec3A::new(1.0, 0.5, 0.0).normalize()));
    }

    #[test]
    fn base_cap_from_below_and_apex_from_above() {
        let c = unit();
        let cap = c
            .intersect(
                &Ray::new(Vec3A::new(0.3, -4.0, 0.1), Vec3A::Y),
                f32::INFINITY,
            )
            .unwrap();
        assert!((cap.t - 4.0).abs() < 1e-6);
        assert!(close(cap.normal, -Vec3A::Y));
        assert_eq!(cap.point.y, 0.0);
        // Along the axis from above: hits the apex.
        let apex = c
            .intersect(&Ray::new(Vec3A::new(0.0, 6.0, 0.0), -Vec3A::Y), 100.0)
            .unwrap();
        assert!((apex.t - 4.0).abs() < 1e-6);
        assert!(close(apex.point, Vec3A::new(0.0, 2.0, 0.0)));
        assert!(apex.normal.y > 0.0, "points away from the cone");
    }

    #[test]
    fn the_other_nappe_is_not_part_of_the_cone() {
        // Horizontal ray above the apex: meets the mirrored nappe only.
        assert!(unit()
            .intersect(
                &Ray::new(Vec3A::new(5.0, 3.0, 0.0), -Vec3A::X),
                f32::INFINITY
            )
            .is_none());
    }

    #[test]
    fn rays_parallel_to_a_generator_take_the_linear_case() {
        // In the plane z = 0 the cone is the triangle (−1,0), (1,0), (0,2). The generator from
        // the rim (1,0) to the apex has direction (−1, 2): for lines parallel to it the
        // quadratic's leading coefficient is exactly 0.
        let c = unit();
        let dir = Vec3A::new(-1.0, 2.0, 0.0);
        // Parallel, 0.5 outside: it meets the double cone only on the other nappe (y = 2.5).
        let outside = Ray::new(Vec3A::new(1.5, 0.0, 0.0) - dir, dir);
        assert!(c.intersect(&outside, f32::INFINITY).is_none());
        // Parallel, 0.5 inside: enters through the base at (0.5, 0) ...
        let inside = Ray::new(Vec3A::new(0.5, 0.0, 0.0) - dir, dir);
        let h = c.intersect(&inside, f32::INFINITY).unwrap();
        assert!((h.t - 1.0).abs() < 1e-6);
        assert!(close(h.normal, -Vec3A::Y));
        // ... and leaves through the opposite generator at (−0.25, 1.5): one linear root.
        let from_cap = Ray::new(Vec3A::new(0.5, 0.0, 0.0), dir);
        let exit = c.intersect(&from_cap, f32::INFINITY).unwrap();
        assert!((exit.t - 0.75).abs() < 1e-6, "{}", exit.t);
        assert!(close(exit.point, Vec3A::new(-0.25, 1.5, 0.0)));
        assert!(close(exit.normal, Vec3A::new(-1.0, 0.5, 0.0).normalize()));
        // Along the generator itself from below the base: the base rim or nothing, never NaN.
        let on = Ray::new(Vec3A::new(1.0, 0.0, 0.0) - dir, dir);
        if let Some(h) = c.intersect(&on, f32::INFINITY) {
            assert!(h.point.is_finite() && h.normal.is_finite() && h.t.is_finite());
            assert!((h.point - Vec3A::X).length() < 1e-5);
        }
    }

    #[test]
    fn rays_through_the_apex_do_not_leak_into_the_cone() {
        // Rays along (or nearly along) the axis passing within a few ulps of the apex: the
        // two side roots (leaving the mirrored nappe, entering ours) merge into a near-double
        // root whose discriminant rounding can push below zero. Losing both would let the ray
        // in through the apex and report the base cap from inside.
        let tip = Vec3A::new(0.3, 2.7, -1.1);
        let base = Vec3A::new(0.1, -0.4, -0.2);
        for radius in [0.02f32, 0.3, 1.0, 5.0] {
            let c = Cone::new(base, tip, radius).unwrap();
            let axis = (tip - base).normalize();
            let (u, v) = axis.any_orthonormal_pair();
            for i in 0..2000 {
                let a = i as f32 * 0.618;
                let eps = 1e-7 * (1.0 + (i % 7) as f32);
                let aim = tip + (u * a.cos() + v * a.sin()) * eps;
                let origin = aim + axis * 3.0;
                let h = c.intersect(&Ray::new(origin, aim - origin), 10.0).unwrap();
                assert!(
                    (h.t - 1.0).abs() < 1e-4,
                    "radius {radius}, ray {i}: t = {} (1 = at the apex)",
                    h.t
                );
            }
        }
    }

    #[test]
    fn pinned_apex_leak() {
        // Found by tests/robustness/: a ray along the axis of a flat cone (slope 2.07) passes
        // the apex within f32 rounding; the side's near-double root had discriminant
        // −1.9e-6 against b² = 1.5e10, both roots were dropped, and the ray reported the base
        // cap from inside at t = 3.78 instead of the apex at t = 2.33.
        let c = Cone::new(
            Vec3A::new(1.101987, -2.394507, -24.098375),
            Vec3A::new(-89.07244, -185.84276, -36.937916),
            424.8002,
        )
        .unwrap();
        let ray = Ray::new(
            Vec3A::new(-233.958, -480.59375, -57.567528),
            Vec3A::new(62.159836, 126.45618, 8.850664),
        );
        let h = c.intersect(&ray, f32::INFINITY).unwrap();
        assert!((h.t - 2.330_855).abs() < 1e-4, "t = {}", h.t);
        assert!((h.point - c.tip).length() < 1e-3, "{:?}", h.point);
    }

    #[test]
    fn pinned_apex_root_rounded_below_zero() {
        // Found by tests/robustness/: the double root at the apex was found but its height
        // came out as z = −1.1e-16, just on the mirrored nappe, and was dropped: the ray
        // reported the base cap from inside at t = 3.85 instead of the apex at t = 2.52.
        let c = Cone::new(
            Vec3A::new(0.04907558, 0.16300318, 0.22441933),
            Vec3A::new(0.57556444, 1.3189116, -0.16124275),
            2.5702057,
        )
        .unwrap();
        let ray = Ray::new(
            Vec3A::new(1.5745933, 3.5122836, -0.8930484),
            Vec3A::new(-0.39662498, -0.8707918, 0.29053456),
        );
        let h = c.intersect(&ray, f32::INFINITY).unwrap();
        assert!((h.t - 2.518_825).abs() < 1e-4, "t = {}", h.t);
        assert!((h.point - c.tip).length() < 1e-5, "{:?}", h.point);
    }

    #[test]
    fn pinned_apex_double_root_below_zero() {
        // Found by tests/robustness/: a ray aimed at the apex from off the axis (inside the
        // cone of entering directions). b² − 4ac rounded to exactly 0 and the merged root
        // landed at z = −8.1e-11, on the mirrored nappe: the ray entered unseen and reported
        // the base cap from inside at t = 1.67 instead of the apex at t = 0.247.
        let c = Cone::new(
            Vec3A::new(0.7932931, 0.0783234, -0.81044483),
            Vec3A::new(0.3247967, 0.4168598, -1.6601522),
            2.2248428,
        )
        .unwrap();
        let ray = Ray::new(
            Vec3A::new(0.2520011, 0.4851955, -1.8090702),
            Vec3A::new(0.29419494, -0.27617067, 0.60183483),
        );
        let h = c.intersect(&ray, f32::INFINITY).unwrap();
        assert!((h.t - 0.247_440_1).abs() < 1e-5, "t = {}", h.t);
        assert!((h.point - c.tip).length() < 1e-5, "{:?}", h.point);
        // And the reverse: from inside the cone out through the apex must not escape.
        let out = Ray::new(ray.at(1.0), -ray.dir);
        let h = c.intersect(&out, f32::INFINITY).unwrap();
        assert!((out.at(h.t) - c.tip).length() < 1e-5, "{:?}", h.point);
    }

    #[test]
    fn rim_and_apex_hits_are_snapped_with_safe_normals() {
        use crate::math::spawn_ray;
        let c = unit();
        // Aimed exactly at the rim point (1, 0, 0) towards the interior point (0, 0.5, 0).
        let h = c
            .intersect(
                &Ray::new(Vec3A::new(3.0, -1.0, 0.0), Vec3A::new(-1.0, 0.5, 0.0)),
                f32::INFINITY,
            )
            .unwrap();
        assert!((h.t - 2.0).abs() < 1e-6);
        assert!(close(h.point, Vec3A::X));
        // Halfway between the side's normal (2, 1, 0)/√5 and the cap's (0, −1, 0).
        let halfway = (Vec3A::new(2.0, 1.0, 0.0).normalize() - Vec3A::Y).normalize();
        assert!(close(h.normal, halfway), "{:?}", h.normal);
        // At this acute edge an offset along either face's normal would leave the solid
        // through the other face; along the halfway normal it stays inside both.
        for dir in [
            Vec3A::new(-1.0, 0.01, 0.1),
            Vec3A::new(-0.45, 0.9, 0.0),
            Vec3A::new(-1.0, 0.5, 0.0),
        ] {
            let inward = c.intersect(&spawn_ray(h.point, h.normal, dir), f32::INFINITY);
            assert!(inward.is_some_and(|e| e.t > 0.3), "{dir:?}: {inward:?}");
        }
        // The apex: normal −w (here +y), so a ray spawned into the cone starts on the axis.
        let apex = c
            .intersect(
                &Ray::new(Vec3A::new(0.3, 3.0, 0.0), Vec3A::new(-0.3, -1.0, 0.0)),
                f32::INFINITY,
            )
            .unwrap();
        assert!(close(apex.point, c.tip));
        assert!(close(apex.normal, Vec3A::Y));
        let down = c.intersect(
            &spawn_ray(apex.point, apex.normal, -Vec3A::Y),
            f32::INFINITY,
        );
        assert!(down.is_some_and(|e| (e.t - 2.0).abs() < 1e-4), "{down:?}");
    }

    #[test]
    fn inside_hits_have_outward_normals() {
        let c = unit();
        let up = c
            .intersect(&Ray::new(Vec3A::new(0.0, 0.5, 0.0), Vec3A::X), 10.0)
            .unwrap();
        assert!((up.t - 0.75).abs() < 1e-6);
        assert!(up.normal.x > 0.0 && up.normal.y > 0.0);
        let down = c
            .intersect(&Ray::new(Vec3A::new(0.0, 0.5, 0.0), -Vec3A::Y), 10.0)
            .unwrap();
        assert!((down.t - 0.5).abs() < 1e-6);
        assert!(close(down.normal, -Vec3A::Y));
    }

    #[test]
    fn misses_t_max_and_zero_direction() {
        let c = unit();
        assert!(c
            .intersect(
                &Ray::new(Vec3A::new(5.0, 1.0, 0.0), Vec3A::X),
                f32::INFINITY
            )
            .is_none());
        assert!(c
            .intersect(&Ray::new(Vec3A::new(5.0, 1.0, 0.0), -Vec3A::X), 4.4)
            .is_none());
        assert!(c
            .intersect(&Ray::new(Vec3A::new(5.0, 1.0, 0.0), Vec3A::ZERO), 10.0)
            .is_none());
    }

    #[test]
    fn bounds_contain_tip_and_rim() {
        let c = Cone::new(Vec3A::new(1.0, -2.0, 0.5), Vec3A::new(-1.0, 3.0, 2.0), 0.7).unwrap();
        let b = c.bounds();
        let w = (c.base - c.tip).normalize();
        let (u, v) = w.any_orthonormal_pair();
        assert!(c.tip.cmpge(b.min).all() && c.tip.cmple(b.max).all());
        for i in 0..64 {
            let a = i as f32 * std::f32::consts::TAU / 64.0;
            let p = c.base + (u * a.cos() + v * a.sin()) * 0.7;
            assert!(p.cmpge(b.min).all() && p.cmple(b.max).all(), "{p:?} {b:?}");
        }
    }

    #[test]
    fn a_move_across_the_thin_tip_takes_the_axis_instead() {
        // Radius 1 at y = 0, apex at y = 2: the side point at height 2 − 2e-4 lies 1e-4 from
        // the axis, along +x.
        let c = unit();
        let near_tip = Vec3A::new(1e-4, 2.0 - 2e-4, 0.0);
        let inward = Vec3A::new(-1.0, 0.5, 0.0).normalize();
        let (axis, sin) = c
            .apex_escape_near(near_tip, inward * 1e-4)
            .expect("a move of 1e-4 is as long as the tip is wide");
        assert!(close(axis, Vec3A::new(0.0, -1.0, 0.0)));
        assert!(
            (sin - 1.0 / 5f32.sqrt()).abs() < 1e-6,
            "half-angle atan(1/2): {sin}"
        );
        let sideways = Vec3A::new(0.0, 0.0, 1e-4);
        assert!(c.apex_escape_near(near_tip, sideways).is_some());
        // A move a tenth as long, or the same move far from the apex, stays on its side.
        assert_eq!(c.apex_escape_near(near_tip, inward * 1e-5), None);
        let low = Vec3A::new(0.5, 1.0, 0.0);
        assert_eq!(c.apex_escape_near(low, inward * 1e-4), None);
    }

    #[test]
    fn degenerate_cones_are_rejected() {
        let o = Vec3A::ZERO;
        assert!(Cone::new(o, o, 1.0).is_none());
        assert!(Cone::new(o, Vec3A::Y, 0.0).is_none());
        assert!(Cone::new(o, Vec3A::Y, -2.0).is_none());
        assert!(Cone::new(o, Vec3A::new(f32::NAN, 1.0, 0.0), 1.0).is_none());
        assert!(Cone::new(o, Vec3A::Y, f32::INFINITY).is_none());
    }

    #[test]
    fn a_ray_leaving_the_apex_outside_the_cone_does_not_meet_it_again() {
        use crate::math::spawn_ray;
        let c = unit();
        let h = c
            .intersect(
                &Ray::new(Vec3A::new(0.0, 5.0, 0.0), -Vec3A::Y),
                f32::INFINITY,
            )
            .unwrap();
        assert!(close(h.point, Vec3A::new(0.0, 2.0, 0.0)));
        // Below the apex's supporting plane (into the solid by its normal +y) but outside the
        // cone's half-angle of atan(1/2): it leaves at once.
        for dir in [
            Vec3A::new(1.0, -0.2, 0.0),
            Vec3A::new(-0.3, -0.1, 0.9),
            Vec3A::new(0.7, -0.3, -0.7),
        ] {
            let dir = dir.normalize();
            assert!(h.normal.dot(dir) < 0.0);
            let again = c.intersect(&spawn_ray(h.point, h.normal, dir), f32::INFINITY);
            // It may cross the face it leaves through a few offsets on (its origin is inside),
            // but as an exit, never as an entry of the surface it left.
            assert!(
                again.is_none_or(|e| e.normal.dot(dir) > 0.0),
                "{dir:?}: {again:?}"
            );
        }
        // Down the axis it goes through the solid to the base.
        let down = c.intersect(&spawn_ray(h.point, h.normal, -Vec3A::Y), f32::INFINITY);
        assert!(down.is_some_and(|e| (e.t - 2.0).abs() < 1e-4), "{down:?}");
    }
}
