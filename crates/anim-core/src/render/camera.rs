//! The camera model: a pinhole camera with a horizontal field of view, rays through sub-pixel
//! positions, row 0 at the top of the image. The renderer's camera rays and the blank-image
//! probe's come from it alike.

use crate::accel::ImageView;
use crate::math::Ray;
use crate::scene::Camera;
use glam::{DVec3, Vec3A};

/// A pinhole camera placed in the scene, with the size of its image.
#[derive(Clone, Debug)]
pub struct PinholeCamera {
    /// Its image-plane distance is `(w/2)/tan(fov/2)` pixels.
    view: ImageView,
    /// The angle one pixel spans at the image centre (radians).
    pixel_angle: f32,
}

/// Why a camera cannot make rays.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CameraError {
    /// The field of view is not between 0° and 180°.
    Fov,
    /// The viewing direction is zero or parallel to the up vector.
    Orientation,
}

impl PinholeCamera {
    /// The camera `cam` for an image of `width` × `height` pixels.
    pub fn new(cam: &Camera, width: u32, height: u32) -> Result<Self, CameraError> {
        if !(cam.fov_x_deg > 0.0 && cam.fov_x_deg < 180.0) {
            return Err(CameraError::Fov);
        }
        let d = cam.dir.try_normalize().ok_or(CameraError::Orientation)?;
        let r = d
            .cross(cam.up)
            .try_normalize()
            .ok_or(CameraError::Orientation)?;
        let u = r.cross(d);
        let dist = (width as f64 / 2.0) / (cam.fov_x_deg.to_radians() / 2.0).tan();
        let v = |x: DVec3| Vec3A::from(x.as_vec3());
        Ok(PinholeCamera {
            view: ImageView {
                eye: v(cam.eye),
                forward: v(d * dist),
                right: v(r),
                up: v(u),
                half_w: width as f32 / 2.0,
                half_h: height as f32 / 2.0,
            },
            pixel_angle: (2.0 * (cam.fov_x_deg.to_radians() / 2.0).tan() / width.max(1) as f64)
                as f32,
        })
    }

    /// Where the rays start.
    pub fn eye(&self) -> Vec3A {
        self.view.eye
    }

    /// The image the rays pass through.
    pub fn view(&self) -> ImageView {
        self.view
    }

    /// The angle one pixel spans at the image centre (radians).
    pub fn pixel_angle(&self) -> f32 {
        self.pixel_angle
    }

    /// World units per pixel at the depth of `p`: a move of the eye by δ across the view
    /// shifts `p`'s image by δ over this (negative: `p` is behind the eye).
    pub fn world_per_pixel(&self, p: Vec3A) -> f32 {
        let v = &self.view;
        (p - v.eye).dot(v.forward) / v.forward.length_squared()
    }

    /// How much a move of the eye along the view shifts an image point at most, against the
    /// same move across it, for points within `margin` pixels beyond the image's edges.
    pub fn reach(&self, margin: f32) -> f32 {
        let v = &self.view;
        1.0 + (v.half_w.hypot(v.half_h) + margin) / v.forward.length()
    }

    /// Whether `other` looks the same way through the same image plane (its eye aside).
    pub fn same_view(&self, other: &PinholeCamera) -> bool {
        ImageView {
            eye: other.view.eye,
            ..self.view
        } == other.view
    }

    /// The image position (pixels from the top-left corner) at which `p` is seen, if it lies
    /// in front of the eye: the inverse of [`PinholeCamera::ray`].
    pub fn project(&self, p: Vec3A) -> Option<(f32, f32)> {
        self.view.pixel_of(p - self.view.eye)
    }

    /// Ray through image position (`x`, `y`) in pixels from the top-left corner.
    #[inline]
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        Ray::new(self.view.eye, self.view.through(x, y).normalize())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_down_minus_z_and_edges_span_the_fov() {
        let cam = Camera::default_with_fov("c", 90.0);
        let rays = PinholeCamera::new(&cam, 200, 100).unwrap();
        let c = rays.ray(100.0, 50.0);
        assert!((c.dir - Vec3A::NEG_Z).length() < 1e-6);
        // The left edge of the image is 45° off axis for a 90° horizontal fov.
        let edge = rays.ray(0.0, 50.0);
        assert!((edge.dir.dot(Vec3A::NEG_Z) - 45f32.to_radians().cos()).abs() < 1e-6);
        assert!(edge.dir.x < 0.0);
        // Row 0 is the top: y grows upwards in the scene.
        assert!(rays.ray(100.0, 0.0).dir.y > 0.0);
    }

    #[test]
    fn project_undoes_ray() {
        let mut cam = Camera::default_with_fov("c", 70.0);
        cam.eye = DVec3::new(1.0, -2.0, 3.0);
        cam.dir = DVec3::new(0.3, -0.2, -1.0);
        let rays = PinholeCamera::new(&cam, 64, 48).unwrap();
        for (x, y) in [(0.5, 0.5), (32.0, 24.0), (63.2, 11.7)] {
            let r = rays.ray(x, y);
            let (px, py) = rays.project(r.at(7.5)).expect("in front");
            assert!((px - x).abs() < 1e-3 && (py - y).abs() < 1e-3, "{px} {py}");
        }
        assert!(rays.project(rays.ray(10.0, 10.0).at(-1.0)).is_none());
    }

    #[test]
    fn degenerate_cameras_are_rejected() {
        let mut cam = Camera::default_with_fov("c", 180.0);
        assert_eq!(
            PinholeCamera::new(&cam, 10, 10).unwrap_err(),
            CameraError::Fov
        );
        cam.fov_x_deg = 60.0;
        cam.up = DVec3::NEG_Z;
        assert_eq!(
            PinholeCamera::new(&cam, 10, 10).unwrap_err(),
            CameraError::Orientation
        );
    }
}
