//! Every definition of a file, final versions, with its values checked when the statements
//! did not come through the reader.

use super::{At, Builder};
use crate::diag::Severity;
use crate::limits::{clamp_fraction, fov_is_valid, FOV_RULE};
use crate::scene::{Geometry, Material};
use crate::sdf::ast::{
    CameraDef, LensDef, LightDef, MaterialDef, MotionDef, NameRef, Statement, StatementKind,
    TransformOp,
};
use crate::sdf::repair;
use crate::shape::geometry::{is_zero, parallel};
use crate::shape::{degeneracy, MeshFile};
use glam::{DVec3, Vec3};
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// A shape or composite.
pub(super) struct Object<'s> {
    pub(super) name: &'s str,
    /// The statement that defines it.
    pub(super) statement: &'s Statement,
    pub(super) kind: ObjectKind<'s>,
}

pub(super) enum ObjectKind<'s> {
    /// `material` is `None` when it could not be resolved (reported) or the shape is
    /// degenerate: the shape is then not drawn.
    Shape {
        geometry: &'s Geometry,
        material: Option<usize>,
    },
    /// The children that resolved.
    Composite { children: Vec<&'s str> },
}

/// Every definition of the file, final versions (a later duplicate replaces the earlier).
#[derive(Default)]
pub(super) struct Definitions<'s> {
    pub(super) materials: Vec<Material>,
    pub(super) material_index: HashMap<&'s str, usize>,
    pub(super) objects: Vec<Object<'s>>,
    /// Name → index into `objects` of its final definition.
    pub(super) object_index: HashMap<&'s str, usize>,
    /// Shapes defined again by a later shape of the same name, by their statement's place
    /// in the list: still drawn (as course renderers that keep every shape in a list draw
    /// them), but no longer named.
    pub(super) shadowed: HashMap<*const Statement, usize>,
    pub(super) cameras: Vec<&'s CameraDef>,
    pub(super) camera_index: HashMap<&'s str, usize>,
    pub(super) lights: Vec<&'s LightDef>,
    pub(super) light_index: HashMap<&'s str, usize>,
    /// Camera name → its lens (the last `lens` line of the camera).
    pub(super) lenses: HashMap<&'s str, &'s LensDef>,
    pub(super) ambient: Vec3,
    pub(super) background: Vec3,
}

/// Where each name was first defined (statement index and line), for a use that comes before
/// its definition.
#[derive(Default)]
struct FirstDefinitions<'s> {
    /// Shapes and composites: a child must be defined before the composite.
    objects: HashMap<&'s str, (usize, u32)>,
    /// A material used before its definition is warned of.
    materials: HashMap<&'s str, (usize, u32)>,
}

