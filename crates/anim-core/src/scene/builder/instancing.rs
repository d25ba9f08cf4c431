//! Which composites are kept once as prototypes (see `crate::scene::Instanced`), and their
//! making while the tree is flattened: a composite listed more than once, big enough to be
//! worth it, becomes a prototype the first time it is met, and a use wherever it is listed.
//!
//! Instancing, one home per layer: `crate::scene::instancing` (what a composite drawn in
//! several places expands to), `crate::scene::builder::instancing` (which composites are kept
//! once) and `crate::render::geometry::instancing` (their hierarchies, entered by a use's
//! transform).

use super::definitions::{Definitions, ObjectKind};
use super::jobs::{Expansion, Flatten, Walked};
use super::Builder;
use crate::limits::{
    scene_memory, INSTANCE_BUDGET_SHARE, INSTANCE_MAX_FLAT, INSTANCE_MIN_SHAPES, MAX_NESTING,
};
use crate::scene::{Instanced, Prototype, Use};
use std::sync::Arc;

/// No prototype made yet for an object.
const NONE: u32 = u32::MAX;

/// Which objects become prototypes. Inactive (nothing instanced) unless some composite
/// qualifies.
#[derive(Default)]
pub(super) struct Plan {
    /// Per object: kept as a prototype.
    instanced: Vec<bool>,
    /// Per object: composite levels at and below it (0 for a shape), to keep the nesting
    /// limit where the flattening checks it.
    height: Vec<u32>,
}

impl Plan {
    pub(super) fn is_active(&self) -> bool {
        self.instanced.iter().any(|&b| b)
    }
}

/// Counts of one object's subtree, by dynamic programming over the composite graph.
#[derive(Clone, Copy, Default)]
struct Counts {
    shapes: u64,
    height: u32,
    unbounded: bool,
}

/// Objects reachable from `roots`, children before parents (each once); a child that closes
/// a cycle is left out of its parent's walk (the flattening reports the cycle).
fn post_order(d: &Definitions, roots: &[usize]) -> Vec<usize> {
    const NEW: u8 = 0;
    const OPEN: u8 = 1;
    let n = d.objects.len();
    let mut state = vec![NEW; n];
    let mut out = Vec::new();
    for &root in roots {
        if state[root] != NEW {
            continue;
        }
        state[root] = OPEN;
        let mut stack: Vec<(usize, usize)> = vec![(root, 0)];
        while let Some(top) = stack.last_mut() {
            let (i, next) = *top;
            let child = match &d.objects[i].kind {
                ObjectKind::Composite { children } => children.get(next),
                ObjectKind::Shape { .. } => None,
            };
            match child {
                Some(name) => {
                    top.1 += 1;
                    if let Some(&c) = d.object_index.get(name) {
                        if state[c] == NEW {
                            state[c] = OPEN;
                            stack.push((c, 0));
                        }
                    }
                }
                None => {
                    out.push(i);
                    stack.pop();
                }
            }
        }
    }
    out
}

fn children<'d>(d: &'d Definitions, i: usize) -> impl Iterator<Item = usize> + 'd {
    let list: &[&str] = match &d.objects[i].kind {
        ObjectKind::Composite { children } => children,
        ObjectKind::Shape { .. } => &[],
    };
    list.iter().filter_map(|c| d.object_index.get(c).copied())
}

