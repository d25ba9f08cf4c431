//! Orientations: Euler angles in a stated order, the turn that makes one direction face
//! another, and the axis and angle a frame file writes. Quaternions throughout, so that keyed
//! orientations interpolate by slerp (`spec_file::model::OrientChannel`).

use glam::{DMat3, DQuat, DVec3};
use serde::Deserialize;

/// The order in which Euler angles turn, about the parent's fixed axes: `XYZ` turns about x,
/// then y, then z (the same rotation as turning about the object's own z, then y', then x'').
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Deserialize)]
#[allow(clippy::upper_case_acronyms)]
pub enum EulerOrder {
    #[default]
    XYZ,
    XZY,
    YXZ,
    YZX,
    ZXY,
    ZYX,
}

impl EulerOrder {
    /// The axes in the order they turn (0 = x).
    fn axes(self) -> [usize; 3] {
        match self {
            EulerOrder::XYZ => [0, 1, 2],
            EulerOrder::XZY => [0, 2, 1],
            EulerOrder::YXZ => [1, 0, 2],
            EulerOrder::YZX => [1, 2, 0],
            EulerOrder::ZXY => [2, 0, 1],
            EulerOrder::ZYX => [2, 1, 0],
        }
    }
}

/// The rotation of Euler angles `degrees` (about x, y and z), turned in `order` about the
/// parent's fixed axes: the first axis of the order turns first.
pub fn euler(degrees: DVec3, order: EulerOrder) -> DQuat {
    order.axes().iter().fold(DQuat::IDENTITY, |q, &axis| {
        let unit = DVec3::AXES[axis];
        DQuat::from_axis_angle(unit, degrees[axis].to_radians()) * q
    })
}

/// A right-handed frame looking along `forward` with `up` kept up: right, true up, backwards
/// as columns. `None` when `forward` is zero or parallel to `up`.
fn look_basis(forward: DVec3, up: DVec3) -> Option<DMat3> {
    let f = forward.try_normalize()?;
    let r = f.cross(up).try_normalize()?;
    // Nearly parallel: the cross product is tiny and its direction is noise.
    if f.cross(up).length() <= 1e-9 * up.length() {
        return None;
    }
    Some(DMat3::from_cols(r, r.cross(f), -f))
}

/// The turn that takes a thing facing `from` (with `up` up) to face `to` (with `up` up), then
/// rolls it `roll_degrees` about its line of sight. `None` when either direction is zero or
/// parallel to `up`.
pub fn facing(from: DVec3, to: DVec3, up: DVec3, roll_degrees: f64) -> Option<DQuat> {
    let turn = look_basis(to, up)? * look_basis(from, up)?.transpose();
    let aim = DQuat::from_mat3(&turn).normalize();
    let roll = DQuat::from_axis_angle(to.normalize(), roll_degrees.to_radians());
    Some((roll * aim).normalize())
}

/// `up` turned `roll_degrees` about the line of sight `dir`.
pub fn rolled_up(dir: DVec3, up: DVec3, roll_degrees: f64) -> DVec3 {
    if roll_degrees == 0.0 {
        return up;
    }
    DQuat::from_axis_angle(dir.normalize(), roll_degrees.to_radians()) * up
}

/// Whether a camera at `eye` can look at `target` with `up` up.
pub fn can_look(eye: DVec3, target: DVec3, up: DVec3) -> bool {
    look_basis(target - eye, up).is_some()
}

/// The axis and angle (degrees, 0–180) of a rotation, as a frame's `rotate` writes it; the
/// angle is 0 for no turn.
pub fn axis_degrees(q: DQuat) -> (DVec3, f64) {
    // q and −q are one rotation: the one with w ≥ 0 turns 180° at most.
    let q = if q.w < 0.0 { -q } else { q };
    let (axis, angle) = q.normalize().to_axis_angle();
    if !axis.is_finite() || angle == 0.0 {
        return (DVec3::Y, 0.0);
    }
    (axis, angle.to_degrees())
}

