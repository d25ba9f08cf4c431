//! SDF statements as parsed, each with its source location, and their canonical text form.
//! Variants of the scene language accepted by the reader are normalised into these canonical
//! statements, so writing a statement list back out gives a plain-dialect file that loads to
//! the same scene (read with the default `--material-fields`, as materials are written with
//! all three extras: reflectivity, opacity, ior).

use crate::diag::Loc;
use crate::shape::Geometry;
use crate::util::FastMap;
use glam::{DVec3, Vec3};
use std::fmt;
use std::path::Path;
use std::sync::Arc;

/// A name used to refer to something defined elsewhere, kept with where it was written.
#[derive(Clone, Debug, PartialEq)]
pub struct NameRef {
    /// The name as written.
    pub name: String,
    /// Where the name is written.
    pub loc: Loc,
}

/// One statement in canonical form, with where it was read.
#[derive(Clone, Debug, PartialEq)]
pub struct Statement {
    /// What the statement says.
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
    /// The column the token starts at, in characters from 1.
    pub col: u32,
    /// How many characters the token covers.
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

/// Shapes per chunk of [`FlatShapes`]: chunks are freed one by one as the scene builder
/// turns them into instances, so the two are never both whole in memory.
const FLAT_CHUNK: usize = 1 << 14;

/// The primitive shape statements of a file read from text, when nothing in the file refers
/// to a shape by name (no composite, no transform, no mesh), kept compactly instead of as
/// [`Statement`]s, so that a flat file of a million shapes loads in little memory
/// (BENCHMARKS.md, "Scale"). Each shape keeps what the scene builder can point at: where its
/// statement, name and material are written.
#[derive(Clone, Debug, Default)]
pub struct FlatShapes {
    file: Option<Arc<Path>>,
    chunks: Vec<Vec<FlatShape>>,
    len: usize,
    /// Every shape name, one after the other.
    names: String,
    /// The distinct material names the shapes use, by id.
    materials: Vec<String>,
    material_ids: FastMap<String, u32>,
    /// Whether a material statement of that name was read (so far, while reading).
    material_defined: Vec<bool>,
}

/// One shape statement of [`FlatShapes`]. Its name token is as wide as the name has
/// characters, and its statement starts with `define` (else it is kept as a [`Statement`]).
#[derive(Clone, Debug, PartialEq)]
pub struct FlatShape {
    /// The primitive as its statement writes it, in object space.
    pub geometry: Geometry,
    name_start: u32,
    name_len: u32,
    /// Material id; the top bit says whether the material was defined before this line.
    material: u32,
    line: u32,
    col: u32,
    name_col: u32,
    material_col: u32,
    /// Statements (other than these shapes) read before this one.
    pos: u32,
}

/// A primitive shape as its line is written, for [`FlatShapes::push_fitting`].
pub struct FlatShapeLine<'a> {
    /// The file the line is in.
    pub file: &'a Arc<Path>,
    /// The name the statement gives the shape.
    pub name: &'a str,
    /// The primitive, in object space.
    pub geometry: Geometry,
    /// The name of the material the shape is drawn with.
    pub material: &'a str,
    /// The line, and the columns of its first token, name and material.
    pub line: u32,
    /// The column the statement's first token starts at.
    pub col: u32,
    /// The column the shape's name starts at.
    pub name_col: u32,
    /// The column the material's name starts at.
    pub material_col: u32,
    /// Statements (other than the shapes kept apart) read before it.
    pub pos: usize,
}

impl FlatShape {
    /// The line its statement is on.
    pub fn line(&self) -> u32 {
        self.line
    }

    /// The column its statement starts at.
    pub fn col(&self) -> u32 {
        self.col
    }
}

const DEFINED_BEFORE: u32 = 1 << 31;
const FIRST_WIDTH: u32 = "define".len() as u32;

impl FlatShapes {
    /// How many shapes are held.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no shape is held.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Records that a material statement named `name` was read.
    pub fn define_material(&mut self, name: &str) {
        let id = self.material_id(name);
        self.material_defined[id as usize] = true;
    }

