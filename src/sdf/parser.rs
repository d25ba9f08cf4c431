//! Parsing: the tokens of each line → canonical statements (DIALECT.md).
//!
//! Every accepted variant is normalised here, so the statement list that comes out only uses
//! the canonical forms of `ast.rs`. Problems are reported with the line, the column of the
//! offending token and, where it helps, the canonical form of the statement. A statement with
//! an error is dropped (parsing goes on, to report every problem in one run); the names it
//! would have defined are remembered so that later references to them do not pile up
//! follow-on errors.

use super::ast::{
    CameraDef, LightDef, MaterialDef, NameRef, RenderDef, Statement, StatementKind, TransformOp,
};
use super::lexer::{self, looks_numeric, Line, NumberError};
use super::{LoadOptions, MaterialField};
use crate::diag::{suggest, Diagnostic, Loc, Severity};
use crate::limits::{self, DEFAULT_IMAGE_SIZE, FOV_RULE};
use crate::shape::geometry::{degeneracy, is_zero, parallel};
use crate::shape::Geometry;
use glam::{DVec3, Vec3};
use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::sync::Arc;

/// Smallest scale factor accepted (besides the error for 0 itself).
const MIN_SCALE: f64 = 1e-9;

const FORM_MATERIAL: &str = "define material <name> [Ka] [Kd] [Ks] <m> [extras...]";
const FORM_SPHERE: &str = "define shape sphere <name> [center] <radius> <material>";
const FORM_BOX: &str = "define shape box <name> [p1] [p2] <material>";
const FORM_TRIANGLE: &str = "define shape triangle <name> [v1] [v2] [v3] <material>";
const FORM_CYLINDER: &str = "define shape cylinder <name> [p1] [p2] <radius> <material>";
const FORM_CONE: &str = "define shape cone <name> [base] [tip] <radius> <material>";
const FORM_PLANE: &str = "define shape plane <name> [point] [normal] <material>";
const FORM_COMPOSITE: &str = "define shape composite <name> <child> ...";
const FORM_LIGHT: &str = "define light <name> [pos] [color] <brightness>";
const FORM_AMBIENT_LIGHT: &str = "define light ambient <name> [rgb]";
const FORM_AMBIENT: &str = "ambient [rgb]";
const FORM_BACKGROUND: &str = "background [rgb]";
const FORM_CAMERA: &str = "define camera <name> <fov-x> [eye] [dir] [up]";
const FORM_TRANSFORM: &str =
    "transform <target> translate [v] | rotate <degrees> [axis] | scale <s> | scale [sx sy sz]";
const FORM_RENDER: &str = "render <camera> <file> <width> <height> [<samples>]";

const STATEMENT_KEYWORDS: [&str; 6] = [
    "define",
    "transform",
    "render",
    "camera",
    "ambient",
    "background",
];
const DEFINE_KINDS: [&str; 8] = [
    "material",
    "shape",
    "light",
    "camera",
    "ambient",
    "background",
    "transform",
    "render",
];
const SHAPE_KINDS: [&str; 7] = [
    "sphere",
    "box",
    "triangle",
    "cylinder",
    "cone",
    "plane",
    "composite",
];

/// The statements of a file, the problems met, and what `build` needs to know about the text.
pub struct Parsed {
    pub statements: Vec<Statement>,
    pub diagnostics: Vec<Diagnostic>,
    pub source: SourceContext,
}

/// What the builder needs from the source beyond the statements themselves.
#[derive(Debug, Default)]
pub struct SourceContext {
    /// The file's lines as written, for quoting them in diagnostics.
    pub lines: Vec<String>,
    /// Names whose definition was rejected or skipped (already reported): references to them
    /// are ignored instead of being reported again as undefined.
    pub skipped: HashSet<String>,
    /// Render-like lines met, including rejected ones: a file whose only render line was
    /// rejected has not "no render statement".
    pub render_lines: usize,
    /// Whether a camera definition was rejected (so the default camera is no stand-in).
    pub cameras_rejected: bool,
    /// Names defined only in commented-out lines → the line (see `commented_definitions`).
    pub commented: HashMap<String, u32>,
}

impl SourceContext {
    pub fn line(&self, number: u32) -> Option<&str> {
        let i = usize::try_from(number).ok()?.checked_sub(1)?;
        self.lines.get(i).map(String::as_str)
    }
}

/// An error has been reported; the statement is dropped.
struct Fail;
type PResult<T> = Result<T, Fail>;

/// Where on a line a diagnostic points.
#[derive(Clone, Copy, Debug)]
enum At {
    /// One token.
    Tok(usize),
    /// Tokens `a..=b`.
    Span(usize, usize),
    /// Just after the last token (something is missing).
    End,
}

/// A place in the source, kept after the line itself is gone (for checks done at the end).
#[derive(Clone, Debug)]
struct Anchor {
    loc: Loc,
    width: u32,
    text: String,
}

/// How a render-like line named its camera.
enum RenderCamera {
    Named,
    /// A lone name that is either a camera (no file given) or a file (no camera given);
    /// decided once every camera of the file is known.
    Ambiguous(String),
    Missing,
}

/// A render statement whose camera or output is settled after the whole file is read.
struct PendingRender {
    index: usize,
    anchor: Anchor,
    camera: RenderCamera,
    output_given: bool,
    /// Where the output name is written (the whole line if it is not).
    output_anchor: Anchor,
    /// Descriptions of the variants read on this line, for one warning.
    notes: Vec<String>,
}

pub(super) fn parse(text: &str, path: &Path, opts: &LoadOptions) -> Parsed {
    let lines = lexer::lines(text);
    let mut p = Parser {
        file: Arc::from(path),
        path,
        opts,
        statements: Vec::new(),
        diagnostics: Vec::new(),
        skipped: HashSet::new(),
        camera_names: Vec::new(),
        pending: Vec::new(),
        nine_number_noted: [false; 2],
        variants_noted: HashSet::new(),
        render_lines: 0,
        cameras_rejected: false,
    };
    for line in &lines {
        p.line(line);
    }
    p.resolve_renders();
    p.prune_skipped_references();
    p.drop_transforms_of_commented_definitions(&lines);
    Parsed {
        statements: p.statements,
        diagnostics: p.diagnostics,
        source: SourceContext {
            lines: lines.iter().map(|l| l.text.to_string()).collect(),
            skipped: p.skipped,
            render_lines: p.render_lines,
            cameras_rejected: p.cameras_rejected,
            commented: commented_definitions(&lines)
                .into_iter()
                .map(|(name, line)| (name.to_string(), line))
                .collect(),
        },
    }
}

struct Parser<'a> {
    file: Arc<Path>,
    path: &'a Path,
    opts: &'a LoadOptions,
    statements: Vec<Statement>,
    diagnostics: Vec<Diagnostic>,
    skipped: HashSet<String>,
    /// Every camera name defined in the file (also by lines that failed), in order.
    camera_names: Vec<String>,
    pending: Vec<PendingRender>,
    /// Whether the 9-number light reading was already explained: [rgb-brightness, lecture].
    nine_number_noted: [bool; 2],
    /// Variant spellings already explained: each is warned about once per file, as the same
    /// reading applies to every later line written that way.
    variants_noted: HashSet<&'static str>,
    render_lines: usize,
    cameras_rejected: bool,
}

