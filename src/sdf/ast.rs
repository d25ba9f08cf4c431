//! SDF statements as parsed, each with its source location, and their canonical text form.
//! Variants of the scene language accepted by the reader are normalised into these canonical
//! statements, so writing a statement list back out gives a plain-dialect file that loads to
//! the same scene (read with the default `--material-fields`, as materials are written with
//! all three extras: reflectivity, opacity, ior).

use crate::diag::Loc;
use crate::shape::Geometry;
use glam::{DVec3, Vec3};
use std::fmt;

/// A name used to refer to something defined elsewhere, kept with where it was written.
#[derive(Clone, Debug, PartialEq)]
pub struct NameRef {
    pub name: String,
    pub loc: Loc,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Statement {
    pub kind: StatementKind,
    /// Where the statement starts (its first token).
    pub loc: Loc,
    /// Where the reader found the tokens that problems found after reading point at; `None`
    /// for statements made by a program.
    pub spans: Option<StatementSpans>,
}

impl Statement {
    /// A statement made by a program rather than read from text.
    pub fn new(kind: StatementKind, loc: Loc) -> Self {
        Statement {
            kind,
            loc,
            spans: None,
        }
    }
}

/// A token of a statement's line as written: the column (in characters, from 1) where it
/// starts and how many characters it covers. Its file and line are the statement's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Span {
    pub col: u32,
    pub width: u32,
}

/// The tokens of a statement read from text that the scene builder may point at.
#[derive(Clone, Debug, PartialEq)]
pub struct StatementSpans {
    /// The width of the first token (the one at `Statement::loc`).
    pub first_width: u32,
    /// The name the statement is about: the one a definition gives (a material, shape,
    /// composite, light or camera), or a transform's target.
    pub name: Option<Span>,
}

#[derive(Clone, Debug, PartialEq)]
pub enum StatementKind {
    Material(MaterialDef),
    Shape {
        name: String,
        geometry: Geometry,
        material: NameRef,
    },
    Composite {
        name: String,
        children: Vec<NameRef>,
    },
    Light(LightDef),
    /// Sets the scene's ambient light.
    Ambient(Vec3),
    /// Adds to the scene's ambient light (the lecture form `light [pos] [La] [Ld]`).
    AmbientAdd(Vec3),
    Background(Vec3),
    Camera(CameraDef),
    Transform {
        target: NameRef,
        ops: Vec<TransformOp>,
    },
    Render(RenderDef),
}

#[derive(Clone, Debug, PartialEq)]
pub struct MaterialDef {
    pub name: String,
    pub ka: Vec3,
    pub kd: Vec3,
    pub ks: Vec3,
    pub m: f32,
    pub reflectivity: f32,
    pub opacity: f32,
    pub ior: f32,
}

/// A point light; intensity = brightness · colour.
#[derive(Clone, Debug, PartialEq)]
pub struct LightDef {
    pub name: String,
    pub position: DVec3,
    pub color: Vec3,
    pub brightness: f32,
}

#[derive(Clone, Debug, PartialEq)]
pub struct CameraDef {
    pub name: String,
    pub fov_x_deg: f64,
    pub eye: DVec3,
    pub dir: DVec3,
    pub up: DVec3,
}

impl CameraDef {
    /// A camera at the origin looking along -z with y up: the pose of a camera whose line
    /// gives no eye, direction or up vector.
    pub fn at_origin(name: &str, fov_x_deg: f64) -> Self {
        CameraDef {
            name: name.to_string(),
            fov_x_deg,
            eye: DVec3::ZERO,
            dir: DVec3::NEG_Z,
            up: DVec3::Y,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TransformOp {
    Translate(DVec3),
    /// Degrees about an axis (any length but zero).
    Rotate {
        degrees: f64,
        axis: DVec3,
    },
    Scale(DVec3),
}

#[derive(Clone, Debug, PartialEq)]
pub struct RenderDef {
    pub camera: NameRef,
    pub output: String,
    pub width: u32,
    pub height: u32,
    pub samples: Option<u32>,
}

/// Shortest decimal text that reads back to the same value.
struct Num(f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0 == 0.0 {
            write!(f, "0")
        } else {
            write!(f, "{}", self.0)
        }
    }
}

fn v3(v: DVec3) -> String {
    format!("{} {} {}", Num(v.x), Num(v.y), Num(v.z))
}

/// Shortest decimal text that reads back to the same `f32` (`0.1`, not the `f64` expansion
/// `0.10000000149011612` of the same value): the reader parses in `f64` and rounds to `f32`.
struct Num32(f32);

impl fmt::Display for Num32 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0 == 0.0 {
            write!(f, "0")
        } else {
            write!(f, "{}", self.0)
        }
    }
}

