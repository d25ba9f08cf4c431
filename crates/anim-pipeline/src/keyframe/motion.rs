//! Motion during the exposure, for specs with a `shutter` (docs/scene-language.md §10).
//!
//! A blurred frame states the scene at the middle of its exposure, as an unblurred frame states
//! it at its instant, then one `motion` line per moving thing and instant of the exposure: the
//! transform that takes the thing from where the frame puts it to where it is at that instant.
//! The instants are evenly spread, close enough that no thing turns more than
//! `limits::MOTION_KEY_DEGREES` from one to the next, so a reader interpolating between them
//! follows arcs rather than chords.
//!
//! Motion has a home in each layer of the renderer library too: `anim_core::math::motion`
//! (keys), `anim_core::sdf::parse::motion` (reading these lines), `anim_core::scene::motion`
//! and `anim_core::render::motion`.

use super::orbit::{self, Pose};
use super::rotation::axis_degrees;
use super::spec_file::{Animation, Track};
use super::tidy::{tidy, tidy3};
use anim_core::limits;
use anim_core::sdf::ast::TransformOp;
use glam::{DMat3, DQuat, DVec3};

/// Where a track puts its target at one instant: its keyed translation, turn and scale, and
/// its orientation (keyed, or turned to face what it looks at).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrackPose {
    pub translate: DVec3,
    pub degrees: f64,
    pub scale: DVec3,
    pub orient: DQuat,
}

impl TrackPose {
    /// The track's values at time `t` (neutral where it keys nothing), tidied as frames write
    /// them.
    pub fn at(track: &Track, t: f64) -> TrackPose {
        let translate = match &track.travel {
            Some(travel) => travel.at(t),
            None => track
                .translate
                .as_ref()
                .and_then(|c| c.at(t))
                .unwrap_or(DVec3::ZERO),
        };
        TrackPose {
            translate: tidy3(translate),
            degrees: tidy(track.rotate.as_ref().and_then(|c| c.at(t)).unwrap_or(0.0)),
            scale: tidy3(
                track
                    .scale
                    .as_ref()
                    .and_then(|c| c.at(t))
                    .unwrap_or(DVec3::ONE),
            ),
            orient: track
                .orient
                .as_ref()
                .and_then(|c| c.orientation(t))
                .unwrap_or(DQuat::IDENTITY),
        }
    }

    /// The orientation as the frame writes it: a tidy axis and angle, `None` for no turn.
    fn orientation_op(&self) -> Option<TransformOp> {
        let (axis, degrees) = axis_degrees(self.orient);
        let degrees = tidy(degrees);
        (degrees != 0.0).then(|| TransformOp::Rotate {
            degrees,
            axis: tidy3(axis),
        })
    }

    /// The operations that place the target (see `generate`'s module doc): about the pivot
    /// `p`, scale, orient and turn, then move by the translation.
    pub fn ops(&self, pivot: DVec3, axis: DVec3) -> Vec<TransformOp> {
        let mut ops = Vec::new();
        let turns = self.degrees != 0.0;
        let scales = self.scale != DVec3::ONE;
        let orientation = self.orientation_op();
        if turns || scales || orientation.is_some() {
            let p = tidy3(pivot);
            if p != DVec3::ZERO {
                ops.push(TransformOp::Translate(-p));
            }
            if scales {
                ops.push(TransformOp::Scale(self.scale));
            }
            ops.extend(orientation);
            if turns {
                ops.push(TransformOp::Rotate {
                    degrees: self.degrees,
                    axis,
                });
            }
            let back = tidy3(p + self.translate);
            if back != DVec3::ZERO {
                ops.push(TransformOp::Translate(back));
            }
        } else if self.translate != DVec3::ZERO {
            ops.push(TransformOp::Translate(self.translate));
        }
        ops
    }
}

