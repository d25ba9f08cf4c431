//! The 4-wide hierarchy rays traverse: each node holds its children's boxes in SoA lanes so
//! one SIMD slab test covers all four, and leaves keep their primitive indices contiguously.
//!
//! It is the binary SAH tree with levels collapsed, and it offers primitives in the order the
//! binary traversal did (minus some it culled): the closest hit keeps the same winner among
//! equally close hits, and transparent shadow crossings multiply in the same order, so images
//! stay byte-identical to the binary tree's.

use super::binary::{BinaryBvh, MAX_DEPTH, PARALLEL_MIN};
use crate::math::{Aabb, Ray, SLAB_WIDEN};
use arrayvec::ArrayVec;
use glam::Vec4;

mod packet;
pub use packet::Packet;

const WIDTH: usize = 4;
/// Marks a child reference as a leaf; the other bits index the leaf's header in `prims`.
const LEAF: u32 = 1 << 31;
/// Every wide level consumes at least one binary level (at most `MAX_DEPTH + 1` of them), and
/// visiting a node pops one entry and pushes at most `WIDTH`.
const STACK_SIZE: usize = (WIDTH - 1) * (MAX_DEPTH + 1) + 1;

/// One wide node: 128 bytes, two cache lines, aligned to them.
#[derive(Clone, Debug)]
#[repr(align(64))]
struct Node {
    /// Child boxes, lane `i` for child `i`: `min[axis]`, `max[axis]`.
    min: [Vec4; 3],
    max: [Vec4; 3],
    /// A node index, or `LEAF | start` where `prims[start]` counts the leaf's primitives and
    /// their indices follow it.
    child: [u32; WIDTH],
    /// For each ray octant (bit `a` set when the direction's component `a` is negative), the
    /// child slots in the order the binary tree's front-to-back traversal reached them, two
    /// bits per slot, first in the low bits.
    order: [u8; 8],
    /// Number of children (1 only for a root that is a single leaf).
    len: u8,
    /// `len` low bits set: the lanes that hold a child (kept, not derived per visit).
    live: u8,
}

#[derive(Clone, Debug, Default)]
/// The 4-wide bounding volume hierarchy over a set of primitives' world bounds, which
/// rays walk front to back (see the module doc).
pub struct Bvh {
    /// Depth-first: a node's children follow it (the root is node 0).
    nodes: Vec<Node>,
    /// Leaves, each a count followed by that many primitive indices.
    prims: Vec<u32>,
}

/// The ray splatted over the lanes, per axis.
struct RayLanes {
    origin: [Vec4; 3],
    inv_dir: [Vec4; 3],
}

impl RayLanes {
    /// Whether no slab test of this ray can make NaN: `(b − o) · (1/d)` is NaN only for
    /// `0 · ∞` or `∞ − ∞`, and with a finite origin and every `1/d` finite and non-zero the
    /// factors are never 0 and ∞ together (box coordinates are finite, or ±∞ in unused lanes).
    #[inline(always)]
    fn nan_free(ray: &Ray) -> bool {
        let inv = ray.dir.recip();
        ray.origin.is_finite() && inv.is_finite() && inv.cmpne(glam::Vec3A::ZERO).all()
    }

    #[inline(always)]
    fn new(ray: &Ray) -> RayLanes {
        // 1/0 = ±inf for zero components; `Node::hit` deals with the NaNs they can make.
        let inv = ray.dir.recip();
        RayLanes {
            origin: crate::math::splat3(ray.origin),
            inv_dir: crate::math::splat3(inv),
        }
    }
}

