//! Packets of coherent rays through the wide hierarchy: one walk of the tree for several rays
//! (a camera ray per pixel of a small block), one node fetch and one stack entry for all of
//! them, each child box tested against four rays at once.
//!
//! Every ray makes exactly the decisions its single-ray walk makes, so its answers are the
//! same to the bit: the rays share an octant, so the walk visits children in the order each
//! of them would; a ray takes part in a subtree only where its own slab test (the same f32
//! operations as [`Node::hit`], with the ray's own `t_max` at that moment) lets it in, and
//! drops out where its own hits since have moved `t_max` before the box, as the single walk
//! does when it pops the entry. Leaves are handed over ray by ray, so what a leaf test finds
//! is the single walk's, too.
//!
//! Packets, one home per layer: `crate::accel::wide::packet` (the shared walk of the
//! hierarchy), `crate::render::geometry::packet` (closest hits of a packet) and
//! `crate::render::sampler::packet` (camera rays of a block of pixels, traced together).

use super::{Bvh, Node, LEAF, STACK_SIZE, WIDTH};
use crate::math::{Ray, SLAB_WIDEN};
use arrayvec::ArrayVec;
use glam::{Mat4, Vec4};

/// Rays tested at once against one box.
const LANES: usize = 4;

/// `N` rays in SoA form (`N` a multiple of four, at most 32), all with the same octant.
pub struct Packet<const N: usize> {
    origin: [[f32; N]; 3],
    inv_dir: [[f32; N]; 3],
    octant: usize,
    nan_free: bool,
    /// For rays from one origin that cannot make NaN (camera rays): bounds of all of them,
    /// which reject a child box for the whole packet with one test.
    bounds: Option<Bounds>,
}

/// The shared origin and, per axis, the least and greatest `1/d` of the packet's rays.
///
/// Why one test can speak for every ray: from a common origin, a slab distance is
/// `(b − o) · (1/d)` with the same `b − o` for all rays, and a rounded product is monotonic in
/// each factor, so the products with the least and the greatest `1/d` bound every ray's, as
/// computed. Min, max and the widening product are monotonic too, so a box whose least
/// possible entry lies beyond its greatest possible exit (or the greatest `t_max`) is missed
/// by every ray in [`Node::hit_packet`]'s own arithmetic.
struct Bounds {
    origin: [Vec4; 3],
    inv_lo: [Vec4; 3],
    inv_hi: [Vec4; 3],
}

impl<const N: usize> Packet<N> {
    const GROUPS: usize = {
        assert!(N.is_multiple_of(LANES) && N <= 32 && N > 0);
        N / LANES
    };

