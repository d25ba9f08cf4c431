//! Composites drawn in several places, kept once: a prototype holds what one composite
//! expands to (shapes placed in its own frame, and uses of further prototypes), and each place
//! it is listed holds only a [`Use`] of it. The renderer builds one hierarchy per prototype and
//! instances it by the transforms of its uses, so memory and build time grow with the file,
//! not with the flattened tree.
//!
//! Every shape still gets exactly the world transform the flattened tree would give it: the
//! transforms along its path are composed top-down, one statement's transform at a time, as
//! the flattening does ([`Scene::prototype_world`]), and the transforms that move the whole
//! scene after building ([`Scene::transform_all`]) are applied last. The shapes are also
//! numbered as the flattened tree would number them (depth first), so that equally close
//! hits resolve the same way.
//!
//! Instancing, one home per layer: `crate::scene::instancing` (what a composite drawn in
//! several places expands to), `crate::scene::builder::instancing` (which composites are kept
//! once) and `crate::render::geometry::instancing` (their hierarchies, entered by a use's
//! transform).

use super::{Instance, Scene};
use crate::limits::MAX_NESTING;
use crate::math::Transform;
use arrayvec::ArrayVec;

/// The instanced part of a scene, shared by the jobs of a file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Instanced {
    /// Every composite kept once, by `Use::prototype`.
    pub prototypes: Vec<Prototype>,
    /// Uses at the top of the tree, in depth-first order; their `slot` is a slot of
    /// `Scene::transforms`.
    pub uses: Vec<Use>,
    /// Depth-first number of each of `Scene::instances` in the flattened tree (empty when the
    /// scene has no uses: then it is the instance's index).
    pub offsets: Vec<u32>,
    /// Shapes in the flattened tree.
    pub shapes: u64,
}

/// What one instanced composite expands to, in the frame it is listed in (local slot 0).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Prototype {
    /// Its shapes; `Instance::transform` is a local slot.
    pub leaves: Vec<Instance>,
    /// Depth-first number of each leaf within the prototype's expansion.
    pub offsets: Vec<u32>,
    /// Uses of other prototypes inside it (their `slot` is a local slot), depth-first.
    pub uses: Vec<Use>,
    /// Local slot `k` (from 1) is `slots[k - 1]`: the local slot it is listed in, and the
    /// index in `Scene::local_transforms` of the transform its object's statements give it.
    pub slots: Vec<(u32, u32)>,
    /// Shapes in its expansion.
    pub shapes: u32,
    /// Prototypes nested in it, itself included (1 for one holding only shapes).
    pub depth: u32,
}

/// One place a prototype is listed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Use {
    /// The prototype listed, by its index in `Instanced::prototypes`.
    pub prototype: u32,
    /// The slot its frame is in (of the scene at the top, local inside a prototype).
    pub slot: u32,
    /// Depth-first number of its first shape in the enclosing expansion.
    pub offset: u32,
    /// Its path node in `Scene::names`.
    pub path: u32,
}

/// Where one shape of an instanced composite is: the prototype leaf and its world frame.
#[derive(Clone, Debug)]
pub struct Placed<'s> {
    /// The shape as the prototype holds it: its `transform` is a local slot of the prototype.
    pub instance: &'s Instance,
    /// The shape's world transform, as the flattened tree would give it, moves included.
    pub transform: Transform,
    /// Depth-first number in the flattened tree.
    pub flat: u64,
}

impl Scene {
    /// Shapes the scene draws: its instances and every shape of its uses of prototypes.
    pub fn shape_count(&self) -> u64 {
        if self.instanced.uses.is_empty() {
            self.instances.len() as u64
        } else {
            self.instanced.shapes
        }
    }

    /// Whether some composites are kept as prototypes.
    pub fn has_prototypes(&self) -> bool {
        !self.instanced.uses.is_empty()
    }

    /// The frame of a top-level use as the flattening composed it (before
    /// [`Scene::transform_all`]).
    pub fn use_frame(&self, u: &Use) -> Transform {
        let table = if self.moves.is_empty() {
            &self.transforms
        } else {
            &self.unmoved
        };
        table
            .get(u.slot as usize)
            .copied()
            .unwrap_or(Transform::IDENTITY)
    }

    /// The frame of local slot `slot` of prototype `p` used in frame `frame`, composed as the
    /// flattening composes it: from the use's frame down, each object's own transform after
    /// its parent's.
    #[inline]
    pub fn prototype_world(&self, p: &Prototype, frame: &Transform, slot: u32) -> Transform {
        let mut chain: ArrayVec<u32, { MAX_NESTING + 2 }> = ArrayVec::new();
        let mut k = slot;
        while k != 0 {
            let Some(&(parent, own)) = p.slots.get(k as usize - 1) else {
                break;
            };
            if chain.try_push(own).is_err() {
                break;
            }
            k = parent;
        }
        let mut world = *frame;
        for &own in chain.iter().rev() {
            let t = self
                .local_transforms
                .get(own as usize)
                .copied()
                .unwrap_or(Transform::IDENTITY);
            world = world.then_after(&t);
        }
        world
    }

    /// `world` moved by the transforms [`Scene::transform_all`] applied, in order.
    #[inline]
    pub fn moved(&self, world: Transform) -> Transform {
        self.moves.iter().fold(world, |w, t| t.then_after(&w))
    }

    /// Every shape of the uses of prototypes, one at a time with its world transform (moves
    /// included), without storing the flattened list: for consumers that need every shape.
    /// `visit` returns false to stop.
    pub fn for_each_instanced(&self, mut visit: impl FnMut(Placed) -> bool) {
        let inst = &self.instanced;
        for u in &inst.uses {
            let frame = self.use_frame(u);
            if !self.visit_use(u, &frame, u64::from(u.offset), &mut visit) {
                return;
            }
        }
    }

    fn visit_use(
        &self,
        u: &Use,
        frame: &Transform,
        base: u64,
        visit: &mut impl FnMut(Placed) -> bool,
    ) -> bool {
        let Some(p) = self.instanced.prototypes.get(u.prototype as usize) else {
            return true;
        };
        for (leaf, &offset) in p.leaves.iter().zip(&p.offsets) {
            let world = self.prototype_world(p, frame, leaf.transform);
            let placed = Placed {
                instance: leaf,
                transform: self.moved(world),
                flat: base + u64::from(offset),
            };
            if !visit(placed) {
                return false;
            }
        }
        for nested in &p.uses {
            let world = self.prototype_world(p, frame, nested.slot);
            if !self.visit_use(nested, &world, base + u64::from(nested.offset), visit) {
                return false;
            }
        }
        true
    }

    /// The flattened instance list, in depth-first order: for tests and small scenes (it
    /// stores every shape).
    pub fn flattened(&self) -> Vec<(Instance, Transform)> {
        let mut all: Vec<(u64, Instance, Transform)> = self
            .instances
            .iter()
            .enumerate()
            .map(|(i, inst)| {
                let flat = self
                    .instanced
                    .offsets
                    .get(i)
                    .map_or(i as u64, |&o| u64::from(o));
                (flat, inst.clone(), *self.transform_of(inst))
            })
            .collect();
        self.for_each_instanced(|p| {
            all.push((p.flat, p.instance.clone(), p.transform));
            true
        });
        all.sort_by_key(|(flat, _, _)| *flat);
        all.into_iter().map(|(_, i, t)| (i, t)).collect()
    }
}
