//! The binary tree the wide hierarchy is collapsed from: binned SAH build into flat nodes in
//! depth-first order (the first child follows its parent, the second is linked). Large inputs
//! build their two halves in parallel; the tree is the same whatever the thread count.

use crate::math::Aabb;
use glam::Vec3A;

const BINS: usize = 16;
const MAX_LEAF: usize = 4;
/// Cost of one node visit relative to one primitive test, for the SAH.
const TRAVERSAL_COST: f32 = 0.5;
/// Nodes of at least this many primitives choose their split from a sample of about
/// `SAMPLED_ITEMS` of them, one from each run of their order (`sample`): binning is most of a
/// large build, and a thousand centroids place a split among 16 bins about as well as all
/// of them; below a few thousand, the sample would place splits worse than the full bins
/// (docs/benchmarks-history.md §10.1).
const SAMPLED_MIN: usize = 4096;
const SAMPLED_ITEMS: usize = 1024;
/// Deepest level of the binary tree (the root is level 0); deeper nodes become leaves. The
/// wide tree's traversal stacks are sized from it.
pub(super) const MAX_DEPTH: usize = 63;
/// Below this many primitives a subtree is built on the calling thread: spawning costs more
/// than it saves, and small scenes should not touch the pool at all.
pub(super) const PARALLEL_MIN: usize = 100_000;

#[derive(Clone, Debug, PartialEq)]
pub(super) struct Node {
    pub bounds: Aabb,
    /// Leaf: index of the first primitive in `order`. Interior: index of the second child
    /// (the first child follows the node directly).
    pub offset: u32,
    /// Number of primitives; 0 marks an interior node.
    pub count: u16,
    pub axis: u8,
}

impl Node {
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct BinaryBvh {
    pub nodes: Vec<Node>,
    /// Primitive indices in leaf order.
    pub order: Vec<u32>,
}

struct BuildItem {
    bounds: Aabb,
    centroid: Vec3A,
    index: u32,
}

/// A node's items as the builder knows them: the union of their boxes and of their
/// centroids. A split hands each side its own, gathered while binning and partitioning, so
/// no level reads its items only to measure them.
#[derive(Clone, Copy)]
struct Extent {
    bounds: Aabb,
    centroids: Aabb,
}

impl Extent {
    fn of(items: &[BuildItem]) -> Extent {
        items.iter().fold(
            Extent {
                bounds: Aabb::EMPTY,
                centroids: Aabb::EMPTY,
            },
            |e, it| Extent {
                bounds: e.bounds.union(it.bounds),
                centroids: e.centroids.union_point(it.centroid),
            },
        )
    }
}

/// A node's split: along `axis`, items `..mid` to the first child, with each side's extent.
struct Split {
    axis: usize,
    mid: usize,
    left: Extent,
    right: Extent,
}

impl BinaryBvh {
    /// Builds over `bounds[i]` for the primitive indices in `items`; subtrees of at least
    /// `parallel_min` primitives build their halves with `rayon::join`.
    pub fn build(
        bounds: &[Aabb],
        items: impl IntoIterator<Item = u32>,
        parallel_min: usize,
    ) -> BinaryBvh {
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
        if work.is_empty() {
            return BinaryBvh::default();
        }
        let extent = Extent::of(&work);
        build_subtree(&mut work, extent, 0, parallel_min.max(2))
    }

    fn with_capacity(items: usize) -> BinaryBvh {
        BinaryBvh {
            nodes: Vec::with_capacity(items.max(1) * 2),
            order: Vec::with_capacity(items),
        }
    }

