//! `define shape`: the geometric primitives and composites.

use super::{At, Fail, PResult, Parser};
use crate::diag::suggest;
use crate::limits;
use crate::sdf::ast::{FlatShapeLine, StatementKind};
use crate::sdf::lexer::{self, looks_numeric, Line};
use crate::shape::geometry::degeneracy;
use crate::shape::{Geometry, MeshFile};
use glam::DVec3;

/// The kinds a `define shape` statement names by keyword (a mesh is `obj`, read apart).
pub(super) const SHAPE_KINDS: [&str; 7] = [
    "sphere",
    "box",
    "triangle",
    "cylinder",
    "cone",
    "plane",
    "composite",
];

const FORM_SPHERE: &str = "define shape sphere <name> [center] <radius> <material>";
const FORM_BOX: &str = "define shape box <name> [p1] [p2] <material>";
const FORM_TRIANGLE: &str = "define shape triangle <name> [v1] [v2] [v3] <material>";
const FORM_CYLINDER: &str = "define shape cylinder <name> [p1] [p2] <radius> <material>";
const FORM_CONE: &str = "define shape cone <name> [base] [tip] <radius> <material>";
const FORM_PLANE: &str = "define shape plane <name> [point] [normal] <material>";
const FORM_OBJ: &str = "define shape obj <name> <file.obj> <material>";
const FORM_COMPOSITE: &str = "define shape composite <name> <child> ...";

