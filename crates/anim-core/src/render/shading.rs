//! The shading part of a compiled scene: materials in f32 SIMD form, point lights (and where
//! the moving ones are at an instant), the ambient light and the background, and the bounds
//! the integrator stops rays by (docs/shading.md).

use crate::scene::motion::Motion;
use crate::scene::{Material, Scene};
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

/// A point light: where it is (in the middle of the exposure, if it moves) and its intensity.
#[derive(Clone, Debug)]
pub struct PointLight {
    /// Where it is (camera-relative).
    pub position: Vec3A,
    /// Brightness times colour, per channel.
    pub intensity: Vec3A,
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
            })
            .collect();
        let ambient: Vec3A = scene.ambient.into();
        let background: Vec3A = scene.background.into();
        let any_transparent = materials
            .iter()
            .zip(used)
            .any(|(m, &used)| m.is_transparent() && used);
        let max_radiance = bound_radiance(&materials, &lights, ambient, background);
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

/// [`Shading::max_radiance`] of `scene`.
pub fn max_radiance(scene: &Scene) -> f32 {
    let materials: Vec<ShadeMaterial> = scene.materials.iter().map(ShadeMaterial::from).collect();
    let lights: Vec<PointLight> = scene
        .lights
        .iter()
        .map(|l| PointLight {
            position: Vec3A::ZERO,
            intensity: l.intensity.into(),
        })
        .collect();
    bound_radiance(
        &materials,
        &lights,
        scene.ambient.into(),
        scene.background.into(),
    )
}

/// An upper bound of the radiance any ray can carry under `materials`, `lights`, `ambient`
/// and `background`. Every shaded colour is a convex combination of local colours and the
/// background (the weights in docs/shading.md §3 sum to 1), so the largest local colour
/// bounds them all.
fn bound_radiance(
    materials: &[ShadeMaterial],
    lights: &[PointLight],
    ambient: Vec3A,
    background: Vec3A,
) -> f32 {
    let total_light: Vec3A = lights.iter().map(|l| l.intensity.max(Vec3A::ZERO)).sum();
    let max_local = materials
        .iter()
        .map(|m| {
            (m.ka * ambient + total_light * (m.kd.max(Vec3A::ZERO) + m.ks.max(Vec3A::ZERO)))
                .max_element()
        })
        .fold(0.0f32, f32::max);
    max_local.max(background.max_element())
}

/// Where light `k` of `positions`, moved by `motion`, is at `time`.
#[inline(never)]
fn light_at((motion, positions): &(Arc<Motion>, Vec<DVec3>), k: usize, time: f32) -> Vec3A {
    let p = positions
        .get(k)
        .map_or(DVec3::ZERO, |&p| motion.light_position(k, p, time as f64));
    Vec3A::from(p.as_vec3())
}
