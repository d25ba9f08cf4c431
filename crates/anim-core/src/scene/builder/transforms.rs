//! Transform statements: which namespace each target lies in, and the transform of every
//! target at each render statement.

use super::definitions::Definitions;
use super::{At, Builder};
use crate::diag::Severity;
use crate::math::Transform;
use crate::sdf::ast::{NameRef, Statement, StatementKind, TransformOp};
use crate::sdf::TransformOrder;
use std::collections::{HashMap, HashSet};

/// The namespaces a transform can target.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(super) enum Space {
    Object,
    Camera,
    Light,
}

/// The transform of every target at some point of the file.
pub(super) type Snapshot<'s> = HashMap<(Space, &'s str), Transform>;

impl Builder<'_> {
    // ----- transforms --------------------------------------------------------------------

    /// What a transform statement's target names, or `None` (reported, or known skipped).
    /// `reported_names` holds the names already warned about, to warn once per name.
    pub(super) fn resolve_target<'s>(
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
                    help = Some(format!("the camera is named `{}`", d.cameras[0].name));
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
    pub(super) fn op_transform(&mut self, op: &TransformOp, stmt: &Statement) -> Option<Transform> {
        let t = match *op {
            TransformOp::Translate(v) => Some(Transform::translate(v)),
            TransformOp::Rotate { degrees, axis } => Transform::rotate(degrees, axis),
            TransformOp::Scale(s) => Transform::scale(s),
        };
        if t.is_none() {
            self.error(
                At::Name(stmt),
                "scale by 0 or rotation about a zero axis: the transform has no inverse"
                    .to_string(),
                None,
            );
        }
        t
    }

    /// The transforms of every target at each render statement (one snapshot per job).
    pub(super) fn snapshots<'s>(
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
                        self.warn(At::Statement(stmt),
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
                        let Some(t) = self.op_transform(op, stmt) else {
                            continue;
                        };
                        let next = match self.opts.transform_order {
                            TransformOrder::World => t.then_after(&m),
                            TransformOrder::Local => m.then_after(&t),
                        };
                        if !finite_transform(&next) {
                            self.error(At::Name(stmt),
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
}

/// Whether a transform and its inverse are usable (no overflow to infinity or NaN).
pub(super) fn finite_transform(t: &Transform) -> bool {
    t.world_from_object.is_finite() && t.object_from_world.is_finite()
}