impl Parser<'_> {
    /// `define shape <kind> <name> ...` (`kind_at` = 2) or the variant without `shape`
    /// (`kind_at` = 1).
    pub(super) fn shape(&mut self, line: &Line, kind_at: usize) {
        let Some(kind) = line.tokens.get(kind_at) else {
            self.error(
                line,
                At::End,
                "expected a shape kind, found end of line",
                Some(format!("shapes: {}", SHAPE_KINDS.join(", "))),
            );
            return;
        };
        let name_at = kind_at + 1;
        match kind.text {
            "composite" => {
                if self.composite(line, name_at).is_err() {
                    self.skip_name(line, name_at);
                }
            }
            "obj" => {
                if self.mesh(line, kind_at).is_err() {
                    self.skip_name(line, name_at);
                }
            }
            k if SHAPE_KINDS.contains(&k) => {
                if kind_at == 2 && self.flat_shape(line, k) {
                    return;
                }
                if let Some(reordered) = name_after_material(line, kind_at) {
                    let last = line.tokens.len() - 1;
                    self.variant(
                        line,
                        At::Tok(last),
                        "name-after-material",
                        format!(
                            "the {k}'s name `{}` written after its material",
                            line.tokens[last].text
                        ),
                        format!(
                            "write `define shape {k} {} <numbers> {}`",
                            line.tokens[last].text,
                            line.tokens[last - 1].text
                        ),
                    );
                    if self.geometric_shape(&reordered, kind_at).is_err() {
                        self.skip_name(&reordered, name_at);
                    }
                } else if self.geometric_shape(line, kind_at).is_err() {
                    self.skip_name(line, name_at);
                }
            }
            other => {
                let help = suggest(other, SHAPE_KINDS)
                    .map(|s| format!("did you mean `{s}`?"))
                    .unwrap_or_else(|| format!("shapes: {}", SHAPE_KINDS.join(", ")));
                self.warn(
                    line,
                    At::Tok(kind_at),
                    format!("unknown shape kind '{other}'; line skipped"),
                    Some(help),
                );
                self.skip_name(line, name_at);
            }
        }
    }

    /// `define shape obj <name> <file.obj> <material>`; the file is read by the scene builder.
    fn mesh(&mut self, line: &Line, kind_at: usize) -> PResult<()> {
        let args = line.tokens.len() - kind_at - 1;
        if args < 3 {
            // Other renderers write `define shape obj <file>`, with no name or material.
            self.warn(
                line,
                At::Tok(kind_at),
                "a mesh needs a name, an OBJ file and a material; shape skipped",
                Some(format!(
                    "write `{FORM_OBJ}`; the short form `define shape obj <file>` is not supported"
                )),
            );
            return Err(Fail);
        }
        if args > 3 {
            let last = line.tokens.len() - 1;
            return Err(self.error(
                line,
                At::Span(kind_at + 4, last),
                format!("a mesh takes a name, an OBJ file and a material; found {args} words"),
                Some(FORM_OBJ.to_string()),
            ));
        }
        let kind = StatementKind::Shape {
            name: line.tokens[kind_at + 1].text.to_string(),
            geometry: Geometry::Mesh(MeshFile::new(line.tokens[kind_at + 2].text)),
            material: self.name_ref(line, kind_at + 3),
        };
        self.emit_named(line, kind_at + 1, kind);
        Ok(())
    }

    /// The common line of a flat file, `define shape <kind> <name> <numbers> <material>`
    /// written in canonical form with a shape that can be drawn, read straight into the
    /// compact shapes: no statement, string or list is made for it. `false`, with nothing
    /// done, for any other line (the general path reads it, and says what there is to say).
    fn flat_shape(&mut self, line: &Line, kind: &str) -> bool {
        let toks = &line.tokens;
        let expected = Layout::of(kind).numbers;
        if !self.flat || toks.len() != expected + 5 {
            return false;
        }
        let (name, material) = (toks[3], toks[expected + 4]);
        if looks_numeric(material.text) {
            return false;
        }
        let mut nums = [0.0; 9];
        for (slot, t) in nums.iter_mut().zip(&toks[4..expected + 4]) {
            match lexer::parse_number(t.text) {
                Ok(v) => *slot = v,
                Err(_) => return false,
            }
        }
        let geometry = geometry_from(kind, &nums[..expected]);
        let warned = match (geometry.radius(), &geometry) {
            (Some(radius), _) => radius < 0.0,
            (None, Geometry::Box { p1, p2 }) => (*p2 - *p1).to_array().contains(&0.0),
            (None, _) => false,
        };
        let pos = self.statements.len();
        if warned
            || degeneracy(&geometry).is_some()
            || !self.shapes.fits(&self.file, name.text, name.width, pos)
        {
            return false;
        }
        self.shapes.push_fitting(FlatShapeLine {
            file: &self.file,
            name: name.text,
            geometry,
            material: material.text,
            line: line.number,
            col: toks[0].col,
            name_col: name.col,
            material_col: material.col,
            pos,
        });
        true
    }

    fn geometric_shape(&mut self, line: &Line, kind_at: usize) -> PResult<()> {
        let kind = line.tokens[kind_at].text;
        let layout = Layout::of(kind);
        let args = self.shape_arguments(line, kind_at, &layout)?;
        let mut geometry = geometry_from(kind, &args.nums);
        if args.nums.len() == UPRIGHT_NUMBERS {
            // `[base] <height> <radius>`: the upright cones and cylinders of renderers whose
            // shapes stand on their base along +y.
            self.variant(
                line,
                At::Span(args.nums_from, args.nums_to - 1),
                "upright",
                format!(
                    "{kind} with 5 numbers read as [base] <height> <radius>, standing upright \
                     along +y from its base"
                ),
                format!(
                    "read as `{}`",
                    StatementKind::Shape {
                        name: args.name.clone(),
                        geometry: geometry.clone(),
                        material: self.name_ref(line, args.material_at),
                    }
                ),
            );
        }
        self.check_geometry(line, kind, &args, &mut geometry);
        let material = self.name_ref(line, args.material_at);
        let kind_stmt = StatementKind::Shape {
            name: args.name,
            geometry,
            material,
        };
        if kind_at == 1 {
            self.variant(
                line,
                At::Tok(1),
                "define-without-shape",
                format!("`define {kind}` without `shape`"),
                format!("read as `{kind_stmt}`"),
            );
        }
        if args.material_first {
            self.variant(
                line,
                At::Tok(args.material_at),
                "material-first",
                "material written before the coordinates".to_string(),
                format!("read as `{kind_stmt}`"),
            );
        }
        self.emit_named(line, kind_at + 1, kind_stmt);
        Ok(())
    }

    /// The name, numbers and material of a primitive's line, in either order of numbers and
    /// material.
    fn shape_arguments(
        &mut self,
        line: &Line,
        kind_at: usize,
        layout: &Layout,
    ) -> PResult<ShapeArguments> {
        let toks = &line.tokens;
        let (kind, expected) = (layout.kind, layout.numbers);
        let name_at = kind_at + 1;
        let Some(name_tok) = toks.get(name_at) else {
            return Err(self.error(
                line,
                At::End,
                format!("expected the {kind}'s name, found end of line"),
                Some(layout.canonical()),
            ));
        };
        let name = name_tok.text.to_string();
        let args = name_at + 1..toks.len();
        if args.is_empty() {
            return Err(self.error(
                line,
                At::End,
                format!(
                    "expected the {kind}'s {} and material, found end of line",
                    layout.numbers_meaning
                ),
                Some(layout.canonical()),
            ));
        }
        // The material normally comes last; some files write it right after the name.
        let material_first = args.len() >= 2
            && !looks_numeric(toks[args.start].text)
            && toks[args.start + 1..].iter().all(|t| looks_numeric(t.text));
        let (material_at, nums_from, nums_to) = if material_first {
            (args.start, args.start + 1, toks.len())
        } else {
            (toks.len() - 1, args.start, toks.len() - 1)
        };
        if !material_first
            && looks_numeric(toks[material_at].text)
            && nums_to - nums_from + 1 == expected
        {
            return Err(self.error(
                line,
                At::End,
                format!("expected a material name after the {kind}'s numbers, found end of line"),
                Some(layout.canonical()),
            ));
        }
        let mut nums = self.numbers(line, nums_from, nums_to)?;
        if kind == "box" && nums.len() == BOX_WITH_AXIS {
            // `[p1] [p2] [axis]`: renderers whose boxes carry an axis they never turn by.
            self.warn(
                line,
                At::Span(nums_from + expected, nums_to - 1),
                "three numbers after the box's corners (an axis, in renderers that write one) ignored",
                Some(layout.canonical()),
            );
            nums.truncate(expected);
        }
        if nums.len() != expected && Some(nums.len()) != layout.upright_numbers() {
            let at = if nums.len() > expected {
                At::Span(nums_from + expected, nums_to - 1)
            } else if material_first {
                At::End
            } else {
                At::Tok(material_at)
            };
            return Err(self.error(
                line,
                at,
                format!(
                    "a {kind} takes {expected} numbers ({}), found {}",
                    layout.numbers_meaning,
                    nums.len()
                ),
                Some(layout.canonical()),
            ));
        }
        Ok(ShapeArguments {
            name,
            nums,
            nums_from,
            nums_to,
            material_at,
            material_first,
        })
    }

    /// Makes a negative radius positive and reports a shape that cannot be drawn, each with
    /// a warning at the numbers concerned.
    fn check_geometry(
        &mut self,
        line: &Line,
        kind: &str,
        args: &ShapeArguments,
        geometry: &mut Geometry,
    ) {
        // The radius, where there is one, is the last number.
        let radius_at = At::Tok(args.nums_to - 1);
        if let Some(radius) = geometry.radius_mut() {
            if *radius < 0.0 {
                self.warn(
                    line,
                    radius_at,
                    format!("negative radius {}; its absolute value is used", *radius),
                    None,
                );
                *radius = limits::fixed_radius(*radius);
            }
        }
        if let Geometry::Box { p1, p2 } = geometry {
            // One flat axis is a rectangle (floors, walls); two or three leave a line or a
            // point, which no ray hits: almost always a typo in the corners.
            let flat = (*p2 - *p1).to_array().iter().filter(|d| **d == 0.0).count();
            if flat >= 2 {
                self.warn(
                    line,
                    At::Span(args.nums_from, args.nums_to - 1),
                    format!(
                        "box `{}` has zero size on {flat} axes: it is a {} and cannot be seen",
                        args.name,
                        if flat == 3 { "point" } else { "line" }
                    ),
                    Some("a box is given by two opposite corners: [p1] [p2]".to_string()),
                );
            }
        }
        if let Some(reason) = degeneracy(geometry) {
            let at = if geometry.radius().is_some() && reason.contains("radius") {
                radius_at
            } else {
                At::Span(args.nums_from, args.nums_to - 1)
            };
            self.warn(
                line,
                at,
                format!("{kind} `{}` {reason}; shape dropped", args.name),
                None,
            );
        }
    }

    fn composite(&mut self, line: &Line, name_at: usize) -> PResult<()> {
        let toks = &line.tokens;
        let Some(name_tok) = toks.get(name_at) else {
            return Err(self.error(
                line,
                At::End,
                "expected the composite's name, found end of line",
                Some(format!("canonical form: `{FORM_COMPOSITE}`")),
            ));
        };
        let name = name_tok.text.to_string();
        let mut children = Vec::new();
        for (i, tok) in toks.iter().enumerate().skip(name_at + 1) {
            if tok.text == name {
                self.warn(
                    line,
                    At::Tok(i),
                    format!("composite `{name}` cannot contain itself; child skipped"),
                    None,
                );
                continue;
            }
            children.push(self.name_ref(line, i));
        }
        if toks.len() == name_at + 1 {
            self.warn(
                line,
                At::Tok(name_at),
                format!("composite `{name}` has no children"),
                None,
            );
        }
        self.emit_named(line, name_at, StatementKind::Composite { name, children });
        Ok(())
    }
}

