//! Bounding volume hierarchy over primitives' world bounds: binned SAH build, flat nodes,
//! ordered traversal for closest hits and early exit for shadow (any-hit) queries.

use crate::math::{Aabb, Ray};
use glam::Vec3A;

const BINS: usize = 16;
const MAX_LEAF: usize = 4;
/// Cost of one node visit relative to one primitive test, for the SAH.
const TRAVERSAL_COST: f32 = 0.5;
const STACK_DEPTH: usize = 64;

#[derive(Clone, Debug)]
struct Node {
    bounds: Aabb,
    /// Leaf: index of the first primitive in `order`. Interior: index of the second child
    /// (the first child follows the node directly).
    offset: u32,
    /// Number of primitives; 0 marks an interior node.
    count: u16,
    axis: u8,
}

#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Primitive indices in leaf order.
    order: Vec<u32>,
}

struct BuildItem {
    bounds: Aabb,
    centroid: Vec3A,
    index: u32,
}

impl Bvh {
    /// Builds over `bounds[i]` for the primitive indices in `items` (unbounded primitives must
    /// be kept elsewhere by the caller).
    pub fn build(bounds: &[Aabb], items: impl IntoIterator<Item = u32>) -> Bvh {
        let mut work: Vec<BuildItem> = items
            .into_iter()
            .map(|i| {
                let b = bounds[i as usize];
                BuildItem {
                    bounds: b,
                    centroid: b.centroid(),
                    index: i,
                }
            })
            .collect();
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(work.len().max(1) * 2),
            order: Vec::with_capacity(work.len()),
        };
        if !work.is_empty() {
            bvh.build_node(&mut work, 0);
        }
        bvh
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    fn build_node(&mut self, items: &mut [BuildItem], depth: usize) -> usize {
        let node_index = self.nodes.len();
        let bounds = items.iter().fold(Aabb::EMPTY, |b, it| b.union(it.bounds));
        self.nodes.push(Node {
            bounds,
            offset: 0,
            count: 0,
            axis: 0,
        });
        let split = if items.len() <= MAX_LEAF || depth + 1 >= STACK_DEPTH {
            None
        } else {
            find_split(items, &bounds)
        };
        match split {
            None => self.make_leaf(node_index, items),
            Some((axis, mid)) => {
                self.nodes[node_index].axis = axis as u8;
                let (left, right) = items.split_at_mut(mid);
                self.build_node(left, depth + 1);
                let second = self.build_node(right, depth + 1);
                self.nodes[node_index].offset = second as u32;
            }
        }
        node_index
    }

    fn make_leaf(&mut self, node_index: usize, items: &[BuildItem]) {
        // Leaves are capped at u16::MAX primitives; a pathological pile of identical boxes
        // beyond that is split in halves instead.
        let node = &mut self.nodes[node_index];
        node.offset = self.order.len() as u32;
        node.count = items.len() as u16;
        self.order.extend(items.iter().map(|it| it.index));
    }

    /// Closest hit: calls `hit(prim, t_max)` for candidate primitives in roughly front-to-back
    /// order; it returns the new `t_max` when the primitive is hit closer.
    #[inline]
    pub fn closest(
        &self,
        ray: &Ray,
        mut t_max: f32,
        mut hit: impl FnMut(u32, f32) -> Option<f32>,
    ) -> f32 {
        if self.nodes.is_empty() {
            return t_max;
        }
        let inv_dir = ray.dir.recip();
        let negative = [ray.dir.x < 0.0, ray.dir.y < 0.0, ray.dir.z < 0.0];
        let mut stack = [0u32; STACK_DEPTH];
        let mut top = 0usize;
        let mut current = 0usize;
        loop {
            let node = &self.nodes[current];
            if node.bounds.hit_range(ray, inv_dir, 0.0, t_max).is_some() {
                if node.count > 0 {
                    let start = node.offset as usize;
                    for &prim in &self.order[start..start + node.count as usize] {
                        if let Some(t) = hit(prim, t_max) {
                            t_max = t;
                        }
                    }
                } else {
                    // Visit the child on the ray's side of the split first.
                    let (near, far) = if negative[node.axis as usize] {
                        (node.offset as usize, current + 1)
                    } else {
                        (current + 1, node.offset as usize)
                    };
                    stack[top] = far as u32;
                    top += 1;
                    current = near;
                    continue;
                }
            }
            if top == 0 {
                return t_max;
            }
            top -= 1;
            current = stack[top] as usize;
        }
    }

