//! Building: canonical statements → render jobs, each with its scene description.
//!
//! Definitions are global to a file (statement order is free in most real files); transforms
//! apply in the order written, composed by the rule of `TransformOrder`; each `render` line
//! sees the transforms DIALECT.md gives it (all of them when the file has one render line,
//! those written before it when it has several). The composite tree is flattened into
//! instances, so a shape listed in two composites is drawn twice.

use super::ast::{
    CameraDef, LightDef, MaterialDef, NameRef, Statement, StatementKind, TransformOp,
};
use super::lexer;
use super::parser::{default_output, SourceContext};
use super::{LoadOptions, TransformOrder};
use crate::diag::{suggest, Diagnostic, Loc, Severity};
use crate::math::Transform;
use crate::scene::{Camera, Geometry, Instance, Light, Material, RenderJob, Scene};
use crate::shape::geometry::{degeneracy, is_zero, parallel};
use glam::{DVec3, Vec3};
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

/// More instances than this means a composite tree that multiplies out of all proportion
/// (each level listing the one below twice, ...): refused before it exhausts memory.
const MAX_INSTANCES: usize = 250_000;
/// The same over all the jobs of a file (each job holds its own scene).
const MAX_TOTAL_INSTANCES: usize = 2_000_000;
/// Deeper composite nesting than this is refused (the tree is walked recursively).
const MAX_DEPTH: usize = 256;
/// Name comparisons allowed for "did you mean" suggestions in one file (about a second's
/// work at worst).
const SUGGESTION_BUDGET: usize = 1_000_000;
/// Image size for files without a render statement.
const DEFAULT_SIZE: (u32, u32) = (800, 600);

/// Builds the render jobs of a statement list. `source` is present when the statements come
/// from `parser::parse`, which has already checked (and reported) the values of every
/// statement; without it (statements made by a program) those checks are made here.
pub(crate) fn build(
    statements: &[Statement],
    path: &Path,
    opts: &LoadOptions,
    source: Option<&SourceContext>,
) -> (Vec<RenderJob>, Vec<Diagnostic>) {
    let empty = SourceContext::default();
    let mut b = Builder {
        path,
        opts,
        check_values: source.is_none(),
        source: source.unwrap_or(&empty),
        diagnostics: Vec::new(),
        reported_composites: HashSet::new(),
        too_many_reported: false,

        suggestion_budget: SUGGESTION_BUDGET,
        total_instances: 0,
    };
    let defs = b.definitions(statements);
    b.check_cycles(&defs);
    let jobs = b.jobs(statements, &defs);
    (jobs, b.diagnostics)
}

/// A shape or composite.
struct Object<'s> {
    name: &'s str,
    loc: &'s Loc,
    kind: ObjectKind<'s>,
}

enum ObjectKind<'s> {
    /// `material` is `None` when it could not be resolved (reported) or the shape is
    /// degenerate: the shape is then not drawn.
    Shape {
        geometry: &'s Geometry,
        material: Option<usize>,
    },
    /// The children that resolved.
    Composite { children: Vec<&'s str> },
}

/// The namespaces a transform can target.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Space {
    Object,
    Camera,
    Light,
}

/// Every definition of the file, final versions (a later duplicate replaces the earlier).
#[derive(Default)]
struct Definitions<'s> {
    materials: Vec<Material>,
    material_index: HashMap<&'s str, usize>,
    objects: Vec<Object<'s>>,
    /// Name → index into `objects` of its final definition.
    object_index: HashMap<&'s str, usize>,
    cameras: Vec<(&'s CameraDef, &'s Loc)>,
    camera_index: HashMap<&'s str, usize>,
    lights: Vec<&'s LightDef>,
    light_index: HashMap<&'s str, usize>,
    ambient: Vec3,
    background: Vec3,
}

/// The transform of every target at some point of the file.
type Snapshot<'s> = HashMap<(Space, &'s str), Transform>;

struct Builder<'a> {
    path: &'a Path,
    opts: &'a LoadOptions,
    /// Whether to check values (radii, scale factors, cameras): only for statements that did
    /// not come through the parser, which checks them with exact columns.
    check_values: bool,
    source: &'a SourceContext,
    diagnostics: Vec<Diagnostic>,
    /// Composites whose cycle or depth problem has been reported (once, not once per job).
    reported_composites: HashSet<String>,
    too_many_reported: bool,

    /// Name comparisons left for "did you mean" suggestions.
    suggestion_budget: usize,
    /// Instances made so far, over all jobs.
    total_instances: usize,
}