/// `define shape sphere 0 0 0 1 red ball`: the name slot holds a number and the line ends
/// with two words, a material and then the name. The line with its tokens put in canonical
/// order (each keeps its column, so diagnostics still point where it is written).
fn name_after_material<'t>(line: &Line<'t>, kind_at: usize) -> Option<Line<'t>> {
    let toks = &line.tokens;
    let name_at = kind_at + 1;
    let n = toks.len();
    let numeric_name = toks.get(name_at).is_some_and(|t| looks_numeric(t.text));
    if !numeric_name || n < name_at + 3 {
        return None;
    }
    let (material, name) = (toks[n - 2], toks[n - 1]);
    if looks_numeric(material.text) || looks_numeric(name.text) {
        return None;
    }
    let mut tokens = toks[..name_at].to_vec();
    tokens.push(name);
    tokens.extend_from_slice(&toks[name_at..n - 2]);
    tokens.push(material);
    Some(Line {
        number: line.number,
        text: line.text,
        tokens,
    })
}

/// How a primitive is written: how many numbers it takes and what they mean.
struct Layout {
    kind: &'static str,
    numbers: usize,
    numbers_meaning: &'static str,
    form: &'static str,
}

/// Numbers of a box written `[p1] [p2] [axis]`.
const BOX_WITH_AXIS: usize = 9;

