//! The base scene of an animation: its statements, what each name is, and where each thing
//! sits (the default pivots and the centres that `look_at` follows).

use super::expr::Val;
use super::spec_file::{SceneNames, TargetKind};
use anim_core::limits;
use anim_core::math::Transform;
use anim_core::scene::Geometry;
use anim_core::sdf::ast::{Statement, StatementKind, TransformOp};
use anim_core::util::FastMap;
use glam::DVec3;
use std::collections::{BTreeMap, BTreeSet};

/// The base scene: its statements without render lines, and what each name is.
pub struct BaseScene {
    pub statements: Vec<Statement>,
    kinds: BTreeMap<String, TargetKind>,
    materials: BTreeSet<String>,
    /// Where each thing's last definition stands in `statements`, and its transform
    /// statements: a default pivot asks for them once per descendant, and a scene can hold a
    /// hundred thousand things.
    definitions: FastMap<String, usize>,
    transforms: FastMap<String, Vec<usize>>,
    /// Each composite's children, as its last definition lists them.
    children: BTreeMap<String, Vec<String>>,
    default_camera: Option<String>,
}

impl BaseScene {
    pub fn new(statements: Vec<Statement>) -> BaseScene {
        let mut kinds = BTreeMap::new();
        let mut children = BTreeMap::new();
        let mut materials = BTreeSet::new();
        let mut render_camera = None;
        let mut first_camera = None;
        for s in &statements {
            let entry = match &s.kind {
                StatementKind::Shape { name, .. } => Some((name, TargetKind::Shape)),
                StatementKind::Composite { name, children: c } => {
                    children.insert(name.clone(), c.iter().map(|c| c.name.clone()).collect());
                    Some((name, TargetKind::Composite))
                }
                StatementKind::Material(m) => {
                    materials.insert(m.name.clone());
                    None
                }
                StatementKind::Light(l) => Some((&l.name, TargetKind::Light)),
                StatementKind::Camera(c) => {
                    first_camera.get_or_insert_with(|| c.name.clone());
                    Some((&c.name, TargetKind::Camera))
                }
                StatementKind::Render(r) => {
                    render_camera.get_or_insert_with(|| r.camera.name.clone());
                    None
                }
                _ => None,
            };
            // A later definition of a name replaces the earlier one (docs/scene-language.md §2).
            if let Some((name, kind)) = entry {
                kinds.insert(name.clone(), kind);
            }
        }
        // A material that shares its name with a thing is reached through the thing: tracks
        // that key materials name materials of their own.
        for m in &materials {
            kinds.entry(m.clone()).or_insert(TargetKind::Material);
        }
        let default_camera = render_camera
            .filter(|c| kinds.get(c) == Some(&TargetKind::Camera))
            .or(first_camera);
        let statements: Vec<Statement> = statements
            .into_iter()
            .filter(|s| !matches!(s.kind, StatementKind::Render(_)))
            .collect();
        let mut definitions = FastMap::default();
        let mut transforms: FastMap<String, Vec<usize>> = FastMap::default();
        for (i, s) in statements.iter().enumerate() {
            match &s.kind {
                StatementKind::Shape { name, .. } | StatementKind::Composite { name, .. } => {
                    definitions.insert(name.clone(), i);
                }
                StatementKind::Light(l) => {
                    definitions.insert(l.name.clone(), i);
                }
                StatementKind::Camera(c) => {
                    definitions.insert(c.name.clone(), i);
                }
                StatementKind::Transform { target, .. } => {
                    transforms.entry(target.name.clone()).or_default().push(i);
                }
                _ => {}
            }
        }
        BaseScene {
            statements,
            definitions,
            transforms,
            kinds,
            materials,
            children,
            default_camera,
        }
    }

    /// `name`'s own transform statements composed as the scene builder composes them for
    /// generated frames (`TransformOrder::World`: each applies after the ones before it).
    pub fn own_transform(&self, name: &str) -> Transform {
        let at = self.transforms.get(name).map_or(&[][..], Vec::as_slice);
        let ops = at.iter().flat_map(|&i| match &self.statements[i].kind {
            StatementKind::Transform { ops, .. } => ops.as_slice(),
            _ => &[],
        });
        ops.filter_map(op_transform)
            .fold(Transform::IDENTITY, |m, t| t.then_after(&m))
    }

    /// The composites that list `name` among their children.
    pub fn parents(&self, name: &str) -> Vec<&str> {
        self.children
            .iter()
            .filter(|(_, c)| c.iter().any(|c| c == name))
            .map(|(p, _)| p.as_str())
            .collect()
    }

    /// The children `name` lists, if it is a composite.
    pub fn children(&self, name: &str) -> &[String] {
        self.children.get(name).map_or(&[], Vec::as_slice)
    }

    /// The last definition of `name` (later definitions replace earlier ones).
    fn definition(&self, name: &str) -> Option<&StatementKind> {
        Some(&self.statements.get(*self.definitions.get(name)?)?.kind)
    }

    /// Bounding box of `name` in its parent's frame: its geometry (or its children) under
    /// its own transforms.
    fn local_bounds(&self, name: &str, depth: usize) -> Option<Bounds> {
        if depth > limits::MAX_NESTING {
            return None;
        }
        let own = match self.definition(name)? {
            StatementKind::Shape { geometry, .. } => Bounds::of_geometry(geometry),
            StatementKind::Composite { children, .. } => children
                .iter()
                .filter_map(|c| self.local_bounds(&c.name, depth + 1))
                .reduce(Bounds::union)?,
            StatementKind::Light(l) => Bounds::point(l.position),
            StatementKind::Camera(c) => Bounds::point(c.eye),
            _ => return None,
        };
        Some(own.transformed(&self.own_transform(name)))
    }