impl Node {
    /// Bit `i` set when the ray meets child `i`'s box within `[0, t_max]`, and each lane's
    /// entry distance. Lane by lane the same arithmetic as `Aabb::hit_range` (and so the same
    /// answer): a ray parallel to a slab with its origin on one of the planes gives
    /// `0 · inf = NaN` there, and is inside that slab, so NaN becomes the unbounded interval
    /// before SSE min/max (which would not drop it) see it.
    ///
    /// `NAN_FREE` skips that repair for rays that cannot make NaN (see [`RayLanes::nan_free`]),
    /// where it changes nothing.
    #[inline(always)]
    fn hit<const NAN_FREE: bool>(&self, ray: &RayLanes, t_max: f32) -> (u32, Vec4) {
        let mut enter = Vec4::ZERO;
        let mut exit = Vec4::INFINITY;
        for axis in 0..3 {
            let t0 = (self.min[axis] - ray.origin[axis]) * ray.inv_dir[axis];
            let t1 = (self.max[axis] - ray.origin[axis]) * ray.inv_dir[axis];
            if NAN_FREE {
                enter = enter.max(t0.min(t1));
                exit = exit.min(t0.max(t1));
            } else {
                let on_plane = t0.is_nan_mask() | t1.is_nan_mask();
                enter = enter.max(Vec4::select(on_plane, Vec4::NEG_INFINITY, t0.min(t1)));
                exit = exit.min(Vec4::select(on_plane, Vec4::INFINITY, t0.max(t1)));
            }
        }
        let exit = (exit * SLAB_WIDEN).min(Vec4::splat(t_max));
        (enter.cmple(exit).bitmask() & u32::from(self.live), enter)
    }
}

impl Bvh {
    /// Builds over `bounds[i]` for the primitive indices in `items` (unbounded primitives must
    /// be kept elsewhere by the caller).
    pub fn build(bounds: &[Aabb], items: impl IntoIterator<Item = u32>) -> Bvh {
        Bvh::from_binary(&BinaryBvh::build(bounds, items, PARALLEL_MIN))
    }

