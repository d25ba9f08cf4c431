//! The shading part of a compiled scene: materials in f32 SIMD form, lights (and where the
//! moving ones are at an instant; the cone a spot shines into; the disc a spherical light
//! shows a point), the ambient light and the background, and the bounds the integrator stops
//! rays by (docs/shading.md).

use crate::math::sampling::{concentric, orthonormal_pair};
use crate::scene::motion::Motion;
use crate::scene::{Material, Scene, Spot};
use glam::{DVec3, Vec3A};
use std::sync::Arc;

/// A material as the integrator reads it; reflectivity and opacity clamped to [0, 1].
#[derive(Clone, Debug)]
pub struct ShadeMaterial {
    /// Ambient reflectance, per channel.
    pub ka: Vec3A,
    /// Diffuse reflectance, per channel.
    pub kd: Vec3A,
    /// Specular reflectance, per channel.
    pub ks: Vec3A,
    /// Phong exponent of the highlight.
    pub m: f32,
    /// Share of light mirrored, in [0, 1].
    pub reflectivity: f32,
    /// Share of light the surface stops, in [0, 1] (1: opaque).
    pub opacity: f32,
    /// Index of refraction of what the surface encloses.
    pub ior: f32,
}

impl ShadeMaterial {
    fn from(m: &Material) -> Self {
        ShadeMaterial {
            ka: m.ka.into(),
            kd: m.kd.into(),
            ks: m.ks.into(),
            m: m.m,
            reflectivity: m.reflectivity.clamp(0.0, 1.0),
            opacity: m.opacity.clamp(0.0, 1.0),
            ior: m.ior,
        }
    }

    /// Whether light passes through it.
    pub fn is_transparent(&self) -> bool {
        self.opacity < 1.0
    }
}

/// A light: where it is (in the middle of the exposure, if it moves), its intensity, and the
/// radius of the sphere it is (0 for a point) and the cone it shines into, if any.
#[derive(Clone, Debug)]
pub struct PointLight {
    /// Where it is (camera-relative): the centre of its sphere.
    pub position: Vec3A,
    /// Brightness times colour, per channel.
    pub intensity: Vec3A,
    /// The radius of its sphere; 0 for a point light.
    pub radius: f32,
    /// The cone of a spot light.
    pub spot: Option<SpotCone>,
}

/// The cone a spot light shines into (docs/shading.md §2.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotCone {
    /// The unit direction of its axis, from the light towards its target.
    pub axis: Vec3A,
    /// The cosine of the half-angle inside which it shines in full.
    pub cos_inner: f32,
    /// The cosine of the half-angle beyond which it does not shine.
    pub cos_outer: f32,
}

impl SpotCone {
    /// The cone of `spot`, for a light at `position`.
    fn new(spot: &Spot, position: DVec3) -> SpotCone {
        let axis = (spot.target - position).normalize_or_zero();
        SpotCone {
            axis: Vec3A::from(axis.as_vec3()),
            cos_inner: spot.inner_deg.to_radians().cos() as f32,
            cos_outer: spot.outer_deg.to_radians().cos() as f32,
        }
    }

    /// The share of the light's intensity sent along unit direction `dir` (from the light):
    /// 1 inside the inner cone, 0 outside the outer one, and between them smoothstep of the
    /// cosine, as pbrt's and POV-Ray's spot lights fall off.
    #[inline]
    pub fn factor(&self, dir: Vec3A) -> f32 {
        let cos = self.axis.dot(dir);
        if cos >= self.cos_inner {
            return 1.0;
        }
        if cos <= self.cos_outer {
            return 0.0;
        }
        let t = (cos - self.cos_outer) / (self.cos_inner - self.cos_outer);
        t * t * (3.0 - 2.0 * t)
    }
}

/// The disc a spherical light of `radius` about `centre` shows from a point in direction
/// `axis` (unit, from the point to the centre): a sphere of even brightness looks like an
/// evenly bright disc across the line of sight. Its points are those of the unit disc, taken
/// across `axis` (docs/shading.md §2.1).
#[derive(Clone, Copy, Debug)]
pub struct LightDisc {
    /// The centre of the light.
    pub centre: Vec3A,
    /// The radius of the light.
    pub radius: f32,
    /// Two unit vectors across the line of sight, at right angles to each other.
    pub across: [Vec3A; 2],
}

impl LightDisc {
    /// The disc of a light of `radius` about `centre`, seen along unit direction `axis`.
    #[inline]
    pub fn new(centre: Vec3A, radius: f32, axis: Vec3A) -> LightDisc {
        LightDisc {
            centre,
            radius,
            across: orthonormal_pair(axis),
        }
    }

    /// The point of the disc at `(u, v)` of the unit disc.
    #[inline]
    pub fn at(&self, (u, v): (f32, f32)) -> Vec3A {
        self.centre + (self.across[0] * u + self.across[1] * v) * self.radius
    }

    /// The point of the disc that the point `uv` of the unit square maps to (Shirley and
    /// Chiu's concentric map, which keeps strata of the square strata of the disc, of even
    /// area).
    #[inline]
    pub fn sample(&self, uv: [f32; 2]) -> Vec3A {
        self.at(concentric(uv))
    }
}