/// The angle in degrees between two orientations, along the shorter arc.
pub fn angle_between(a: DQuat, b: DQuat) -> f64 {
    let d = a.dot(b).abs().min(1.0);
    (2.0 * d.acos()).to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DVec3, b: DVec3) {
        assert!((a - b).length() < 1e-12, "{a} != {b}");
    }

    #[test]
    fn single_euler_angles_turn_right_handed() {
        // 90° about x takes +y to +z; about y takes +z to +x; about z takes +x to +y.
        close(
            euler(DVec3::new(90.0, 0.0, 0.0), EulerOrder::XYZ) * DVec3::Y,
            DVec3::Z,
        );
        close(
            euler(DVec3::new(0.0, 90.0, 0.0), EulerOrder::XYZ) * DVec3::Z,
            DVec3::X,
        );
        close(
            euler(DVec3::new(0.0, 0.0, 90.0), EulerOrder::XYZ) * DVec3::X,
            DVec3::Y,
        );
    }

    #[test]
    fn the_order_decides_which_axis_turns_first() {
        // +x under XYZ (90, 90, 0): about x, +x stays; then about y, +x goes to −z.
        let angles = DVec3::new(90.0, 90.0, 0.0);
        close(euler(angles, EulerOrder::XYZ) * DVec3::X, -DVec3::Z);
        // Under YXZ: about y first, +x goes to −z; then about x, −z goes to +y.
        close(euler(angles, EulerOrder::YXZ) * DVec3::X, DVec3::Y);
        // ZYX (30, 0, 0) is the same as XYZ with one angle: the order of one turn is moot.
        let one = DVec3::new(30.0, 0.0, 0.0);
        let (a, b) = (euler(one, EulerOrder::ZYX), euler(one, EulerOrder::XYZ));
        assert!(a.abs_diff_eq(b, 1e-15));
    }

    #[test]
    fn a_hand_computed_euler_rotation() {
        // XYZ (0, 90, 90): about y, +x → −z; then about z, −z stays. And +y: about y stays
        // +y, then about z +y → −x.
        let q = euler(DVec3::new(0.0, 90.0, 90.0), EulerOrder::XYZ);
        close(q * DVec3::X, -DVec3::Z);
        close(q * DVec3::Y, -DVec3::X);
        // And +z: about y → +x, then about z → +y.
        close(q * DVec3::Z, DVec3::Y);
    }

    #[test]
    fn slerp_halfway_turns_half_the_angle() {
        let a = DQuat::IDENTITY;
        let b = DQuat::from_axis_angle(DVec3::Z, 90f64.to_radians());
        let half = a.slerp(b, 0.5);
        // Halfway: 45° about z, +x at (cos 45°, sin 45°, 0).
        let s = 0.5f64.sqrt();
        close(half * DVec3::X, DVec3::new(s, s, 0.0));
        assert!((angle_between(a, half) - 45.0).abs() < 1e-9);
    }

    #[test]
    fn facing_turns_one_direction_onto_another() {
        let q = facing(-DVec3::Z, DVec3::X, DVec3::Y, 0.0).expect("not parallel");
        close(q * -DVec3::Z, DVec3::X);
        close(q * DVec3::Y, DVec3::Y);
        // A roll of 90° about the line of sight (+x) takes up (+y) to +z.
        let rolled = facing(-DVec3::Z, DVec3::X, DVec3::Y, 90.0).expect("not parallel");
        close(rolled * DVec3::Y, DVec3::Z);
        close(rolled * -DVec3::Z, DVec3::X);
        assert!(facing(-DVec3::Z, DVec3::Y, DVec3::Y, 0.0).is_none());
        close(rolled_up(DVec3::X, DVec3::Y, 90.0), DVec3::Z);
    }

    #[test]
    fn axis_and_degrees_of_a_turn() {
        let q = DQuat::from_axis_angle(DVec3::new(0.0, 0.0, 1.0), 270f64.to_radians());
        // 270° about +z is 90° about −z.
        let (axis, degrees) = axis_degrees(q);
        assert!((degrees - 90.0).abs() < 1e-9, "{degrees}");
        close(axis, -DVec3::Z);
        assert_eq!(axis_degrees(DQuat::IDENTITY).1, 0.0);
    }
}
