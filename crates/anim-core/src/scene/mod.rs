//! The scene description: what an SDF file means, with names resolved, transforms composed
//! and the composite tree flattened into instances. It is built here from the statements of
//! `crate::sdf` (or directly in tests) and compiled by `crate::render::compile` into the
//! render scene.

mod builder;
mod instancing;
pub mod motion;

pub use crate::shape::Geometry;
pub use builder::build_jobs;
pub use instancing::{Instanced, Placed, Prototype, Use};

use crate::diag::Loc;
use crate::math::Transform;
use glam::{DVec3, Vec3};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// How a surface reflects light: the coefficients of the shading model (`docs/shading.md`
/// §2 and §3), one value per RGB channel where the model has a colour.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// The name its definition gives it.
    pub name: String,
    /// Ka: the ambient reflection coefficient, the share of the ambient light reflected.
    pub ka: Vec3,
    /// Kd: the diffuse reflection coefficient.
    pub kd: Vec3,
    /// Ks: the specular reflection coefficient, the strength of the Phong highlight.
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
/// yields two instances. Kept small, as a scene may hold millions: its world transform, name
/// and source location are looked up in its [`Scene`] ([`Scene::transform_of`],
/// [`Scene::instance_name`], [`Scene::instance_loc`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    /// The primitive, in its object space: as its statement writes it, before `transform`.
    pub geometry: Geometry,
    /// Index into `Scene::materials`.
    pub material: usize,
    /// Index into `Scene::transforms`: the accumulated world transform (parents' transforms
    /// included). Instances under no transform share slot 0, so they cost nothing for it.
    pub transform: u32,
    /// The object it is drawn from, in `Scene::names` ([`NO_NAME`] for none).
    pub object: u32,
    /// The composite it is listed in, as a path node of `Scene::names` ([`NO_NAME`] at the
    /// top of the tree).
    pub parent: u32,
}

/// No name or path node: an instance made by a program, or one at the top of the tree.
pub const NO_NAME: u32 = u32::MAX;

impl Instance {
    /// An instance with no name, placed by transform slot 0 (the identity unless the whole
    /// scene was moved): for scenes made by programs.
    pub fn new(geometry: Geometry, material: usize) -> Self {
        Instance {
            geometry,
            material,
            transform: 0,
            object: NO_NAME,
            parent: NO_NAME,
        }
    }
}

/// The names of a scene's objects and where they are defined, and the composite paths its
/// instances are listed under: what diagnostics name an instance by (`root/table/leg1`),
/// built only when one is needed. Shared by the jobs of a file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Names {
    /// Every object name, one after the other.
    text: String,
    objects: Vec<ObjectName>,
    files: Vec<Arc<Path>>,
    paths: Vec<PathNode>,
}

/// An object's name (ending at `end` in `Names::text`) and its definition's location.
#[derive(Clone, Copy, Debug, PartialEq)]
struct ObjectName {
    end: u32,
    file: u32,
    line: u32,
    col: u32,
}

/// A composite as listed on one path through the tree.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PathNode {
    parent: u32,
    object: u32,
}

impl Names {
    /// Records an object's name and location; its id.
    pub fn add_object(&mut self, name: &str, loc: &Loc) -> u32 {
        let file = self.file_id(&loc.file);
        self.add_object_in(name, file, loc.line, loc.col)
    }

    /// The id of `file` among the files of the objects, recorded if new.
    pub fn file_id(&mut self, file: &Arc<Path>) -> u32 {
        let i = match self.files.iter().rposition(|f| Arc::ptr_eq(f, file)) {
            Some(i) => i,
            None => {
                self.files.push(file.clone());
                self.files.len() - 1
            }
        };
        i as u32
    }

    /// Records an object's name and location, in file `file` (from [`Names::file_id`]); its
    /// id.
    pub fn add_object_in(&mut self, name: &str, file: u32, line: u32, col: u32) -> u32 {
        self.text.push_str(name);
        self.objects.push(ObjectName {
            end: u32::try_from(self.text.len()).unwrap_or(u32::MAX),
            file,
            line,
            col,
        });
        (self.objects.len() - 1) as u32
    }