impl Builder<'_> {
    /// Decides which composites become prototypes: those listed more than once (counting
    /// every listing in the composites the scene reaches) that expand to at least
    /// [`INSTANCE_MIN_SHAPES`] shapes and hold no unbounded shape (a plane). Nothing is
    /// instanced when the flattened tree would take no more than a small share of the memory
    /// budget ([`INSTANCE_BUDGET_SHARE`]), in a scene drawing a material that lets light through
    /// (shadow rays multiply its crossings in the order the hierarchy offers them, which
    /// instancing would change), or when the flattened tree is too big to number
    /// ([`INSTANCE_MAX_FLAT`]).
    pub(super) fn instancing_plan(&self, d: &Definitions, roots: &[usize]) -> Plan {
        let n = d.objects.len();
        let order = post_order(d, roots);
        let mut counts = vec![Counts::default(); n];
        let mut done = vec![false; n];
        let mut transparent = false;
        for &i in &order {
            let c = match &d.objects[i].kind {
                ObjectKind::Shape { geometry, material } => {
                    transparent |= material
                        .and_then(|m| d.materials.get(m))
                        .is_some_and(|m| m.opacity < 1.0);
                    Counts {
                        shapes: u64::from(material.is_some()),
                        height: 0,
                        unbounded: !geometry.is_bounded(),
                    }
                }
                ObjectKind::Composite { .. } => {
                    let mut c = Counts {
                        shapes: 0,
                        height: 1,
                        unbounded: false,
                    };
                    for k in children(d, i).filter(|&k| done[k]) {
                        c.shapes = c.shapes.saturating_add(counts[k].shapes);
                        c.height = c.height.max(counts[k].height.saturating_add(1));
                        c.unbounded |= counts[k].unbounded;
                    }
                    c
                }
            };
            counts[i] = c;
            done[i] = true;
        }
        let total = roots
            .iter()
            .fold(0u64, |t, &r| t.saturating_add(counts[r].shapes));
        // A tree deeper than the nesting limit is refused by the flattening, as before.
        let deepest = roots.iter().map(|&r| counts[r].height).max().unwrap_or(0);
        if transparent
            || deepest as usize > MAX_NESTING
            || total > INSTANCE_MAX_FLAT
            || scene_memory(total) <= self.opts.max_memory / INSTANCE_BUDGET_SHARE
        {
            return Plan::default();
        }
        let mut listed = vec![0u32; n];
        for &i in &order {
            for k in children(d, i) {
                listed[k] = listed[k].saturating_add(1);
            }
        }
        let instanced = (0..n)
            .map(|i| {
                matches!(d.objects[i].kind, ObjectKind::Composite { .. })
                    && done[i]
                    && listed[i] >= 2
                    && counts[i].shapes >= INSTANCE_MIN_SHAPES
                    && !counts[i].unbounded
            })
            .collect();
        Plan {
            instanced,
            height: counts.iter().map(|c| c.height).collect(),
        }
    }

    /// What the tree below each object costs when its prototypes are kept once: a prototype
    /// counts as one object where it is listed, and its contents once, added to the first
    /// root's count (the budget is checked on the roots' sum).
    pub(super) fn stored_expansion(
        &self,
        d: &Definitions,
        roots: &[usize],
        moved: &[bool],
        plan: &Plan,
    ) -> Vec<Expansion> {
        let n = d.objects.len();
        let mut memo = vec![Expansion::default(); n];
        let mut done = vec![false; n];
        let mut prototypes = Expansion::default();
        for i in post_order(d, roots) {
            let mut e = Expansion {
                shapes: 0,
                nodes: 1,
                slots: u64::from(moved[i]),
            };
            match &d.objects[i].kind {
                ObjectKind::Shape { material, .. } => e.shapes = u64::from(material.is_some()),
                ObjectKind::Composite { .. } => {
                    let mut inside = Expansion::default();
                    for k in children(d, i).filter(|&k| done[k]) {
                        inside.shapes = inside.shapes.saturating_add(memo[k].shapes);
                        inside.nodes = inside.nodes.saturating_add(memo[k].nodes);
                        inside.slots = inside.slots.saturating_add(memo[k].slots);
                    }
                    if plan.instanced[i] {
                        prototypes.shapes = prototypes.shapes.saturating_add(inside.shapes);
                        prototypes.nodes = prototypes.nodes.saturating_add(inside.nodes);
                        prototypes.slots = prototypes.slots.saturating_add(inside.slots);
                    } else {
                        e.shapes = inside.shapes;
                        e.nodes = e.nodes.saturating_add(inside.nodes);
                        e.slots = e.slots.saturating_add(inside.slots);
                    }
                }
            }
            memo[i] = e;
            done[i] = true;
        }
        if let Some(&first) = roots.first() {
            let e = &mut memo[first];
            e.shapes = e.shapes.saturating_add(prototypes.shapes);
            e.nodes = e.nodes.saturating_add(prototypes.nodes);
            e.slots = e.slots.saturating_add(prototypes.slots);
        }
        memo
    }

    /// Lists composite `i` (met in the flattening at path node `node`, in slot `slot`) as a
    /// use of its prototype, making the prototype the first time. False when it is not
    /// instanced here (not chosen, or listed so deep that the flattening must check the
    /// nesting limit on its own walk): the caller then flattens it.
    pub(super) fn use_prototype<'s>(
        &mut self,
        walked: Walked<'_, 's>,
        i: usize,
        slot: u32,
        node: u32,
        stack: &mut Vec<&'s str>,
        out: &mut Flatten,
    ) -> bool {
        let d = walked.defs;
        let b = &out.inst;
        if !b.plan.instanced.get(i).copied().unwrap_or(false)
            || stack.len() + b.plan.height[i] as usize > MAX_NESTING
        {
            return false;
        }
        let mut proto = b.proto_of[i];
        if proto == NONE {
            let instances = std::mem::take(&mut out.instances);
            let slots = std::mem::take(&mut out.slots);
            let target = std::mem::take(&mut out.inst.target);
            stack.push(d.objects[i].name);
            for c in children(d, i) {
                self.flatten(walked, c, 0, node, stack, out);
            }
            stack.pop();
            let leaves = std::mem::replace(&mut out.instances, instances);
            let local = std::mem::replace(&mut out.slots, slots);
            let made = std::mem::replace(&mut out.inst.target, target);
            let b = &mut out.inst;
            let base = b.local_objects.len() as u32;
            b.local_objects
                .extend(local.iter().map(|&(_, object)| object));
            let depth = made
                .uses
                .iter()
                .map(|u| b.prototypes[u.prototype as usize].depth + 1)
                .max()
                .unwrap_or(1);
            proto = b.prototypes.len() as u32;
            b.prototypes.push(Prototype {
                leaves,
                offsets: made.offsets,
                uses: made.uses,
                slots: local
                    .iter()
                    .enumerate()
                    .map(|(k, &(parent, _))| (parent, base + k as u32))
                    .collect(),
                shapes: u32::try_from(made.next).unwrap_or(u32::MAX),
                depth,
            });
            b.proto_of[i] = proto;
        }
        let b = &mut out.inst;
        let shapes = b.prototypes[proto as usize].shapes;
        b.target.uses.push(Use {
            prototype: proto,
            slot,
            offset: u32::try_from(b.target.next).unwrap_or(u32::MAX),
            path: node,
        });
        b.target.next += u64::from(shapes);
        true
    }
}