impl Builder<'_> {
    // ----- definitions -------------------------------------------------------------------

    pub(super) fn definitions<'s>(&mut self, statements: &'s [Statement]) -> Definitions<'s> {
        let (mut d, first) = self.read_definitions(statements);
        // Shapes whose material is undefined, for one report per material.
        let undefined: Vec<(&NameRef, &str)> = statements
            .iter()
            .filter_map(|stmt| match &stmt.kind {
                StatementKind::Shape { name, material, .. }
                    if !d.material_index.contains_key(material.name.as_str()) =>
                {
                    Some((material, name.as_str()))
                }
                _ => None,
            })
            .collect();
        let fallback_of = self.undefined_materials(&mut d, &undefined);
        self.resolve_names(&mut d, statements, &first, &fallback_of);
        self.resolve_lenses(&mut d);
        d
    }

    /// Drops the lenses of names that are no camera of the file (reported, unless the
    /// camera's own line was rejected).
    fn resolve_lenses(&mut self, d: &mut Definitions) {
        let mut unknown: Vec<&NameRef> = d
            .lenses
            .values()
            .map(|l| &l.camera)
            .filter(|c| !d.camera_index.contains_key(c.name.as_str()))
            .collect();
        unknown.sort_by_key(|c| (c.loc.line, c.loc.col));
        for camera in unknown {
            d.lenses.remove(camera.name.as_str());
            if self.skipped(&camera.name) {
                continue;
            }
            let help = self.name_help(&camera.name, d.camera_index.keys().copied());
            let message = format!("lens of `{}`, which is no camera of this file", camera.name);
            self.at_ref(Severity::Error, camera, message, help);
        }
    }

    /// Every definition of `statements`, final versions, with shapes' materials and
    /// composites' children not yet resolved, and where each name was first defined.
    fn read_definitions<'s>(
        &mut self,
        statements: &'s [Statement],
    ) -> (Definitions<'s>, FirstDefinitions<'s>) {
        let mut d = Definitions::default();
        let mut first = FirstDefinitions::default();
        let mut ambient_set: Option<Vec3> = None;
        let mut ambient_added = Vec3::ZERO;
        for (index, stmt) in statements.iter().enumerate() {
            if !self.from_reader && !finite_statement(&stmt.kind) {
                self.error(
                    At::Statement(stmt),
                    "statement holds a number that is not finite".to_string(),
                    None,
                );
                continue;
            }
            match &stmt.kind {
                StatementKind::Material(m) => {
                    let material = self.material(m, stmt);
                    first
                        .materials
                        .entry(m.name.as_str())
                        .or_insert((index, stmt.loc.line));
                    let (items, names) = (&mut d.materials, &mut d.material_index);
                    self.define_named(stmt, "material", &m.name, material, items, names);
                }
                StatementKind::Shape { name, geometry, .. } => {
                    self.check_shape(stmt, name, geometry);
                    first
                        .objects
                        .entry(name.as_str())
                        .or_insert((index, stmt.loc.line));
                    // The material is resolved later, once every material is known.
                    let object = Object {
                        name,
                        statement: stmt,
                        kind: ObjectKind::Shape {
                            geometry,
                            material: None,
                        },
                    };
                    self.define_object(&mut d, object);
                }
                StatementKind::Composite { name, .. } => {
                    first
                        .objects
                        .entry(name.as_str())
                        .or_insert((index, stmt.loc.line));
                    let object = Object {
                        name,
                        statement: stmt,
                        kind: ObjectKind::Composite {
                            children: Vec::new(),
                        },
                    };
                    self.define_object(&mut d, object);
                }
                StatementKind::Light(l) => {
                    if !self.from_reader && !self.light_ok(l, stmt) {
                        continue;
                    }
                    let (items, names) = (&mut d.lights, &mut d.light_index);
                    self.define_named(stmt, "light", &l.name, l, items, names);
                }
                StatementKind::Lens(l) => {
                    let usable = l.aperture >= 0.0 && l.focus > 0.0;
                    if !self.from_reader && !usable {
                        let message = "a lens needs an aperture of at least 0 and a focus above 0";
                        self.error(At::Name(stmt), message.to_string(), None);
                    } else if d.lenses.insert(&l.camera.name, l).is_some() {
                        let message = format!(
                            "camera `{}` already has a lens; the later line replaces it",
                            l.camera.name
                        );
                        self.warn(At::Name(stmt), message, None);
                    }
                }
                StatementKind::Camera(c) => {
                    if !self.from_reader && !self.camera_ok(c, stmt) {
                        continue;
                    }
                    let (items, names) = (&mut d.cameras, &mut d.camera_index);
                    self.define_named(stmt, "camera", &c.name, c, items, names);
                }
                StatementKind::Ambient(rgb) => ambient_set = Some(*rgb),
                StatementKind::AmbientAdd(rgb) => ambient_added += *rgb,
                StatementKind::Background(rgb) => d.background = *rgb,
                StatementKind::Transform { .. }
                | StatementKind::Render(_)
                | StatementKind::Motion(_) => {}
            }
        }
        d.ambient = ambient_set.unwrap_or(Vec3::ZERO) + ambient_added;
        (d, first)
    }

    /// Loads a shape's mesh, and warns of a degenerate shape made by a program (the parser
    /// warns of those it reads).
    fn check_shape(&mut self, stmt: &Statement, name: &str, geometry: &Geometry) {
        if let Geometry::Mesh(m) = geometry {
            self.load_mesh(m, stmt);
        }
        if let Some(reason) = degeneracy(geometry) {
            if !self.from_reader {
                self.warn(
                    At::Name(stmt),
                    format!("shape `{name}` {reason}; shape dropped"),
                    None,
                );
            }
        }
    }

    /// Adds `item`, the `what` named `name`, to `items` and `index`; a later definition of the
    /// name replaces the earlier one in place, with a warning.
    fn define_named<'s, T>(
        &mut self,
        stmt: &Statement,
        what: &str,
        name: &'s str,
        item: T,
        items: &mut Vec<T>,
        index: &mut HashMap<&'s str, usize>,
    ) {
        if let Some(&i) = index.get(name) {
            self.duplicate(stmt, name, what);
            items[i] = item;
        } else {
            index.insert(name, items.len());
            items.push(item);
        }
    }

    /// Shapes' materials and composites' children, now that every name is known; a shape
    /// whose material is undefined takes `fallback_of` it.
    fn resolve_names<'s>(
        &mut self,
        d: &mut Definitions<'s>,
        statements: &'s [Statement],
        first: &FirstDefinitions,
        fallback_of: &HashMap<&str, usize>,
    ) {
        for (index, stmt) in statements.iter().enumerate() {
            match &stmt.kind {
                StatementKind::Shape {
                    name,
                    geometry,
                    material,
                } => {
                    let resolved = self
                        .resolve_material(d, &first.materials, index, material)
                        .or_else(|| fallback_of.get(material.name.as_str()).copied());
                    let named = d.object_index.get(name.as_str()).copied();
                    let Some(i) = d.shadowed.get(&std::ptr::from_ref(stmt)).copied().or(named)
                    else {
                        continue;
                    };
                    // The object of this very statement: an earlier definition of a name
                    // that a composite replaced is checked but not drawn.
                    if std::ptr::eq(d.objects[i].statement, stmt) {
                        d.objects[i].kind = ObjectKind::Shape {
                            geometry,
                            material: if degeneracy(geometry).is_some() {
                                None
                            } else {
                                resolved
                            },
                        };
                    }
                }
                StatementKind::Composite { name, children } => {
                    let resolved = self.resolve_children(d, &first.objects, index, name, children);
                    if let Some(&i) = d.object_index.get(name.as_str()) {
                        if std::ptr::eq(d.objects[i].statement, stmt) {
                            d.objects[i].kind = ObjectKind::Composite { children: resolved };
                        }
                    }
                }
                _ => {}
            }
        }
    }

    pub(super) fn define_object<'s>(&mut self, d: &mut Definitions<'s>, object: Object<'s>) {
        if let Some(&i) = d.object_index.get(object.name) {
            let is_shape = |k: &ObjectKind| matches!(k, ObjectKind::Shape { .. });
            let earlier_line = d.objects[i].statement.loc.line;
            let message = if is_shape(&object.kind) && is_shape(&d.objects[i].kind) {
                d.shadowed
                    .insert(std::ptr::from_ref(d.objects[i].statement), i);
                format!(
                    "shape `{}` is already defined (line {earlier_line}); both are drawn, and the name refers to this one",
                    object.name
                )
            } else {
                let what = if is_shape(&object.kind) {
                    "shape"
                } else {
                    "composite"
                };
                format!(
                    "{what} `{}` is already defined (line {earlier_line}); the later definition replaces it",
                    object.name
                )
            };
            self.warn(At::Name(object.statement), message, None);
        }
        d.object_index.insert(object.name, d.objects.len());
        d.objects.push(object);
    }

    /// Reads a mesh's OBJ file, relative to the scene file. Problems inside it point at the
    /// OBJ file's own lines; a file that cannot be read at all, at the statement.
    fn load_mesh(&mut self, m: &MeshFile, stmt: &Statement) {
        if m.mesh().is_some() {
            return;
        }
        // Relative to the file the statement is written in (an included file's own folder).
        let written_in: &Path = if stmt.loc.file.as_os_str().is_empty() {
            self.path
        } else {
            &stmt.loc.file
        };
        let file = written_in.parent().unwrap_or(Path::new("")).join(&m.file);
        let opened = match crate::input::open_named(&file, self.path, self.opts.allow_any_input) {
            Ok(opened) => opened,
            Err(refusal) => {
                use crate::input::{Refusal, OUTSIDE_ROOTS};
                let why = match refusal {
                    Refusal::Outside => OUTSIDE_ROOTS.to_string(),
                    Refusal::Io(e) => format!("cannot be read: {e}"),
                    Refusal::Changed => "was replaced while it was being opened".to_string(),
                    Refusal::Folder | Refusal::NotRegular => {
                        "cannot be read: it is not a regular file".to_string()
                    }
                };
                let message = format!("mesh file `{}` {why}", m.file);
                self.error(At::Statement(stmt), message, None);
                return;
            }
        };
        let (max_input, max_memory) = (self.opts.max_input, self.opts.max_memory);
        let loaded = self
            .opts
            .meshes
            .load(opened.file(), opened.real(), max_input, |f| {
                crate::shape::mesh::load_open(f, &file, max_input, max_memory).map(Arc::new)
            });
        match loaded {
            Ok(mesh) => m.set(mesh),
            Err(d) if d.loc.is_none() => {
                let message = format!("mesh file `{}` {}", m.file, d.message);
                self.error(At::Statement(stmt), message, d.help);
            }
            Err(d) => self.push(*d),
        }
    }

    pub(super) fn duplicate(&mut self, stmt: &Statement, name: &str, what: &str) {
        self.warn(
            At::Name(stmt),
            format!("{what} `{name}` is already defined; the later definition replaces it"),
            None,
        );
    }

    pub(super) fn material(&mut self, m: &MaterialDef, stmt: &Statement) -> Material {
        let mut out = Material {
            name: m.name.clone(),
            ka: m.ka,
            kd: m.kd,
            ks: m.ks,
            m: m.m,
            reflectivity: clamp_fraction(f64::from(m.reflectivity)) as f32,
            opacity: clamp_fraction(f64::from(m.opacity)) as f32,
            ior: m.ior,
        };
        out.m = repair::phong_exponent(out.m);
        out.ior = repair::usable_ior(f64::from(out.ior)).map_or(repair::AIR_IOR, |ior| ior as f32);
        if !self.from_reader
            && (out.m != m.m
                || out.ior != m.ior
                || out.reflectivity != m.reflectivity
                || out.opacity != m.opacity)
        {
            self.warn(
                At::Name(stmt),
                format!(
                    "material `{}` has values out of range (m and ior must be positive, \
                     reflectivity and opacity in [0, 1]); repaired",
                    m.name
                ),
                None,
            );
        }
        out
    }

    /// Checks a light made by a program (the parser checks those it reads): a radius of at
    /// least 0, a spot's target away from the light and its angles in order.
    fn light_ok(&mut self, l: &LightDef, stmt: &Statement) -> bool {
        let spot_ok = l.spot.is_none_or(|s| {
            s.target != l.position
                && 0.0 <= s.inner_deg
                && s.inner_deg <= s.outer_deg
                && 0.0 < s.outer_deg
                && s.outer_deg <= 180.0
        });
        if l.radius >= 0.0 && spot_ok {
            return true;
        }
        let message = format!(
            "light `{}` needs a radius of at least 0 and, as a spot, a target away from it and \
             half-angles 0 ≤ inner ≤ outer ≤ 180 (outer above 0)",
            l.name
        );
        self.error(At::Name(stmt), message, None);
        false
    }

    /// Checks a camera made by a program (the parser checks those it reads).
    pub(super) fn camera_ok(&mut self, c: &CameraDef, stmt: &Statement) -> bool {
        let problem = if !fov_is_valid(c.fov_x_deg) {
            Some(format!("a field of view {FOV_RULE}"))
        } else if is_zero(c.dir) {
            Some("a non-zero viewing direction".to_string())
        } else if parallel(c.dir, c.up) {
            Some("an up vector that is not parallel to the viewing direction".to_string())
        } else {
            None
        };
        match problem {
            Some(need) => {
                self.error(
                    At::Name(stmt),
                    format!("camera `{}` needs {need}", c.name),
                    None,
                );
                false
            }
            None => true,
        }
    }
}