    fn material_id(&mut self, name: &str) -> u32 {
        // Files use few materials: comparing names is then faster than hashing them.
        if self.materials.len() <= 8 {
            if let Some(id) = self.materials.iter().position(|m| m == name) {
                return id as u32;
            }
        } else if let Some(&id) = self.material_ids.get(name) {
            return id;
        }
        let id = self.materials.len() as u32;
        self.materials.push(name.to_string());
        self.material_ids.insert(name.to_string(), id);
        self.material_defined.push(false);
        id
    }

    /// Takes `stmt`, read after `pos` other statements, if it is a primitive shape whose
    /// places fit the compact form; else gives it back.
    pub fn push(&mut self, stmt: Statement, pos: usize) -> Option<Statement> {
        match stmt {
            Statement {
                kind:
                    StatementKind::Shape {
                        name,
                        geometry,
                        material,
                    },
                loc,
                spans:
                    Some(StatementSpans {
                        first_width: FIRST_WIDTH,
                        name: Some(name_span),
                    }),
            } if !matches!(geometry, Geometry::Mesh(_))
                && material.loc.line == loc.line
                && self.fits(&loc.file, &name, name_span.width, pos) =>
            {
                self.push_fitting(FlatShapeLine {
                    file: &loc.file,
                    name: &name,
                    geometry,
                    material: &material.name,
                    line: loc.line,
                    col: loc.col,
                    name_col: name_span.col,
                    material_col: material.loc.col,
                    pos,
                });
                None
            }
            other => Some(other),
        }
    }

    /// Whether a primitive shape of `file` named `name` (its token `name_width` characters
    /// wide), read after `pos` other statements, fits the compact form.
    pub fn fits(&self, file: &Arc<Path>, name: &str, name_width: u32, pos: usize) -> bool {
        let fits = |v: usize| u32::try_from(v).is_ok_and(|v| v < DEFINED_BEFORE);
        fits(self.names.len())
            && fits(pos)
            && self.file.as_ref().is_none_or(|f| Arc::ptr_eq(f, file))
            && fits(name.len())
            && name_width as usize == name.chars().count()
            && (self.materials.len() as u64) < u64::from(DEFINED_BEFORE)
    }

    /// Takes a primitive shape written on one line, straight from the reader's tokens (no
    /// statement made). Its places must fit the compact form ([`FlatShapes::fits`]).
    pub fn push_fitting(&mut self, shape: FlatShapeLine<'_>) {
        let id = self.material_id(shape.material);
        let before = if self.material_defined[id as usize] {
            DEFINED_BEFORE
        } else {
            0
        };
        let name_start = self.names.len() as u32;
        self.names.push_str(shape.name);
        let record = FlatShape {
            geometry: shape.geometry,
            name_start,
            name_len: shape.name.len() as u32,
            material: id | before,
            line: shape.line,
            col: shape.col,
            name_col: shape.name_col,
            material_col: shape.material_col,
            pos: shape.pos as u32,
        };
        if self.file.is_none() {
            self.file = Some(shape.file.clone());
        }
        match self.chunks.last_mut() {
            Some(chunk) if chunk.len() < FLAT_CHUNK => chunk.push(record),
            // The first chunk grows as a vector does (a small file holds no empty chunk); the
            // next ones are made whole at once, never copied as they fill.
            Some(_) => {
                let mut chunk = Vec::with_capacity(FLAT_CHUNK);
                chunk.push(record);
                self.chunks.push(chunk);
            }
            None => self.chunks.push(vec![record]),
        }
        self.len += 1;
    }

    /// The shapes, in file order.
    pub fn iter(&self) -> impl Iterator<Item = &FlatShape> {
        self.chunks.iter().flatten()
    }

    /// The shapes in file order, a chunk at a time.
    pub fn chunks(&self) -> impl Iterator<Item = &[FlatShape]> {
        self.chunks.iter().map(Vec::as_slice)
    }