/// The operations that take a target from where `from` puts it to where `to` does: `to`'s
/// placement after undoing `from`'s, `P(to)·P(from)⁻¹`, with the steps that cancel left out.
pub fn delta_ops(from: &TrackPose, to: &TrackPose, pivot: DVec3, axis: DVec3) -> Vec<TransformOp> {
    if from.orient != DQuat::IDENTITY || to.orient != DQuat::IDENTITY {
        // Two orientations do not fold into one turn about the track's axis: undo one
        // placement, then make the other.
        let mut ops = inverse_ops(&from.ops(pivot, axis));
        ops.extend(to.ops(pivot, axis));
        return simplify(ops);
    }
    let p = tidy3(pivot);
    let mut ops = Vec::new();
    let translate = |v: DVec3, ops: &mut Vec<TransformOp>| {
        let v = tidy3(v);
        if v != DVec3::ZERO {
            ops.push(TransformOp::Translate(v));
        }
    };
    if from.scale == to.scale {
        let turn = tidy(to.degrees - from.degrees);
        if turn == 0.0 {
            translate(to.translate - from.translate, &mut ops);
        } else {
            translate(-(p + from.translate), &mut ops);
            ops.push(TransformOp::Rotate {
                degrees: turn,
                axis,
            });
            translate(p + to.translate, &mut ops);
        }
        return ops;
    }
    // Undo the turn, then both scales at once (they act on the same axes), then turn again.
    translate(-(p + from.translate), &mut ops);
    if from.degrees != 0.0 {
        ops.push(TransformOp::Rotate {
            degrees: -from.degrees,
            axis,
        });
    }
    ops.push(TransformOp::Scale(tidy3(to.scale / from.scale)));
    if to.degrees != 0.0 {
        ops.push(TransformOp::Rotate {
            degrees: to.degrees,
            axis,
        });
    }
    translate(p + to.translate, &mut ops);
    ops
}

/// The operations that undo `ops`: each one inverted, in reverse order.
pub fn inverse_ops(ops: &[TransformOp]) -> Vec<TransformOp> {
    ops.iter()
        .rev()
        .map(|op| match *op {
            TransformOp::Translate(v) => TransformOp::Translate(-v),
            TransformOp::Rotate { degrees, axis } => TransformOp::Rotate {
                degrees: -degrees,
                axis,
            },
            TransformOp::Scale(s) => TransformOp::Scale(tidy3(s.recip())),
        })
        .collect()
}

/// `ops` with neighbours of one kind merged (translations add, scales multiply, turns about
/// one axis add) and what then does nothing left out; the same transform.
pub fn simplify(ops: Vec<TransformOp>) -> Vec<TransformOp> {
    let mut out: Vec<TransformOp> = Vec::with_capacity(ops.len());
    for op in ops {
        let merged = match (out.last(), op) {
            (Some(&TransformOp::Translate(a)), TransformOp::Translate(b)) => {
                Some(TransformOp::Translate(tidy3(a + b)))
            }
            (Some(&TransformOp::Scale(a)), TransformOp::Scale(b)) => {
                Some(TransformOp::Scale(tidy3(a * b)))
            }
            (
                Some(&TransformOp::Rotate { degrees: a, axis }),
                TransformOp::Rotate {
                    degrees: b,
                    axis: other,
                },
            ) if axis == other => Some(TransformOp::Rotate {
                degrees: tidy(a + b),
                axis,
            }),
            _ => None,
        };
        match merged {
            Some(m) => {
                out.pop();
                out.push(m);
            }
            None => out.push(op),
        }
        let idle = match out.last() {
            Some(TransformOp::Translate(v)) => *v == DVec3::ZERO,
            Some(TransformOp::Scale(s)) => *s == DVec3::ONE,
            Some(TransformOp::Rotate { degrees, .. }) => *degrees == 0.0,
            None => false,
        };
        if idle {
            out.pop();
        }
    }
    out
}

/// The camera's frame: right, true up and backwards, as columns (a rotation).
fn camera_basis(pose: &Pose) -> DMat3 {
    let f = pose.dir.normalize();
    let r = f.cross(pose.up).normalize();
    DMat3::from_cols(r, r.cross(f), -f)
}

/// The rigid motion that takes a camera at `from` to `to`: about `from`'s eye, the turn from
/// one frame to the other, then the eye's move.
pub fn camera_delta_ops(from: &Pose, to: &Pose) -> Vec<TransformOp> {
    let turn = camera_basis(to) * camera_basis(from).transpose();
    let (axis, angle) = DQuat::from_mat3(&turn).normalize().to_axis_angle();
    let degrees = tidy(angle.to_degrees());
    let mut ops = Vec::new();
    if degrees == 0.0 || !axis.is_finite() || axis == DVec3::ZERO {
        let v = tidy3(to.eye - from.eye);
        if v != DVec3::ZERO {
            ops.push(TransformOp::Translate(v));
        }
        return ops;
    }
    let back = tidy3(-from.eye);
    if back != DVec3::ZERO {
        ops.push(TransformOp::Translate(back));
    }
    ops.push(TransformOp::Rotate {
        degrees,
        axis: tidy3(axis),
    });
    let there = tidy3(to.eye);
    if there != DVec3::ZERO {
        ops.push(TransformOp::Translate(there));
    }
    ops
}