/// Materials, lights, ambient and background of a compiled scene.
#[derive(Clone, Debug)]
pub struct Shading {
    /// Every material, by index.
    pub materials: Vec<ShadeMaterial>,
    /// Every light.
    pub lights: Vec<PointLight>,
    /// The ambient light, per channel.
    pub ambient: Vec3A,
    /// What a ray that meets nothing sees.
    pub background: Vec3A,
    /// Whether a material some primitive draws with lets light through: if not, shadow rays
    /// stop at the first hit.
    pub any_transparent: bool,
    /// An upper bound of the radiance any ray can carry (per channel max), used to stop
    /// tracing rays whose weight can no longer change the 8-bit result.
    pub max_radiance: f32,
    /// The motion of the lights that move, with every light's position as the scene places
    /// it (f64, as the motion keys place it).
    light_motion: Option<(Arc<Motion>, Vec<DVec3>)>,
}

impl Shading {
    /// The shading data of `scene`; `used` says which materials some primitive draws with.
    pub fn new(scene: &Scene, used: &[bool]) -> Shading {
        let materials: Vec<ShadeMaterial> =
            scene.materials.iter().map(ShadeMaterial::from).collect();
        let lights: Vec<PointLight> = scene
            .lights
            .iter()
            .map(|l| PointLight {
                position: l.position.as_vec3().into(),
                intensity: l.intensity.into(),
                radius: l.radius as f32,
                spot: l.spot.as_ref().map(|s| SpotCone::new(s, l.position)),
            })
            .collect();
        let ambient: Vec3A = scene.ambient.into();
        let background: Vec3A = scene.background.into();
        let any_transparent = materials
            .iter()
            .zip(used)
            .any(|(m, &used)| m.is_transparent() && used);
        // Every shaded colour is a convex combination of local colours and the background
        // (the weights in docs/shading.md §3 sum to 1), so the largest local colour bounds them all.
        let total_light: Vec3A = lights.iter().map(|l| l.intensity.max(Vec3A::ZERO)).sum();
        let max_local = materials
            .iter()
            .map(|m| {
                (m.ka * ambient + total_light * (m.kd.max(Vec3A::ZERO) + m.ks.max(Vec3A::ZERO)))
                    .max_element()
            })
            .fold(0.0f32, f32::max);
        let max_radiance = max_local.max(background.max_element());
        let light_motion = scene
            .motion
            .as_ref()
            .filter(|m| m.moves_lights())
            .map(|m| (m.clone(), scene.lights.iter().map(|l| l.position).collect()));
        Shading {
            materials,
            lights,
            ambient,
            background,
            any_transparent,
            max_radiance,
            light_motion,
        }
    }

    /// Whether some light is a sphere (of radius above 0).
    pub fn any_spherical(&self) -> bool {
        self.lights.iter().any(|l| l.radius > 0.0)
    }

    /// Whether a light moves during the exposure.
    pub fn lights_move(&self) -> bool {
        self.light_motion.is_some()
    }

    /// Where light `k` is at `time` (its position unless it moves).
    #[inline(always)]
    pub fn light_position(&self, k: usize, light: &PointLight, time: f32) -> Vec3A {
        match &self.light_motion {
            None => light.position,
            Some(m) => light_at(m, k, time),
        }
    }
}

/// Where light `k` of `positions`, moved by `motion`, is at `time`.
#[inline(never)]
fn light_at((motion, positions): &(Arc<Motion>, Vec<DVec3>), k: usize, time: f32) -> Vec3A {
    let p = positions
        .get(k)
        .map_or(DVec3::ZERO, |&p| motion.light_position(k, p, time as f64));
    Vec3A::from(p.as_vec3())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spot_shines_in_full_inside_its_inner_cone_and_not_at_all_outside_its_outer_one() {
        let spot = Spot {
            target: DVec3::new(0.0, -1.0, 0.0),
            inner_deg: 20.0,
            outer_deg: 40.0,
        };
        let cone = SpotCone::new(&spot, DVec3::ZERO);
        let at = |deg: f32| {
            let r = deg.to_radians();
            cone.factor(Vec3A::new(r.sin(), -r.cos(), 0.0))
        };
        assert_eq!(at(0.0), 1.0);
        assert_eq!(at(19.9), 1.0);
        assert_eq!(at(40.1), 0.0);
        assert_eq!(at(90.0), 0.0);
        // Halfway in cosine, smoothstep is one half; it falls all the way between.
        let mid = ((20f32.to_radians().cos() + 40f32.to_radians().cos()) / 2.0).acos();
        assert!((at(mid.to_degrees()) - 0.5).abs() < 1e-4);
        let falls = (20..=40).map(|d| at(d as f32)).collect::<Vec<_>>();
        assert!(falls.windows(2).all(|w| w[1] <= w[0]), "{falls:?}");
    }

    #[test]
    fn a_disc_lies_across_its_axis() {
        for axis in [
            Vec3A::X,
            Vec3A::NEG_Z,
            Vec3A::new(0.3, -0.4, 0.866).normalize(),
        ] {
            let disc = LightDisc::new(Vec3A::new(1.0, 2.0, 3.0), 0.5, axis);
            let [e1, e2] = disc.across;
            assert!(e1.dot(axis).abs() < 1e-6 && e2.dot(axis).abs() < 1e-6);
            assert!(e1.dot(e2).abs() < 1e-6);
            assert!((e1.length() - 1.0).abs() < 1e-6 && (e2.length() - 1.0).abs() < 1e-6);
            let rim = disc.sample([1.0, 0.5]);
            assert!(((rim - disc.centre).length() - 0.5).abs() < 1e-5);
        }
    }
}