impl<'a> Builder<'a> {
    // ----- diagnostics -------------------------------------------------------------------

    /// A diagnostic at `loc`, moved onto the token `name` when the line is known and `loc`
    /// is the start of a statement rather than the name itself.
    fn report(
        &mut self,
        severity: Severity,
        loc: &Loc,
        name: Option<&str>,
        message: String,
        help: Option<String>,
    ) {
        let mut loc = loc.clone();
        let mut d = match self.source.line(loc.line) {
            Some(text) => {
                let tokens = lexer::tokenize(text);
                let width = match name {
                    Some(name) => {
                        match tokens
                            .iter()
                            .skip(1)
                            .find(|t| t.text == name && t.col >= loc.col)
                        {
                            Some(t) => {
                                loc.col = t.col;
                                t.width
                            }
                            None => name.chars().count() as u32,
                        }
                    }
                    None => tokens
                        .iter()
                        .find(|t| t.col == loc.col)
                        .map_or(1, |t| t.width),
                };
                Diagnostic::new(severity, loc, message).with_source(text, width)
            }
            None => Diagnostic::new(severity, loc, message),
        };
        if let Some(h) = help {
            d = d.with_help(h);
        }
        self.diagnostics.push(d);
    }

    fn warn(&mut self, loc: &Loc, name: Option<&str>, message: String, help: Option<String>) {
        self.report(Severity::Warning, loc, name, message, help);
    }

    fn error(&mut self, loc: &Loc, name: Option<&str>, message: String, help: Option<String>) {
        self.report(Severity::Error, loc, name, message, help);
    }

    /// An error or warning about a name reference (the location is the name itself).
    fn at_ref(&mut self, severity: Severity, r: &NameRef, message: String, help: Option<String>) {
        self.report(severity, &r.loc, Some(&r.name), message, help);
    }

    fn skipped(&self, name: &str) -> bool {
        self.source.skipped.contains(name)
    }

    /// The line of a commented-out definition of `name` (`# define shape box b ...`), for
    /// the common case of a definition disabled while its uses were left in.
    fn commented_definition(&self, name: &str) -> Option<u32> {
        self.source.commented.get(name).copied()
    }