impl Layout {
    fn of(kind: &str) -> Layout {
        let (kind, numbers, numbers_meaning, form) = match kind {
            "sphere" => ("sphere", 4, "[center] <radius>", FORM_SPHERE),
            "box" => ("box", 6, "[p1] [p2]", FORM_BOX),
            "triangle" => ("triangle", 9, "[v1] [v2] [v3]", FORM_TRIANGLE),
            "cylinder" => ("cylinder", 7, "[p1] [p2] <radius>", FORM_CYLINDER),
            "cone" => ("cone", 7, "[base] [tip] <radius>", FORM_CONE),
            _ => ("plane", 6, "[point] [normal]", FORM_PLANE),
        };
        Layout {
            kind,
            numbers,
            numbers_meaning,
            form,
        }
    }

    /// How many numbers the upright form `[base] <height> <radius>` takes, for the kinds
    /// that have one.
    fn upright_numbers(&self) -> Option<usize> {
        matches!(self.kind, "cylinder" | "cone").then_some(UPRIGHT_NUMBERS)
    }

    fn canonical(&self) -> String {
        let form = self.form;
        if matches!(self.kind, "cylinder" | "cone") {
            format!(
                "canonical form: `{form}`; also read: [base] <height> <radius> (5 numbers, upright along +y); \
                 layouts such as `pos axis radius height` are not read"
            )
        } else {
            format!("canonical form: `{form}`")
        }
    }
}

/// A primitive's line taken apart: numbers at tokens `nums_from..nums_to`, material at
/// `material_at`.
struct ShapeArguments {
    name: String,
    nums: Vec<f64>,
    nums_from: usize,
    nums_to: usize,
    material_at: usize,
    material_first: bool,
}