/// What is being filled: the top of the tree or a prototype.
#[derive(Default)]
pub(super) struct Target {
    uses: Vec<Use>,
    offsets: Vec<u32>,
    /// Shapes flattened so far (the depth-first number of the next).
    next: u64,
}

/// The prototypes being made while the tree is flattened.
#[derive(Default)]
pub(super) struct Building {
    plan: Plan,
    /// Object → its prototype ([`NONE`] before it is made).
    proto_of: Vec<u32>,
    prototypes: Vec<Prototype>,
    /// Object of each local slot of every prototype, for the jobs' transforms.
    local_objects: Vec<usize>,
    target: Target,
}

impl Building {
    pub(super) fn new(plan: Plan, objects: usize) -> Building {
        Building {
            proto_of: if plan.is_active() {
                vec![NONE; objects]
            } else {
                Vec::new()
            },
            plan,
            ..Building::default()
        }
    }

    /// Records a shape just flattened.
    #[inline]
    pub(super) fn leaf(&mut self) {
        if !self.proto_of.is_empty() {
            let t = &mut self.target;
            t.offsets.push(u32::try_from(t.next).unwrap_or(u32::MAX));
            t.next += 1;
        }
    }

    /// The instanced part of the scene, and the object of each local transform slot.
    pub(super) fn finish(self) -> (Arc<Instanced>, Vec<usize>) {
        let t = self.target;
        if t.uses.is_empty() {
            return (Arc::default(), Vec::new());
        }
        let instanced = Instanced {
            prototypes: self.prototypes,
            uses: t.uses,
            offsets: t.offsets,
            shapes: t.next,
        };
        (Arc::new(instanced), self.local_objects)
    }
}