fn c3(v: Vec3) -> String {
    format!("{} {} {}", Num32(v.x), Num32(v.y), Num32(v.z))
}

impl fmt::Display for StatementKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StatementKind::Material(m) => write!(
                f,
                "define material {} {} {} {} {} {} {} {}",
                m.name,
                c3(m.ka),
                c3(m.kd),
                c3(m.ks),
                Num32(m.m),
                Num32(m.reflectivity),
                Num32(m.opacity),
                Num32(m.ior)
            ),
            StatementKind::Shape {
                name,
                geometry,
                material,
            } => {
                let body = match geometry {
                    Geometry::Sphere { center, radius } => {
                        format!("sphere {name} {} {}", v3(*center), Num(*radius))
                    }
                    Geometry::Box { p1, p2 } => format!("box {name} {} {}", v3(*p1), v3(*p2)),
                    Geometry::Plane { point, normal } => {
                        format!("plane {name} {} {}", v3(*point), v3(*normal))
                    }
                    Geometry::Triangle {
                        vertices: [a, b, c],
                    } => {
                        format!("triangle {name} {} {} {}", v3(*a), v3(*b), v3(*c))
                    }
                    Geometry::Cylinder { p1, p2, radius } => {
                        format!("cylinder {name} {} {} {}", v3(*p1), v3(*p2), Num(*radius))
                    }
                    Geometry::Cone { base, tip, radius } => {
                        format!("cone {name} {} {} {}", v3(*base), v3(*tip), Num(*radius))
                    }
                    Geometry::Mesh(m) => format!("obj {name} {}", m.file),
                };
                write!(f, "define shape {body} {}", material.name)
            }
            StatementKind::Composite { name, children } => {
                write!(f, "define shape composite {name}")?;
                for c in children {
                    write!(f, " {}", c.name)?;
                }
                Ok(())
            }
            StatementKind::Light(l) => write!(
                f,
                "define light {} {} {} {}",
                l.name,
                v3(l.position),
                c3(l.color),
                Num32(l.brightness)
            ),
            StatementKind::Ambient(rgb) => write!(f, "ambient {}", c3(*rgb)),
            // There is no canonical "add" statement: a light named like this with zero
            // intensity in the lecture's 9-number form carries the ambient contribution.
            StatementKind::AmbientAdd(rgb) => {
                write!(f, "define light ambient-term 0 0 0 {} 0 0 0", c3(*rgb))
            }
            StatementKind::Background(rgb) => write!(f, "background {}", c3(*rgb)),
            StatementKind::Camera(c) => write!(
                f,
                "define camera {} {} {} {} {}",
                c.name,
                Num(c.fov_x_deg),
                v3(c.eye),
                v3(c.dir),
                v3(c.up)
            ),
            StatementKind::Transform { target, ops } => {
                write!(f, "transform {}", target.name)?;
                for op in ops {
                    match op {
                        TransformOp::Translate(v) => write!(f, " translate {}", v3(*v))?,
                        TransformOp::Rotate { degrees, axis } => {
                            write!(f, " rotate {} {}", Num(*degrees), v3(*axis))?
                        }
                        TransformOp::Scale(s) => write!(f, " scale {}", v3(*s))?,
                    }
                }
                Ok(())
            }
            StatementKind::Render(r) => {
                write!(
                    f,
                    "render {} {} {} {}",
                    r.camera.name, r.output, r.width, r.height
                )?;
                if let Some(s) = r.samples {
                    write!(f, " {s}")?;
                }
                Ok(())
            }
        }
    }
}

impl fmt::Display for Statement {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.kind.fmt(f)
    }
}