    fn from_binary(bin: &BinaryBvh) -> Bvh {
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(bin.nodes.len() / 2 + 1),
            prims: Vec::with_capacity(bin.order.len() + bin.nodes.len() / 2 + 1),
        };
        if !bin.nodes.is_empty() {
            bvh.collapse(bin, 0);
        }
        // Collapsing leaves far fewer wide nodes than the capacity guessed from the binary
        // tree; the hierarchy lives as long as the render, so its slack is worth returning.
        bvh.nodes.shrink_to_fit();
        bvh.prims.shrink_to_fit();
        bvh
    }

    /// Whether it holds no primitive.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Nodes in the tree (a measure of its depth and width, for the policy that picks
    /// camera packets).
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Bytes the hierarchy holds (nodes and leaf lists, not counting spare capacity).
    pub fn bytes(&self) -> usize {
        self.nodes.len() * size_of::<Node>() + self.prims.len() * size_of::<u32>()
    }

    /// Makes the wide node for the binary subtree at `root` and, depth first, its children;
    /// returns its index.
    fn collapse(&mut self, bin: &BinaryBvh, root: usize) -> u32 {
        // Open the child with the largest surface area until there are four: big boxes are
        // the ones rays meet most often, so theirs are the splits worth testing at once.
        // Slots stay in the binary tree's left-to-right order.
        let mut slots = [root; WIDTH];
        let mut len = 1;
        while len < WIDTH {
            let area = |i: usize| bin.nodes[slots[i]].bounds.surface_area();
            let Some(open) = (0..len)
                .filter(|&i| !bin.nodes[slots[i]].is_leaf())
                .reduce(|a, b| if area(b) > area(a) { b } else { a })
            else {
                break;
            };
            let b = slots[open];
            slots.copy_within(open + 1..len, open + 2);
            slots[open] = b + 1;
            slots[open + 1] = bin.nodes[b].offset as usize;
            len += 1;
        }
        let slots = &slots[..len];

        let mut order = [0u8; 8];
        for (octant, o) in order.iter_mut().enumerate() {
            let mut k = 0;
            visit_order(bin, root, slots, octant, o, &mut k);
        }
        let index = self.nodes.len();
        self.nodes.push(Node {
            min: [Vec4::INFINITY; 3],
            max: [Vec4::NEG_INFINITY; 3],
            child: [0; WIDTH],
            order,
            len: len as u8,
            live: (1u8 << len) - 1,
        });
        let mut min = [[f32::INFINITY; WIDTH]; 3];
        let mut max = [[f32::NEG_INFINITY; WIDTH]; 3];
        let mut child = [0u32; WIDTH];
        for (i, &b) in slots.iter().enumerate() {
            let node = &bin.nodes[b];
            for axis in 0..3 {
                min[axis][i] = node.bounds.min[axis];
                max[axis][i] = node.bounds.max[axis];
            }
            child[i] = if node.is_leaf() {
                let start = node.offset as usize;
                let leaf = self.prims.len() as u32;
                self.prims.push(node.count as u32);
                self.prims
                    .extend_from_slice(&bin.order[start..start + node.count as usize]);
                LEAF | leaf
            } else {
                self.collapse(bin, b)
            };
        }
        let node = &mut self.nodes[index];
        node.min = min.map(Vec4::from_array);
        node.max = max.map(Vec4::from_array);
        node.child = child;
        index as u32
    }

    #[inline(always)]
    fn leaf(&self, reference: u32) -> &[u32] {
        let start = (reference & !LEAF) as usize;
        let count = self.prims[start] as usize;
        &self.prims[start + 1..start + 1 + count]
    }

    /// Renumbers the primitives in leaf order, so that every leaf holds consecutive indices
    /// (`first..first + len`) and neighbouring leaves neighbouring ones: storage laid out in
    /// this order is read front to back by a leaf. Returns `order`, `order[new] = old`. The
    /// traversal order is unchanged.
    pub fn renumber_in_leaf_order(&mut self) -> Vec<u32> {
        let mut order = Vec::with_capacity(self.prims.len());
        let mut header = 0;
        while header < self.prims.len() {
            let count = self.prims[header] as usize;
            for id in &mut self.prims[header + 1..header + 1 + count] {
                order.push(*id);
                *id = order.len() as u32 - 1;
            }
            header += 1 + count;
        }
        order
    }

    /// Closest hit: calls `hit(prim, t_max)` for candidate primitives in roughly front-to-back
    /// order; it returns the new `t_max` when the primitive is hit closer.
    #[inline]
    pub fn closest(
        &self,
        ray: &Ray,
        t_max: f32,
        mut hit: impl FnMut(u32, f32) -> Option<f32>,
    ) -> f32 {
        self.closest_leaves(ray, t_max, |leaf, mut t_max| {
            for &prim in leaf {
                if let Some(t) = hit(prim, t_max) {
                    t_max = t;
                }
            }
            t_max
        })
    }

    /// Closest hit a leaf at a time: `leaf(prims, t_max)` tests a leaf's primitives in their
    /// order and returns the new `t_max` (the old one if nothing was hit closer). Leaves come
    /// in the order `closest` offers their primitives.
    #[inline]
    pub fn closest_leaves(
        &self,
        ray: &Ray,
        t_max: f32,
        leaf: impl FnMut(&[u32], f32) -> f32,
    ) -> f32 {
        if RayLanes::nan_free(ray) {
            self.closest_impl::<true>(ray, t_max, leaf)
        } else {
            self.closest_impl::<false>(ray, t_max, leaf)
        }
    }

    #[inline(always)]
    fn closest_impl<const NAN_FREE: bool>(
        &self,
        ray: &Ray,
        mut t_max: f32,
        mut leaf: impl FnMut(&[u32], f32) -> f32,
    ) -> f32 {
        if self.nodes.is_empty() {
            return t_max;
        }
        let lanes = RayLanes::new(ray);
        let octant = octant(ray);
        // Entries carry their box's entry distance: one that lies beyond a hit found since it
        // was pushed is dropped without touching its node.
        // Not zero-filled: a ray uses a few entries of a stack sized for the deepest tree,
        // and clearing it all would cost more than the walk of a shallow one.
        let mut stack: ArrayVec<(u32, f32), STACK_SIZE> = ArrayVec::new();
        let mut reference = 0;
        loop {
            if reference & LEAF != 0 {
                t_max = leaf(self.leaf(reference), t_max);
            } else {
                let node = &self.nodes[reference as usize];
                let (mask, enter) = node.hit::<NAN_FREE>(&lanes, t_max);
                if mask.is_power_of_two() {
                    // One child met: visited next without a trip through the stack (its
                    // entry lies within `t_max`, so popping it would not drop it).
                    reference = node.child[mask.trailing_zeros() as usize];
                    continue;
                }
                if mask != 0 {
                    let enter = enter.to_array();
                    let order = node.order[octant];
                    let (nearest, k) = nearest_met(order, mask);
                    // The others pushed farthest first; the nearest visited next, without a
                    // trip through the stack.
                    for k in (k..node.len).rev() {
                        let slot = usize::from((order >> (2 * k)) & 3);
                        if mask & (1 << slot) != 0 {
                            stack.push((node.child[slot], enter[slot]));
                        }
                    }
                    reference = node.child[nearest];
                    continue;
                }
            }
            loop {
                let Some((next, enter)) = stack.pop() else {
                    return t_max;
                };
                if enter > t_max {
                    continue;
                }
                reference = next;
                break;
            }
        }
    }

    /// Any hit before `t_max`: stops as soon as `occludes(prim)` says yes. Children are
    /// offered left to right, the binary tree's order.
    #[inline]
    pub fn any(&self, ray: &Ray, t_max: f32, mut occludes: impl FnMut(u32) -> bool) -> bool {
        let leaf = |leaf: &[u32]| leaf.iter().any(|&p| occludes(p));
        if RayLanes::nan_free(ray) {
            self.any_in_order::<false, true>(ray, t_max, leaf)
        } else {
            self.any_in_order::<false, false>(ray, t_max, leaf)
        }
    }

    /// Any hit a leaf at a time: stops as soon as `occludes(prims)` says yes. Children are
    /// visited nearest first (the order `closest` uses), where an occluder near the ray's
    /// origin is found without visiting what lies behind it; so the order in which leaves
    /// come differs from `any`'s.
    #[inline]
    pub fn any_leaves(&self, ray: &Ray, t_max: f32, occludes: impl FnMut(&[u32]) -> bool) -> bool {
        if RayLanes::nan_free(ray) {
            self.any_in_order::<true, true>(ray, t_max, occludes)
        } else {
            self.any_in_order::<true, false>(ray, t_max, occludes)
        }
    }

    #[inline(always)]
    fn any_in_order<const NEAR_FIRST: bool, const NAN_FREE: bool>(
        &self,
        ray: &Ray,
        t_max: f32,
        mut occludes: impl FnMut(&[u32]) -> bool,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let lanes = RayLanes::new(ray);
        let octant = octant(ray);
        let mut stack: ArrayVec<u32, STACK_SIZE> = ArrayVec::new();
        let mut next = Some(0);
        while let Some(reference) = next.take().or_else(|| stack.pop()) {
            if reference & LEAF != 0 {
                if occludes(self.leaf(reference)) {
                    return true;
                }
                continue;
            }
            let node = &self.nodes[reference as usize];
            let (mask, _) = node.hit::<NAN_FREE>(&lanes, t_max);
            if mask.is_power_of_two() {
                // One child met: visited next without a trip through the stack.
                next = Some(node.child[mask.trailing_zeros() as usize]);
                continue;
            }
            if mask == 0 {
                continue;
            }
            if !NEAR_FIRST {
                // Pushed from the last slot down, so that they come off left to right.
                for slot in (0..usize::from(node.len)).rev() {
                    if mask & (1 << slot) != 0 {
                        stack.push(node.child[slot]);
                    }
                }
                continue;
            }
            // The others pushed farthest first; the nearest visited next, without a trip
            // through the stack.
            let order = node.order[octant];
            let (nearest, k) = nearest_met(order, mask);
            for k in (k..node.len).rev() {
                let slot = usize::from((order >> (2 * k)) & 3);
                if mask & (1 << slot) != 0 {
                    stack.push(node.child[slot]);
                }
            }
            next = Some(node.child[nearest]);
        }
        false
    }

    /// Offers every leaf under nodes whose boxes `meets(min, max)` (conservatively) to
    /// `visit`, until it returns true (then true): the walk of a query that is no ray, such
    /// as a cone of shadow rays. Children are offered left to right.
    pub fn any_meeting(
        &self,
        meets: impl Fn(Vec4, Vec4) -> bool,
        mut visit: impl FnMut(&[u32]) -> bool,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let mut stack: ArrayVec<u32, STACK_SIZE> = ArrayVec::new();
        stack.push(0);
        while let Some(reference) = stack.pop() {
            if reference & LEAF != 0 {
                if visit(self.leaf(reference)) {
                    return true;
                }
                continue;
            }
            let node = &self.nodes[reference as usize];
            for slot in (0..usize::from(node.len)).rev() {
                let lane = |v: &[Vec4; 3]| Vec4::new(v[0][slot], v[1][slot], v[2][slot], 0.0);
                if meets(lane(&node.min), lane(&node.max)) {
                    stack.push(node.child[slot]);
                }
            }
        }
        false
    }

    /// Bytes held by the hierarchy.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<Node>() + self.prims.capacity() * 4
    }
}