    /// Shape `k` (from 0, in file order).
    pub fn get(&self, k: usize) -> Option<&FlatShape> {
        // Every chunk but the last is full.
        self.chunks.get(k / FLAT_CHUNK)?.get(k % FLAT_CHUNK)
    }

    /// The shapes in chunks, in file order, each chunk freed once the caller drops it.
    pub fn take_chunks(&mut self) -> Vec<Vec<FlatShape>> {
        self.len = 0;
        std::mem::take(&mut self.chunks)
    }

    /// The name the statement of `s` gives it.
    pub fn name(&self, s: &FlatShape) -> &str {
        let start = s.name_start as usize;
        self.names
            .get(start..start + s.name_len as usize)
            .unwrap_or("")
    }

    /// The file every shape was read from (`None` when there is no shape).
    pub fn file(&self) -> Option<&Arc<Path>> {
        self.file.as_ref()
    }

    /// Bytes of all the shapes' names together.
    pub fn names_len(&self) -> usize {
        self.names.len()
    }

    /// The material id of `s` (from 0, below [`FlatShapes::material_count`]).
    pub fn material_of(&self, s: &FlatShape) -> usize {
        (s.material & !DEFINED_BEFORE) as usize
    }

    /// How many distinct material names the shapes use: their ids run from 0 below this.
    pub fn material_count(&self) -> usize {
        self.materials.len()
    }

    /// The material name of id `id`; empty for an id that names none.
    pub fn material_name(&self, id: usize) -> &str {
        self.materials.get(id).map_or("", String::as_str)
    }

    /// Whether a statement defining the material of `s` was read before `s`.
    pub fn material_defined_before(&self, s: &FlatShape) -> bool {
        s.material & DEFINED_BEFORE != 0
    }

    /// Where the statement of `s` starts.
    pub fn loc(&self, s: &FlatShape) -> Loc {
        self.loc_at(s, s.col)
    }

    fn loc_at(&self, s: &FlatShape, col: u32) -> Loc {
        Loc {
            file: self
                .file
                .clone()
                .unwrap_or_else(|| Arc::from(Path::new(""))),
            line: s.line,
            col,
        }
    }

    /// Where the name of `s` is written, and its width.
    pub fn name_place(&self, s: &FlatShape) -> (Loc, u32) {
        let width = self.name(s).chars().count() as u32;
        (self.loc_at(s, s.name_col), width)
    }

    /// The material reference of `s` as written.
    pub fn material_ref(&self, s: &FlatShape) -> NameRef {
        NameRef {
            name: self.material_name(self.material_of(s)).to_string(),
            loc: self.loc_at(s, s.material_col),
        }
    }

    /// `s` as the statement it was read as.
    pub fn statement(&self, s: &FlatShape) -> Statement {
        let name = self.name(s);
        Statement {
            kind: StatementKind::Shape {
                name: name.to_string(),
                geometry: s.geometry.clone(),
                material: self.material_ref(s),
            },
            loc: self.loc(s),
            spans: Some(StatementSpans {
                first_width: FIRST_WIDTH,
                name: Some(Span {
                    col: s.name_col,
                    width: name.chars().count() as u32,
                }),
            }),
        }
    }

    /// Every statement of a file: `others` (the statements that are not in `self`) with the
    /// shapes put back where they were read. `others` must be as they were read (each shape's
    /// place counts them); the new index of `others[k]` is `moved[k]`.
    pub fn merge_into(self, others: Vec<Statement>) -> (Vec<Statement>, Vec<usize>) {
        let mut out = Vec::with_capacity(others.len() + self.len);
        let mut moved = Vec::with_capacity(others.len());
        let mut shapes = self.iter().peekable();
        for (k, stmt) in others.into_iter().enumerate() {
            while let Some(s) = shapes.next_if(|s| s.pos as usize <= k) {
                out.push(self.statement(s));
            }
            moved.push(out.len());
            out.push(stmt);
        }
        out.extend(shapes.map(|s| self.statement(s)));
        (out, moved)
    }