    /// `None` when the rays' directions do not share an octant: children would then be
    /// visited in different orders, and the single-ray walk is the one to take.
    ///
    /// Built four rays at a time, transposed into lanes (`1/d` is `Vec3A::recip`'s division
    /// lane by lane, so the same floats), rather than gathered ray by ray and axis by axis.
    pub fn new(rays: &[Ray; N]) -> Option<Packet<N>> {
        let mut origin = [[0.0f32; N]; 3];
        let mut inv_dir = [[0.0f32; N]; 3];
        // Per axis, the rays whose direction is negative there; per ray, NaN-free.
        let mut negative = [0u32; 3];
        let mut nan_free = true;
        // The rays whose origin is, bit for bit, the first ray's (finite origins assumed:
        // only asked when all are NaN-free).
        let mut same = 0u32;
        let o0 = rays[0].origin;
        let o0_lanes = crate::math::splat3(o0);
        let o0_sign = [o0.x, o0.y, o0.z].map(|c| if c.is_sign_negative() { 0xF } else { 0 });
        for g in 0..Self::GROUPS {
            let four = &rays[g * LANES..g * LANES + LANES];
            let (o, d) = (lanes3(four, |r| r.origin), lanes3(four, |r| r.dir));
            let mut same_here = 0xF;
            for axis in 0..3 {
                let inv = Vec4::ONE / d[axis];
                negative[axis] |= d[axis].cmplt(Vec4::ZERO).bitmask() << (g * LANES);
                let ok = o[axis].is_finite_mask() & inv.is_finite_mask() & inv.cmpne(Vec4::ZERO);
                nan_free &= ok.all();
                same_here &= o[axis].cmpeq(o0_lanes[axis]).bitmask()
                    & !(o[axis].is_negative_bitmask() ^ o0_sign[axis]);
                o[axis].write_to_slice(&mut origin[axis][g * LANES..g * LANES + LANES]);
                inv.write_to_slice(&mut inv_dir[axis][g * LANES..g * LANES + LANES]);
            }
            same |= same_here << (g * LANES);
        }
        let all = Self::all();
        if negative.iter().any(|&m| m != 0 && m != all) {
            return None;
        }
        let octant = (0..3).fold(0, |o, a| o | ((negative[a] & 1) as usize) << a);
        // Finite and non-zero (NaN-free rays), the `1/d` have one least and one greatest
        // value whatever the order they are compared in.
        let bounds = (nan_free && same == all).then(|| {
            let lanes = |a: usize, f: fn(Vec4, Vec4) -> Vec4| {
                (1..Self::GROUPS).fold(group(&inv_dir[a], 0), |m, g| f(m, group(&inv_dir[a], g)))
            };
            Bounds {
                origin: o0_lanes,
                inv_lo: [0, 1, 2].map(|a| Vec4::splat(lanes(a, Vec4::min).min_element())),
                inv_hi: [0, 1, 2].map(|a| Vec4::splat(lanes(a, Vec4::max).max_element())),
            }
        });
        Some(Packet {
            bounds,
            origin,
            inv_dir,
            octant,
            nan_free,
        })
    }

    /// All rays' bits.
    fn all() -> u32 {
        u32::MAX >> (32 - N)
    }
}

/// A vector of each of four rays (`of`), transposed: per axis, the four rays' components.
#[inline(always)]
fn lanes3(four: &[Ray], of: impl Fn(&Ray) -> glam::Vec3A) -> [Vec4; 3] {
    let m = Mat4::from_cols(
        of(&four[0]).extend(0.0),
        of(&four[1]).extend(0.0),
        of(&four[2]).extend(0.0),
        of(&four[3]).extend(0.0),
    )
    .transpose();
    [m.x_axis, m.y_axis, m.z_axis]
}

#[inline(always)]
fn group<const N: usize>(v: &[f32; N], g: usize) -> Vec4 {
    Vec4::from_slice(&v[g * LANES..g * LANES + LANES])
}

impl Node {
    /// For child `slot`: bit `r` set when ray `r` meets its box within `[0, t_max[r]]`, and
    /// each ray's entry distance. Ray by ray the same arithmetic as [`Node::hit`] does for
    /// that child's lane, so the same floats and the same answer.
    #[inline(always)]
    fn hit_packet<const N: usize, const NAN_FREE: bool>(
        &self,
        slot: usize,
        p: &Packet<N>,
        t_max: &[f32; N],
        enter_out: &mut [f32; N],
    ) -> u32 {
        let min = self.min.map(|m| Vec4::splat(m[slot]));
        let max = self.max.map(|m| Vec4::splat(m[slot]));
        let mut mask = 0;
        for g in 0..Packet::<N>::GROUPS {
            let mut enter = Vec4::ZERO;
            let mut exit = Vec4::INFINITY;
            for axis in 0..3 {
                let origin = group(&p.origin[axis], g);
                let inv_dir = group(&p.inv_dir[axis], g);
                let t0 = (min[axis] - origin) * inv_dir;
                let t1 = (max[axis] - origin) * inv_dir;
                if NAN_FREE {
                    enter = enter.max(t0.min(t1));
                    exit = exit.min(t0.max(t1));
                } else {
                    let on_plane = t0.is_nan_mask() | t1.is_nan_mask();
                    enter = enter.max(Vec4::select(on_plane, Vec4::NEG_INFINITY, t0.min(t1)));
                    exit = exit.min(Vec4::select(on_plane, Vec4::INFINITY, t0.max(t1)));
                }
            }
            let exit = (exit * SLAB_WIDEN).min(group(t_max, g));
            mask |= enter.cmple(exit).bitmask() << (g * LANES);
            enter.write_to_slice(&mut enter_out[g * LANES..g * LANES + LANES]);
        }
        mask
    }
}

