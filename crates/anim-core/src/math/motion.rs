//! Transforms between keys: each key decomposed into translation, rotation and stretch, the
//! parts interpolated separately (the rotation along the great arc) and composed again
//! (Shoemake and Duff, "Matrix animation and polar decomposition", 1992; pbrt's
//! `AnimatedTransform`). Interpolating the matrices themselves would shrink a turning object
//! half-way between keys 90° apart to 71 % of its size; the parts keep it rigid.
//!
//! A key is decomposed about a centre given in object space (`MotionKeys::new`): the
//! translation is where the centre goes, so a thing turning about its own centre keeps it
//! still between keys, whatever its object space's origin.
//!
//! Motion, one home per layer: `crate::math::motion` (keys and their interpolation),
//! `crate::sdf::parse::motion` (the `motion` lines), `crate::scene::motion` (what moves in a
//! scene) with `crate::scene::builder::motion` (made from the lines),
//! `crate::render::geometry::motion` (moving shapes as primitives), `crate::render::motion`
//! (the exposure, as the samplers see it), and the animation pipeline's `keyframe::motion`
//! (the lines a spec with a `shutter` writes).

use super::Transform;
use glam::{DMat3, DMat4, DQuat, DVec3};

/// Iterations of the polar decomposition: it converges quadratically, so a well-conditioned
/// matrix needs 6 to 10; the loop also stops once an update changes nothing.
const POLAR_ITERATIONS: usize = 100;

/// An affine transform as `Translate(translation) · rotation · stretch`, about a centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decomposed {
    /// Where the centre goes.
    pub translation: DVec3,
    /// The rotation, as a unit quaternion. A mirroring transform keeps its reflection in
    /// `stretch`, so this is always a proper rotation.
    pub rotation: DQuat,
    /// Symmetric: the scale and shear left once the rotation is taken out.
    pub stretch: DMat3,
}

impl Decomposed {
    /// `m` about `centre` (object space): `m = Translate(t) · R · S · Translate(−centre)`.
    /// `None` when `m`'s linear part is singular or not finite.
    pub fn of(m: &DMat4, centre: DVec3) -> Option<Decomposed> {
        let linear = DMat3::from_mat4(*m);
        let det = linear.determinant();
        if !(det.is_finite() && det != 0.0) {
            return None;
        }
        // Polar decomposition by averaging with the inverse transpose (Higham's iteration):
        // converges to the orthogonal factor.
        let mut r = linear;
        for _ in 0..POLAR_ITERATIONS {
            let next = (r + r.inverse().transpose()) * 0.5;
            let change = (0..3)
                .map(|i| (next.col(i) - r.col(i)).abs().max_element())
                .fold(0.0, f64::max);
            r = next;
            if change <= 1e-15 {
                break;
            }
        }
        // A mirroring transform keeps its reflection in the stretch, so that the rotation
        // is a rotation and slerps.
        if r.determinant() < 0.0 {
            r = -r;
        }
        let stretch = r.transpose() * linear;
        Some(Decomposed {
            translation: m.transform_point3(centre),
            rotation: DQuat::from_mat3(&r).normalize(),
            stretch,
        })
    }

    /// The transform again, about `centre`.
    pub fn matrix(&self, centre: DVec3) -> DMat4 {
        let linear = DMat3::from_quat(self.rotation) * self.stretch;
        DMat4::from_translation(self.translation)
            * DMat4::from_mat3(linear)
            * DMat4::from_translation(-centre)
    }

    /// The way `f` (0 to 1) from `self` to `to`: translation and stretch linearly, the
    /// rotation along the shorter great arc at constant angular speed.
    pub fn lerp(&self, to: &Decomposed, f: f64) -> Decomposed {
        let stretch = DMat3::from_cols(
            self.stretch.x_axis.lerp(to.stretch.x_axis, f),
            self.stretch.y_axis.lerp(to.stretch.y_axis, f),
            self.stretch.z_axis.lerp(to.stretch.z_axis, f),
        );
        Decomposed {
            translation: self.translation.lerp(to.translation, f),
            rotation: self.rotation.slerp(to.rotation, f).normalize(),
            stretch,
        }
    }
}

/// A transform keyed at instants `u` of an exposure (0 at shutter open, 1 at close).
#[derive(Clone, Debug, PartialEq)]
pub struct MotionKeys {
    centre: DVec3,
    keys: Vec<(f64, Decomposed)>,
}

impl MotionKeys {
    /// Keys `(u, transform)` in increasing `u`, decomposed about `centre` (object space).
    /// `None` without keys, with instants out of order or not finite, or with a singular
    /// transform.
    pub fn new(centre: DVec3, keys: &[(f64, Transform)]) -> Option<MotionKeys> {
        Self::from_keys(centre, keys.iter().map(|(u, t)| (*u, *t)))
    }

