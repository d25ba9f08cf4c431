//! The scene description: what an SDF file means, with names resolved, transforms composed
//! and the composite tree flattened into instances. It is built here from the statements of
//! `crate::sdf` (or directly in tests) and compiled by `crate::render::compile` into the
//! render scene.

mod build;
mod load;
pub mod probe;
#[cfg(test)]
mod tests;

pub use crate::shape::Geometry;
pub use load::{build, load_file, load_str, read_input, Loaded};

use crate::diag::Loc;
use crate::math::Transform;
use glam::{DVec3, Vec3};
use std::path::PathBuf;

#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    pub ka: Vec3,
    pub kd: Vec3,
    pub ks: Vec3,
    /// Phong exponent.
    pub m: f32,
    /// ρ of the shading model: the share of light reflected as by a mirror, in [0, 1].
    pub reflectivity: f32,
    /// α of the shading model: the share of light the surface stops, in [0, 1]; 1 is opaque.
    pub opacity: f32,
    /// η, index of refraction; the medium outside every object is air (1).
    pub ior: f32,
}

impl Material {
    /// A plain Phong material: opaque, not a mirror.
    pub fn phong(name: &str, ka: Vec3, kd: Vec3, ks: Vec3, m: f32) -> Self {
        Material {
            name: name.to_string(),
            ka,
            kd,
            ks,
            m,
            reflectivity: 0.0,
            opacity: 1.0,
            ior: 1.0,
        }
    }
}

/// One leaf of the composite tree placed in the world. A shape listed in two composites
/// yields two instances.
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    /// Path through the composite tree, e.g. `root/table/leg1`.
    pub name: String,
    pub geometry: Geometry,
    /// Index into `Scene::materials`.
    pub material: usize,
    /// The accumulated world transform (parents' transforms included).
    pub transform: Transform,
    pub loc: Option<Loc>,
}

/// A point light, already in world space. Intensity is brightness · colour.
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    pub name: String,
    pub position: DVec3,
    pub intensity: Vec3,
}

/// A pinhole camera in world space (its transforms already applied). `dir` and `up` need not
/// be unit length or orthogonal; the renderer re-orthonormalises them.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub name: String,
    /// Full horizontal field of view in degrees.
    pub fov_x_deg: f64,
    pub eye: DVec3,
    pub dir: DVec3,
    pub up: DVec3,
}

impl Camera {
    /// At the origin, looking along −z, y up.
    pub fn default_with_fov(name: &str, fov_x_deg: f64) -> Self {
        Camera {
            name: name.to_string(),
            fov_x_deg,
            eye: DVec3::ZERO,
            dir: DVec3::NEG_Z,
            up: DVec3::Y,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Default)]
pub struct Scene {
    pub materials: Vec<Material>,
    pub instances: Vec<Instance>,
    pub lights: Vec<Light>,
    pub ambient: Vec3,
    pub background: Vec3,
}

/// One image to make: the scene as it stands at a `render` statement.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderJob {
    pub scene: Scene,
    pub camera: Camera,
    /// As written in the file (after repairs such as `image . ppm`); relative paths are
    /// resolved by the renderer against the output directory (the SDF file's by default).
    pub output: PathBuf,
    pub width: u32,
    pub height: u32,
    /// Samples per pixel asked for by the `render` line itself.
    pub samples: Option<u32>,
    pub loc: Option<Loc>,
}