impl Node {
    /// Bit `i` clear when no ray of the packet can meet child `i`'s box within its `t_max`
    /// (at most `t_max_hi`); see [`Bounds`].
    #[inline(always)]
    fn maybe_hit(&self, b: &Bounds, t_max_hi: f32) -> u32 {
        let mut enter = Vec4::ZERO;
        let mut exit = Vec4::INFINITY;
        for axis in 0..3 {
            let d0 = self.min[axis] - b.origin[axis];
            let d1 = self.max[axis] - b.origin[axis];
            let (a0, b0) = (d0 * b.inv_lo[axis], d0 * b.inv_hi[axis]);
            let (a1, b1) = (d1 * b.inv_lo[axis], d1 * b.inv_hi[axis]);
            enter = enter.max(a0.min(b0).min(a1.min(b1)));
            exit = exit.min(a0.max(b0).max(a1.max(b1)));
        }
        let exit = (exit * SLAB_WIDEN).min(Vec4::splat(t_max_hi));
        enter.cmple(exit).bitmask()
    }
}

/// Rays of `mask` whose entry distance lies beyond their `t_max`: the single walk drops the
/// entry for them when it pops it.
#[inline(always)]
fn beyond<const N: usize>(enter: &[f32; N], t_max: &[f32; N]) -> u32 {
    let mut out = 0;
    for g in 0..Packet::<N>::GROUPS {
        out |= group(enter, g).cmpgt(group(t_max, g)).bitmask() << (g * LANES);
    }
    out
}

/// The bits of `mask`, lowest first.
#[inline(always)]
fn bits(mut mask: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let r = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            r
        })
    })
}

impl Bvh {
    /// [`Bvh::closest_leaves`] for each ray of the packet: `t_max[r]` is ray `r`'s limit and
    /// becomes its result; `leaf(r, prims, t_max)` tests a leaf for ray `r`. Each ray is
    /// offered the leaves its single-ray walk would offer, in the same order, with the same
    /// `t_max`.
    #[inline]
    pub fn closest_leaves_packet<const N: usize>(
        &self,
        p: &Packet<N>,
        t_max: &mut [f32; N],
        mut leaf: impl FnMut(usize, &[u32], f32) -> f32,
    ) {
        self.closest_leaf_visits_packet(p, t_max, |rays, prims, t_max| {
            for r in bits(rays) {
                t_max[r] = leaf(r, prims, t_max[r]);
            }
        });
    }

    /// [`Bvh::closest_leaves_packet`] a leaf visit at a time: `leaf(rays, prims, t_max)`
    /// tests the leaf for each ray whose bit is set in `rays`, lowest first, updating its
    /// `t_max` (what is shared between them, such as the leaf's primitives in lanes, is then
    /// prepared once).
    #[inline]
    pub fn closest_leaf_visits_packet<const N: usize>(
        &self,
        p: &Packet<N>,
        t_max: &mut [f32; N],
        leaf: impl FnMut(u32, &[u32], &mut [f32; N]),
    ) {
        if p.nan_free {
            self.closest_packet_impl::<N, true>(p, t_max, leaf);
        } else {
            self.closest_packet_impl::<N, false>(p, t_max, leaf);
        }
    }