    /// Bytes held, for the memory measurements of tests.
    pub fn bytes(&self) -> usize {
        self.chunks.capacity() * std::mem::size_of::<Vec<FlatShape>>()
            + self
                .chunks
                .iter()
                .map(|c| c.capacity() * std::mem::size_of::<FlatShape>())
                .sum::<usize>()
            + self.names.capacity()
            // Each material name is held twice: in the list and as the key of its id.
            + self.materials.iter().map(|m| m.capacity() * 2).sum::<usize>()
            + self.materials.capacity() * std::mem::size_of::<String>()
            + self.material_ids.capacity() * (std::mem::size_of::<(String, u32)>() + 1)
            + self.material_defined.capacity()
    }
}

/// What a statement says: one case per canonical statement.
#[derive(Clone, Debug, PartialEq)]
pub enum StatementKind {
    /// `define material`: a named material.
    Material(MaterialDef),
    /// `define shape` of a primitive or a mesh: a named shape drawn with a material.
    Shape {
        /// The name it defines.
        name: String,
        /// The primitive, in its object space.
        geometry: Geometry,
        /// The material it is drawn with.
        material: NameRef,
    },
    /// `define shape composite`: a named group of shapes and composites defined before it.
    Composite {
        /// The name it defines.
        name: String,
        /// The shapes and composites it groups, as listed.
        children: Vec<NameRef>,
    },
    /// `define light`: a named point light (spherical with a radius, a spot with a cone).
    Light(LightDef),
    /// Sets the scene's ambient light.
    Ambient(Vec3),
    /// Adds to the scene's ambient light (the lecture form `light [pos] [La] [Ld]`).
    AmbientAdd(Vec3),
    /// Sets the colour of rays that hit nothing.
    Background(Vec3),
    /// `define camera`: a named camera.
    Camera(CameraDef),
    /// `transform`: places a shape, composite, light or camera by further operations.
    Transform {
        /// The shape, composite, light or camera placed.
        target: NameRef,
        /// The operations, in the order written.
        ops: Vec<TransformOp>,
    },
    /// `render`: one image to make.
    Render(RenderDef),
    /// A thing's motion while the shutter is open (docs/scene-language.md §10).
    Motion(MotionDef),
    /// `lens`: a camera's thin lens (docs/scene-language.md §6.1).
    Lens(LensDef),
}

/// A material as its line defines it, its extras read by the material layout (each field as
/// in `crate::scene::Material`).
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialDef {
    /// The name it defines.
    pub name: String,
    /// Ka, the ambient reflection coefficient per channel.
    pub ka: Vec3,
    /// Kd, the diffuse reflection coefficient per channel.
    pub kd: Vec3,
    /// Ks, the specular reflection coefficient per channel.
    pub ks: Vec3,
    /// The Phong exponent.
    pub m: f32,
    /// ρ, the share of light reflected as by a mirror, in [0, 1].
    pub reflectivity: f32,
    /// α, the share of light the surface stops, in [0, 1]; 1 is opaque.
    pub opacity: f32,
    /// η, the index of refraction; 1 when the line gives none.
    pub ior: f32,
}

/// A point light; intensity = brightness · colour. With a radius it is a sphere of that
/// radius about its position, with a spot it shines into a cone (docs/scene-language.md §5).
#[derive(Clone, Debug, PartialEq)]
pub struct LightDef {
    /// The name it defines.
    pub name: String,
    /// Where the light is, before its transforms.
    pub position: DVec3,
    /// The colour, per channel.
    pub color: Vec3,
    /// The factor the colour is scaled by.
    pub brightness: f32,
    /// The radius of the sphere it is (scene units); 0 for a point.
    pub radius: f64,
    /// The cone it shines into, if it is a spot.
    pub spot: Option<SpotDef>,
}

/// The cone of a spot light: `spot [target] <inner-deg> <outer-deg>`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotDef {
    /// The point the cone's axis runs through, before the light's transforms.
    pub target: DVec3,
    /// The half-angle of full intensity, in degrees.
    pub inner_deg: f64,
    /// The half-angle at which the intensity has fallen to zero, in degrees (at least
    /// `inner_deg`).
    pub outer_deg: f64,
}