impl Parser<'_> {
    // ----- diagnostics -------------------------------------------------------------------

    /// Column and caret width of `at`.
    fn place(line: &Line, at: At) -> (u32, u32) {
        match at {
            At::Tok(i) => line
                .tokens
                .get(i)
                .map_or((line.end_col(), 1), |t| (t.col, t.width)),
            At::Span(a, b) => match (line.tokens.get(a), line.tokens.get(b)) {
                (Some(ta), Some(tb)) => (
                    ta.col,
                    tb.col
                        .saturating_add(tb.width)
                        .saturating_sub(ta.col)
                        .max(1),
                ),
                _ => (line.end_col(), 1),
            },
            At::End => (line.end_col(), 1),
        }
    }

    fn anchor(&self, line: &Line, at: At) -> Anchor {
        let (col, width) = Self::place(line, at);
        Anchor {
            loc: Loc {
                file: self.file.clone(),
                line: line.number,
                col,
            },
            width,
            text: line.text.to_string(),
        }
    }

    /// The location of `at` (without copying the line, as `anchor` does: name references
    /// are made for every token of long composite lines).
    fn loc(&self, line: &Line, at: At) -> Loc {
        Loc {
            file: self.file.clone(),
            line: line.number,
            col: Self::place(line, at).0,
        }
    }

    fn report(
        &mut self,
        severity: Severity,
        anchor: Anchor,
        message: String,
        help: Option<String>,
    ) {
        let mut d =
            Diagnostic::new(severity, anchor.loc, message).with_source(anchor.text, anchor.width);
        if let Some(h) = help {
            d = d.with_help(h);
        }
        self.diagnostics.push(d);
    }

    fn error(
        &mut self,
        line: &Line,
        at: At,
        message: impl Into<String>,
        help: Option<String>,
    ) -> Fail {
        let anchor = self.anchor(line, at);
        self.report(Severity::Error, anchor, message.into(), help);
        Fail
    }

    fn warn(&mut self, line: &Line, at: At, message: impl Into<String>, help: Option<String>) {
        let anchor = self.anchor(line, at);
        self.report(Severity::Warning, anchor, message.into(), help);
    }

    /// Explains a variant spelling the first time the file uses it.
    fn variant(&mut self, line: &Line, at: At, key: &'static str, message: String, help: String) {
        let help =
            format!("{help} (later lines written this way are read the same, without a warning)");
        self.warn_once(line, at, key, message, help);
    }

    /// A warning given only the first time its `key` comes up in the file.
    fn warn_once(&mut self, line: &Line, at: At, key: &'static str, message: String, help: String) {
        if self.variants_noted.insert(key) {
            self.warn(line, at, message, Some(help));
        }
    }

    fn emit(&mut self, line: &Line, kind: StatementKind) {
        let loc = self.loc(line, At::Tok(0));
        self.statements.push(Statement { kind, loc });
    }

    fn name_ref(&self, line: &Line, i: usize) -> NameRef {
        NameRef {
            name: line
                .tokens
                .get(i)
                .map_or(String::new(), |t| t.text.to_string()),
            loc: self.loc(line, At::Tok(i)),
        }
    }

    /// Remembers that the definition of the name at token `i` was not taken, so references
    /// to it stay quiet (the problem was reported here).
    fn skip_name(&mut self, line: &Line, i: usize) {
        if let Some(t) = line.tokens.get(i) {
            self.skipped.insert(t.text.to_string());
        }
    }

    // ----- numbers -----------------------------------------------------------------------

    fn bad_number(&mut self, line: &Line, i: usize, e: NumberError) -> Fail {
        let text = line.tokens.get(i).map_or("", |t| t.text).to_string();
        let (message, help) = match e {
            NumberError::Malformed => {
                let help = if text.contains(['O', 'o'])
                    && lexer::parse_number(&text.replace(['O', 'o'], "0")).is_ok()
                {
                    format!(
                        "`{text}` contains the letter O; did you mean `{}`?",
                        text.replace(['O', 'o'], "0")
                    )
                } else {
                    "numbers look like 1, -1.5, .5, +100 or 1e-3".to_string()
                };
                (format!("expected a number, found '{text}'"), help)
            }
            NumberError::NotFinite => (
                format!("expected a number, found '{text}'"),
                "nan and inf are not allowed: every number must be finite".to_string(),
            ),
            NumberError::Suffix(plain) => (
                format!("expected a number, found '{text}'"),
                format!("SDF numbers take no type suffix: write `{plain}`"),
            ),
            NumberError::DecimalComma(dotted) => (
                format!("expected a number, found '{text}'"),
                format!("use a decimal point: `{dotted}`"),
            ),
            NumberError::TooLarge => (
                format!("number '{text}' is out of range"),
                format!(
                    "numbers must lie between -{m:e} and {m:e}",
                    m = lexer::MAX_MAGNITUDE
                ),
            ),
        };
        self.error(line, At::Tok(i), message, Some(help))
    }

    /// Reads tokens `from..to` as numbers, reporting every one that is not.
    fn numbers(&mut self, line: &Line, from: usize, to: usize) -> PResult<Vec<f64>> {
        let mut out = Vec::with_capacity(to.saturating_sub(from));
        let mut failed = false;
        for i in from..to.min(line.tokens.len()) {
            match lexer::parse_number(line.tokens[i].text) {
                Ok(v) => out.push(v),
                Err(e) => {
                    self.bad_number(line, i, e);
                    failed = true;
                }
            }
        }
        if failed {
            Err(Fail)
        } else {
            Ok(out)
        }
    }

    /// The index just past the run of number-like tokens starting at `from`.
    fn number_run_end(line: &Line, from: usize) -> usize {
        let mut j = from;
        while j < line.tokens.len() && looks_numeric(line.tokens[j].text) {
            j += 1;
        }
        j
    }

    // ----- dispatch ----------------------------------------------------------------------

    fn line(&mut self, line: &Line) {
        let Some(first) = line.tokens.first() else {
            return;
        };
        match first.text {
            "define" => self.define(line),
            "transform" => self.transform(line, 1, None),
            "view" => self.transform(line, 1, Some("`view` read as `transform`")),
            "render" => self.render(line, 1, true, None),
            "renderer" => self.render(line, 1, false, Some("`renderer` read as `render`")),
            "camera" => self.camera(line, 1),
            "ambient" => self.ambient(line, 1),
            "background" => self.background(line, 1),
            other => {
                let help = if other.starts_with("<<<<<<<")
                    || other.starts_with("=======")
                    || other.starts_with(">>>>>>>")
                {
                    Some("this looks like a merge-conflict marker".to_string())
                } else {
                    suggest(other, STATEMENT_KEYWORDS).map(|s| format!("did you mean `{s}`?"))
                };
                self.warn(
                    line,
                    At::Tok(0),
                    format!("unknown statement '{other}'; line skipped"),
                    help,
                );
            }
        }
    }

    fn define(&mut self, line: &Line) {
        let Some(kind) = line.tokens.get(1) else {
            self.warn(
                line,
                At::Tok(0),
                "`define` without anything to define; line skipped",
                None,
            );
            return;
        };
        match kind.text {
            "material" => self.material(line),
            "shape" => self.shape(line, 2),
            "light" => self.light(line),
            "camera" => self.camera(line, 2),
            "ambient" => self.ambient(line, 2),
            "background" => self.background(line, 2),
            "backgroundcolor" => self.background(line, 2),
            "transform" => self.transform(line, 2, Some("`define transform` read as `transform`")),
            "render" | "renderer" => {
                let note = format!("`define {}` read as `render`", kind.text);
                self.render(line, 2, false, Some(&note))
            }
            k if SHAPE_KINDS.contains(&k) => self.shape(line, 1),
            other => {
                let help = suggest(other, DEFINE_KINDS)
                    .map(|s| format!("did you mean `{s}`?"))
                    .unwrap_or_else(|| format!("known kinds: {}", DEFINE_KINDS.join(", ")));
                self.warn(
                    line,
                    At::Tok(1),
                    format!("unknown definition kind '{other}'; line skipped"),
                    Some(help),
                );
                self.skip_name(line, 2);
            }
        }
    }

    // ----- materials ---------------------------------------------------------------------

    fn material(&mut self, line: &Line) {
        if self.material_inner(line).is_err() {
            self.skip_name(line, 2);
        }
    }

    fn material_inner(&mut self, line: &Line) -> PResult<()> {
        let toks = &line.tokens;
        if toks.len() < 3 {
            return Err(self.error(
                line,
                At::End,
                "expected a material name, found end of line",
                Some(format!("canonical form: `{FORM_MATERIAL}`")),
            ));
        }
        let name = toks[2].text.to_string();
        let nums = self.numbers(line, 3, toks.len())?;
        let opts = self.opts;
        let fields = &opts.material_fields;
        let field_list = field_names(fields);
        if nums.len() < 10 {
            return Err(self.error(
                line,
                At::End,
                format!(
                    "a material needs 10 numbers ([Ka] [Kd] [Ks] <m>), found {}",
                    nums.len()
                ),
                Some(format!("canonical form: `{FORM_MATERIAL}`")),
            ));
        }
        let extras = nums.len() - 10;
        if extras > fields.len() {
            let first_surplus = 3 + 10 + fields.len();
            // The current list, padded with the ignored field to the count on this line.
            let mut padded: Vec<&str> = fields.iter().map(field_name).collect();
            padded.resize(extras, "roughness");
            let padded = padded.join(",");
            let help = format!(
                "the numbers after m are read as --material-fields {field_list}; this line has {extras}. \
                 Name them all with --material-fields (from reflectivity, opacity, transparency, ior, \
                 roughness), e.g. `--material-fields {padded}` (roughness is read and ignored)"
            );
            return Err(self.error(
                line,
                At::Span(first_surplus, toks.len() - 1),
                format!(
                    "too many numbers for a material: {} (at most {} with --material-fields {field_list})",
                    nums.len(),
                    10 + fields.len()
                ),
                Some(help),
            ));
        }
        let c3 = |i: usize| Vec3::new(nums[i] as f32, nums[i + 1] as f32, nums[i + 2] as f32);
        let mut def = MaterialDef {
            name,
            ka: c3(0),
            kd: c3(3),
            ks: c3(6),
            m: nums[9] as f32,
            reflectivity: 0.0,
            opacity: 1.0,
            ior: 1.0,
        };
        if def.m < 0.0 {
            self.warn(
                line,
                At::Tok(12),
                format!(
                    "the Phong exponent m must not be negative, found {}; its absolute value is used",
                    nums[9]
                ),
                None,
            );
            def.m = def.m.abs();
        } else if def.m == 0.0 {
            // Kept: pow(x, 0) = 1 is well defined, and it is what the file's own renderer drew.
            self.warn(
                line,
                At::Tok(12),
                "the Phong exponent m is 0: the highlight covers the whole lit side",
                Some("m is usually between 1 (dull) and a few hundred (sharp)".to_string()),
            );
        }
        let mut opacity_at = None;
        for (k, field) in fields.iter().enumerate().take(extras) {
            let value = nums[10 + k];
            let at = At::Tok(13 + k);
            match field {
                MaterialField::Reflectivity => {
                    def.reflectivity = self.unit_interval(line, at, "reflectivity", value);
                }
                MaterialField::Opacity => {
                    def.opacity = self.unit_interval(line, at, "opacity", value);
                    opacity_at = Some(at);
                }
                MaterialField::Transparency => {
                    def.opacity = 1.0 - self.unit_interval(line, at, "transparency", value);
                }
                MaterialField::Ior => {
                    if value <= 0.0 {
                        self.warn(
                            line,
                            at,
                            format!(
                                "the index of refraction must be positive, found {value}; 1 used"
                            ),
                            None,
                        );
                    } else {
                        def.ior = value as f32;
                    }
                }
                MaterialField::Roughness => {}
            }
        }
        if let Some(at) = opacity_at.filter(|_| def.opacity == 0.0 && def.ior == 1.0) {
            // Fully transparent without refraction: invisible. Many files mean transparency
            // by this number (0 = opaque), and this is the symptom. Said once per file.
            self.warn_once(
                line,
                at,
                "invisible-material",
                format!(
                    "material `{}` is invisible: fully transparent (opacity 0) and not refracting (ior 1)",
                    def.name
                ),
                "if this file means transparency by this number, load it with \
                 --material-fields reflectivity,transparency,ior"
                    .to_string(),
            );
        }
        self.emit(line, StatementKind::Material(def));
        Ok(())
    }

    /// A value that must lie in [0, 1]: clamped with a warning.
    fn unit_interval(&mut self, line: &Line, at: At, what: &str, value: f64) -> f32 {
        let clamped = limits::clamp_fraction(value);
        if clamped != value {
            self.warn(
                line,
                at,
                format!("{what} {value} is outside [0, 1]; clamped to {clamped}"),
                None,
            );
        }
        clamped as f32
    }

    // ----- shapes ------------------------------------------------------------------------

    /// `define shape <kind> <name> ...` (`kind_at` = 2) or the variant without `shape`
    /// (`kind_at` = 1).
    fn shape(&mut self, line: &Line, kind_at: usize) {
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

    // ----- lights ------------------------------------------------------------------------

    fn light(&mut self, line: &Line) {
        let toks = &line.tokens;
        // `define light ambient|diffuse <name> ...` is the typed form only when a name
        // follows; `define light ambient 0 0 0 ...` is a point light named `ambient`.
        let typed = toks
            .get(2)
            .filter(|t| matches!(t.text, "ambient" | "diffuse"))
            .is_some_and(|_| toks.get(3).is_some_and(|n| !looks_numeric(n.text)));
        let name_at = if typed { 3 } else { 2 };
        let result = if typed && toks[2].text == "ambient" {
            self.ambient_light(line, name_at)
        } else {
            self.point_light(line, name_at)
        };
        if result.is_err() {
            self.skip_name(line, name_at);
        }
    }

    fn ambient_light(&mut self, line: &Line, name_at: usize) -> PResult<()> {
        let nums = self.numbers(line, name_at + 1, line.tokens.len())?;
        let rgb = match nums.len() {
            1 => Vec3::splat(nums[0] as f32),
            3 => Vec3::new(nums[0] as f32, nums[1] as f32, nums[2] as f32),
            n => {
                return Err(self.error(
                    line,
                    At::Span(
                        name_at + 1,
                        line.tokens.len().saturating_sub(1).max(name_at + 1),
                    ),
                    format!("an ambient light takes 3 numbers (r g b), found {n}"),
                    Some(format!("canonical form: `{FORM_AMBIENT_LIGHT}`")),
                ))
            }
        };
        // The name is not needed: ambient light is one value for the whole scene.
        self.skipped.insert(line.tokens[name_at].text.to_string());
        self.emit(line, StatementKind::Ambient(rgb));
        Ok(())
    }

    fn point_light(&mut self, line: &Line, name_at: usize) -> PResult<()> {
        let toks = &line.tokens;
        let Some(name_tok) = toks.get(name_at) else {
            return Err(self.error(
                line,
                At::End,
                "expected the light's name, found end of line",
                Some(format!("canonical form: `{FORM_LIGHT}`")),
            ));
        };
        let name = name_tok.text.to_string();
        let nums = self.numbers(line, name_at + 1, toks.len())?;
        let v = |i: usize| DVec3::new(nums[i], nums[i + 1], nums[i + 2]);
        let c = |i: usize| Vec3::new(nums[i] as f32, nums[i + 1] as f32, nums[i + 2] as f32);
        let light = |color: Vec3, brightness: f32| LightDef {
            name: name.clone(),
            position: v(0),
            color,
            brightness,
        };
        match nums.len() {
            7 => {
                let l = light(c(3), nums[6] as f32);
                self.emit(line, StatementKind::Light(l));
            }
            6 => {
                let l = light(c(3), 1.0);
                self.emit(line, StatementKind::Light(l));
            }
            9 => {
                let last = c(6);
                let nums_at = At::Span(name_at + 4, toks.len() - 1);
                if last.max_element() > 1.0 {
                    let l = light(c(3) * last, 1.0);
                    if !self.nine_number_noted[0] {
                        self.nine_number_noted[0] = true;
                        self.warn(
                            line,
                            nums_at,
                            "9-number light read as [pos] [color] [rgb-brightness] (a brightness above 1); \
                             intensity = color × brightness per channel",
                            Some(format!("read as `{}`", StatementKind::Light(l.clone()))),
                        );
                    }
                    self.emit(line, StatementKind::Light(l));
                } else {
                    let ambient = c(3);
                    let diffuse = last;
                    if !self.nine_number_noted[1] {
                        self.nine_number_noted[1] = true;
                        self.warn(
                            line,
                            nums_at,
                            "9-number light read as the lecture form [pos] [La] [Ld] (no number above 1): \
                             La is added to the ambient light, Ld is the light's intensity",
                            Some(format!(
                                "for a brightness per channel, one of the last three numbers must exceed 1; \
                                 canonical form: `{FORM_LIGHT}`"
                            )),
                        );
                    }
                    if ambient != Vec3::ZERO {
                        self.emit(line, StatementKind::AmbientAdd(ambient));
                    }
                    if diffuse == Vec3::ZERO {
                        // A pure ambient term: there is no point light to place.
                        self.skipped.insert(name);
                    } else {
                        let l = light(diffuse, 1.0);
                        self.emit(line, StatementKind::Light(l));
                    }
                }
            }
            4 => {
                // No position: the only meaning left is an ambient term, colour × brightness
                // (`define light ambient1 .3 .2 .6 5`), added like the lecture form's La.
                let rgb = c(0) * nums[3] as f32;
                self.warn(
                    line,
                    At::Span(name_at + 1, toks.len() - 1),
                    "a light with 4 numbers has no position: read as ambient light [rgb] <brightness>, \
                     added to the scene's ambient light",
                    Some(format!(
                        "write `{FORM_AMBIENT}` for ambient light, or `{FORM_LIGHT}` for a point light"
                    )),
                );
                self.skipped.insert(name);
                self.emit(line, StatementKind::AmbientAdd(rgb));
            }
            n => {
                let at = if n > 7 {
                    At::Span(name_at + 8, toks.len() - 1)
                } else {
                    At::End
                };
                let mut help = format!(
                    "canonical form: `{FORM_LIGHT}`; 6 numbers (no brightness) and 9 are also read"
                );
                if matches!(n, 1 | 3) {
                    help.push_str(&format!(
                        ". An ambient light is written `{FORM_AMBIENT}` or `{FORM_AMBIENT_LIGHT}`"
                    ));
                }
                return Err(self.error(
                    line,
                    at,
                    format!("a light takes 7 numbers ([pos] [color] <brightness>), found {n}"),
                    Some(help),
                ));
            }
        }
        Ok(())
    }

    // ----- ambient and background --------------------------------------------------------

    /// `ambient [<name>] <s>|[rgb]`, `define ambient [<name>] [rgb] [<k>]`.
    fn ambient(&mut self, line: &Line, from: usize) {
        let toks = &line.tokens;
        let mut at = from;
        if toks.get(at).is_some_and(|t| !looks_numeric(t.text)) {
            at += 1; // an ambient light's name, not needed
        }
        let Ok(nums) = self.numbers(line, at, toks.len()) else {
            return;
        };
        let c = |i: usize| Vec3::new(nums[i] as f32, nums[i + 1] as f32, nums[i + 2] as f32);
        let rgb = match nums.len() {
            1 => Vec3::splat(nums[0] as f32),
            3 => c(0),
            4 => c(0) * nums[3] as f32,
            n => {
                self.error(
                    line,
                    if n == 0 { At::End } else { At::Span(at, toks.len() - 1) },
                    format!("ambient takes 3 numbers (r g b), found {n}"),
                    Some(format!(
                        "canonical form: `{FORM_AMBIENT}`; also read: `ambient <s>`, `define ambient <name> [rgb] <k>`"
                    )),
                );
                return;
            }
        };
        self.emit(line, StatementKind::Ambient(rgb));
    }

    fn background(&mut self, line: &Line, from: usize) {
        let toks = &line.tokens;
        let Ok(nums) = self.numbers(line, from, toks.len()) else {
            return;
        };
        match nums.len() {
            3 => {
                let rgb = Vec3::new(nums[0] as f32, nums[1] as f32, nums[2] as f32);
                self.emit(line, StatementKind::Background(rgb));
            }
            1 => {
                let kind = StatementKind::Background(Vec3::splat(nums[0] as f32));
                self.warn(
                    line,
                    At::Tok(from),
                    "background with one number read as a grey",
                    Some(format!("read as `{kind}`")),
                );
                self.emit(line, kind);
            }
            n => {
                self.error(
                    line,
                    if n == 0 {
                        At::End
                    } else {
                        At::Span(from, toks.len() - 1)
                    },
                    format!("background takes 3 numbers (r g b), found {n}"),
                    Some(format!("canonical form: `{FORM_BACKGROUND}`")),
                );
            }
        }
    }

    // ----- cameras -----------------------------------------------------------------------

    fn camera(&mut self, line: &Line, name_at: usize) {
        if let Some(t) = line.tokens.get(name_at) {
            self.camera_names.push(t.text.to_string());
        }
        if self.camera_inner(line, name_at).is_err() {
            self.cameras_rejected = true;
            self.skip_name(line, name_at);
        }
    }

    fn camera_inner(&mut self, line: &Line, name_at: usize) -> PResult<()> {
        let toks = &line.tokens;
        let form = Some(format!("canonical form: `{FORM_CAMERA}`"));
        let Some(name_tok) = toks.get(name_at) else {
            return Err(self.error(
                line,
                At::End,
                "expected the camera's name, found end of line",
                form,
            ));
        };
        let name = name_tok.text.to_string();
        let first = name_at + 1;
        let mut nums = self.numbers(line, first, toks.len())?;
        // Two unambiguous layouts that their authors' renderers drew: the eye alone (looking
        // along -z with y up), and the full form with one stray number after it.
        if nums.len() == 4 {
            self.warn(
                line,
                At::Span(first + 1, first + 3),
                "camera with an eye position but no direction or up vector: looking along -z with y up",
                Some(format!("canonical form: `{FORM_CAMERA}`")),
            );
        } else if nums.len() == 11 {
            self.warn(
                line,
                At::Tok(first + 10),
                format!(
                    "extra number '{}' after the camera's up vector ignored",
                    toks[first + 10].text
                ),
                Some(format!("canonical form: `{FORM_CAMERA}`")),
            );
            nums.truncate(10);
        } else if nums.len() != 1 && nums.len() != 10 {
            let n = nums.len();
            let mut help = format!("canonical form: `{FORM_CAMERA}` (1 or 10 numbers)");
            if n == 3 || n == 9 {
                help.push_str("; the image size belongs on the render line, not after the fov");
            }
            return Err(self.error(
                line,
                if n == 0 { At::End } else { At::Span(first, toks.len() - 1) },
                format!("a camera takes <fov-x> or <fov-x> [eye] [dir] [up] (1 or 10 numbers), found {n}"),
                Some(help),
            ));
        }
        let fov = nums[0];
        if !limits::fov_is_valid(fov) {
            let fov_last = nums.len() == 10 && limits::fov_is_valid(nums[9]);
            let help = if fov_last {
                format!("the fov comes first: `{FORM_CAMERA}`")
            } else {
                format!("canonical form: `{FORM_CAMERA}`")
            };
            return Err(self.error(
                line,
                At::Tok(first),
                format!("the horizontal field of view must be {FOV_RULE}, found {fov}"),
                Some(help),
            ));
        }
        if fov < std::f64::consts::PI {
            self.warn(
                line,
                At::Tok(first),
                format!("a field of view of {fov}° is very narrow"),
                Some(format!(
                    "the fov is in degrees; {fov} radians would be {:.1}",
                    fov.to_degrees()
                )),
            );
        }
        let mut def = CameraDef {
            name,
            fov_x_deg: fov,
            eye: DVec3::ZERO,
            dir: DVec3::NEG_Z,
            up: DVec3::Y,
        };
        if nums.len() == 4 {
            def.eye = DVec3::new(nums[1], nums[2], nums[3]);
        }
        if nums.len() == 10 {
            let v = |i: usize| DVec3::new(nums[i], nums[i + 1], nums[i + 2]);
            def.eye = v(1);
            def.dir = v(4);
            def.up = v(7);
            if is_zero(def.dir) {
                return Err(self.error(
                    line,
                    At::Span(first + 4, first + 6),
                    "the camera's viewing direction is zero",
                    form,
                ));
            }
            if parallel(def.dir, def.up) {
                return Err(self.error(
                    line,
                    At::Span(first + 7, first + 9),
                    "the camera's up vector is zero or parallel to its viewing direction",
                    Some("up must point away from the viewing direction, e.g. 0 1 0 when looking along -z".to_string()),
                ));
            }
        }
        self.emit(line, StatementKind::Camera(def));
        Ok(())
    }

    // ----- transforms --------------------------------------------------------------------

    /// `transform <target> <op> <args> [<op> <args> ...]` with the target at `target_at`;
    /// `variant` names the accepted variant spelling of the statement, if any.
    fn transform(&mut self, line: &Line, target_at: usize, variant: Option<&'static str>) {
        let toks = &line.tokens;
        let form = Some(format!("canonical form: `{FORM_TRANSFORM}`"));
        let Some(target_tok) = toks.get(target_at) else {
            self.error(
                line,
                At::End,
                "expected the name of a shape, composite, camera or light, found end of line",
                form,
            );
            return;
        };
        if toks.len() == target_at + 1 {
            self.error(
                line,
                At::End,
                format!(
                    "expected translate, rotate or scale after `{}`, found end of line",
                    target_tok.text
                ),
                form,
            );
            return;
        }
        let target = self.name_ref(line, target_at);
        let mut ops = Vec::new();
        // Variant spellings read on this line: (where, kind, description).
        let mut notes: Vec<(At, &'static str, String)> = Vec::new();
        if let Some(v) = variant {
            // The description doubles as the key: each keyword variant is explained once.
            notes.push((At::Span(0, target_at - 1), v, v.to_string()));
        }
        let mut failed = false;
        let mut i = target_at + 1;
        while i < toks.len() {
            let op_at = i;
            let op = toks[i].text;
            let nums_from = i + 1;
            let nums_to = Self::number_run_end(line, nums_from);
            let mut next = nums_to;
            let lower = op.to_ascii_lowercase();
            let axis_letter = if op == "rotate" {
                toks.get(nums_to).and_then(|t| axis_of_letter(t.text))
            } else {
                None
            };
            if axis_letter.is_some() {
                next += 1;
            }
            let Ok(nums) = self.numbers(line, nums_from, nums_to) else {
                failed = true;
                i = next.max(i + 1);
                continue;
            };
            let span = if nums.is_empty() {
                At::Tok(op_at)
            } else {
                At::Span(nums_from, nums_to - 1)
            };
            let result = match (op, lower.as_str()) {
                ("translate", _) => {
                    if nums.len() == 3 {
                        Ok(TransformOp::Translate(DVec3::new(nums[0], nums[1], nums[2])))
                    } else {
                        Err(format!("translate takes 3 numbers, found {}", nums.len()))
                    }
                }
                ("scale", _) => {
                    let s = match nums.len() {
                        1 => Ok(DVec3::splat(nums[0])),
                        3 => Ok(DVec3::new(nums[0], nums[1], nums[2])),
                        n => Err(format!("scale takes 1 or 3 numbers, found {n}")),
                    };
                    match s {
                                                Ok(s) if s.cmpeq(DVec3::ZERO).any() => {
                            self.error(
                                line,
                                span,
                                "scale by 0 flattens the object and cannot be undone (the matrix has no inverse)",
                                Some("use a small factor such as 0.001 instead".to_string()),
                            );
                            failed = true;
                            i = next;
                            continue;
                        }
                        Ok(s) if s.abs().min_element() < MIN_SCALE => {
                            // Its inverse would be astronomically large: rays mapped into the
                            // object's space would overflow.
                            self.error(
                                line,
                                span,
                                format!("scale factor too close to 0 (below {MIN_SCALE:e})"),
                                Some("use a factor such as 0.001 instead".to_string()),
                            );
                            failed = true;
                            i = next;
                            continue;
                        }
                        Ok(s) => Ok(TransformOp::Scale(s)),
                        Err(e) => Err(e),
                    }
                }
                ("rotate", _) => match (nums.len(), axis_letter) {
                    (1, Some(axis)) => Ok(TransformOp::Rotate {
                        degrees: nums[0],
                        axis,
                    }),
                    (4, None) => {
                        let axis = DVec3::new(nums[1], nums[2], nums[3]);
                                                if is_zero(axis) && nums[0] == 0.0 {
                            // Turning by 0° is the identity whatever the axis: nothing to do.
                            self.warn(
                                line,
                                span,
                                "rotation by 0° about a zero axis has no effect; ignored",
                                None,
                            );
                            i = next;
                            continue;
                        }
                        if is_zero(axis) {
                            self.error(
                                line,
                                At::Span(nums_from + 1, nums_to - 1),
                                "rotation about a zero axis",
                                Some("the axis must be a non-zero vector, e.g. 0 1 0".to_string()),
                            );
                            failed = true;
                            i = next;
                            continue;
                        }
                        Ok(TransformOp::Rotate {
                            degrees: nums[0],
                            axis,
                        })
                    }
                    (3, None) => {
                        let nonzero: Vec<usize> = (0..3).filter(|&k| nums[k] != 0.0).collect();
                        if nonzero.len() <= 1 {
                            let k = nonzero.first().copied().unwrap_or(0);
                            let op = TransformOp::Rotate {
                                degrees: nums[k],
                                axis: unit_axis(k),
                            };
                                                        notes.push((
                                span,
                                "euler",
                                "`rotate` with 3 numbers read as Euler angles about x, y and z \
                                 (only one of them is non-zero, so their order does not matter)"
                                    .to_string(),
                            ));
                            Ok(op)
                        } else {
                            self.error(
                                line,
                                span,
                                "`rotate` with 3 numbers reads as Euler angles, and with more than one \
                                 non-zero angle their order is ambiguous",
                                Some(
                                    "write one `rotate <degrees> <axis>` per axis, in the order meant, \
                                     e.g. `rotate 30 1 0 0 rotate 45 0 1 0`"
                                        .to_string(),
                                ),
                            );
                            failed = true;
                            i = next;
                            continue;
                        }
                    }
                    (n, Some(_)) => Err(format!("rotate with an axis letter takes 1 number (degrees), found {n}")),
                    (n, None) => Err(format!(
                        "rotate takes <degrees> <axis x y z> (4 numbers) or <degrees> x|y|z, found {n} numbers"
                    )),
                },
                (_, "rotatex" | "rotatey" | "rotatez") => {
                    if nums.len() == 1 {
                        let k = match lower.as_str() {
                            "rotatex" => 0,
                            "rotatey" => 1,
                            _ => 2,
                        };
                        notes.push((At::Tok(op_at), "rotatexyz", format!("`{op}` read as `rotate`")));
                        Ok(TransformOp::Rotate {
                            degrees: nums[0],
                            axis: unit_axis(k),
                        })
                    } else {
                        Err(format!("{op} takes 1 number (degrees), found {}", nums.len()))
                    }
                }
                _ => {
                    let help = suggest(op, ["translate", "rotate", "scale"])
                        .map(|s| format!("did you mean `{s}`?"))
                        .or(form.clone());
                    self.error(
                        line,
                        At::Tok(op_at),
                        format!("expected translate, rotate or scale, found '{op}'"),
                        help,
                    );
                    failed = true;
                    // Nothing after an unknown operation can be trusted.
                    break;
                }
            };
            match result {
                Ok(op) => ops.push(op),
                Err(message) => {
                    let at = if nums.is_empty() {
                        At::Tok(op_at)
                    } else {
                        span
                    };
                    self.error(line, at, message, form.clone());
                    failed = true;
                }
            }
            i = next;
        }
        if failed || ops.is_empty() {
            return;
        }
        let kind = StatementKind::Transform { target, ops };
        // Each variant is explained once per file.
        notes.retain(|(_, key, _)| self.variants_noted.insert(key));
        if let Some((at, _, _)) = notes.first() {
            let what: Vec<&str> = notes.iter().map(|(_, _, n)| n.as_str()).collect();
            self.warn(
                line,
                *at,
                what.join("; "),
                Some(format!(
                    "read as `{kind}` (later lines written this way are read the same, without a warning)"
                )),
            );
        }
        self.emit(line, kind);
    }

    // ----- render ------------------------------------------------------------------------

    /// A render-like line with its arguments from `from`. `camera_expected` is false for the
    /// variants that never name a camera (`renderer <file>`, `define render <file> w h`).
    fn render(&mut self, line: &Line, from: usize, camera_expected: bool, variant: Option<&str>) {
        self.render_lines += 1;
        let toks = &line.tokens;
        let mut notes: Vec<String> = variant.map(str::to_string).into_iter().collect();
        // Names (camera, file) come first, then the numbers. A file name may start with a
        // digit (`001.png`) and a camera may be named by a number (`render 1 out.png ...`):
        // a token is a name if it is not number-like, looks like a file name, or is the
        // first one and a name follows it.
        let is_name =
            |t: &str| !looks_numeric(t) || (file_like(t) && lexer::parse_number(t).is_err());
        let names_end = {
            let mut j = from;
            while j < toks.len()
                && (is_name(toks[j].text)
                    || (j == from && toks.get(j + 1).is_some_and(|t| is_name(t.text))))
            {
                j += 1;
            }
            j
        };
        let nums_end = Self::number_run_end(line, names_end);
        let mut tail = nums_end..toks.len();
        let names = from..names_end;

        let mut camera = RenderCamera::Missing;
        let mut camera_at = None;
        let mut output: Option<String> = None;
        let mut output_at = At::Tok(0);
        let file_pieces = match (camera_expected, names.len()) {
            (_, 0) => None,
            (true, 1) => {
                if tail.len() == 1 && nums_end - names_end >= 2 {
                    // `render cam 800 600 out.ppm`
                    notes.push("image size written before the file name".to_string());
                    camera = RenderCamera::Named;
                    camera_at = Some(from);
                    let pieces = tail.clone();
                    tail = toks.len()..toks.len();
                    Some(pieces)
                } else {
                    camera = RenderCamera::Ambiguous(toks[from].text.to_string());
                    camera_at = Some(from);
                    output_at = At::Tok(from);
                    None
                }
            }
            (true, _) => {
                camera = RenderCamera::Named;
                camera_at = Some(from);
                Some(from + 1..names_end)
            }
            (false, _) => Some(names.clone()),
        };
        if let Some(pieces) = file_pieces {
            output_at = At::Span(pieces.start, pieces.end.saturating_sub(1).max(pieces.start));
            match self.file_name(line, pieces.clone()) {
                Some(name) => output = Some(name),
                None => {
                    self.error(
                        line,
                        At::Span(from, names_end - 1),
                        format!(
                            "expected <camera> <file> before the image size, found {} names",
                            names.len()
                        ),
                        Some(format!("canonical form: `{FORM_RENDER}`")),
                    );
                    return;
                }
            }
        }
        let Ok(nums) = self.numbers(line, names_end, nums_end) else {
            return;
        };
        let (width, height) = match nums.len() {
            0 => {
                notes.push(format!(
                    "no image size given: {}×{}",
                    DEFAULT_IMAGE_SIZE.0, DEFAULT_IMAGE_SIZE.1
                ));
                DEFAULT_IMAGE_SIZE
            }
            1 => {
                self.error(
                    line,
                    At::End,
                    "expected the image height, found end of line",
                    Some(format!("canonical form: `{FORM_RENDER}`")),
                );
                return;
            }
            _ => {
                let (min, max) = (
                    f64::from(*limits::IMAGE_SIDE.start()),
                    f64::from(*limits::IMAGE_SIDE.end()),
                );
                let w = self.whole(line, names_end, nums[0], "image width", min, max);
                let h = self.whole(line, names_end + 1, nums[1], "image height", min, max);
                match (w, h) {
                    (Ok(w), Ok(h)) => (w, h),
                    _ => return,
                }
            }
        };
        let mut samples = None;
        if nums.len() == 3 {
            let Ok(s) = self.whole(line, names_end + 2, nums[2], "sample count", 0.0, f64::MAX)
            else {
                return;
            };
            if s == 0 {
                self.warn(
                    line,
                    At::Tok(names_end + 2),
                    "0 samples per pixel; the default is used",
                    None,
                );
            } else if !limits::SAMPLES.contains(&s) {
                let most = *limits::SAMPLES.end();
                self.warn(
                    line,
                    At::Tok(names_end + 2),
                    format!("{s} samples per pixel is more than {most}; {most} used"),
                    None,
                );
                samples = Some(most);
            } else {
                samples = Some(s);
            }
        } else if nums.len() > 3 {
            self.warn(
                line,
                At::Span(names_end + 2, nums_end - 1),
                format!("{} numbers after the image size ignored", nums.len() - 2),
                Some(format!(
                    "anim reads at most one: samples per pixel. canonical form: `{FORM_RENDER}`"
                )),
            );
        }
        if !tail.is_empty() {
            self.warn(
                line,
                At::Span(tail.start, tail.end - 1),
                "words after the image size ignored",
                Some(format!("canonical form: `{FORM_RENDER}`")),
            );
        }
        let camera_ref = match camera_at {
            Some(i) if matches!(camera, RenderCamera::Named) => self.name_ref(line, i),
            // Settled in `resolve_renders`.
            Some(i) => NameRef {
                name: String::new(),
                loc: self.loc(line, At::Tok(i)),
            },
            None => NameRef {
                name: String::new(),
                loc: self.loc(line, At::Tok(0)),
            },
        };
        let output_given = output.is_some();
        let def = RenderDef {
            camera: camera_ref,
            output: output.unwrap_or_default(),
            width,
            height,
            samples,
        };
        let anchor = self.anchor(line, At::Tok(0));
        let output_anchor = self.anchor(line, output_at);
        self.pending.push(PendingRender {
            index: self.statements.len(),
            anchor,
            camera,
            output_given,
            output_anchor,
            notes,
        });
        self.emit(line, StatementKind::Render(def));
    }

    /// The output file name from the tokens `pieces`; a name broken by spaces around its
    /// dot (`image . ppm`, `image .ppm`) is joined with a warning. `None` if the pieces do not
    /// form one name.
    fn file_name(&mut self, line: &Line, pieces: std::ops::Range<usize>) -> Option<String> {
        let toks = &line.tokens;
        let parts: Vec<&str> = toks[pieces.clone()].iter().map(|t| t.text).collect();
        let (first, rest) = parts.split_first()?;
        let joinable = parts
            .windows(2)
            .all(|w| w[1].starts_with('.') || w[0].ends_with('.'));
        if rest.is_empty() {
            return Some((*first).to_string());
        }
        if !joinable {
            return None;
        }
        let joined = parts.concat();
        self.warn(
            line,
            At::Span(pieces.start, pieces.end - 1),
            format!(
                "file name written with spaces: `{}` is read as `{joined}`",
                parts.join(" ")
            ),
            None,
        );
        Some(joined)
    }

    /// A whole number in `[min, max]` at token `i`.
    fn whole(
        &mut self,
        line: &Line,
        i: usize,
        v: f64,
        what: &str,
        min: f64,
        max: f64,
    ) -> PResult<u32> {
        if v.fract() != 0.0 || v < min || v > max.min(u32::MAX as f64) {
            let range = if max >= u32::MAX as f64 {
                format!("a whole number of at least {min}")
            } else {
                format!("a whole number from {min} to {max}")
            };
            return Err(self.error(
                line,
                At::Tok(i),
                format!("the {what} must be {range}, found {v}"),
                Some(format!("canonical form: `{FORM_RENDER}`")),
            ));
        }
        Ok(v as u32)
    }

    /// Removes references to names whose definition was skipped (a mesh, an ambient light's
    /// name, a line with an error): their transforms and composite entries mean nothing, and
    /// the statement list must stand on its own when written back out as canonical text.
    fn prune_skipped_references(&mut self) {
        if self.skipped.is_empty() {
            return;
        }
        let defined: HashSet<String> = self
            .statements
            .iter()
            .filter_map(|s| match &s.kind {
                StatementKind::Shape { name, .. } | StatementKind::Composite { name, .. } => {
                    Some(name.clone())
                }
                StatementKind::Light(l) => Some(l.name.clone()),
                StatementKind::Camera(c) => Some(c.name.clone()),
                _ => None,
            })
            .collect();
        let gone = |name: &str| self.skipped.contains(name) && !defined.contains(name);
        self.statements.retain_mut(|s| match &mut s.kind {
            StatementKind::Transform { target, .. } => !gone(&target.name),
            StatementKind::Composite { children, .. } => {
                children.retain(|c| !gone(&c.name));
                true
            }
            _ => true,
        });
    }

    /// Drops (with one warning per name) the transforms of names that are defined only in a
    /// commented-out line: a definition disabled while its transforms were left in, which
    /// leaves them nothing to move (as for a composite's commented-out child).
    fn drop_transforms_of_commented_definitions(&mut self, lines: &[Line]) {
        let commented = commented_definitions(lines);
        if commented.is_empty() {
            return;
        }
        let defined: HashSet<&str> = self
            .statements
            .iter()
            .filter_map(|s| match &s.kind {
                StatementKind::Shape { name, .. } | StatementKind::Composite { name, .. } => {
                    Some(name.as_str())
                }
                StatementKind::Light(l) => Some(l.name.as_str()),
                StatementKind::Camera(c) => Some(c.name.as_str()),
                _ => None,
            })
            .collect();
        let mut dropped: Vec<(usize, &NameRef, u32)> = Vec::new();
        for (i, s) in self.statements.iter().enumerate() {
            if let StatementKind::Transform { target, .. } = &s.kind {
                if let Some(&line) = commented.get(target.name.as_str()) {
                    if !defined.contains(target.name.as_str()) {
                        dropped.push((i, target, line));
                    }
                }
            }
        }
        let mut warned = HashSet::new();
        let mut notes = Vec::new();
        for &(_, target, comment_line) in &dropped {
            if warned.insert(target.name.as_str()) {
                let text = lines
                    .get((target.loc.line as usize).saturating_sub(1))
                    .map_or("", |l| l.text);
                let d = Diagnostic::new(
                    Severity::Warning,
                    target.loc.clone(),
                    format!(
                        "`{}` is only defined in a comment (line {comment_line}); its transforms are skipped",
                        target.name
                    ),
                )
                .with_source(text, target.name.chars().count() as u32);
                notes.push(d);
            }
        }
        let gone: HashSet<usize> = dropped.iter().map(|&(i, _, _)| i).collect();
        self.diagnostics.extend(notes);
        let mut index = 0;
        self.statements.retain(|_| {
            index += 1;
            !gone.contains(&(index - 1))
        });
    }

    /// Settles the camera and output of render lines that left them open, now that every
    /// camera of the file is known, and explains every variant read.
    fn resolve_renders(&mut self) {
        let default_output = default_output(self.path);
        let first_camera = self.camera_names.first().cloned();
        let mut need_default_camera = false;
        let mut rejected = Vec::new();
        for pending in std::mem::take(&mut self.pending) {
            let mut notes = pending.notes;
            let Some(Statement {
                kind: StatementKind::Render(def),
                ..
            }) = self.statements.get_mut(pending.index)
            else {
                continue;
            };
            let mut camera_missing = false;
            match pending.camera {
                RenderCamera::Named => {}
                RenderCamera::Ambiguous(word) => {
                    if self.camera_names.contains(&word) {
                        def.camera.name = word;
                    } else {
                        def.output = word;
                        camera_missing = true;
                    }
                }
                RenderCamera::Missing => camera_missing = true,
            }
            if camera_missing {
                match &first_camera {
                    Some(c) => {
                        def.camera.name = c.clone();
                        notes.push(format!(
                            "no camera named: the file's first camera `{c}` is used"
                        ));
                    }
                    None => {
                        def.camera.name = "default".to_string();
                        need_default_camera = true;
                        notes.push(format!(
                            "no camera named and none defined: a default camera (fov {}) is used",
                            limits::DEFAULT_FOV_DEG
                        ));
                    }
                }
            }
            if def.output.is_empty() {
                def.output = default_output.clone();
                if !pending.output_given {
                    notes.push(format!(
                        "no output file named: `{default_output}` is written"
                    ));
                }
            }
            let output = def.output.clone();
            let canonical = StatementKind::Render(def.clone()).to_string();
            if is_scene_file(self.path, &output) {
                rejected.push(pending.index);
                self.report(
                    Severity::Error,
                    pending.output_anchor,
                    format!("the render output `{output}` is this scene file itself"),
                    Some("name an image file such as image.png".to_string()),
                );
            } else if !notes.is_empty() {
                self.report(
                    Severity::Warning,
                    pending.anchor,
                    notes.join("; "),
                    Some(format!("read as `{canonical}`")),
                );
            }
        }
        // Indices were taken in increasing order; remove from the back so they stay valid.
        for index in rejected.into_iter().rev() {
            self.statements.remove(index);
        }
        if need_default_camera {
            let loc = Loc {
                file: self.file.clone(),
                line: 1,
                col: 1,
            };
            self.statements.insert(
                0,
                Statement {
                    kind: StatementKind::Camera(CameraDef {
                        name: "default".to_string(),
                        fov_x_deg: limits::DEFAULT_FOV_DEG,
                        eye: DVec3::ZERO,
                        dir: DVec3::NEG_Z,
                        up: DVec3::Y,
                    }),
                    loc,
                },
            );
        }
    }
}

/// Whether a token looks like a file name rather than a (malformed) number: it holds a path
/// separator or an extension (`001.png`, `out/1.ppm`), unlike `1O` or `1.0f`.
fn file_like(t: &str) -> bool {
    t.contains('/')
        || t.contains('\\')
        || t.rsplit_once('.').is_some_and(|(_, ext)| {
            ext.len() >= 2 && ext.chars().next().is_some_and(|c| c.is_ascii_alphabetic())
        })
}

/// Names defined in commented-out lines (`# define shape box b ...`, `//define light l ...`)
/// → the line, for explaining references to them.
pub(crate) fn commented_definitions<'t>(lines: &[Line<'t>]) -> HashMap<&'t str, u32> {
    let mut index = HashMap::new();
    for line in lines {
        let body = line.text.trim_start();
        let Some(body) = body.strip_prefix("//").or_else(|| body.strip_prefix('#')) else {
            continue;
        };
        let tokens = lexer::tokenize(body.trim_start_matches(['#', '/']));
        if tokens.first().is_some_and(|t| t.text == "define") {
            // `define shape <kind> <name>` or `define <kind> <name>`.
            for t in tokens.iter().skip(2).take(2) {
                index.entry(t.text).or_insert(line.number);
            }
        }
    }
    index
}

