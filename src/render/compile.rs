//! Compiles a scene description into the flat render scene that the integrator touches per
//! ray: primitives in one array, a BVH over the bounded ones, materials in f32 SIMD form.

use super::primitive::{Primitive, SurfaceHit};
use crate::accel::Bvh;
use crate::math::Ray;
use crate::scene::{Material, Scene};
use glam::Vec3A;

#[derive(Clone, Debug)]
pub struct ShadeMaterial {
    pub ka: Vec3A,
    pub kd: Vec3A,
    pub ks: Vec3A,
    pub m: f32,
    pub reflectivity: f32,
    pub opacity: f32,
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

    pub fn is_transparent(&self) -> bool {
        self.opacity < 1.0
    }
}

#[derive(Clone, Debug)]
pub struct PointLight {
    pub position: Vec3A,
    pub intensity: Vec3A,
}

#[derive(Clone, Debug)]
pub struct RenderScene {
    pub prims: Vec<Primitive>,
    bvh: Bvh,
    /// Primitives without finite bounds (planes), tested on every ray.
    unbounded: Vec<u32>,
    pub materials: Vec<ShadeMaterial>,
    pub lights: Vec<PointLight>,
    pub ambient: Vec3A,
    pub background: Vec3A,
    /// Whether any material lets light through: if not, shadow rays stop at the first hit.
    pub any_transparent: bool,
    /// An upper bound of the radiance any ray can carry (per channel max), used to stop
    /// tracing rays whose weight can no longer change the 8-bit result.
    pub max_radiance: f32,
}

/// A primitive that could not be placed (degenerate after transformation).
#[derive(Clone, Debug)]
pub struct Dropped {
    pub instance: String,
    pub loc: Option<crate::diag::Loc>,
}

impl RenderScene {
    pub fn compile(scene: &Scene) -> (RenderScene, Vec<Dropped>) {
        let mut prims = Vec::with_capacity(scene.instances.len());
        let mut dropped = Vec::new();
        for inst in scene.instances.iter() {
            match Primitive::new(
                &inst.geometry,
                scene.transform_of(inst),
                inst.material as u32,
            ) {
                Ok(p) => prims.push(p),
                Err(_) => dropped.push(Dropped {
                    instance: scene.instance_name(inst),
                    loc: scene.instance_loc(inst),
                }),
            }
        }
        let bounds: Vec<_> = prims.iter().map(|p| p.bounds).collect();
        let (bounded, unbounded): (Vec<u32>, Vec<u32>) =
            (0..prims.len() as u32).partition(|&i| prims[i as usize].is_bounded());
        let bvh = Bvh::build(&bounds, bounded);
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
        let used = |i: usize| prims.iter().any(|p| p.material as usize == i);
        let any_transparent = materials
            .iter()
            .enumerate()
            .any(|(i, m)| m.is_transparent() && used(i));
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
        let scene = RenderScene {
            prims,
            bvh,
            unbounded,
            materials,
            lights,
            ambient,
            background,
            any_transparent,
            max_radiance,
        };
        (scene, dropped)
    }

    /// Nearest surface along the ray with `t < t_max`.
    #[inline]
    pub fn closest(&self, ray: &Ray, t_max: f32) -> Option<(u32, SurfaceHit)> {
        let mut best = None;
        let mut t_best = t_max;
        for &i in &self.unbounded {
            if let Some(h) = self.prims[i as usize].hit(ray, t_best) {
                t_best = h.t;
                best = Some((i, h));
            }
        }
        self.bvh.closest(ray, t_best, |i, t_max| {
            let h = self.prims[i as usize].hit(ray, t_max)?;
            best = Some((i, h));
            Some(h.t)
        });
        best.map(|(i, h)| (i, self.prims[i as usize].surface(&h)))
    }

    /// Whether anything lies on the ray before `t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        self.any_candidate(ray, t_max, |i| {
            self.prims[i as usize].hit(ray, t_max).is_some()
        })
    }

    /// Offers every primitive the ray may meet before `t_max` to `stop`, in no particular
    /// order, until it returns true (then true).
    #[inline]
    pub fn any_candidate(&self, ray: &Ray, t_max: f32, mut stop: impl FnMut(u32) -> bool) -> bool {
        self.unbounded.iter().any(|&i| stop(i)) || self.bvh.any(ray, t_max, stop)
    }
}