/// The first slot of a node's visit `order` (for the ray's octant) whose bit is set in
/// `mask` (not empty), and the position in `order` after it.
#[inline(always)]
fn nearest_met(order: u8, mask: u32) -> (usize, u8) {
    let mut k = 0;
    loop {
        let slot = usize::from((order >> (2 * k)) & 3);
        k += 1;
        if mask & (1 << slot) != 0 {
            return (slot, k);
        }
    }
}

/// The ray's octant: bit `a` set when its direction's component `a` is negative.
#[inline(always)]
fn octant(ray: &Ray) -> usize {
    usize::from(ray.dir.x < 0.0)
        | usize::from(ray.dir.y < 0.0) << 1
        | usize::from(ray.dir.z < 0.0) << 2
}

/// Appends to `order` the slots of the binary subtree at `b` in the order the binary
/// closest-hit traversal reaches them for rays of `octant`: at each split, the child on the
/// ray's side first.
fn visit_order(
    bin: &BinaryBvh,
    b: usize,
    slots: &[usize],
    octant: usize,
    order: &mut u8,
    k: &mut u32,
) {
    if let Some(slot) = slots.iter().position(|&s| s == b) {
        *order |= (slot as u8) << (2 * *k);
        *k += 1;
        return;
    }
    let node = &bin.nodes[b];
    let (first, second) = (b + 1, node.offset as usize);
    let (near, far) = if (octant >> node.axis) & 1 == 1 {
        (second, first)
    } else {
        (first, second)
    };
    visit_order(bin, near, slots, octant, order, k);
    visit_order(bin, far, slots, octant, order, k);
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3A;

    pub(super) use crate::util::SplitMix64;

    /// Test points from the one test generator, shared with the packet tests.
    pub(super) trait Points {
        /// A point in the cube [0, `scale`)³.
        fn vec(&mut self, scale: f32) -> Vec3A;
    }

    impl Points for SplitMix64 {
        fn vec(&mut self, scale: f32) -> Vec3A {
            Vec3A::new(self.unit_f32(), self.unit_f32(), self.unit_f32()) * scale
        }
    }

    /// Unit cubes on a grid; each "primitive" is its own bounding box.
    fn grid(n: usize) -> Vec<Aabb> {
        let mut v = Vec::new();
        for x in 0..n {
            for y in 0..n {
                for z in 0..n {
                    let p = Vec3A::new(x as f32 * 2.0, y as f32 * 2.0, z as f32 * 2.0);
                    v.push(Aabb::new(p, p + Vec3A::ONE));
                }
            }
        }
        v
    }

    /// Boxes of many sizes, overlapping, some flat (zero extent on an axis).
    fn random_boxes(rng: &mut SplitMix64, n: usize) -> Vec<Aabb> {
        (0..n)
            .map(|i| {
                let p = rng.vec(40.0);
                let mut e = rng.vec(3.0);
                e[i % 3] *= f32::from(u8::from(!i.is_multiple_of(4)));
                Aabb::new(p, p + e)
            })
            .collect()
    }

    pub(super) fn box_t(b: &Aabb, ray: &Ray) -> Option<f32> {
        b.hit_range(ray, ray.dir.recip(), 0.0, f32::INFINITY)
            .map(|(t, _)| t)
    }

    /// Rays through the scene, a third of them axis-parallel (zero direction components),
    /// some starting exactly on box faces.
    fn random_ray(rng: &mut SplitMix64, boxes: &[Aabb], i: usize) -> Ray {
        let o = rng.vec(60.0) - Vec3A::splat(10.0);
        let target = rng.vec(40.0);
        let mut dir = (target - o).normalize();
        if i.is_multiple_of(3) {
            let keep = i / 3 % 3;
            dir = Vec3A::ZERO;
            dir[keep] = if rng.unit_f32() < 0.5 { 1.0 } else { -1.0 };
        }
        let mut origin = o;
        if i.is_multiple_of(5) {
            // On the plane of a face, parallel to it when the direction is axis-aligned.
            let b = &boxes[i % boxes.len()];
            origin[(i / 5) % 3] = b.min[(i / 5) % 3];
        }
        Ray::new(origin, dir)
    }

    #[test]
    fn closest_and_any_equal_brute_force() {
        let mut rng = SplitMix64::new(0x9E3779B97F4A7C15);
        for boxes in [
            grid(6),
            random_boxes(&mut rng, 700),
            random_boxes(&mut rng, 3),
        ] {
            let bvh = Bvh::build(&boxes, 0..boxes.len() as u32);
            for i in 0..3000 {
                let ray = random_ray(&mut rng, &boxes, i);
                let brute = boxes
                    .iter()
                    .filter_map(|b| box_t(b, &ray))
                    .fold(f32::INFINITY, f32::min);
                let via_bvh = bvh.closest(&ray, f32::INFINITY, |i, t_max| {
                    box_t(&boxes[i as usize], &ray).filter(|&t| t < t_max)
                });
                assert_eq!(brute, via_bvh);
                let blocked = bvh.any(&ray, f32::INFINITY, |i| {
                    box_t(&boxes[i as usize], &ray).is_some()
                });
                assert_eq!(blocked, brute.is_finite());
            }
        }
    }

    /// The wide tree offers hits in the binary tree's order: the sequence of accepted closest
    /// hits, and the sequence of primitives an any-hit query meets, are the same.
    #[test]
    fn offers_hits_in_the_binary_order() {
        let mut rng = SplitMix64::new(0xD1B54A32D192ED03);
        let boxes = random_boxes(&mut rng, 2000);
        let bin = BinaryBvh::build(&boxes, 0..boxes.len() as u32, usize::MAX);
        let wide = Bvh::from_binary(&bin);
        for i in 0..3000 {
            let ray = random_ray(&mut rng, &boxes, i);
            let t_limit = if i.is_multiple_of(2) {
                f32::INFINITY
            } else {
                30.0
            };
            let mut seen = [Vec::new(), Vec::new()];
            let record = |seen: &mut Vec<(u32, f32)>, i: u32, t_max: f32| {
                let t = box_t(&boxes[i as usize], &ray).filter(|&t| t < t_max)?;
                seen.push((i, t));
                Some(t)
            };
            bin.closest(&ray, t_limit, |i, t| record(&mut seen[0], i, t));
            wide.closest(&ray, t_limit, |i, t| record(&mut seen[1], i, t));
            assert_eq!(seen[0], seen[1]);
            let mut met = [Vec::new(), Vec::new()];
            let meet = |met: &mut Vec<u32>, i: u32| {
                if box_t(&boxes[i as usize], &ray).is_some_and(|t| t < t_limit) {
                    met.push(i);
                }
                false
            };
            assert!(!bin.any(&ray, t_limit, |i| meet(&mut met[0], i)));
            assert!(!wide.any(&ray, t_limit, |i| meet(&mut met[1], i)));
            assert_eq!(met[0], met[1]);
        }
    }

    #[test]
    fn grazing_and_axis_parallel_rays_are_not_rejected() {
        let boxes = vec![Aabb::new(Vec3A::ZERO, Vec3A::ONE); 1];
        let bvh = Bvh::build(&boxes, [0]);
        // In the plane x = 0, parallel to the x slab; along an edge; from inside a face.
        for ray in [
            Ray::new(Vec3A::new(0.0, 0.5, -1.0), Vec3A::Z),
            Ray::new(Vec3A::new(1.0, 1.0, -1.0), Vec3A::Z),
            Ray::new(Vec3A::new(0.5, 0.0, 0.5), Vec3A::NEG_Y),
            Ray::new(Vec3A::new(0.0, 0.0, 0.0), Vec3A::X),
        ] {
            assert!(bvh.any(&ray, f32::INFINITY, |_| true), "{ray:?}");
        }
        let beside = Ray::new(Vec3A::new(2.0, 0.5, -1.0), Vec3A::Z);
        assert!(!bvh.any(&beside, f32::INFINITY, |_| true));
        let short = Ray::new(Vec3A::new(0.5, 0.5, -1.0), Vec3A::Z);
        assert!(!bvh.any(&short, 0.5, |_| true));
    }

    #[test]
    fn parallel_build_makes_the_same_tree() {
        let mut rng = SplitMix64::new(0x2545F4914F6CDD1D);
        let boxes = random_boxes(&mut rng, 5000);
        let serial = BinaryBvh::build(&boxes, 0..boxes.len() as u32, usize::MAX);
        for threads in [1, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let parallel = pool.install(|| BinaryBvh::build(&boxes, 0..boxes.len() as u32, 64));
            assert_eq!(serial, parallel);
        }
    }

    /// Exponentially spaced boxes make a deep, lopsided tree (binning peels a few boxes off
    /// per level); traversal through every level stays within the fixed stack, whose size
    /// follows from the depth cap (`STACK_SIZE`).
    #[test]
    fn deep_tree_traverses_every_level() {
        let boxes: Vec<Aabb> = (0..90)
            .map(|i| {
                let x = 2f32.powi(i);
                Aabb::new(Vec3A::new(x, 0.0, 0.0), Vec3A::new(x * 1.01, 1.0, 1.0))
            })
            .collect();
        let bin = BinaryBvh::build(&boxes, 0..boxes.len() as u32, usize::MAX);
        fn depth(bin: &BinaryBvh, n: usize) -> usize {
            let node = &bin.nodes[n];
            if node.is_leaf() {
                0
            } else {
                1 + depth(bin, n + 1).max(depth(bin, node.offset as usize))
            }
        }
        assert!(depth(&bin, 0) > 16, "depth {}", depth(&bin, 0));
        let bvh = Bvh::from_binary(&bin);
        let ray = Ray::new(Vec3A::new(0.0, 0.5, 0.5), Vec3A::X);
        let mut offered = 0;
        assert!(!bvh.any(&ray, f32::INFINITY, |_| {
            offered += 1;
            false
        }));
        assert_eq!(offered, boxes.len());
        let t = bvh.closest(&ray, f32::INFINITY, |i, t_max| {
            box_t(&boxes[i as usize], &ray).filter(|&t| t < t_max)
        });
        assert_eq!(t, 1.0);
    }

    /// Renumbered, leaves hold consecutive indices and offer the same primitives (under their
    /// new names) in the same order.
    #[test]
    fn renumbering_keeps_the_offer_order() {
        let mut rng = SplitMix64::new(0x94D049BB133111EB);
        let boxes = random_boxes(&mut rng, 1500);
        let bvh = Bvh::build(&boxes, 0..boxes.len() as u32);
        let mut renamed = bvh.clone();
        let order = renamed.renumber_in_leaf_order();
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..boxes.len() as u32).collect::<Vec<_>>());
        for i in 0..1000 {
            let ray = random_ray(&mut rng, &boxes, i);
            let mut seen = [Vec::new(), Vec::new()];
            bvh.closest(&ray, f32::INFINITY, |p, t_max| {
                seen[0].push(p);
                box_t(&boxes[p as usize], &ray).filter(|&t| t < t_max)
            });
            renamed.closest_leaves(&ray, f32::INFINITY, |leaf, mut t_max| {
                for (k, &p) in leaf.iter().enumerate() {
                    assert_eq!(p, leaf[0] + k as u32, "consecutive");
                    let old = order[p as usize];
                    seen[1].push(old);
                    if let Some(t) = box_t(&boxes[old as usize], &ray).filter(|&t| t < t_max) {
                        t_max = t;
                    }
                }
                t_max
            });
            assert_eq!(seen[0], seen[1]);
        }
    }

    #[test]
    fn coincident_primitives_make_a_leaf() {
        let boxes = vec![Aabb::new(Vec3A::ZERO, Vec3A::ONE); 10];
        let bvh = Bvh::build(&boxes, 0..10);
        assert_eq!(bvh.node_count(), 1);
        let ray = Ray::new(Vec3A::new(0.5, 0.5, -1.0), Vec3A::Z);
        let mut tested = 0;
        bvh.closest(&ray, f32::INFINITY, |_, _| {
            tested += 1;
            None
        });
        assert_eq!(tested, 10);
    }

    #[test]
    fn empty_bvh_hits_nothing() {
        let bvh = Bvh::build(&[], std::iter::empty());
        assert!(bvh.is_empty());
        let ray = Ray::new(Vec3A::ZERO, Vec3A::Z);
        assert!(!bvh.any(&ray, 1.0, |_| true));
        assert_eq!(bvh.closest(&ray, 1.0, |_, _| Some(0.0)), 1.0);
    }
}