    /// Room for `objects` more objects whose names take `bytes` bytes together.
    pub fn reserve(&mut self, objects: usize, bytes: usize) {
        self.objects.reserve_exact(objects);
        self.text.reserve_exact(bytes);
    }

    /// Records composite `object` listed under path node `parent`; the new path node's id.
    pub fn add_path(&mut self, parent: u32, object: u32) -> u32 {
        self.paths.push(PathNode { parent, object });
        (self.paths.len() - 1) as u32
    }

    fn object_name(&self, id: u32) -> &str {
        let i = id as usize;
        let Some(o) = self.objects.get(i) else {
            return "";
        };
        let start = if i == 0 {
            0
        } else {
            self.objects[i - 1].end as usize
        };
        self.text.get(start..o.end as usize).unwrap_or("")
    }
}

/// A light, already in world space: a point, or a sphere about it, shining everywhere or
/// into a cone (docs/shading.md §2). Intensity is brightness · colour.
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    /// The name its definition gives it.
    pub name: String,
    /// Where the light is (the centre of its sphere), in world space.
    pub position: DVec3,
    /// `I_l` of the shading model per channel, not limited to [0, 1]; it does not fall off
    /// with distance.
    pub intensity: Vec3,
    /// The radius of the sphere it is; 0 for a point light.
    pub radius: f64,
    /// The cone a spot light shines into; `None` for a light that shines everywhere.
    pub spot: Option<Spot>,
}

impl Light {
    /// A point light shining everywhere.
    pub fn point(name: &str, position: DVec3, intensity: Vec3) -> Light {
        Light {
            name: name.to_string(),
            position,
            intensity,
            radius: 0.0,
            spot: None,
        }
    }
}

/// The cone of a spot light, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spot {
    /// A point on the cone's axis, away from the light.
    pub target: DVec3,
    /// The half-angle inside which the light shines in full, in degrees.
    pub inner_deg: f64,
    /// The half-angle beyond which it does not shine, in degrees (at least `inner_deg`).
    pub outer_deg: f64,
}

/// A camera's thin lens (docs/shading.md §1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lens {
    /// The radius of the aperture, in scene units; above 0 (a camera without a lens is a
    /// pinhole).
    pub aperture: f64,
    /// How far in front of the eye, along the view direction, the plane in focus lies.
    pub focus: f64,
}

/// A camera in world space (its transforms already applied). `dir` and `up` need not
/// be unit length or orthogonal; the renderer re-orthonormalises them.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// The name its definition gives it, by which `render` lines choose it.
    pub name: String,
    /// Full horizontal field of view in degrees.
    pub fov_x_deg: f64,
    /// The eye point, in world space.
    pub eye: DVec3,
    /// The direction the camera looks in, in world space.
    pub dir: DVec3,
    /// The direction that shows as up in the image, in world space.
    pub up: DVec3,
    /// Its thin lens; `None` for a pinhole camera.
    pub lens: Option<Lens>,
}

impl Camera {
    /// At the origin, looking along −z, y up; a pinhole.
    pub fn default_with_fov(name: &str, fov_x_deg: f64) -> Self {
        Camera {
            name: name.to_string(),
            fov_x_deg,
            eye: DVec3::ZERO,
            dir: DVec3::NEG_Z,
            up: DVec3::Y,
            lens: None,
        }
    }
}