/// `<file-stem>.png`, the output for files that name none.
pub fn default_output(path: &Path) -> String {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "image".to_string());
    format!("{stem}.png")
}

/// Whether the output path, resolved (as the renderer does) against the scene file's
/// directory, is the scene file itself.
fn is_scene_file(scene: &Path, output: &str) -> bool {
    let out = Path::new(output);
    if out.is_absolute() {
        return out == scene;
    }
    let in_same_dir = out.parent().is_none_or(|p| {
        p.components()
            .all(|c| matches!(c, std::path::Component::CurDir))
    });
    in_same_dir && out.file_name().is_some() && out.file_name() == scene.file_name()
}

fn field_name(field: &MaterialField) -> &'static str {
    match field {
        MaterialField::Reflectivity => "reflectivity",
        MaterialField::Opacity => "opacity",
        MaterialField::Transparency => "transparency",
        MaterialField::Ior => "ior",
        MaterialField::Roughness => "roughness",
    }
}

fn field_names(fields: &[MaterialField]) -> String {
    if fields.is_empty() {
        "(none)".to_string()
    } else {
        fields.iter().map(field_name).collect::<Vec<_>>().join(",")
    }
}

fn axis_of_letter(s: &str) -> Option<DVec3> {
    match s {
        "x" | "X" => Some(DVec3::X),
        "y" | "Y" => Some(DVec3::Y),
        "z" | "Z" => Some(DVec3::Z),
        _ => None,
    }
}

fn unit_axis(k: usize) -> DVec3 {
    match k {
        0 => DVec3::X,
        1 => DVec3::Y,
        _ => DVec3::Z,
    }
}