    /// A pointer to a commented-out definition of `name`, else "did you mean" among
    /// `candidates`.
    fn name_help<'n>(
        &mut self,
        name: &str,
        candidates: impl IntoIterator<Item = &'n str>,
    ) -> Option<String> {
        // A commented-out definition explains the problem better than a similar name.
        if let Some(line) = self.commented_definition(name) {
            return Some(format!(
                "`{name}` is only defined in a comment, on line {line}"
            ));
        }
        // Only names of about the same length can be close enough to be suggested; the edit
        // distance is costly, so a file with very many unknown names among very many defined
        // ones stops getting suggestions once the budget is spent.
        let len = name.chars().count();
        let near: Vec<&str> = candidates
            .into_iter()
            .filter(|c| {
                // The edit distance is at least the difference in length, and `suggest`
                // accepts at most a third of the longer name (at least 1).
                let other = c.chars().count();
                other.abs_diff(len) <= (len.max(other) / 3).max(1)
            })
            .collect();
        if near.len() > self.suggestion_budget {
            return None;
        }
        self.suggestion_budget -= near.len();
        suggest(name, near).map(|s| format!("did you mean `{s}`?"))
    }

    // ----- definitions -------------------------------------------------------------------

    fn definitions<'s>(&mut self, statements: &'s [Statement]) -> Definitions<'s> {
        let mut d = Definitions::default();
        // Where each object name was first defined, for "a child must be defined before the
        // composite": statement index and line.
        let mut first_object_def: HashMap<&str, (usize, u32)> = HashMap::new();
        let mut material_first_def: HashMap<&str, (usize, u32)> = HashMap::new();
        let mut ambient_set: Option<Vec3> = None;
        let mut ambient_added = Vec3::ZERO;
        for (index, stmt) in statements.iter().enumerate() {
            if self.check_values && !finite_statement(&stmt.kind) {
                self.error(
                    &stmt.loc,
                    None,
                    "statement holds a number that is not finite".to_string(),
                    None,
                );
                continue;
            }
            match &stmt.kind {
                StatementKind::Material(m) => {
                    let material = self.material(m, &stmt.loc);
                    material_first_def
                        .entry(m.name.as_str())
                        .or_insert((index, stmt.loc.line));
                    if let Some(&i) = d.material_index.get(m.name.as_str()) {
                        self.duplicate(&stmt.loc, &m.name, "material");
                        d.materials[i] = material;
                    } else {
                        d.material_index.insert(&m.name, d.materials.len());
                        d.materials.push(material);
                    }
                }
                StatementKind::Shape { name, geometry, .. } => {
                    if let Some(reason) = degeneracy(geometry) {
                        if self.check_values {
                            self.warn(
                                &stmt.loc,
                                Some(name),
                                format!("shape `{name}` {reason}; shape dropped"),
                                None,
                            );
                        }
                    }
                    first_object_def
                        .entry(name.as_str())
                        .or_insert((index, stmt.loc.line));
                    // The material is resolved below, once every material is known.
                    let object = Object {
                        name,
                        loc: &stmt.loc,
                        kind: ObjectKind::Shape {
                            geometry,
                            material: None,
                        },
                    };
                    self.define_object(&mut d, object);
                }
                StatementKind::Composite { name, .. } => {
                    first_object_def
                        .entry(name.as_str())
                        .or_insert((index, stmt.loc.line));
                    let object = Object {
                        name,
                        loc: &stmt.loc,
                        kind: ObjectKind::Composite {
                            children: Vec::new(),
                        },
                    };
                    self.define_object(&mut d, object);
                }
                StatementKind::Light(l) => {
                    if let Some(&i) = d.light_index.get(l.name.as_str()) {
                        self.duplicate(&stmt.loc, &l.name, "light");
                        d.lights[i] = l;
                    } else {
                        d.light_index.insert(&l.name, d.lights.len());
                        d.lights.push(l);
                    }
                }
                StatementKind::Camera(c) => {
                    if self.check_values && !self.camera_ok(c, &stmt.loc) {
                        continue;
                    }
                    if let Some(&i) = d.camera_index.get(c.name.as_str()) {
                        self.duplicate(&stmt.loc, &c.name, "camera");
                        d.cameras[i] = (c, &stmt.loc);
                    } else {
                        d.camera_index.insert(&c.name, d.cameras.len());
                        d.cameras.push((c, &stmt.loc));
                    }
                }
                StatementKind::Ambient(rgb) => ambient_set = Some(*rgb),
                StatementKind::AmbientAdd(rgb) => ambient_added += *rgb,
                StatementKind::Background(rgb) => d.background = *rgb,
                StatementKind::Transform { .. } | StatementKind::Render(_) => {}
            }
        }
        d.ambient = ambient_set.unwrap_or(Vec3::ZERO) + ambient_added;

        // Shapes' materials and composites' children, now that every name is known.
        for (index, stmt) in statements.iter().enumerate() {
            match &stmt.kind {
                StatementKind::Shape {
                    name,
                    geometry,
                    material,
                } => {
                    let resolved = self.resolve_material(&d, &material_first_def, index, material);
                    let Some(&i) = d.object_index.get(name.as_str()) else {
                        continue;
                    };
                    // Only the final definition of the name is drawn; earlier ones were
                    // still checked above.
                    if std::ptr::eq(d.objects[i].loc, &stmt.loc) {
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
                    let resolved =
                        self.resolve_children(&d, &first_object_def, index, name, children);
                    if let Some(&i) = d.object_index.get(name.as_str()) {
                        if std::ptr::eq(d.objects[i].loc, &stmt.loc) {
                            d.objects[i].kind = ObjectKind::Composite { children: resolved };
                        }
                    }
                }
                _ => {}
            }
        }
        d
    }

    fn define_object<'s>(&mut self, d: &mut Definitions<'s>, object: Object<'s>) {
        if let Some(&i) = d.object_index.get(object.name) {
            let what = match object.kind {
                ObjectKind::Shape { .. } => "shape",
                ObjectKind::Composite { .. } => "composite",
            };
            let earlier_line = d.objects[i].loc.line;
            self.warn(
                object.loc,
                Some(object.name),
                format!(
                    "{what} `{}` is already defined (line {earlier_line}); the later definition replaces it",
                    object.name
                ),
                None,
            );
        }
        d.object_index.insert(object.name, d.objects.len());
        d.objects.push(object);
    }

    fn duplicate(&mut self, loc: &Loc, name: &str, what: &str) {
        self.warn(
            loc,
            Some(name),
            format!("{what} `{name}` is already defined; the later definition replaces it"),
            None,
        );
    }

    fn material(&mut self, m: &MaterialDef, loc: &Loc) -> Material {
        let mut out = Material {
            name: m.name.clone(),
            ka: m.ka,
            kd: m.kd,
            ks: m.ks,
            m: m.m,
            reflectivity: m.reflectivity.clamp(0.0, 1.0),
            opacity: m.opacity.clamp(0.0, 1.0),
            ior: m.ior,
        };
        // m = 0 is kept (pow(x, 0) = 1 is well defined); a negative m would send the
        // highlight to infinity where R·V = 0.
        out.m = out.m.abs();
        if out.ior <= 0.0 {
            out.ior = 1.0;
        }
        if self.check_values
            && (out.m != m.m
                || out.ior != m.ior
                || out.reflectivity != m.reflectivity
                || out.opacity != m.opacity)
        {
            self.warn(
                loc,
                Some(&m.name),
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

    fn resolve_material(
        &mut self,
        d: &Definitions,
        first_def: &HashMap<&str, (usize, u32)>,
        index: usize,
        material: &NameRef,
    ) -> Option<usize> {
        let name = material.name.as_str();
        match d.material_index.get(name) {
            Some(&i) => {
                if let Some(&(def_index, def_line)) = first_def.get(name) {
                    if def_index > index {
                        self.at_ref(
                            Severity::Warning,
                            material,
                            format!(
                                "material `{name}` is used before its definition (line {def_line})"
                            ),
                            Some("define materials before the shapes that use them".to_string()),
                        );
                    }
                }
                Some(i)
            }
            None => {
                if !self.skipped(name) {
                    let help = self.name_help(name, d.material_index.keys().copied());
                    self.at_ref(
                        Severity::Error,
                        material,
                        format!("unknown material `{name}`"),
                        help,
                    );
                }
                None
            }
        }
    }

    fn resolve_children<'s>(
        &mut self,
        d: &Definitions<'s>,
        first_def: &HashMap<&str, (usize, u32)>,
        index: usize,
        composite: &str,
        children: &'s [NameRef],
    ) -> Vec<&'s str> {
        let mut out = Vec::with_capacity(children.len());
        for child in children {
            let name = child.name.as_str();
            if name == composite {
                self.at_ref(
                    Severity::Warning,
                    child,
                    format!("composite `{composite}` cannot contain itself; child skipped"),
                    None,
                );
                continue;
            }
            match first_def.get(name) {
                Some(&(def_index, _)) if def_index < index => out.push(name),
                Some(&(_, def_line)) => self.at_ref(
                    Severity::Warning,
                    child,
                    format!(
                        "child `{name}` is defined after this composite (line {def_line}); skipped"
                    ),
                    Some("a composite's children must be defined before it".to_string()),
                ),
                None if self.skipped(name) => {}
                None => {
                    let other = if d.camera_index.contains_key(name) {
                        Some("a camera")
                    } else if d.light_index.contains_key(name) {
                        Some("a light")
                    } else if d.material_index.contains_key(name) {
                        Some("a material")
                    } else {
                        None
                    };
                    let (message, help) = match other {
                        Some(what) => (
                            format!("child `{name}` is {what}, not a shape; skipped"),
                            None,
                        ),
                        None => (
                            format!("undefined child `{name}`; skipped"),
                            self.name_help(name, d.object_index.keys().copied()),
                        ),
                    };
                    self.at_ref(Severity::Warning, child, message, help);
                }
            }
        }
        out
    }

    /// Checks a camera made by a program (the parser checks those it reads).
    fn camera_ok(&mut self, c: &CameraDef, loc: &Loc) -> bool {
        let problem = if !(c.fov_x_deg > 0.0 && c.fov_x_deg < 180.0) {
            Some("a field of view between 0 and 180 degrees")
        } else if is_zero(c.dir) {
            Some("a non-zero viewing direction")
        } else if parallel(c.dir, c.up) {
            Some("an up vector that is not parallel to the viewing direction")
        } else {
            None
        };
        match problem {
            Some(need) => {
                self.error(
                    loc,
                    Some(&c.name),
                    format!("camera `{}` needs {need}", c.name),
                    None,
                );
                false
            }
            None => true,
        }
    }

    /// Reports every composite that contains itself, directly or through others. (Cycles
    /// are also stopped while flattening, but a cycle that no root reaches would go unseen.)
    fn check_cycles(&mut self, d: &Definitions) {
        #[derive(Clone, Copy, PartialEq)]
        enum Mark {
            New,
            Open,
            Done,
        }
        let mut mark = vec![Mark::New; d.objects.len()];
        let children_of = |i: usize| -> Vec<usize> {
            match &d.objects[i].kind {
                ObjectKind::Composite { children } => children
                    .iter()
                    .filter_map(|c| d.object_index.get(c).copied())
                    .collect(),
                ObjectKind::Shape { .. } => Vec::new(),
            }
        };
        let mut finals: Vec<usize> = d.object_index.values().copied().collect();
        finals.sort_unstable();
        for start in finals {
            if mark[start] != Mark::New {
                continue;
            }
            // Depth-first with an explicit stack (nesting depth is unbounded in the input):
            // (object, its children, next child to visit).
            let mut stack = vec![(start, children_of(start), 0usize)];
            mark[start] = Mark::Open;
            while let Some((node, children, next)) = stack.last_mut() {
                let node = *node;
                if let Some(&child) = children.get(*next) {
                    *next += 1;
                    match mark[child] {
                        Mark::New => {
                            mark[child] = Mark::Open;
                            let grandchildren = children_of(child);
                            stack.push((child, grandchildren, 0));
                        }
                        Mark::Open => {
                            let from = stack.iter().position(|(n, _, _)| *n == child).unwrap_or(0);
                            let mut cycle: Vec<&str> = stack[from..]
                                .iter()
                                .map(|(n, _, _)| d.objects[*n].name)
                                .collect();
                            cycle.push(d.objects[child].name);
                            let object = &d.objects[child];
                            if self.reported_composites.insert(object.name.to_string()) {
                                self.error(
                                    object.loc,
                                    Some(object.name),
                                    format!(
                                        "composite `{}` contains itself ({})",
                                        object.name,
                                        cycle.join(" → ")
                                    ),
                                    None,
                                );
                            }
                        }
                        Mark::Done => {}
                    }
                } else {
                    mark[node] = Mark::Done;
                    stack.pop();
                }
            }
        }
    }

    // ----- transforms --------------------------------------------------------------------

    /// What a transform statement's target names, or `None` (reported, or known skipped).
    /// `reported_names` holds the names already warned about, to warn once per name.
    fn resolve_target<'s>(
        &mut self,
        d: &Definitions<'s>,
        target: &'s NameRef,
        reported_names: &mut HashSet<&'s str>,
    ) -> Option<Space> {
        let name = target.name.as_str();
        let mut found = Vec::new();
        if d.object_index.contains_key(name) {
            found.push((Space::Object, "shape or composite"));
        }
        if d.camera_index.contains_key(name) {
            found.push((Space::Camera, "camera"));
        }
        if d.light_index.contains_key(name) {
            found.push((Space::Light, "light"));
        }
        match found.as_slice() {
            [] => {
                if self.skipped(name) {
                    return None;
                }
                if d.material_index.contains_key(name) {
                    self.at_ref(
                        Severity::Error,
                        target,
                        format!("`{name}` is a material; only shapes, composites, cameras and lights can be transformed"),
                        None,
                    );
                    return None;
                }

                let candidates = d
                    .object_index
                    .keys()
                    .chain(d.camera_index.keys())
                    .chain(d.light_index.keys())
                    .copied();
                let mut help = self.name_help(name, candidates);
                if help.is_none() && name == "camera" && d.cameras.len() == 1 {
                    help = Some(format!("the camera is named `{}`", d.cameras[0].0.name));
                }
                self.at_ref(
                    Severity::Error,
                    target,
                    format!("unknown transform target `{name}`"),
                    help,
                );
                None
            }
            [(space, _)] => Some(*space),
            [(space, first), rest @ ..] => {
                if reported_names.insert(name) {
                    let others: Vec<&str> = rest.iter().map(|(_, w)| *w).collect();
                    self.at_ref(
                        Severity::Warning,
                        target,
                        format!(
                            "`{name}` names a {first} and a {}; the transform applies to the {first}",
                            others.join(" and a ")
                        ),
                        Some("give them different names".to_string()),
                    );
                }
                Some(*space)
            }
        }
    }

    /// The transform of one operation, or `None` (reported) when it has no inverse.
    fn op_transform(&mut self, op: &TransformOp, loc: &Loc, target: &str) -> Option<Transform> {
        let t = match *op {
            TransformOp::Translate(v) => Some(Transform::translate(v)),
            TransformOp::Rotate { degrees, axis } => Transform::rotate(degrees, axis),
            TransformOp::Scale(s) => Transform::scale(s),
        };
        if t.is_none() {
            self.error(
                loc,
                Some(target),
                "scale by 0 or rotation about a zero axis: the transform has no inverse"
                    .to_string(),
                None,
            );
        }
        t
    }

    /// The transforms of every target at each render statement (one snapshot per job).
    fn snapshots<'s>(
        &mut self,
        statements: &'s [Statement],
        d: &Definitions<'s>,
    ) -> Vec<(Option<&'s Statement>, Snapshot<'s>)> {
        let renders = statements
            .iter()
            .filter(|s| matches!(s.kind, StatementKind::Render(_)))
            .count();
        let mut current: Snapshot<'s> = HashMap::new();
        let mut out = Vec::new();
        let mut reported_names = HashSet::new();
        let mut renders_seen = 0;
        let mut late_transform_reported = false;
        for stmt in statements {
            match &stmt.kind {
                StatementKind::Transform { target, ops } => {
                    if renders > 1 && renders_seen == renders && !late_transform_reported {
                        late_transform_reported = true;
                        self.warn(
                            &stmt.loc,
                            None,
                            "transform after the last render statement has no effect".to_string(),
                            Some(format!(
                                "this file has {renders} render statements; each renders the transforms written before it"
                            )),
                        );
                    }
                    let Some(space) = self.resolve_target(d, target, &mut reported_names) else {
                        continue;
                    };
                    let key = (space, target.name.as_str());
                    let mut m = current.get(&key).copied().unwrap_or(Transform::IDENTITY);
                    for op in ops {
                        let Some(t) = self.op_transform(op, &stmt.loc, &target.name) else {
                            continue;
                        };
                        let next = match self.opts.transform_order {
                            TransformOrder::World => t.then_after(&m),
                            TransformOrder::Local => m.then_after(&t),
                        };
                        if !finite_transform(&next) {
                            self.error(
                                &stmt.loc,
                                Some(&target.name),
                                format!(
                                    "the transforms of `{}` multiply out beyond floating-point range",
                                    target.name
                                ),
                                Some("use scale factors nearer to 1".to_string()),
                            );
                            break;
                        }
                        m = next;
                    }
                    current.insert(key, m);
                }
                StatementKind::Render(_) => {
                    renders_seen += 1;
                    if renders > 1 {
                        out.push((Some(stmt), current.clone()));
                    }
                }
                _ => {}
            }
        }
        if renders <= 1 {
            let render = statements
                .iter()
                .find(|s| matches!(s.kind, StatementKind::Render(_)));
            out.push((render, current));
        }
        out
    }

    // ----- jobs --------------------------------------------------------------------------

    fn jobs<'s>(&mut self, statements: &'s [Statement], d: &Definitions<'s>) -> Vec<RenderJob> {
        let snapshots = self.snapshots(statements, d);
        let mut jobs = Vec::new();
        for (render, snapshot) in &snapshots {
            let job = match render {
                Some(stmt) => {
                    let StatementKind::Render(r) = &stmt.kind else {
                        continue;
                    };
                    let Some(camera) = self.render_camera(d, &r.camera, snapshot) else {
                        continue;
                    };
                    RenderJob {
                        scene: self.scene(d, snapshot),
                        camera,
                        output: PathBuf::from(&r.output),
                        width: r.width,
                        height: r.height,
                        samples: r.samples,
                        loc: Some(stmt.loc.clone()),
                    }
                }
                None => {
                    if self.source.render_lines > 0
                        || (self.source.cameras_rejected && d.cameras.is_empty())
                    {
                        // The render line or the camera was rejected, with an error: no stand-in.
                        continue;
                    }
                    let camera = match d.cameras.first() {
                        Some((c, _)) => place_camera(c, snapshot),
                        None => Camera::default_with_fov("default", 60.0),
                    };
                    let output = default_output(self.path);
                    let mut w = Diagnostic::file_error(
                        self.path,
                        format!(
                            "no render statement: camera `{}` is rendered to `{output}` at {}×{}",
                            camera.name, DEFAULT_SIZE.0, DEFAULT_SIZE.1
                        ),
                    )
                    .with_help("add e.g. `render <camera> image.png 800 600`");
                    w.severity = Severity::Warning;
                    self.diagnostics.push(w);
                    RenderJob {
                        scene: self.scene(d, snapshot),
                        camera,
                        output: PathBuf::from(output),
                        width: DEFAULT_SIZE.0,
                        height: DEFAULT_SIZE.1,
                        samples: None,
                        loc: None,
                    }
                }
            };
            jobs.push(job);
        }
        jobs
    }

    fn render_camera(
        &mut self,
        d: &Definitions,
        name: &NameRef,
        snapshot: &Snapshot,
    ) -> Option<Camera> {
        match d.camera_index.get(name.name.as_str()) {
            Some(&i) => Some(place_camera(d.cameras[i].0, snapshot)),
            None => {
                if !self.skipped(&name.name) {
                    let help = self
                        .name_help(&name.name, d.camera_index.keys().copied())
                        .or_else(|| {
                            d.cameras
                                .first()
                                .map(|(c, _)| format!("the file defines camera `{}`", c.name))
                        });
                    self.at_ref(
                        Severity::Error,
                        name,
                        format!("unknown camera `{}`", name.name),
                        help,
                    );
                }
                None
            }
        }
    }

    fn scene(&mut self, d: &Definitions, snapshot: &Snapshot) -> Scene {
        let roots: Vec<usize> = match d.object_index.get("root") {
            Some(&i) if matches!(d.objects[i].kind, ObjectKind::Composite { .. }) => vec![i],
            _ => {
                let contained: HashSet<&str> = d
                    .object_index
                    .values()
                    .filter_map(|&i| match &d.objects[i].kind {
                        ObjectKind::Composite { children } => Some(children.iter().copied()),
                        ObjectKind::Shape { .. } => None,
                    })
                    .flatten()
                    .collect();
                let mut roots: Vec<usize> = d
                    .object_index
                    .iter()
                    .filter(|(name, _)| !contained.contains(*name))
                    .map(|(_, &i)| i)
                    .collect();
                roots.sort_unstable(); // definition order
                roots
            }
        };
        let mut instances = Vec::new();
        let mut stack = Vec::new();
        for root in roots {
            let name = d.objects[root].name;
            self.flatten(
                d,
                snapshot,
                name,
                &Transform::IDENTITY,
                "",
                &mut stack,
                &mut instances,
            );
        }
        let lights = d
            .lights
            .iter()
            .map(|l| {
                let t = snapshot
                    .get(&(Space::Light, l.name.as_str()))
                    .copied()
                    .unwrap_or_default();
                Light {
                    name: l.name.clone(),
                    position: t.point(l.position),
                    intensity: l.color * l.brightness,
                }
            })
            .collect();
        Scene {
            materials: d.materials.clone(),
            instances,
            lights,
            ambient: d.ambient,
            background: d.background,
        }
    }

    /// Appends the instances below object `name`, placed by `parent` (its parent's world
    /// transform). `stack` holds the composites being expanded, to stop at cycles.
    #[allow(clippy::too_many_arguments)]
    fn flatten<'s>(
        &mut self,
        d: &Definitions<'s>,
        snapshot: &Snapshot,
        name: &'s str,
        parent: &Transform,
        prefix: &str,
        stack: &mut Vec<&'s str>,
        out: &mut Vec<Instance>,
    ) {
        let Some(&i) = d.object_index.get(name) else {
            return;
        };
        if self.too_many_reported {
            return; // the scene is refused anyway; do not walk the rest of a huge tree
        }
        let object = &d.objects[i];
        let own = snapshot
            .get(&(Space::Object, name))
            .copied()
            .unwrap_or_default();
        let world = parent.then_after(&own);
        if !finite_transform(&world) {
            if self.reported_composites.insert(name.to_string()) {
                self.error(
                    object.loc,
                    Some(name),
                    format!(
                        "the transforms above `{name}` multiply out beyond floating-point range"
                    ),
                    Some("use scale factors nearer to 1".to_string()),
                );
            }
            return;
        }
        let path = if prefix.is_empty() {
            name.to_string()
        } else {
            format!("{prefix}/{name}")
        };
        match &object.kind {
            ObjectKind::Shape { geometry, material } => {
                let Some(material) = *material else {
                    return;
                };
                if out.len() >= MAX_INSTANCES || self.total_instances >= MAX_TOTAL_INSTANCES {
                    if !self.too_many_reported {
                        self.too_many_reported = true;
                        let (message, help) = if out.len() >= MAX_INSTANCES {
                            (
                                format!("the composite tree expands to more than {MAX_INSTANCES} shapes"),
                                "a composite listing another twice, level after level, doubles the scene each time",
                            )
                        } else {
                            (
                                format!("the file's render statements together need more than {MAX_TOTAL_INSTANCES} shapes"),
                                "write one file per frame (as `anim generate` does) instead of many render lines",
                            )
                        };
                        self.error(object.loc, Some(name), message, Some(help.to_string()));
                    }
                    return;
                }
                self.total_instances += 1;
                // The parser makes radii positive; statements made by a program may not.
                let mut geometry = (*geometry).clone();
                if let Geometry::Sphere { radius, .. }
                | Geometry::Cylinder { radius, .. }
                | Geometry::Cone { radius, .. } = &mut geometry
                {
                    *radius = radius.abs();
                }
                out.push(Instance {
                    name: path,
                    geometry,
                    material,
                    transform: world,
                    loc: Some(object.loc.clone()),
                });
            }
            ObjectKind::Composite { children } => {
                if let Some(pos) = stack.iter().position(|&s| s == name) {
                    if self.reported_composites.insert(name.to_string()) {
                        let mut cycle: Vec<&str> = stack[pos..].to_vec();
                        cycle.push(name);
                        self.error(
                            object.loc,
                            Some(name),
                            format!("composite `{name}` contains itself ({})", cycle.join(" → ")),
                            None,
                        );
                    }
                    return;
                }
                if stack.len() >= MAX_DEPTH {
                    if self.reported_composites.insert(name.to_string()) {
                        self.error(
                            object.loc,
                            Some(name),
                            format!("composites are nested more than {MAX_DEPTH} deep"),
                            None,
                        );
                    }
                    return;
                }
                stack.push(name);
                for &child in children {
                    self.flatten(d, snapshot, child, &world, &path, stack, out);
                }
                stack.pop();
            }
        }
    }
}