/// What there is to see: the placed shapes, their materials, the lights, the ambient light and
/// the background, in world space.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Scene {
    /// The materials, by `Instance::material`.
    pub materials: Vec<Material>,
    /// Shared by the jobs of a file: they differ only in their transforms.
    pub instances: Arc<Vec<Instance>>,
    /// World transforms of the instances, by `Instance::transform`; an empty table holds the
    /// identity in slot 0.
    pub transforms: Vec<Transform>,
    /// The names of the objects and composite paths, for diagnostics; shared by the jobs.
    pub names: Arc<Names>,
    /// The point lights.
    pub lights: Vec<Light>,
    /// The ambient light `I_ambient` of the shading model, per channel.
    pub ambient: Vec3,
    /// The radiance of rays that hit nothing, per channel, tone-mapped like every other; black
    /// unless the file says otherwise.
    pub background: Vec3,
    /// Composites kept once and drawn by their uses (see [`Instanced`]); shared by the jobs.
    pub instanced: Arc<Instanced>,
    /// The transforms the statements give the objects moved inside prototypes, by the
    /// index in `Prototype::slots`.
    pub local_transforms: Vec<Transform>,
    /// The transforms [`Scene::transform_all`] applied, in order: applied last to the shapes
    /// of prototypes, as to every slot of `transforms`.
    pub moves: Vec<Transform>,
    /// `transforms` before the first of `moves`, kept when the scene has prototypes (their
    /// uses are placed from it).
    pub unmoved: Vec<Transform>,
    /// What moves while the shutter is open; `None` when nothing does (a frame without
    /// `motion` lines), and then nothing of the renderer's motion machinery runs.
    pub motion: Option<Arc<motion::Motion>>,
}

impl Scene {
    /// The world transform of `instance`.
    pub fn transform_of(&self, instance: &Instance) -> &Transform {
        self.transforms
            .get(instance.transform as usize)
            .unwrap_or(&Transform::IDENTITY)
    }

    /// Moves every instance by `t` (applied after its own transform), without copying them.
    pub fn transform_all(&mut self, t: &Transform) {
        if self.transforms.is_empty() {
            self.transforms.push(Transform::IDENTITY);
        }
        if self.has_prototypes() {
            if self.moves.is_empty() {
                self.unmoved = self.transforms.clone();
            }
            self.moves.push(*t);
        }
        for m in &mut self.transforms {
            *m = t.then_after(m);
        }
        if let Some(motion) = &mut self.motion {
            let motion = Arc::make_mut(motion);
            motion.after = t.then_after(&motion.after);
        }
    }

    /// Adds an instance.
    pub fn push_instance(&mut self, instance: Instance) {
        Arc::make_mut(&mut self.instances).push(instance);
    }

    /// The path of `instance` through the composite tree, e.g. `root/table/leg1`.
    pub fn instance_name(&self, instance: &Instance) -> String {
        let names = &self.names;
        let mut parts = vec![names.object_name(instance.object)];
        let mut node = instance.parent;
        // A path is at most as long as composites nest; the bound guards a malformed table.
        while let Some(p) = names.paths.get(node as usize) {
            if parts.len() > crate::limits::MAX_NESTING + 1 {
                break;
            }
            parts.push(names.object_name(p.object));
            node = p.parent;
        }
        parts.reverse();
        parts.join("/")
    }

    /// Where the object `instance` is drawn from is defined.
    pub fn instance_loc(&self, instance: &Instance) -> Option<Loc> {
        let o = self.names.objects.get(instance.object as usize)?;
        Some(Loc {
            file: self.names.files.get(o.file as usize)?.clone(),
            line: o.line,
            col: o.col,
        })
    }
}

/// One image to make: the scene as it stands at a `render` statement.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderJob {
    /// The scene as it stands at the `render` line.
    pub scene: Scene,
    /// The camera the `render` line names, placed as it stands there.
    pub camera: Camera,
    /// As written in the file (after repairs such as `image . ppm`); relative paths are
    /// resolved by the renderer against the output directory (the SDF file's by default).
    pub output: PathBuf,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel asked for by the `render` line itself.
    pub samples: Option<u32>,
    /// Where the `render` line is; `None` for the image of a file without one (its first
    /// camera, or the default one, at the default size).
    pub loc: Option<Loc>,
}