/// Degrees turned over `[t0, t1]` by a keyed angle, along its path (a curve that turns back
/// counts both ways).
fn degrees_turned(angle: impl Fn(f64) -> f64, t0: f64, t1: f64) -> f64 {
    let steps = limits::MOTION_TURN_SAMPLES;
    (0..steps)
        .map(|k| {
            let a = t0 + (t1 - t0) * k as f64 / steps as f64;
            let b = t0 + (t1 - t0) * (k + 1) as f64 / steps as f64;
            (angle(b) - angle(a)).abs()
        })
        .sum()
}

/// How many equal steps frame `i`'s exposure is cut into: even, so that the middle is an
/// instant, at least 2, and enough that nothing turns more than
/// `limits::MOTION_KEY_DEGREES` in one. `turned` is the most that anything turns during the
/// exposure by orientations and aims, which only the generator can follow.
pub fn steps(anim: &Animation, i: usize, turned: f64) -> usize {
    let (t0, t1) = (anim.shutter_time(i, 0.0), anim.shutter_time(i, 1.0));
    let tracks = anim
        .tracks
        .iter()
        .filter_map(|t| t.rotate.as_ref())
        .map(|c| degrees_turned(|t| c.at(t).unwrap_or(0.0), t0, t1));
    let orbit = anim
        .orbit
        .iter()
        .map(|o| degrees_turned(|t| orbit::angle_at(o, t, anim.duration()), t0, t1));
    let most = tracks.chain(orbit).fold(turned, f64::max);
    let half = (most / (2.0 * limits::MOTION_KEY_DEGREES)).ceil();
    let half = if half.is_finite() { half as usize } else { 1 };
    2 * half.clamp(1, limits::MOTION_MAX_STEPS / 2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use anim_core::math::Transform;

    fn matrix(ops: &[TransformOp]) -> Transform {
        ops.iter().fold(Transform::IDENTITY, |m, op| {
            let t = match *op {
                TransformOp::Translate(v) => Transform::translate(v),
                TransformOp::Rotate { degrees, axis } => {
                    Transform::rotate(degrees, axis).expect("axis")
                }
                TransformOp::Scale(s) => Transform::scale(s).expect("scale"),
            };
            t.then_after(&m)
        })
    }

    #[test]
    fn a_delta_composed_after_one_pose_gives_the_other() {
        let pivot = DVec3::new(1.0, -2.0, 0.5);
        let axis = DVec3::new(0.2, 1.0, -0.3);
        let poses = [
            TrackPose {
                translate: DVec3::new(0.5, 0.0, -1.0),
                degrees: 30.0,
                scale: DVec3::ONE,
                orient: DQuat::IDENTITY,
            },
            TrackPose {
                translate: DVec3::new(2.0, 1.0, 0.0),
                degrees: 75.0,
                scale: DVec3::ONE,
                orient: DQuat::from_axis_angle(DVec3::X, 0.5),
            },
            TrackPose {
                translate: DVec3::ZERO,
                degrees: 0.0,
                scale: DVec3::new(2.0, 0.5, 1.5),
                orient: DQuat::IDENTITY,
            },
            TrackPose {
                translate: DVec3::new(-1.0, 3.0, 2.0),
                degrees: -140.0,
                scale: DVec3::new(1.0, 3.0, 0.25),
                orient: DQuat::IDENTITY,
            },
        ];
        for from in &poses {
            for to in &poses {
                let composed = matrix(&delta_ops(from, to, pivot, axis))
                    .then_after(&matrix(&from.ops(pivot, axis)));
                let direct = matrix(&to.ops(pivot, axis));
                assert!(
                    composed
                        .world_from_object
                        .abs_diff_eq(direct.world_from_object, 1e-9),
                    "{from:?} → {to:?}"
                );
            }
        }
        let still = delta_ops(&poses[1], &poses[1], pivot, axis);
        assert!(still.is_empty(), "{still:?}");
    }

    fn pose() -> impl proptest::strategy::Strategy<Value = TrackPose> {
        use proptest::prelude::*;
        let v = |r: std::ops::Range<f64>| prop::array::uniform3(r).prop_map(DVec3::from);
        let turn =
            (v(-1.0..1.0), -4.0f64..4.0, any::<bool>()).prop_map(
                |(axis, angle, turned)| match axis.try_normalize() {
                    Some(a) if turned => DQuat::from_axis_angle(a, angle),
                    _ => DQuat::IDENTITY,
                },
            );
        (v(-50.0..50.0), -1000.0f64..1000.0, v(0.05..20.0), turn).prop_map(|(t, d, s, q)| {
            TrackPose {
                translate: tidy3(t),
                degrees: tidy(d),
                scale: tidy3(s),
                orient: q,
            }
        })
    }

    proptest::proptest! {
        #[test]
        fn every_delta_takes_one_pose_to_the_other(
            from in pose(),
            to in pose(),
            pivot in proptest::array::uniform3(-20.0f64..20.0),
            axis in proptest::array::uniform3(-1.0f64..1.0),
        ) {
            let axis = DVec3::from(axis);
            proptest::prop_assume!(axis.length() > 1e-2);
            let pivot = DVec3::from(pivot);
            let composed = matrix(&delta_ops(&from, &to, pivot, axis))
                .then_after(&matrix(&from.ops(pivot, axis)));
            let direct = matrix(&to.ops(pivot, axis));
            // The printed numbers keep 12 digits: relative to the largest entry involved.
            let size = direct.world_from_object.abs().to_cols_array().iter().copied().fold(1.0, f64::max);
            proptest::prop_assert!(composed.world_from_object.abs_diff_eq(direct.world_from_object, 1e-8 * size));
            let simplified = simplify(delta_ops(&from, &to, pivot, axis));
            proptest::prop_assert!(matrix(&simplified).then_after(&matrix(&from.ops(pivot, axis)))
                .world_from_object.abs_diff_eq(direct.world_from_object, 1e-8 * size));
        }
    }

    #[test]
    fn inverse_ops_undo_ops() {
        let ops = [
            TransformOp::Translate(DVec3::new(1.0, 2.0, 3.0)),
            TransformOp::Scale(DVec3::new(2.0, 0.5, 4.0)),
            TransformOp::Rotate {
                degrees: 33.0,
                axis: DVec3::new(1.0, 1.0, 0.0),
            },
        ];
        let m = matrix(&inverse_ops(&ops)).then_after(&matrix(&ops));
        assert!(m
            .world_from_object
            .abs_diff_eq(glam::DMat4::IDENTITY, 1e-12));
    }

    #[test]
    fn simplified_ops_are_the_same_transform() {
        let axis = DVec3::new(0.0, 1.0, 0.0);
        let ops = vec![
            TransformOp::Translate(DVec3::new(1.0, 2.0, 3.0)),
            TransformOp::Translate(DVec3::new(-1.0, -2.0, -3.0)),
            TransformOp::Rotate {
                degrees: 30.0,
                axis,
            },
            TransformOp::Rotate {
                degrees: 15.0,
                axis,
            },
            TransformOp::Scale(DVec3::new(2.0, 4.0, 0.5)),
            TransformOp::Scale(DVec3::new(0.5, 0.25, 2.0)),
            TransformOp::Translate(DVec3::X),
        ];
        let short = simplify(ops.clone());
        assert_eq!(short.len(), 2, "{short:?}");
        assert!(matrix(&short)
            .world_from_object
            .abs_diff_eq(matrix(&ops).world_from_object, 1e-12));
        let undone = simplify(vec![
            TransformOp::Translate(DVec3::X),
            TransformOp::Translate(-DVec3::X),
        ]);
        assert!(undone.is_empty());
    }

    #[test]
    fn a_camera_delta_carries_eye_and_frame() {
        let from = Pose {
            eye: DVec3::new(3.0, 1.0, 4.0),
            dir: DVec3::new(-3.0, -1.0, -4.0),
            up: DVec3::Y,
        };
        let to = Pose {
            eye: DVec3::new(4.0, 1.0, 3.0),
            dir: DVec3::new(-4.0, -0.5, -3.0),
            up: DVec3::Y,
        };
        let m = matrix(&camera_delta_ops(&from, &to));
        assert!(m.point(from.eye).abs_diff_eq(to.eye, 1e-9));
        let moved = Pose {
            eye: m.point(from.eye),
            dir: m.vector(from.dir),
            up: m.vector(from.up),
        };
        let (a, b) = (camera_basis(&moved), camera_basis(&to));
        assert!(a.abs_diff_eq(b, 1e-9), "{a} vs {b}");
        assert!(camera_delta_ops(&from, &from).is_empty());
    }

    #[test]
    fn turns_along_a_path_count_both_ways() {
        let back_and_forth = |t: f64| 90.0 * (std::f64::consts::PI * t).sin();
        assert!((degrees_turned(back_and_forth, 0.0, 1.0) - 180.0).abs() < 1e-6);
        assert!((degrees_turned(|t| 720.0 * t, 0.0, 0.5) - 360.0).abs() < 1e-9);
    }
}