/// Numbers of the upright cone and cylinder: `[base] <height> <radius>`.
const UPRIGHT_NUMBERS: usize = 5;

/// The primitive of kind `kind` from its numbers (as many as its layout takes, or the upright
/// form's five for a cone or cylinder).
fn geometry_from(kind: &str, nums: &[f64]) -> Geometry {
    let p = |i: usize| DVec3::new(nums[i], nums[i + 1], nums[i + 2]);
    if nums.len() == UPRIGHT_NUMBERS {
        let base = p(0);
        let top = base + DVec3::new(0.0, nums[3], 0.0);
        let radius = nums[4];
        return if kind == "cone" {
            Geometry::Cone {
                base,
                tip: top,
                radius,
            }
        } else {
            Geometry::Cylinder {
                p1: base,
                p2: top,
                radius,
            }
        };
    }
    // The layouts admit the keywords of primitives alone, and a plane's last.
    Geometry::from_numbers(kind, nums).unwrap_or_else(|| Geometry::Plane {
        point: p(0),
        normal: p(3),
    })
}

#[cfg(test)]
mod tests {
    use crate::diag::Severity;
    use crate::sdf::ast::StatementKind;
    use crate::sdf::{parse, LoadOptions};
    use crate::shape::Geometry;
    use glam::DVec3;

    #[test]
    fn every_shape_keyword_has_its_own_number_layout() {
        // `Layout::of` falls back to the plane's layout; a keyword added to SHAPE_KINDS
        // without its own row would silently read as a plane.
        for kind in super::SHAPE_KINDS.iter().filter(|k| **k != "composite") {
            assert_eq!(super::Layout::of(kind).kind, *kind);
        }
    }
    use std::path::Path;

    fn shapes(text: &str, strict: bool) -> (Vec<Geometry>, Vec<crate::diag::Diagnostic>) {
        let opts = LoadOptions {
            strict,
            ..LoadOptions::default()
        };
        let (statements, ds) = parse(text, Path::new("s.sdf"), &opts);
        let geometries = statements
            .into_iter()
            .filter_map(|s| match s.kind {
                StatementKind::Shape { geometry, .. } => Some(geometry),
                _ => None,
            })
            .collect();
        (geometries, ds)
    }

    #[test]
    fn five_number_cones_and_cylinders_stand_upright_on_their_base() {
        let text = "define material m 1 1 1 1 1 1 1 1 1 10\n\
                    define shape cone k 1 2 3 50 25 m\n\
                    define shape cylinder z -1 0 -2 4 0.5 m\n";
        let (g, ds) = shapes(text, false);
        assert_eq!(
            g,
            [
                Geometry::Cone {
                    base: DVec3::new(1.0, 2.0, 3.0),
                    tip: DVec3::new(1.0, 52.0, 3.0),
                    radius: 25.0
                },
                Geometry::Cylinder {
                    p1: DVec3::new(-1.0, 0.0, -2.0),
                    p2: DVec3::new(-1.0, 4.0, -2.0),
                    radius: 0.5
                }
            ]
        );
        // One warning for the file: later lines written this way are read the same.
        let upright: Vec<_> = ds
            .iter()
            .filter(|d| d.message.contains("[base] <height> <radius>"))
            .collect();
        assert_eq!(upright.len(), 1, "{ds:?}");
        assert_eq!(upright[0].severity, Severity::Warning);
        let (_, ds) = shapes(text, true);
        assert!(ds.iter().any(
            |d| d.severity == Severity::Error && d.message.contains("[base] <height> <radius>")
        ));
    }

    #[test]
    fn other_cone_layouts_stay_errors() {
        let text = "define material m 1 1 1 1 1 1 1 1 1 10\n\
                    define shape cone k 0 6 30 0 1 0 10 20 m\n";
        let (g, ds) = shapes(text, false);
        assert!(g.is_empty());
        let e = ds
            .iter()
            .find(|d| d.severity == Severity::Error)
            .expect("an error");
        assert!(e.message.contains("found 8"), "{}", e.message);
    }
}