    /// The default pivot of `name`: the centre of its bounding box where the base scene puts
    /// it (in its parent's frame); a light's or camera's position.
    pub fn default_pivot(&self, name: &str) -> DVec3 {
        self.local_bounds(name, 0)
            .map(|b| b.center())
            .filter(|c| c.is_finite())
            .unwrap_or(DVec3::ZERO)
    }
}

impl SceneNames for BaseScene {
    fn containers(&self, name: &str) -> Vec<&str> {
        self.parents(name)
    }

    fn kind_of(&self, name: &str) -> Option<TargetKind> {
        self.kinds.get(name).copied()
    }

    fn names(&self) -> Vec<&str> {
        self.kinds.keys().map(String::as_str).collect()
    }

    fn default_camera(&self) -> Option<&str> {
        self.default_camera.as_deref()
    }

    fn has_material(&self, name: &str) -> bool {
        self.materials.contains(name)
    }

    fn base_value(&self, target: &str, channel: &str) -> Option<Val> {
        let num = |v: f64| Some(Val::Num(v));
        let vec = |v: glam::Vec3| Some(Val::Vec(v.as_dvec3()));
        // The last statement that says it: a later definition replaces an earlier one.
        self.statements
            .iter()
            .rev()
            .find_map(|s| match (&s.kind, channel) {
                (StatementKind::Ambient(c), "ambient") => vec(*c),
                (StatementKind::Background(c), "background") => vec(*c),
                (StatementKind::Light(l), _) if l.name == target => match channel {
                    "brightness" => num(f64::from(l.brightness)),
                    "color" => vec(l.color),
                    _ => None,
                },
                (StatementKind::Camera(c), "fov") if c.name == target => num(c.fov_x_deg),
                (StatementKind::Material(m), _) if m.name == target => match channel {
                    "ka" => vec(m.ka),
                    "kd" => vec(m.kd),
                    "ks" => vec(m.ks),
                    "reflectivity" => num(f64::from(m.reflectivity)),
                    "opacity" => num(f64::from(m.opacity)),
                    "ior" => num(f64::from(m.ior)),
                    _ => None,
                },
                _ => None,
            })
    }
}

/// The transform of `ops` applied in order, as the scene builder composes a frame's
/// operations (each after the ones before it).
pub fn ops_transform(ops: &[TransformOp]) -> Transform {
    ops.iter()
        .filter_map(op_transform)
        .fold(Transform::IDENTITY, |m, t| t.then_after(&m))
}

/// The transform of one operation, as the scene builder makes it; `None` for a zero scale or
/// axis, which the builder rejects (the base scene has loaded, so none is left).
fn op_transform(op: &TransformOp) -> Option<Transform> {
    match *op {
        TransformOp::Translate(v) => Some(Transform::translate(v)),
        TransformOp::Rotate { degrees, axis } => Transform::rotate(degrees, axis),
        TransformOp::Scale(s) => Transform::scale(s),
    }
}

/// An axis-aligned box in f64. `anim_core::math::Aabb` is f32 and padded for ray traversal; the
/// default pivots written into frames need the exact centre.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Bounds {
    lo: DVec3,
    hi: DVec3,
}

impl Bounds {
    fn point(p: DVec3) -> Bounds {
        Bounds { lo: p, hi: p }
    }

    fn around(points: &[DVec3], radius: f64) -> Bounds {
        let r = DVec3::splat(limits::fixed_radius(radius));
        let lo = points.iter().copied().fold(DVec3::INFINITY, DVec3::min);
        let hi = points.iter().copied().fold(DVec3::NEG_INFINITY, DVec3::max);
        Bounds {
            lo: lo - r,
            hi: hi + r,
        }
    }

    /// Object-space bounds, loose for cylinders and cones (a sphere around each end); an
    /// infinite plane counts as its anchor point.
    fn of_geometry(g: &Geometry) -> Bounds {
        if let Some((points, radius)) = g.span() {
            return Bounds::around(&points, radius);
        }
        match g {
            Geometry::Plane { point, .. } => Bounds::point(*point),
            Geometry::Mesh(m) => m.mesh().map_or(Bounds::point(DVec3::ZERO), |m| {
                let b = m.bounds();
                Bounds::around(&[b.min.as_dvec3(), b.max.as_dvec3()], 0.0)
            }),
            // Every other primitive has a span.
            _ => Bounds::point(DVec3::ZERO),
        }
    }

    fn union(self, o: Bounds) -> Bounds {
        Bounds {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }

    /// The box around this box's eight corners mapped by `t`.
    fn transformed(&self, t: &Transform) -> Bounds {
        let corners: [DVec3; 8] = std::array::from_fn(|i| {
            t.point(DVec3::new(
                if i & 1 == 0 { self.lo.x } else { self.hi.x },
                if i & 2 == 0 { self.lo.y } else { self.hi.y },
                if i & 4 == 0 { self.lo.z } else { self.hi.z },
            ))
        });
        Bounds::around(&corners, 0.0)
    }

    fn center(&self) -> DVec3 {
        (self.lo + self.hi) * 0.5
    }
}
