//! Parenting: the motion a target follows from its parent (`parent: "name"`), written as
//! transform operations the frames can carry.
//!
//! The parent's motion at time t is `D = W(t) · W₀⁻¹`, its placement in the world at t after
//! undoing its placement in the base scene. A child following all of it is placed by `D`
//! after its own tracks. To follow part of it, `D` is split about the parent's base centre
//! `c₀` as `D(x) = R · S · (x − c₀) + c₁`: `c₁ = D(c₀)` is where the centre goes, `R` a turn
//! and `S` a symmetric stretch (the polar decomposition of D's linear part), and `S` in turn
//! `Q · Λ · Qᵀ`, a scale along its own axes. Following `Translate` keeps `c₁` (else `c₀`),
//! `Rotate` keeps `R`, `Scale` keeps `S`.

use super::motion::simplify;
use super::spec_file::Follow;
use super::tidy::{tidy, tidy3};
use anim_core::sdf::ast::TransformOp;
use glam::{DMat3, DMat4, DQuat, DVec3};

/// Iterations of the polar decomposition (each one at least doubles the digits once close)
/// and of the eigenvector sweeps: enough for any matrix a frame can hold.
const ITERATIONS: usize = 64;

/// The operations that apply the parts `follow` names of the parent's motion `d`, whose
/// base centre is `c0`.
pub fn follow_ops(d: &DMat4, c0: DVec3, follow: &[Follow]) -> Vec<TransformOp> {
    let linear = DMat3::from_mat4(*d);
    let c1 = d.transform_point3(c0);
    let (turn, stretch) = polar(linear);
    let mut ops = vec![TransformOp::Translate(tidy3(-c0))];
    if follow.contains(&Follow::Scale) {
        let (axes, sizes) = symmetric_eigen(stretch);
        ops.extend(rotate_op(axes.transpose()));
        ops.push(TransformOp::Scale(tidy3(sizes)));
        ops.extend(rotate_op(axes));
    }
    if follow.contains(&Follow::Rotate) {
        ops.extend(rotate_op(turn));
    }
    let to = if follow.contains(&Follow::Translate) {
        c1
    } else {
        c0
    };
    ops.push(TransformOp::Translate(tidy3(to)));
    simplify(ops)
}

/// A turn as one operation, none for no turn. `m` is a rotation.
fn rotate_op(m: DMat3) -> Option<TransformOp> {
    let (axis, angle) = DQuat::from_mat3(&m).normalize().to_axis_angle();
    let degrees = tidy(angle.to_degrees());
    (degrees != 0.0 && axis.is_finite() && axis != DVec3::ZERO).then(|| TransformOp::Rotate {
        degrees,
        axis: tidy3(axis),
    })
}

/// `m = R · S` with `R` a rotation and `S` symmetric. A mirroring `m` (negative determinant)
/// gives `S` a negative size, so that `R` stays a turn.
pub fn polar(m: DMat3) -> (DMat3, DMat3) {
    let sign = if m.determinant() < 0.0 { -1.0 } else { 1.0 };
    let mut r = m * sign;
    for _ in 0..ITERATIONS {
        let inv = r.inverse().transpose();
        if !inv.is_finite() {
            // A flattened parent (a zero scale) has no turn to follow.
            return (DMat3::IDENTITY, m);
        }
        let next = (r + inv) * 0.5;
        let done = (next - r).abs().to_cols_array().iter().all(|&e| e <= 1e-15);
        r = next;
        if done {
            break;
        }
    }
    (r, r.transpose() * m)
}

/// The eigenvectors (columns of a rotation) and eigenvalues of a symmetric `s`, by cyclic
/// Jacobi sweeps.
pub fn symmetric_eigen(s: DMat3) -> (DMat3, DVec3) {
    let mut a = s.to_cols_array_2d();
    let mut v = DMat3::IDENTITY.to_cols_array_2d();
    for _ in 0..ITERATIONS {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        if off <= 1e-300 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q].abs() <= 1e-300 {
                continue;
            }
            // The turn in the (p, q) plane that zeroes a[p][q].
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A ← Jᵀ·A·J and V ← V·J (rows indexed first).
            let turn_columns = |rows: &mut [[f64; 3]; 3]| {
                for row in rows.iter_mut() {
                    let (rp, rq) = (row[p], row[q]);
                    row[p] = c * rp - s * rq;
                    row[q] = s * rp + c * rq;
                }
            };
            turn_columns(&mut a);
            let (ap, aq) = (a[p], a[q]);
            a[p] = std::array::from_fn(|k| c * ap[k] - s * aq[k]);
            a[q] = std::array::from_fn(|k| s * ap[k] + c * aq[k]);
            turn_columns(&mut v);
        }
    }
    let mut axes = DMat3::from_cols_array_2d(&v).transpose();
    let mut sizes = DVec3::new(a[0][0], a[1][1], a[2][2]);
    if axes.determinant() < 0.0 {
        axes.x_axis = -axes.x_axis;
    }
    // Axes that are the world's, in some order, are the world's in order: the scale then
    // reads as the parent's own, without turns.
    if let Some(order) = world_order(axes) {
        axes = DMat3::IDENTITY;
        sizes = DVec3::new(sizes[order[0]], sizes[order[1]], sizes[order[2]]);
    }
    (axes, sizes)
}

