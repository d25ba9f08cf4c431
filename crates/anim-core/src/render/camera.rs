//! The camera model: a pinhole camera with a horizontal field of view, rays through sub-pixel
//! positions, row 0 at the top of the image, and the thin lens a scene may give it
//! (docs/shading.md §1). The renderer's camera rays and the blank-image probe's come from it
//! alike; the probe and adaptive sampling's first pass take its pinhole rays.

use crate::accel::ImageView;
use crate::math::sampling::concentric;
use crate::math::Ray;
use crate::scene::Camera;
use glam::{DVec3, Vec3A};

/// A pinhole camera placed in the scene, with the size of its image, and its thin lens if it
/// has one.
#[derive(Clone, Debug)]
pub struct PinholeCamera {
    /// Its image-plane distance is `(w/2)/tan(fov/2)` pixels.
    view: ImageView,
    /// The angle one pixel spans at the image centre (radians).
    pixel_angle: f32,
    lens: Option<ThinLens>,
}

/// A thin lens around the eye (docs/shading.md §1.1).
#[derive(Clone, Copy, Debug, PartialEq)]
struct ThinLens {
    /// The radius of the aperture (scene units).
    aperture: f32,
    /// The distance of the plane in focus over the image plane's (which is in pixels): a
    /// point of the image plane moved out by this lies in focus.
    focus_scale: f32,
    /// The distance of the plane in focus.
    focus: f32,
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
        let lens = cam.lens.filter(|l| l.aperture > 0.0).map(|l| ThinLens {
            aperture: l.aperture as f32,
            focus_scale: (l.focus / dist) as f32,
            focus: l.focus as f32,
        });
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
            lens,
        })
    }

    /// Whether it has a lens (of some aperture): its rays then leave from the aperture.
    pub fn has_lens(&self) -> bool {
        self.lens.is_some()
    }

    /// The ray through image position (`x`, `y`) from the point of the aperture that `uv` of
    /// the unit square maps to: it meets the pinhole's ray through the same position in the
    /// plane in focus. Without a lens, the pinhole's ray.
    #[inline]
    pub fn lens_ray(&self, x: f32, y: f32, uv: [f32; 2]) -> Ray {
        let Some(lens) = &self.lens else {
            return self.ray(x, y);
        };
        let v = &self.view;
        let focused = v.eye + v.through(x, y) * lens.focus_scale;
        let (u, w) = concentric(uv);
        let from = v.eye + (v.right * u + v.up * w) * lens.aperture;
        Ray::new(from, (focused - from).normalize())
    }

    /// The radius, in pixels, over which the lens spreads a point at `p` (its circle of
    /// confusion), negative for a point nearer than the plane in focus:
    /// `aperture · d · (1/focus − 1/z)` for a point at depth `z` along the view and the image
    /// plane `d` pixels from the eye. 0 without a lens, and in the plane in focus.
    pub fn blur(&self, p: Vec3A) -> f32 {
        let Some(lens) = &self.lens else {
            return 0.0;
        };
        let v = &self.view;
        let d = v.forward.length();
        let z = (p - v.eye).dot(v.forward) / d;
        lens.aperture * d * (1.0 / lens.focus - 1.0 / z)
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

    /// Whether `other` looks the same way through the same image plane (its eye aside; a lens
    /// aside).
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

    fn lensed(aperture: f64, focus: f64) -> PinholeCamera {
        let cam = Camera {
            lens: Some(crate::scene::Lens { aperture, focus }),
            ..Camera::default_with_fov("c", 60.0)
        };
        PinholeCamera::new(&cam, 64, 48).unwrap()
    }

    #[test]
    fn lens_rays_meet_the_pinhole_ray_in_the_plane_in_focus() {
        let lens = lensed(0.5, 7.0);
        let pinhole = PinholeCamera::new(&Camera::default_with_fov("c", 60.0), 64, 48).unwrap();
        for (x, y) in [(32.0, 24.0), (3.5, 40.25), (60.0, 1.0)] {
            let p = pinhole.ray(x, y);
            // Where the pinhole ray reaches depth 7 along the view (−z).
            let focused = p.at(7.0 / -p.dir.z);
            for uv in [[0.1, 0.9], [0.5, 0.5], [0.99, 0.2]] {
                let r = lens.lens_ray(x, y, uv);
                assert!(r.origin.z.abs() < 1e-6 && r.origin.length() <= 0.5 + 1e-6);
                let there = r.at((focused - r.origin).length());
                assert!(there.distance(focused) < 1e-4, "{there} {focused}");
            }
        }
        // The centre of the aperture is the pinhole.
        assert_eq!(lens.lens_ray(10.0, 10.0, [0.5, 0.5]).origin, Vec3A::ZERO);
    }

    #[test]
    fn the_circle_of_confusion_is_the_spread_of_a_point_s_image_over_the_aperture() {
        let lens = lensed(0.25, 5.0);
        let pinhole = PinholeCamera::new(&Camera::default_with_fov("c", 60.0), 64, 48).unwrap();
        let p = Vec3A::new(0.3, -0.2, -12.0);
        // Seen from the rim of the aperture through the point in focus on its line, `p`
        // shows where the pinhole sees it, moved by the radius.
        let (x0, y0) = pinhole.project(p).unwrap();
        let rim = Vec3A::new(0.25, 0.0, 0.0);
        // The lens ray from the rim towards p passes the focus plane at q; the pinhole sees q
        // at the image point whose lens rays all meet there, so p lands there.
        let q = rim + (p - rim) * (5.0 / 12.0);
        let (x1, y1) = pinhole.project(q).unwrap();
        let spread = (x1 - x0).hypot(y1 - y0);
        assert!(
            (spread - lens.blur(p)).abs() < 1e-3,
            "{spread} {}",
            lens.blur(p)
        );
        assert!(lens.blur(Vec3A::new(1.0, 1.0, -5.0)).abs() < 1e-4);
        assert!(lens.blur(Vec3A::new(0.0, 0.0, -2.0)) < 0.0);
        assert_eq!(pinhole.blur(p), 0.0);
    }
}