#[cfg(test)]
mod tests {
    use crate::load::load_str;
    use crate::math::Transform;
    use crate::scene::Scene;
    use crate::sdf::LoadOptions;
    use glam::DVec3;
    use std::fmt::Write;
    use std::path::Path;

    /// A file whose composite `part` (`n` spheres in material `mat`, `extra` appended to it)
    /// is listed by two moved wrappers.
    fn file(n: usize, mat: &str, extra: &str) -> String {
        let mut t = String::from(
            "define material red 0.1 0 0 0.8 0 0 0.2 0.2 0.2 10\n\
             define material glass 0 0 0 0.1 0.1 0.1 0.5 0.5 0.5 50 0 0.5 1.5\n",
        );
        let mut names = Vec::new();
        for i in 0..n {
            writeln!(t, "define shape sphere s{i} {i} 0 -10 0.4 {mat}").unwrap();
            names.push(format!("s{i}"));
        }
        writeln!(t, "{extra}").unwrap();
        if !extra.is_empty() {
            names.push("extra".to_string());
        }
        writeln!(t, "define shape composite part {}", names.join(" ")).unwrap();
        t.push_str(
            "define shape composite w1 part\ndefine shape composite w2 part\n\
             transform w1 rotate 30 0 1 0\ntransform w2 scale 0.5\ntransform w2 translate 1 2 3\n\
             define shape composite root w1 w2\n",
        );
        t
    }

    fn scene(text: &str, max_memory: u64) -> Scene {
        let opts = LoadOptions {
            max_memory,
            ..LoadOptions::default()
        };
        let loaded = load_str(text, Path::new("t.sdf"), &opts).unwrap();
        loaded.jobs[0].scene.clone()
    }

    #[test]
    fn a_composite_listed_twice_is_instanced_only_when_it_pays() {
        // 32 flattened spheres take 16 KiB, more than 1/64 of 64 KiB.
        let small = 1 << 16;
        let s = scene(&file(16, "red", ""), small);
        assert!(s.has_prototypes());
        assert_eq!(s.instances.len(), 0);
        assert_eq!(s.instanced.prototypes.len(), 1);
        assert_eq!(s.instanced.prototypes[0].leaves.len(), 16);
        assert_eq!(s.shape_count(), 32);
        // Too small to be worth it, or the budget is large: flattened.
        assert!(!scene(&file(15, "red", ""), small).has_prototypes());
        assert!(!scene(&file(16, "red", ""), 1 << 30).has_prototypes());
        // Unbounded shapes and materials that let light through keep it flat.
        let plane = "define shape plane extra 0 -1 0 0 1 0 red";
        assert!(!scene(&file(16, "red", plane), small).has_prototypes());
        assert!(!scene(&file(16, "glass", ""), small).has_prototypes());
    }

    #[test]
    fn instanced_shapes_get_the_flattened_transforms_after_moves() {
        let text = file(
            20,
            "red",
            "define shape box extra 0 0 0 1 2 3 red\ntransform extra rotate 10 1 1 0",
        );
        let mut inst = scene(&text, 1 << 16);
        let mut flat = scene(&text, 1 << 30);
        assert!(inst.has_prototypes() && !flat.has_prototypes());
        let moves = [
            Transform::translate(DVec3::new(-0.3, 7.0, 1e3)),
            Transform::rotate(13.0, DVec3::new(1.0, 2.0, 3.0)).unwrap(),
        ];
        for round in 0..=moves.len() {
            let a = inst.flattened();
            assert_eq!(a.len(), flat.instances.len());
            for ((i, t), f) in a.iter().zip(flat.instances.iter()) {
                assert_eq!(i.geometry, f.geometry);
                // Named by the path of the composite's first use: the object is the same.
                let object = |name: String| name.rsplit('/').next().map(str::to_string);
                assert_eq!(object(inst.instance_name(i)), object(flat.instance_name(f)));
                // Bit for bit, as the flattening composes them.
                assert_eq!(t, flat.transform_of(f), "round {round}");
            }
            if let Some(m) = moves.get(round) {
                inst.transform_all(m);
                flat.transform_all(m);
            }
        }
    }
}