    /// [`MotionKeys::new`] of keys made one at a time: a file may key a million instants,
    /// and only their decomposed form is kept.
    pub fn from_keys(
        centre: DVec3,
        keys: impl IntoIterator<Item = (f64, Transform)>,
    ) -> Option<MotionKeys> {
        let keys = keys.into_iter();
        let mut out = Vec::with_capacity(keys.size_hint().0);
        for (u, t) in keys {
            let in_order = out.last().is_none_or(|(last, _)| *last < u);
            if !(u.is_finite() && in_order) {
                return None;
            }
            out.push((u, Decomposed::of(&t.world_from_object, centre)?));
        }
        if out.is_empty() {
            return None;
        }
        Some(MotionKeys { centre, keys: out })
    }

    /// The transform at `u`: interpolated between the keys around it, held before the first
    /// and after the last.
    pub fn at(&self, u: f64) -> Transform {
        let m = self.matrix_at(u);
        Transform {
            world_from_object: m,
            object_from_world: m.inverse(),
        }
    }

    /// `at(u).world_from_object`, without the inverse (for chains that invert once).
    pub fn matrix_at(&self, u: f64) -> DMat4 {
        // The first key at or after `u`, by bisection: the keys are in increasing order, and a
        // moving shape is placed at every instant of its keys.
        let first_after = self.keys.partition_point(|(k, _)| *k < u);
        let parts = match (first_after < self.keys.len()).then_some(first_after) {
            // At a key exactly (and before the first), the key itself, not a blend ending on it.
            Some(i) if i == 0 || self.keys[i].0 == u => self.keys[i].1,
            None => self.keys[self.keys.len() - 1].1,
            Some(i) => {
                let ((u0, a), (u1, b)) = (&self.keys[i - 1], &self.keys[i]);
                a.lerp(b, (u - u0) / (u1 - u0))
            }
        };
        parts.matrix(self.centre)
    }