/// For axes that are the world's x, y and z up to order and sign, which column is which.
fn world_order(axes: DMat3) -> Option<[usize; 3]> {
    let mut order = [usize::MAX; 3];
    for (col, v) in [axes.x_axis, axes.y_axis, axes.z_axis].iter().enumerate() {
        let along = (0..3).find(|&k| (v[k].abs() - 1.0).abs() <= 1e-12)?;
        order[along] = col;
    }
    order.iter().all(|&c| c < 3).then_some(order)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::keyframe::base::ops_transform;

    fn all() -> Vec<Follow> {
        vec![Follow::Translate, Follow::Rotate, Follow::Scale]
    }

    #[test]
    fn following_everything_is_the_parent_s_motion() {
        let turn = DMat4::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 1.1);
        let stretch = DMat4::from_scale(DVec3::new(2.0, 0.5, 3.0));
        let skewed = DMat4::from_axis_angle(DVec3::Y, 0.4);
        let cases = [
            DMat4::from_translation(DVec3::new(3.0, -1.0, 2.0)),
            DMat4::from_translation(DVec3::X) * turn,
            turn * stretch,
            DMat4::from_translation(DVec3::new(0.5, 4.0, -2.0))
                * skewed
                * stretch
                * skewed.inverse(),
            DMat4::from_scale(DVec3::new(-1.0, 1.0, 2.0)) * turn,
        ];
        let c0 = DVec3::new(1.0, 2.0, 3.0);
        for d in cases {
            let m = ops_transform(&follow_ops(&d, c0, &all())).world_from_object;
            assert!(m.abs_diff_eq(d, 1e-9), "{d} vs {m}");
        }
    }

    #[test]
    fn parts_of_the_motion_are_the_parts_asked_for() {
        let turn = DMat4::from_axis_angle(DVec3::Z, 0.7);
        let c0 = DVec3::new(1.0, 0.0, 0.0);
        let moved = DVec3::new(0.0, 5.0, 0.0);
        let d = DMat4::from_translation(moved) * turn * DMat4::from_scale(DVec3::splat(2.0));
        let c1 = d.transform_point3(c0);
        let only = |f: &[Follow]| ops_transform(&follow_ops(&d, c0, f)).world_from_object;
        // Where the centre goes, and nothing else.
        let m = only(&[Follow::Translate]);
        assert!(m.abs_diff_eq(DMat4::from_translation(c1 - c0), 1e-9), "{m}");
        // The turn about the base centre, which stays put.
        let m = only(&[Follow::Rotate]);
        let about = DMat4::from_translation(c0) * turn * DMat4::from_translation(-c0);
        assert!(m.abs_diff_eq(about, 1e-9), "{m}");
        // Turn and move, no scale: a rigid motion taking c0 to c1.
        let m = only(&[Follow::Translate, Follow::Rotate]);
        assert!(m.transform_point3(c0).abs_diff_eq(c1, 1e-9));
        assert!((DMat3::from_mat4(m).determinant() - 1.0).abs() < 1e-9);
    }

    #[test]
    fn a_symmetric_matrix_comes_apart_into_axes_and_sizes() {
        let q = DMat3::from_axis_angle(DVec3::new(0.3, -1.0, 0.2).normalize(), 0.9);
        let s = q * DMat3::from_diagonal(DVec3::new(4.0, -0.5, 2.0)) * q.transpose();
        let (axes, sizes) = symmetric_eigen(s);
        let back = axes * DMat3::from_diagonal(sizes) * axes.transpose();
        assert!(back.abs_diff_eq(s, 1e-12), "{back} vs {s}");
        assert!((axes.determinant() - 1.0).abs() < 1e-12);
        // A diagonal one keeps the world's axes.
        let (axes, sizes) = symmetric_eigen(DMat3::from_diagonal(DVec3::new(1.0, 3.0, 2.0)));
        assert_eq!(axes, DMat3::IDENTITY);
        assert_eq!(sizes, DVec3::new(1.0, 3.0, 2.0));
    }
}