/// Whether every number of a statement is finite (statements made by programs may not be).
pub(super) fn finite_statement(kind: &StatementKind) -> bool {
    let v = |v: &DVec3| v.is_finite();
    let c = |c: &Vec3| c.is_finite();
    match kind {
        StatementKind::Material(m) => {
            c(&m.ka)
                && c(&m.kd)
                && c(&m.ks)
                && m.m.is_finite()
                && m.reflectivity.is_finite()
                && m.opacity.is_finite()
                && m.ior.is_finite()
        }
        StatementKind::Shape { geometry, .. } => geometry.is_finite(),
        StatementKind::Light(l) => {
            v(&l.position)
                && c(&l.color)
                && l.brightness.is_finite()
                && l.radius.is_finite()
                && l.spot.is_none_or(|s| {
                    v(&s.target) && s.inner_deg.is_finite() && s.outer_deg.is_finite()
                })
        }
        StatementKind::Lens(l) => l.aperture.is_finite() && l.focus.is_finite(),
        StatementKind::Ambient(rgb)
        | StatementKind::AmbientAdd(rgb)
        | StatementKind::Background(rgb) => c(rgb),
        StatementKind::Camera(cam) => {
            cam.fov_x_deg.is_finite() && v(&cam.eye) && v(&cam.dir) && v(&cam.up)
        }
        StatementKind::Motion(m) if !m.at.is_finite() => false,
        StatementKind::Transform { ops, .. } | StatementKind::Motion(MotionDef { ops, .. }) => {
            ops.iter().all(|op| match op {
                TransformOp::Translate(t) | TransformOp::Scale(t) => v(t),
                TransformOp::Rotate { degrees, axis } => degrees.is_finite() && v(axis),
            })
        }
        StatementKind::Composite { .. } | StatementKind::Render(_) => true,
    }
}