    /// The instants of the keys, in increasing order.
    pub fn instants(&self) -> impl Iterator<Item = f64> + '_ {
        self.keys.iter().map(|(u, _)| *u)
    }

    /// Whether every key is the same transform: then nothing moves.
    pub fn is_still(&self) -> bool {
        self.keys.windows(2).all(|w| w[0].1 == w[1].1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The key found by bisection is the one a walk from the first key finds: before the
    /// first key, on a key exactly, between two, and past the last.
    #[test]
    fn keys_are_found_by_bisection_as_by_a_walk() {
        let keys: Vec<(f64, Transform)> = [0.0, 0.1, 0.35, 0.5, 0.9]
            .iter()
            .map(|&u| (u, Transform::translate(DVec3::new(u * 4.0, u * u, -u))))
            .collect();
        let motion = MotionKeys::new(DVec3::ZERO, &keys).unwrap();
        let walked = |u: f64| {
            let parts = match motion.keys.iter().position(|(k, _)| *k >= u) {
                Some(i) if i == 0 || motion.keys[i].0 == u => motion.keys[i].1,
                None => motion.keys[motion.keys.len() - 1].1,
                Some(i) => {
                    let ((u0, a), (u1, b)) = (&motion.keys[i - 1], &motion.keys[i]);
                    a.lerp(b, (u - u0) / (u1 - u0))
                }
            };
            parts.matrix(motion.centre)
        };
        for u in [
            -0.5, 0.0, 0.05, 0.1, 0.2, 0.35, 0.5, 0.7, 0.9, 0.95, 1.0, 2.0,
        ] {
            assert_eq!(motion.matrix_at(u), walked(u), "u = {u}");
        }
    }
    use proptest::prelude::*;

    fn trs(t: DVec3, degrees: f64, axis: DVec3, s: DVec3) -> Transform {
        Transform::translate(t)
            .then_after(&Transform::rotate(degrees, axis).expect("axis"))
            .then_after(&Transform::scale(s).expect("scale"))
    }

    fn close(a: &DMat4, b: &DMat4, tol: f64) -> bool {
        a.abs_diff_eq(*b, tol)
    }

    #[test]
    fn a_decomposed_transform_composes_back() {
        let centre = DVec3::new(0.3, -1.0, 2.0);
        let shear = DMat4::from_cols_array(&[
            1.0, 0.4, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.2, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        ]);
        let cases = [
            trs(
                DVec3::new(1.0, 2.0, 3.0),
                37.0,
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::ONE,
            ),
            trs(DVec3::ZERO, 170.0, DVec3::Z, DVec3::new(2.0, 0.5, 3.0)),
            trs(DVec3::X, -90.0, DVec3::Y, DVec3::new(-1.0, 1.0, 1.0)),
        ];
        for t in cases {
            for m in [t.world_from_object, t.world_from_object * shear] {
                let d = Decomposed::of(&m, centre).expect("decomposes");
                assert!(close(&d.matrix(centre), &m, 1e-12), "{m}");
                assert!(d.stretch.abs_diff_eq(d.stretch.transpose(), 1e-12));
                assert!((d.rotation.length() - 1.0).abs() < 1e-12);
            }
        }
        assert!(Decomposed::of(&DMat4::from_scale(DVec3::new(1.0, 0.0, 1.0)), centre).is_none());
    }

    #[test]
    fn keys_are_met_exactly_and_held_outside() {
        let keys = [
            (0.0, trs(DVec3::ZERO, 0.0, DVec3::Y, DVec3::ONE)),
            (0.5, trs(DVec3::X, 30.0, DVec3::Y, DVec3::splat(2.0))),
            (
                1.0,
                trs(DVec3::new(2.0, 1.0, 0.0), 60.0, DVec3::Y, DVec3::ONE),
            ),
        ];
        let m = MotionKeys::new(DVec3::ZERO, &keys).expect("keys");
        for (u, t) in &keys {
            assert!(close(
                &m.at(*u).world_from_object,
                &t.world_from_object,
                1e-12
            ));
        }
        assert_eq!(m.at(-1.0), m.at(0.0));
        assert_eq!(m.at(2.0), m.at(1.0));
        assert!(!m.is_still());
        let unordered = [keys[1], keys[0]];
        assert!(MotionKeys::new(DVec3::ZERO, &unordered).is_none());
        assert!(MotionKeys::new(DVec3::ZERO, &[]).is_none());
    }

    #[test]
    fn a_spin_about_the_centre_keeps_it_still_and_turns_at_constant_speed() {
        // A unit cube at (5, 0, 0) in its own space, turning 90° about its own centre: between
        // the keys a matrix blend would pull its corners in; the parts keep it rigid.
        let centre = DVec3::new(5.0, 0.0, 0.0);
        let spin = |deg: f64| {
            Transform::translate(centre)
                .then_after(&Transform::rotate(deg, DVec3::Y).expect("axis"))
                .then_after(&Transform::translate(-centre))
        };
        let m = MotionKeys::new(centre, &[(0.0, spin(0.0)), (1.0, spin(90.0))]).expect("keys");
        let corner = centre + DVec3::new(0.5, 0.5, 0.5);
        for k in 0..=10 {
            let u = k as f64 / 10.0;
            let t = m.at(u);
            assert!(t.point(centre).abs_diff_eq(centre, 1e-12));
            assert!(close(
                &t.world_from_object,
                &spin(90.0 * u).world_from_object,
                1e-12
            ));
            let r = t.point(corner) - centre;
            assert!((r.length() - 0.75f64.sqrt()).abs() < 1e-12);
        }
    }

    #[test]
    fn translation_and_scale_move_linearly() {
        let a = trs(DVec3::ZERO, 0.0, DVec3::Y, DVec3::ONE);
        let b = trs(
            DVec3::new(4.0, -2.0, 0.0),
            0.0,
            DVec3::Y,
            DVec3::new(3.0, 1.0, 1.0),
        );
        let m = MotionKeys::new(DVec3::ZERO, &[(0.0, a), (1.0, b)]).expect("keys");
        let t = m.at(0.25);
        assert!(t
            .point(DVec3::ZERO)
            .abs_diff_eq(DVec3::new(1.0, -0.5, 0.0), 1e-12));
        assert!(t
            .vector(DVec3::X)
            .abs_diff_eq(DVec3::new(1.5, 0.0, 0.0), 1e-12));
    }

    proptest! {
        #[test]
        fn interpolated_transforms_are_finite_and_invertible(
            t0 in prop::array::uniform3(-100.0f64..100.0),
            t1 in prop::array::uniform3(-100.0f64..100.0),
            d0 in -720.0f64..720.0,
            d1 in -720.0f64..720.0,
            axis in prop::array::uniform3(-1.0f64..1.0),
            s0 in prop::array::uniform3(0.01f64..100.0),
            s1 in prop::array::uniform3(0.01f64..100.0),
            u in 0.0f64..1.0,
        ) {
            let axis = DVec3::from(axis);
            prop_assume!(axis.length() > 1e-3);
            let a = trs(t0.into(), d0, axis, s0.into());
            let b = trs(t1.into(), d1, axis, s1.into());
            let m = MotionKeys::new(DVec3::new(0.5, 0.5, 0.5), &[(0.0, a), (1.0, b)]).expect("keys");
            let t = m.at(u);
            prop_assert!(t.world_from_object.is_finite());
            let product = t.world_from_object * t.object_from_world;
            prop_assert!(product.abs_diff_eq(DMat4::IDENTITY, 1e-6));
        }
    }
}
