//! Names a definition refers to: a shape's material, a composite's children, and the
//! composite graph as a whole (which must not contain itself).

use super::definitions::{Definitions, ObjectKind};
use super::{At, Builder};
use crate::diag::Severity;
use crate::scene::Material;
use crate::sdf::ast::NameRef;
use glam::Vec3;
use std::collections::HashMap;

/// The loud stand-in for an undefined material: pure magenta, lit or not, never a colour a
/// scene means.
fn fallback_material() -> Material {
    let magenta = Vec3::new(1.0, 0.0, 1.0);
    Material::phong("(undefined material)", magenta, magenta, Vec3::ZERO, 1.0)
}

impl Builder<'_> {
    pub(super) fn resolve_material(
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
            // Reported together with every shape that uses it, in `undefined_materials`.
            None => None,
        }
    }

    /// Shapes whose material is not defined are drawn in a loud magenta fallback, so the
    /// image shows which ones they are; one warning per material name lists every shape that
    /// uses it. `uses` holds (material, shape name) in file order. A material whose line was
    /// rejected (already an error) gets no fallback and no second report.
    pub(super) fn undefined_materials<'s>(
        &mut self,
        d: &mut Definitions<'s>,
        uses: &[(&'s NameRef, &'s str)],
    ) -> HashMap<&'s str, usize> {
        let mut by_material: Vec<(&NameRef, Vec<&str>)> = Vec::new();
        for &(material, shape) in uses {
            if self.skipped(&material.name) {
                continue;
            }
            match by_material
                .iter_mut()
                .find(|(m, _)| m.name == material.name)
            {
                Some((_, shapes)) => shapes.push(shape),
                None => by_material.push((material, vec![shape])),
            }
        }
        let mut fallback_of = HashMap::new();
        if by_material.is_empty() {
            return fallback_of;
        }
        let fallback = d.materials.len();
        d.materials.push(fallback_material());
        let none_defined = d.material_index.is_empty();
        for (material, shapes) in by_material {
            let mut help = self.name_help(&material.name, d.material_index.keys().copied());
            if none_defined {
                help = Some(format!(
                    "the file defines no material: add `define material {} 0.1 0.1 0.1 0.8 0.8 0.8 0.2 0.2 0.2 20`",
                    material.name
                ));
            }
            let list: Vec<String> = shapes.iter().map(|s| format!("`{s}`")).collect();
            self.at_ref(
                Severity::Warning,
                material,
                format!(
                    "unknown material `{}`: {} drawn in magenta ({} {})",
                    material.name,
                    if shapes.len() == 1 {
                        "the shape is"
                    } else {
                        "the shapes are"
                    },
                    if shapes.len() == 1 { "shape" } else { "shapes" },
                    list.join(", ")
                ),
                help,
            );
            fallback_of.insert(material.name.as_str(), fallback);
        }
        fallback_of
    }

    pub(super) fn resolve_children<'s>(
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

    /// Reports every composite that contains itself, directly or through others. (Cycles
    /// are also stopped while flattening, but a cycle that no root reaches would go unseen.)
    pub(super) fn check_cycles(&mut self, d: &Definitions) {
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
                                    At::Name(object.statement),
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
}