    /// Any hit before `t_max`: stops as soon as `occludes(prim)` says yes.
    #[inline]
    pub fn any(&self, ray: &Ray, t_max: f32, mut occludes: impl FnMut(u32) -> bool) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let inv_dir = ray.dir.recip();
        let mut stack = [0u32; STACK_DEPTH];
        let mut top = 0usize;
        let mut current = 0usize;
        loop {
            let node = &self.nodes[current];
            if node.bounds.hit_range(ray, inv_dir, 0.0, t_max).is_some() {
                if node.count > 0 {
                    let start = node.offset as usize;
                    if self.order[start..start + node.count as usize]
                        .iter()
                        .any(|&p| occludes(p))
                    {
                        return true;
                    }
                } else {
                    stack[top] = node.offset;
                    top += 1;
                    current += 1;
                    continue;
                }
            }
            if top == 0 {
                return false;
            }
            top -= 1;
            current = stack[top] as usize;
        }
    }
}

/// Binned surface-area heuristic: the best (axis, split position) over `BINS` centroid bins,
/// or `None` when a leaf is cheaper (or unavoidable). Partitions `items` in place.
fn find_split(items: &mut [BuildItem], bounds: &Aabb) -> Option<(usize, usize)> {
    let centroid_bounds = items
        .iter()
        .fold(Aabb::EMPTY, |b, it| b.union_point(it.centroid));
    let extent = centroid_bounds.extent();
    let leaf_cost = items.len() as f32;
    let parent_area = bounds.surface_area().max(f32::MIN_POSITIVE);
    let mut best: Option<(f32, usize, usize)> = None;
    for axis in 0..3 {
        // Skips flat axes, and NaN or infinite extents alike.
        if !(extent[axis].is_finite() && extent[axis] > 0.0) {
            continue;
        }
        let scale = BINS as f32 / extent[axis];
        let bin_of =
            |c: Vec3A| (((c[axis] - centroid_bounds.min[axis]) * scale) as usize).min(BINS - 1);
        let mut bin_bounds = [Aabb::EMPTY; BINS];
        let mut bin_counts = [0usize; BINS];
        for it in items.iter() {
            let b = bin_of(it.centroid);
            bin_bounds[b] = bin_bounds[b].union(it.bounds);
            bin_counts[b] += 1;
        }
        // Sweep from the right to get the area and count of everything right of each split.
        let mut right_area = [0.0f32; BINS];
        let mut right_count = [0usize; BINS];
        let (mut acc_b, mut acc_n) = (Aabb::EMPTY, 0);
        for b in (1..BINS).rev() {
            acc_b = acc_b.union(bin_bounds[b]);
            acc_n += bin_counts[b];
            right_area[b] = acc_b.surface_area();
            right_count[b] = acc_n;
        }
        let (mut left_b, mut left_n) = (Aabb::EMPTY, 0);
        for split in 1..BINS {
            left_b = left_b.union(bin_bounds[split - 1]);
            left_n += bin_counts[split - 1];
            if left_n == 0 || right_count[split] == 0 {
                continue;
            }
            let cost = TRAVERSAL_COST
                + (left_b.surface_area() * left_n as f32
                    + right_area[split] * right_count[split] as f32)
                    / parent_area;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, split));
            }
        }
    }
    let (cost, axis, split) = match best {
        Some(b) => b,
        // All centroids coincide: split in halves if the leaf would be too big to store.
        None if items.len() > u16::MAX as usize => {
            let mid = items.len() / 2;
            return Some((0, mid));
        }
        None => return None,
    };
    if cost >= leaf_cost && items.len() <= u16::MAX as usize {
        return None;
    }
    let scale = BINS as f32 / extent[axis];
    let min = centroid_bounds.min[axis];
    let mut left = 0;
    for i in 0..items.len() {
        let b = (((items[i].centroid[axis] - min) * scale) as usize).min(BINS - 1);
        if b < split {
            items.swap(i, left);
            left += 1;
        }
    }
    Some((axis, left))
}

#[cfg(test)]
mod tests {
    use super::*;

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

    fn box_t(b: &Aabb, ray: &Ray) -> Option<f32> {
        b.hit_range(ray, ray.dir.recip(), 0.0, f32::INFINITY)
            .map(|(t, _)| t)
    }

    #[test]
    fn closest_hit_equals_brute_force() {
        let boxes = grid(6);
        let bvh = Bvh::build(&boxes, 0..boxes.len() as u32);
        let mut seed = 0x9E3779B97F4A7C15u64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 40) as f32 / (1u64 << 24) as f32
        };
        for _ in 0..2000 {
            let o = Vec3A::new(rnd() * 30.0 - 10.0, rnd() * 30.0 - 10.0, -5.0);
            let target = Vec3A::new(rnd() * 12.0, rnd() * 12.0, rnd() * 12.0);
            let ray = Ray::new(o, (target - o).normalize());
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
        let ray = Ray::new(Vec3A::ZERO, Vec3A::Z);
        assert!(!bvh.any(&ray, 1.0, |_| true));
    }
}
