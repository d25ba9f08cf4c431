//! The orbit helper: a camera circling a point at a fixed radius and height, always looking
//! at its target — the classic turntable shot.

use super::spec_file::Orbit;
use glam::DVec3;

/// Where a camera is and where it looks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    pub eye: DVec3,
    pub dir: DVec3,
    pub up: DVec3,
}

/// The orbit angle in degrees at time `t` of an animation `duration` seconds long:
/// `start_angle + 360°·turns·e(t / duration)`, `e` the orbit's easing (linear by default, so
/// the camera moves at constant speed and a whole number of turns loops seamlessly).
pub fn angle_at(orbit: &Orbit, t: f64, duration: f64) -> f64 {
    let s = if duration > 0.0 { t / duration } else { 0.0 };
    orbit.start_angle + 360.0 * orbit.turns * orbit.interp.ease(s)
}

/// The camera pose at time `t`. Angle 0 puts the eye on the +z side of the centre (so it looks
/// along −z like the default camera), 90° on the +x side: positive turns run counter-clockwise
/// seen from above. `up` is +y; `None` if the eye would look straight up or down (`look_at`
/// directly above or below the eye), where +y cannot serve as up.
pub fn pose_at(orbit: &Orbit, t: f64, duration: f64) -> Option<Pose> {
    let theta = angle_at(orbit, t, duration).to_radians();
    let eye = orbit.center
        + DVec3::new(
            orbit.radius * theta.sin(),
            orbit.height,
            orbit.radius * theta.cos(),
        );
    let dir = orbit.look_at - eye;
    let up = DVec3::Y;
    let len = dir.length();
    if !(len.is_finite() && len > 0.0) || dir.cross(up).length() <= 1e-9 * len {
        return None;
    }
    Some(Pose { eye, dir, up })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::keyframe::interp::Interp;

    fn orbit() -> Orbit {
        Orbit {
            center: DVec3::new(1.0, 2.0, 3.0),
            radius: 10.0,
            height: 4.0,
            turns: 1.0,
            start_angle: 0.0,
            look_at: DVec3::new(1.0, 2.0, 3.0),
            interp: Interp::Linear,
        }
    }

    #[test]
    fn eye_on_the_circle_looking_at_the_centre() {
        let o = orbit();
        for i in 0..120 {
            let p = pose_at(&o, i as f64 / 24.0, 5.0).expect("pose");
            let rel = p.eye - o.center;
            let horizontal = (rel.x * rel.x + rel.z * rel.z).sqrt();
            assert!((horizontal - 10.0).abs() < 1e-9);
            assert!((rel.y - 4.0).abs() < 1e-12);
            // dir points from the eye at the centre.
            let to_centre = (o.center - p.eye).normalize();
            assert!((p.dir.normalize() - to_centre).length() < 1e-12);
        }
    }

    #[test]
    fn quarter_turns_land_on_the_axes() {
        let o = orbit();
        let at = |t: f64| pose_at(&o, t, 4.0).expect("pose").eye - o.center;
        assert!((at(0.0) - DVec3::new(0.0, 4.0, 10.0)).length() < 1e-9);
        assert!((at(1.0) - DVec3::new(10.0, 4.0, 0.0)).length() < 1e-9);
        assert!((at(2.0) - DVec3::new(0.0, 4.0, -10.0)).length() < 1e-9);
        assert!((at(3.0) - DVec3::new(-10.0, 4.0, 0.0)).length() < 1e-9);
    }

    #[test]
    fn looking_straight_down_has_no_pose() {
        let mut o = orbit();
        o.look_at = DVec3::new(1.0, -100.0, 13.0);
        assert!(pose_at(&o, 0.0, 5.0).is_none());
    }
}
