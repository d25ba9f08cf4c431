//! `define shape`: the geometric primitives and composites.

use super::{At, PResult, Parser, SHAPE_KINDS};
use crate::diag::suggest;
use crate::limits;
use crate::sdf::ast::StatementKind;
use crate::sdf::lexer::{looks_numeric, Line};
use crate::shape::geometry::degeneracy;
use crate::shape::Geometry;
use glam::DVec3;

const FORM_SPHERE: &str = "define shape sphere <name> [center] <radius> <material>";
const FORM_BOX: &str = "define shape box <name> [p1] [p2] <material>";
const FORM_TRIANGLE: &str = "define shape triangle <name> [v1] [v2] [v3] <material>";
const FORM_CYLINDER: &str = "define shape cylinder <name> [p1] [p2] <radius> <material>";
const FORM_CONE: &str = "define shape cone <name> [base] [tip] <radius> <material>";
const FORM_PLANE: &str = "define shape plane <name> [point] [normal] <material>";
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
                self.warn(
                    line,
                    At::Tok(kind_at),
                    "mesh files (`define shape obj`) are not supported; shape skipped",
                    None,
                );
                self.skip_name(line, name_at);
            }
            k if SHAPE_KINDS.contains(&k) => {
                if self.geometric_shape(line, kind_at).is_err() {
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

    fn geometric_shape(&mut self, line: &Line, kind_at: usize) -> PResult<()> {
        let toks = &line.tokens;
        let kind = toks[kind_at].text;
        let (expected, layout, form) = match kind {
            "sphere" => (4, "[center] <radius>", FORM_SPHERE),
            "box" => (6, "[p1] [p2]", FORM_BOX),
            "triangle" => (9, "[v1] [v2] [v3]", FORM_TRIANGLE),
            "cylinder" => (7, "[p1] [p2] <radius>", FORM_CYLINDER),
            "cone" => (7, "[base] [tip] <radius>", FORM_CONE),
            _ => (6, "[point] [normal]", FORM_PLANE),
        };
        let canonical = if matches!(kind, "cylinder" | "cone") {
            format!(
                "canonical form: `{form}` (layouts such as `center height radius` or `pos axis radius height` are not read)"
            )
        } else {
            format!("canonical form: `{form}`")
        };
        let name_at = kind_at + 1;
        let Some(name_tok) = toks.get(name_at) else {
            return Err(self.error(
                line,
                At::End,
                format!("expected the {kind}'s name, found end of line"),
                Some(canonical),
            ));
        };
        let name = name_tok.text.to_string();
        let args = name_at + 1..toks.len();
        if args.is_empty() {
            return Err(self.error(
                line,
                At::End,
                format!("expected the {kind}'s {layout} and material, found end of line"),
                Some(canonical),
            ));
        }
        // The material normally comes last; some files write it right after the name.
        let material_first = args.len() >= 2
            && !looks_numeric(toks[args.start].text)
            && toks[args.start + 1..].iter().all(|t| looks_numeric(t.text));
        let (mat_at, nums_from, nums_to) = if material_first {
            (args.start, args.start + 1, toks.len())
        } else {
            (toks.len() - 1, args.start, toks.len() - 1)
        };
        if !material_first
            && looks_numeric(toks[mat_at].text)
            && nums_to - nums_from + 1 == expected
        {
            return Err(self.error(
                line,
                At::End,
                format!("expected a material name after the {kind}'s numbers, found end of line"),
                Some(canonical),
            ));
        }
        let nums = self.numbers(line, nums_from, nums_to)?;
        if nums.len() != expected {
            let at = if nums.len() > expected {
                At::Span(nums_from + expected, nums_to - 1)
            } else if material_first {
                At::End
            } else {
                At::Tok(mat_at)
            };
            return Err(self.error(
                line,
                at,
                format!(
                    "a {kind} takes {expected} numbers ({layout}), found {}",
                    nums.len()
                ),
                Some(canonical),
            ));
        }
        let p = |i: usize| DVec3::new(nums[i], nums[i + 1], nums[i + 2]);
        let radius_at = At::Tok(nums_from + expected - 1);
        let mut geometry = match kind {
            "sphere" => Geometry::Sphere {
                center: p(0),
                radius: nums[3],
            },
            "box" => Geometry::Box { p1: p(0), p2: p(3) },
            "triangle" => Geometry::Triangle {
                vertices: [p(0), p(3), p(6)],
            },
            "cylinder" => Geometry::Cylinder {
                p1: p(0),
                p2: p(3),
                radius: nums[6],
            },
            "cone" => Geometry::Cone {
                base: p(0),
                tip: p(3),
                radius: nums[6],
            },
            _ => Geometry::Plane {
                point: p(0),
                normal: p(3),
            },
        };
        if let Geometry::Sphere { radius, .. }
        | Geometry::Cylinder { radius, .. }
        | Geometry::Cone { radius, .. } = &mut geometry
        {
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
        if let Some(reason) = degeneracy(&geometry) {
            let at = match geometry {
                Geometry::Sphere { .. } | Geometry::Cylinder { .. } | Geometry::Cone { .. }
                    if reason.contains("radius") =>
                {
                    radius_at
                }
                _ => At::Span(nums_from, nums_to - 1),
            };
            self.warn(
                line,
                at,
                format!("{kind} `{name}` {reason}; shape dropped"),
                None,
            );
        }
        let material = self.name_ref(line, mat_at);
        let kind_stmt = StatementKind::Shape {
            name,
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
        if material_first {
            self.variant(
                line,
                At::Tok(mat_at),
                "material-first",
                "material written before the coordinates".to_string(),
                format!("read as `{kind_stmt}`"),
            );
        }
        self.emit(line, kind_stmt);
        Ok(())
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
        self.emit(line, StatementKind::Composite { name, children });
        Ok(())
    }
}