    fn build_node(&mut self, items: &mut [BuildItem], extent: Extent, depth: usize) -> usize {
        let node_index = self.nodes.len();
        self.nodes.push(Node {
            bounds: extent.bounds,
            offset: 0,
            count: 0,
            axis: 0,
        });
        match split_of(items, &extent, depth) {
            None => self.make_leaf(node_index, items),
            Some(split) => {
                self.nodes[node_index].axis = split.axis as u8;
                let (left, right) = items.split_at_mut(split.mid);
                self.build_node(left, split.left, depth + 1);
                let second = self.build_node(right, split.right, depth + 1);
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

    /// Appends `sub` (built on its own, offsets relative to itself) after the current nodes.
    fn append(&mut self, sub: BinaryBvh) {
        let node_base = self.nodes.len() as u32;
        let order_base = self.order.len() as u32;
        self.nodes.extend(sub.nodes.into_iter().map(|mut n| {
            n.offset += if n.is_leaf() { order_base } else { node_base };
            n
        }));
        self.order.extend(sub.order);
    }
}

/// The split of a node at `depth`, or `None` for a leaf. Partitions `items` in place.
fn split_of(items: &mut [BuildItem], extent: &Extent, depth: usize) -> Option<Split> {
    if items.len() <= MAX_LEAF || depth >= MAX_DEPTH {
        None
    } else {
        let stride = if items.len() >= SAMPLED_MIN {
            items.len() / SAMPLED_ITEMS
        } else {
            1
        };
        find_split(items, extent, stride)
            .or_else(|| (stride > 1).then(|| find_split(items, extent, 1)).flatten())
    }
}

/// The tree over `items`, exactly as `build_node` makes it; above `parallel_min` primitives
/// the two halves are built concurrently and joined in a fixed order (left, then right), so
/// the layout does not depend on which thread finished first.
fn build_subtree(
    items: &mut [BuildItem],
    extent: Extent,
    depth: usize,
    parallel_min: usize,
) -> BinaryBvh {
    if items.len() < parallel_min {
        let mut bvh = BinaryBvh::with_capacity(items.len());
        bvh.build_node(items, extent, depth);
        return bvh;
    }
    let Some(split) = split_of(items, &extent, depth) else {
        let mut bvh = BinaryBvh::with_capacity(items.len());
        bvh.build_node(items, extent, depth);
        return bvh;
    };
    let (left, right) = items.split_at_mut(split.mid);
    let (left, right) = rayon::join(
        || build_subtree(left, split.left, depth + 1, parallel_min),
        || build_subtree(right, split.right, depth + 1, parallel_min),
    );
    let mut bvh = BinaryBvh {
        nodes: Vec::with_capacity(1 + left.nodes.len() + right.nodes.len()),
        order: Vec::with_capacity(left.order.len() + right.order.len()),
    };
    bvh.nodes.push(Node {
        bounds: extent.bounds,
        offset: (1 + left.nodes.len()) as u32,
        count: 0,
        axis: split.axis as u8,
    });
    bvh.append(left);
    bvh.append(right);
    bvh
}

/// The items a node of `len` bins when it bins one in `stride`: one from each run of
/// `stride`, at a place in the run that changes from run to run (so that items laid out with
/// a period, a mesh's rows, are not all sampled at the same place in it).
fn sample(len: usize, stride: usize) -> impl Iterator<Item = usize> {
    let runs = len / stride;
    (0..runs).map(move |k| {
        let jitter = (k as u32).wrapping_mul(0x9e37_79b1) >> 16;
        k * stride + jitter as usize % stride
    })
}

/// The bin of a centroid `x` bin widths from the lowest: `(x as usize).min(BINS - 1)` for
/// every float (NaN and negatives to bin 0, large ones to the last), without that
/// float-to-u64 conversion and its saturating range checks, which the build's innermost
/// loop pays for every item.
#[inline(always)]
fn bin(x: f32) -> usize {
    (x as i32).clamp(0, BINS as i32 - 1) as usize
}

/// Binned surface-area heuristic: the best (axis, split position) over `BINS` centroid bins,
/// or `None` when a leaf is cheaper (or unavoidable). Partitions `items` in place.
///
/// One pass bins the items along all three axes at once (lane `a` of a bin index is the bin
/// along axis `a`, the same float operations as binning each axis alone), and the partition
/// pass gathers each side's centroid bounds; each side's bounds are the union of its bins'.
/// With `stride` above 1 only one item of each run of `stride` is binned (`sample`; the
/// counts are scaled back up for the cost), and the partition pass gathers each side's
/// bounds too.
fn find_split(items: &mut [BuildItem], extent: &Extent, stride: usize) -> Option<Split> {
    let centroid_bounds = &extent.centroids;
    let size = centroid_bounds.extent();
    let leaf_cost = items.len() as f32;
    let parent_area = extent.bounds.surface_area().max(f32::MIN_POSITIVE);
    // Skips flat axes, and NaN or infinite extents alike.
    let live = [0, 1, 2].map(|a| size[a].is_finite() && size[a] > 0.0);
    let binning = Binning {
        min: centroid_bounds.min,
        scale: Vec3A::from_array(
            [0, 1, 2].map(|a| if live[a] { BINS as f32 / size[a] } else { 0.0 }),
        ),
    };
    let mut bins = Bins::EMPTY;
    if live.contains(&true) {
        bins.add(items, stride, &binning);
    }
    let mut best: Option<(f32, usize, usize)> = None;
    for axis in (0..3).filter(|&a| live[a]) {
        bins.offer_splits(axis, stride, parent_area, &mut best);
    }
    let (cost, axis, split) = match best {
        Some(b) => b,
        // All centroids coincide: split in halves if the leaf would be too big to store.
        None if items.len() > u16::MAX as usize => {
            let mid = items.len() / 2;
            let (left, right) = items.split_at(mid);
            return Some(Split {
                axis: 0,
                mid,
                left: Extent::of(left),
                right: Extent::of(right),
            });
        }
        None => return None,
    };
    if cost >= leaf_cost && items.len() <= u16::MAX as usize {
        return None;
    }
    Some(partition(items, &bins, &binning, axis, split, stride))
}

/// Where a node's centroids fall among its bins: `BINS` equal slices of the centroid bounds
/// along each axis, and all in bin 0 along an axis whose scale is 0 (a flat one).
struct Binning {
    min: Vec3A,
    scale: Vec3A,
}

impl Binning {
    /// The bins of centroid `c` along the three axes.
    #[inline(always)]
    fn bins(&self, c: Vec3A) -> [usize; 3] {
        let b = (c - self.min) * self.scale;
        [bin(b.x), bin(b.y), bin(b.z)]
    }

    /// The bin of centroid `c` along `axis`: lane `axis` of `bins`.
    #[inline(always)]
    fn bin(&self, c: Vec3A, axis: usize) -> usize {
        bin(((c - self.min) * self.scale)[axis])
    }
}

/// A node's bins along each axis: the union of the boxes of the items binned in each, and
/// how many they are.
struct Bins {
    bounds: [[Aabb; BINS]; 3],
    counts: [[usize; BINS]; 3],
}

impl Bins {
    const EMPTY: Bins = Bins {
        bounds: [[Aabb::EMPTY; BINS]; 3],
        counts: [[0; BINS]; 3],
    };

    /// Bins `items`, or with `stride` above 1 only one item of each run of `stride`
    /// (`sample`).
    #[inline(always)]
    fn add(&mut self, items: &[BuildItem], stride: usize, binning: &Binning) {
        let Bins { bounds, counts } = self;
        let mut add = |it: &BuildItem| {
            let b = binning.bins(it.centroid);
            for axis in 0..3 {
                let bin = &mut bounds[axis][b[axis]];
                *bin = bin.union(it.bounds);
                counts[axis][b[axis]] += 1;
            }
        };
        if stride == 1 {
            items.iter().for_each(&mut add);
        } else {
            sample(items.len(), stride).for_each(|i| add(&items[i]));
        }
    }

    /// Offers the SAH cost of each split along `axis` (with the counts scaled back up by
    /// `stride`) to `best`, which keeps the first of the cheapest as (cost, axis, split).
    #[inline(always)]
    fn offer_splits(
        &self,
        axis: usize,
        stride: usize,
        parent_area: f32,
        best: &mut Option<(f32, usize, usize)>,
    ) {
        let (bin_bounds, bin_counts) = (&self.bounds[axis], &self.counts[axis]);
        // Sweep from the right to get the area and count of everything right of each split.
        let mut right_area = [0.0f32; BINS];
        let mut right_count = [0usize; BINS];
        // An empty bin (its box is `Aabb::EMPTY`, which a union leaves unchanged) adds
        // nothing: the sums right of it are those right of the next bin, and the split
        // after it costs exactly what the split before it did, which it could not beat.
        // Small nodes leave most bins empty.
        let (mut acc_b, mut acc_n) = (Aabb::EMPTY, 0);
        for b in (1..BINS).rev() {
            if bin_counts[b] == 0 && b + 1 < BINS {
                right_area[b] = right_area[b + 1];
                right_count[b] = acc_n;
                continue;
            }
            acc_b = acc_b.union(bin_bounds[b]);
            acc_n += bin_counts[b];
            right_area[b] = acc_b.surface_area();
            right_count[b] = acc_n;
        }
        let (mut left_b, mut left_n) = (Aabb::EMPTY, 0);
        for split in 1..BINS {
            if bin_counts[split - 1] == 0 {
                continue;
            }
            left_b = left_b.union(bin_bounds[split - 1]);
            left_n += bin_counts[split - 1];
            if left_n == 0 || right_count[split] == 0 {
                continue;
            }
            let cost = TRAVERSAL_COST
                + (left_b.surface_area() * left_n as f32
                    + right_area[split] * right_count[split] as f32)
                    * stride as f32
                    / parent_area;
            if best.is_none_or(|(c, _, _)| cost < c) {
                *best = Some((cost, axis, split));
            }
        }
    }
}

/// Moves the items whose centroids fall below bin `split` along `axis` to the front: the
/// split, with each side's centroid bounds gathered on the way, and its bounds the union of
/// its bins'.
#[inline(always)]
fn partition(
    items: &mut [BuildItem],
    bins: &Bins,
    binning: &Binning,
    axis: usize,
    split: usize,
    stride: usize,
) -> Split {
    let side = |bins: &[Aabb]| bins.iter().fold(Aabb::EMPTY, |b, &o| b.union(o));
    let mut left = Extent {
        bounds: side(&bins.bounds[axis][..split]),
        centroids: Aabb::EMPTY,
    };
    let mut right = Extent {
        bounds: side(&bins.bounds[axis][split..]),
        centroids: Aabb::EMPTY,
    };
    // Chosen from a sample, a side's bins hold only the sampled items: its box grows to the
    // rest as they are sorted.
    let mut mid = 0;
    for i in 0..items.len() {
        let c = items[i].centroid;
        let b = items[i].bounds;
        if binning.bin(c, axis) < split {
            left.centroids = left.centroids.union_point(c);
            if stride > 1 {
                left.bounds = left.bounds.union(b);
            }
            items.swap(i, mid);
            mid += 1;
        } else {
            right.centroids = right.centroids.union_point(c);
            if stride > 1 {
                right.bounds = right.bounds.union(b);
            }
        }
    }
    Split {
        axis,
        mid,
        left,
        right,
    }
}

#[cfg(test)]
impl BinaryBvh {
    /// The binary tree's own traversals, kept as the reference the wide tree must reproduce:
    /// the sequence of primitives they offer fixes which of two equally close hits wins and
    /// the order in which transparent shadow crossings multiply.
    pub fn closest(
        &self,
        ray: &crate::math::Ray,
        mut t_max: f32,
        mut hit: impl FnMut(u32, f32) -> Option<f32>,
    ) -> f32 {
        if self.nodes.is_empty() {
            return t_max;
        }
        let inv_dir = ray.dir.recip();
        let negative = [ray.dir.x < 0.0, ray.dir.y < 0.0, ray.dir.z < 0.0];
        let mut stack = Vec::new();
        let mut current = 0usize;
        loop {
            let node = &self.nodes[current];
            if node.bounds.hit_range(ray, inv_dir, 0.0, t_max).is_some() {
                if node.is_leaf() {
                    let start = node.offset as usize;
                    for &prim in &self.order[start..start + node.count as usize] {
                        if let Some(t) = hit(prim, t_max) {
                            t_max = t;
                        }
                    }
                } else {
                    let (near, far) = if negative[node.axis as usize] {
                        (node.offset as usize, current + 1)
                    } else {
                        (current + 1, node.offset as usize)
                    };
                    stack.push(far);
                    current = near;
                    continue;
                }
            }
            match stack.pop() {
                Some(next) => current = next,
                None => return t_max,
            }
        }
    }

    pub fn any(
        &self,
        ray: &crate::math::Ray,
        t_max: f32,
        mut occludes: impl FnMut(u32) -> bool,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let inv_dir = ray.dir.recip();
        let mut stack = vec![0usize];
        while let Some(current) = stack.pop() {
            let node = &self.nodes[current];
            if node.bounds.hit_range(ray, inv_dir, 0.0, t_max).is_none() {
                continue;
            }
            if node.is_leaf() {
                let start = node.offset as usize;
                if self.order[start..start + node.count as usize]
                    .iter()
                    .any(|&p| occludes(p))
                {
                    return true;
                }
            } else {
                stack.push(node.offset as usize);
                stack.push(current + 1);
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `bin` is the saturating `as usize` conversion it replaced, capped at the last bin.
    #[test]
    fn bin_is_the_capped_usize_conversion() {
        let mut xs = vec![
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MAX,
            f32::MIN,
            -0.0,
            0.0,
            2f32.powi(31),
            2f32.powi(63),
            2f32.powi(64),
        ];
        xs.extend((-200..200).map(|i| i as f32 * 0.1));
        xs.extend(
            [15.0f32, 16.0]
                .iter()
                .flat_map(|&x| [x.next_down(), x, x.next_up()]),
        );
        for x in xs {
            assert_eq!(bin(x), (x as usize).min(BINS - 1), "{x}");
        }
    }

    /// A sample takes one item from each whole run of `stride`, and not always from the same
    /// place in the run: items laid out with that period are still seen at many places of
    /// it.
    #[test]
    fn a_sample_takes_one_item_a_run_at_changing_places() {
        for (len, stride) in [(4096, 4), (12_288, 12), (1_000_003, 976), (5000, 2000)] {
            let picked: Vec<usize> = sample(len, stride).collect();
            assert_eq!(picked.len(), len / stride);
            for (k, &i) in picked.iter().enumerate() {
                assert!(
                    (k * stride..(k + 1) * stride).contains(&i),
                    "{len} {stride}: {i}"
                );
            }
            let mut places: Vec<usize> = picked.iter().map(|i| i % stride).collect();
            places.sort_unstable();
            places.dedup();
            assert!(
                places.len() >= (len / stride).min(stride) / 2,
                "{len} {stride}"
            );
        }
    }

    /// Every node's box is exactly the union of its primitives' boxes (no level measures its
    /// items: a split hands each side the union of its bins, or of its items where the split
    /// was chosen from a sample), every primitive is in one leaf, and no leaf is large. The
    /// boxes are enough for the top levels to choose from samples (`SAMPLED_MIN`), and one of
    /// them lies far from the rest where no sample sees it, so that the samples alone find
    /// no split there.
    #[test]
    fn node_bounds_are_the_union_of_their_primitives() {
        let mut rng = crate::util::SplitMix64::new(0x9E37_79B9_7F4A_7C15);
        let mut next = || rng.unit_f32();
        let count = 3 * SAMPLED_MIN;
        let stride = count / SAMPLED_ITEMS;
        let far = (0..count)
            .find(|i| !sample(count, stride).any(|s| s == *i))
            .expect("an item the root does not sample");
        let boxes: Vec<Aabb> = (0..count)
            .map(|i| {
                let p = Vec3A::new(next(), next(), next()) * 50.0;
                if i == far {
                    return Aabb::new(Vec3A::splat(1e5), Vec3A::splat(1e5 + 1.0));
                }
                // Some flat, some on a plane shared by many (one axis without extent).
                let mut e = Vec3A::new(next(), next(), next()) * 2.0;
                e[i % 3] *= f32::from(u8::from(i % 5 != 0));
                let p = if i % 7 == 0 {
                    p * Vec3A::new(1.0, 0.0, 1.0)
                } else {
                    p
                };
                Aabb::new(p, p + e)
            })
            .collect();
        for parallel_min in [usize::MAX, 64] {
            let bvh = BinaryBvh::build(&boxes, 0..boxes.len() as u32, parallel_min);
            fn check(bvh: &BinaryBvh, boxes: &[Aabb], n: usize) -> Aabb {
                let node = &bvh.nodes[n];
                let union = if node.is_leaf() {
                    assert!(node.count <= 64, "node {n} is a leaf of {}", node.count);
                    let start = node.offset as usize;
                    bvh.order[start..start + node.count as usize]
                        .iter()
                        .fold(Aabb::EMPTY, |b, &i| b.union(boxes[i as usize]))
                } else {
                    check(bvh, boxes, n + 1).union(check(bvh, boxes, node.offset as usize))
                };
                assert_eq!(node.bounds, union, "node {n}");
                union
            }
            check(&bvh, &boxes, 0);
            let mut seen = bvh.order.clone();
            seen.sort_unstable();
            assert_eq!(seen, (0..boxes.len() as u32).collect::<Vec<_>>());
        }
    }
}