/// A camera definition with its transform applied: the eye as a point, dir and up as vectors.
fn place_camera(c: &CameraDef, snapshot: &Snapshot) -> Camera {
    let t = snapshot
        .get(&(Space::Camera, c.name.as_str()))
        .copied()
        .unwrap_or_default();
    Camera {
        name: c.name.clone(),
        fov_x_deg: c.fov_x_deg,
        eye: t.point(c.eye),
        dir: t.vector(c.dir),
        up: t.vector(c.up),
    }
}

/// Whether a transform and its inverse are usable (no overflow to infinity or NaN).
fn finite_transform(t: &Transform) -> bool {
    t.world_from_object.is_finite() && t.object_from_world.is_finite()
}

/// Whether every number of a statement is finite (statements made by programs may not be).
fn finite_statement(kind: &StatementKind) -> bool {
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
        StatementKind::Shape { geometry, .. } => match geometry {
            Geometry::Sphere { center, radius } => v(center) && radius.is_finite(),
            Geometry::Box { p1, p2 } => v(p1) && v(p2),
            Geometry::Plane { point, normal } => v(point) && v(normal),
            Geometry::Triangle { vertices } => vertices.iter().all(v),
            Geometry::Cylinder { p1, p2, radius } => v(p1) && v(p2) && radius.is_finite(),
            Geometry::Cone { base, tip, radius } => v(base) && v(tip) && radius.is_finite(),
        },
        StatementKind::Light(l) => v(&l.position) && c(&l.color) && l.brightness.is_finite(),
        StatementKind::Ambient(rgb)
        | StatementKind::AmbientAdd(rgb)
        | StatementKind::Background(rgb) => c(rgb),
        StatementKind::Camera(cam) => {
            cam.fov_x_deg.is_finite() && v(&cam.eye) && v(&cam.dir) && v(&cam.up)
        }
        StatementKind::Transform { ops, .. } => ops.iter().all(|op| match op {
            TransformOp::Translate(t) | TransformOp::Scale(t) => v(t),
            TransformOp::Rotate { degrees, axis } => degrees.is_finite() && v(axis),
        }),
        StatementKind::Composite { .. } | StatementKind::Render(_) => true,
    }
}