    #[inline(always)]
    fn closest_packet_impl<const N: usize, const NAN_FREE: bool>(
        &self,
        p: &Packet<N>,
        t_max: &mut [f32; N],
        mut leaf: impl FnMut(u32, &[u32], &mut [f32; N]),
    ) {
        if self.nodes.is_empty() {
            return;
        }
        // Entries: a reference, the rays that take part, and their entry distances.
        let mut stack: ArrayVec<(u32, u32, [f32; N]), STACK_SIZE> = ArrayVec::new();
        let mut enter = [[0.0f32; N]; WIDTH];
        let (mut reference, mut mask) = (0, Packet::<N>::all());
        loop {
            if reference & LEAF != 0 {
                leaf(mask, self.leaf(reference), t_max);
            } else {
                let node = &self.nodes[reference as usize];
                let mut hit = [0u32; WIDTH];
                let maybe = match &p.bounds {
                    Some(b) if NAN_FREE => {
                        node.maybe_hit(b, t_max.iter().fold(f32::NEG_INFINITY, |a, &t| a.max(t)))
                    }
                    _ => u32::MAX,
                };
                let mut met = 0u32;
                for slot in bits(maybe & u32::from(node.live)) {
                    hit[slot] =
                        node.hit_packet::<N, NAN_FREE>(slot, p, t_max, &mut enter[slot]) & mask;
                    met |= u32::from(hit[slot] != 0) << slot;
                }
                if met.is_power_of_two() {
                    // One child met by any ray: visited next without a trip through the
                    // stack (each of its rays entered it within its `t_max`, so popping it
                    // would not drop them).
                    let slot = met.trailing_zeros() as usize;
                    (reference, mask) = (node.child[slot], hit[slot]);
                    continue;
                }
                let order = node.order[p.octant];
                // Farthest pushed first, so the nearest is visited next.
                for k in (0..node.len).rev() {
                    let slot = usize::from((order >> (2 * k)) & 3);
                    if hit[slot] != 0 {
                        stack.push((node.child[slot], hit[slot], enter[slot]));
                    }
                }
            }
            loop {
                let Some((next, rays, entered)) = stack.pop() else {
                    return;
                };
                let rays = rays & !beyond(&entered, t_max);
                if rays != 0 {
                    (reference, mask) = (next, rays);
                    break;
                }
            }
        }
    }

    /// [`Bvh::any_leaves`] for each ray of the packet, all up to `t_max[r]`: bit `r` of the
    /// result is set when `occludes(r, prims)` said yes for ray `r`, which is then offered
    /// no more leaves. Each ray is offered the leaves its single-ray walk would offer, in the
    /// same order, up to its first yes.
    #[inline]
    pub fn any_leaves_packet<const N: usize>(
        &self,
        p: &Packet<N>,
        t_max: &[f32; N],
        occludes: impl FnMut(usize, &[u32]) -> bool,
    ) -> u32 {
        if p.nan_free {
            self.any_packet_impl::<N, true>(p, t_max, occludes)
        } else {
            self.any_packet_impl::<N, false>(p, t_max, occludes)
        }
    }