/// `lens <camera> <aperture> <focus>`: a camera's thin lens.
#[derive(Clone, Debug, PartialEq)]
pub struct LensDef {
    /// The camera it belongs to.
    pub camera: NameRef,
    /// The radius of the aperture (scene units); 0 for a pinhole.
    pub aperture: f64,
    /// How far in front of the eye, along the view direction, the plane in focus lies.
    pub focus: f64,
}

/// A camera as its line defines it, before its transforms (`crate::scene::Camera` is the
/// placed one).
#[derive(Clone, Debug, PartialEq)]
pub struct CameraDef {
    /// The name it defines, by which `render` lines choose it.
    pub name: String,
    /// Full horizontal field of view in degrees.
    pub fov_x_deg: f64,
    /// The eye point.
    pub eye: DVec3,
    /// The direction the camera looks in.
    pub dir: DVec3,
    /// The direction that shows as up in the image.
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

/// One operation of a `transform` or `motion` line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TransformOp {
    /// A move by the vector.
    Translate(DVec3),
    /// Degrees about an axis (any length but zero).
    Rotate {
        /// The angle in degrees, right-handed about `axis`.
        degrees: f64,
        /// The direction of the axis, which passes through the origin.
        axis: DVec3,
    },
    /// A scale by a factor per axis, about the origin; the reader refuses a zero factor.
    Scale(DVec3),
}

/// `motion <target> <u> [ops]`: at the fraction `u` of the exposure, `target` is placed by
/// its transforms followed by `ops` (docs/scene-language.md §10).
#[derive(Clone, Debug, PartialEq)]
pub struct MotionDef {
    /// The shape, composite, light or camera that moves.
    pub target: NameRef,
    /// The instant `u`: the fraction of the exposure, 0 at shutter open and 1 at close.
    pub at: f64,
    /// The operations that follow the target's transforms at that instant; none for where
    /// the rest of the file puts it.
    pub ops: Vec<TransformOp>,
}

/// `render <camera> <file> <width> <height> [<samples>]`: one image to make.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderDef {
    /// The camera to look through.
    pub camera: NameRef,
    /// The image file as written, after repairs such as `image . ppm`; a relative path is
    /// taken from the output directory.
    pub output: String,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel the line asks for; `None` when it asks for none.
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
                let body = match (geometry, geometry.numbers()) {
                    (_, Some((kind, nums))) => {
                        let nums: Vec<String> = nums.iter().map(|n| Num(*n).to_string()).collect();
                        format!("{kind} {name} {}", nums.join(" "))
                    }
                    (Geometry::Mesh(m), None) => format!("obj {name} {}", m.file),
                    (_, None) => unreachable!("every primitive but a mesh has numbers"),
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
            StatementKind::Light(l) => {
                write!(
                    f,
                    "define light {} {} {} {}",
                    l.name,
                    v3(l.position),
                    c3(l.color),
                    Num32(l.brightness)
                )?;
                if l.radius != 0.0 {
                    write!(f, " radius {}", Num(l.radius))?;
                }
                if let Some(s) = &l.spot {
                    let (inner, outer) = (Num(s.inner_deg), Num(s.outer_deg));
                    write!(f, " spot {} {inner} {outer}", v3(s.target))?;
                }
                Ok(())
            }
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
                write_ops(f, ops)
            }
            StatementKind::Motion(m) => {
                write!(f, "motion {} {}", m.target.name, Num(m.at))?;
                write_ops(f, &m.ops)
            }
            StatementKind::Lens(l) => write!(
                f,
                "lens {} {} {}",
                l.camera.name,
                Num(l.aperture),
                Num(l.focus)
            ),
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

/// Transform operations in canonical form, each after a space.
fn write_ops(f: &mut fmt::Formatter<'_>, ops: &[TransformOp]) -> fmt::Result {
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

impl fmt::Display for Statement {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.kind.fmt(f)
    }
}