    #[inline(always)]
    fn any_packet_impl<const N: usize, const NAN_FREE: bool>(
        &self,
        p: &Packet<N>,
        t_max: &[f32; N],
        mut occludes: impl FnMut(usize, &[u32]) -> bool,
    ) -> u32 {
        let mut open = Packet::<N>::all();
        if self.nodes.is_empty() {
            return 0;
        }
        let t_max_hi = t_max.iter().fold(f32::NEG_INFINITY, |a, &t| a.max(t));
        let mut stack: ArrayVec<(u32, u32), STACK_SIZE> = ArrayVec::new();
        stack.push((0, open));
        let mut enter = [0.0f32; N];
        while let Some((reference, mask)) = stack.pop() {
            let mask = mask & open;
            if mask == 0 {
                if open == 0 {
                    break;
                }
                continue;
            }
            if reference & LEAF != 0 {
                let prims = self.leaf(reference);
                for r in bits(mask) {
                    if occludes(r, prims) {
                        open &= !(1 << r);
                    }
                }
                continue;
            }
            let node = &self.nodes[reference as usize];
            let mut hit = [0u32; WIDTH];
            let maybe = match &p.bounds {
                Some(b) if NAN_FREE => node.maybe_hit(b, t_max_hi),
                _ => u32::MAX,
            };
            for slot in bits(maybe & u32::from(node.live)) {
                hit[slot] = node.hit_packet::<N, NAN_FREE>(slot, p, t_max, &mut enter) & mask;
            }
            let order = node.order[p.octant];
            for k in (0..node.len).rev() {
                let slot = usize::from((order >> (2 * k)) & 3);
                if hit[slot] != 0 {
                    stack.push((node.child[slot], hit[slot]));
                }
            }
        }
        Packet::<N>::all() & !open
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Aabb;
    use glam::Vec3A;

    use super::super::tests::{box_t, Points, SplitMix64};

    /// Packets of rays from one origin towards nearby targets (some axis-parallel, some with
    /// origins on box faces, some with limits): each ray is offered the same leaves in the
    /// same order, with the same `t_max`, as by its own walk, and any-hit answers agree.
    fn check<const N: usize>(seed: u64) {
        let mut rng = SplitMix64::new(seed);
        let boxes: Vec<Aabb> = (0..1500)
            .map(|i| {
                let p = rng.vec(40.0);
                let mut e = rng.vec(3.0);
                e[i % 3] *= f32::from(u8::from(i % 4 != 0));
                Aabb::new(p, p + e)
            })
            .collect();
        let bvh = Bvh::build(&boxes, 0..boxes.len() as u32);
        let mut packets = 0;
        for i in 0..600 {
            let mut origin = rng.vec(60.0) - Vec3A::splat(10.0);
            if i % 5 == 0 {
                let b = &boxes[i % boxes.len()];
                origin[i / 5 % 3] = b.min[i / 5 % 3];
            }
            let target = rng.vec(40.0);
            let spread = [0.01, 0.3, 3.0][i % 3];
            let rays: [Ray; N] = std::array::from_fn(|_| {
                let mut dir = (target + rng.vec(spread) - origin).normalize();
                if i % 7 == 0 {
                    let keep = i / 7 % 3;
                    let sign = dir[keep].signum();
                    dir = Vec3A::ZERO;
                    dir[keep] = sign;
                }
                Ray::new(origin, dir)
            });
            let limit = if i % 2 == 0 { f32::INFINITY } else { 30.0 };
            let Some(p) = Packet::new(&rays) else {
                continue;
            };
            packets += 1;
            let mut seen: [Vec<(u32, f32)>; N] = std::array::from_fn(|_| Vec::new());
            let mut t_max = [limit; N];
            bvh.closest_leaves_packet(&p, &mut t_max, |r, prims, mut t| {
                for &k in prims {
                    seen[r].push((k, t));
                    if let Some(h) = box_t(&boxes[k as usize], &rays[r]).filter(|&h| h < t) {
                        t = h;
                    }
                }
                t
            });
            let mut met = [const { Vec::new() }; N];
            let blocked = bvh.any_leaves_packet(&p, &[limit; N], |r, prims| {
                met[r].extend_from_slice(prims);
                prims
                    .iter()
                    .any(|&k| box_t(&boxes[k as usize], &rays[r]).is_some_and(|h| h < limit))
            });
            for (r, ray) in rays.iter().enumerate() {
                let mut single = Vec::new();
                let t = bvh.closest_leaves(ray, limit, |prims, mut t| {
                    for &k in prims {
                        single.push((k, t));
                        if let Some(h) = box_t(&boxes[k as usize], ray).filter(|&h| h < t) {
                            t = h;
                        }
                    }
                    t
                });
                assert_eq!(single, seen[r], "packet {i} ray {r}");
                assert_eq!(t.to_bits(), t_max[r].to_bits(), "packet {i} ray {r}");
                let mut single = Vec::new();
                let any = bvh.any_leaves(ray, limit, |prims| {
                    single.extend_from_slice(prims);
                    prims
                        .iter()
                        .any(|&k| box_t(&boxes[k as usize], ray).is_some_and(|h| h < limit))
                });
                assert_eq!(any, blocked & (1 << r) != 0, "packet {i} ray {r}");
                assert_eq!(single, met[r], "packet {i} ray {r}");
            }
        }
        assert!(packets > 300, "{packets} packets");
    }

    #[test]
    fn packets_offer_what_single_rays_offer() {
        check::<4>(0x9E3779B97F4A7C15);
        check::<8>(0xD1B54A32D192ED03);
        check::<16>(0x94D049BB133111EB);
    }

    #[test]
    fn mixed_octants_are_not_a_packet() {
        let rays = [Vec3A::X, Vec3A::X, Vec3A::NEG_X, Vec3A::X].map(|d| Ray::new(Vec3A::ZERO, d));
        assert!(Packet::new(&rays).is_none());
        assert!(Packet::new(&[rays[0]; 4]).is_some());
    }
}
