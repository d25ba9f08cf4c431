//! Footprints: what a pixel's rays could be changed by, for frames of a shot that re-trace
//! only what changed (`super::shot`).
//!
//! A frame of a shot knows, before it is traced, what the shot's later frames change
//! ([`Ahead`]): the boxes of space where a shape is or will be (its bounds at both frames of
//! each transition, swept over the exposure where it moves), the materials whose shading
//! changes, whether the lights or the ambient light change, whether the background does. While
//! a pixel is traced, every question its rays ask of the compiled scene (in the facade,
//! `super::compile`) is held against them by a [`Watch`] in the worker's scratch: each ray, as
//! a segment from its origin to its hit (or its light, or without end when it meets nothing),
//! against the boxes; each hit against its material and the shading; each miss against the
//! background. What a pixel keeps is one number, the first later frame whose change one of
//! its rays meets ([`NEVER`] for none): until that frame, its rays ask the same questions and
//! get the same answers, to the bit, so its value is the same. A ray tested only against
//! boxes that are known in advance needs no record of the ray itself: the memory a pixel
//! costs is that number, whatever its rays.
//!
//! The boxes are searched as a tree over the frames they change (Jevans' object-space
//! coherence, with the time axis known): a segment that meets none of them costs one box
//! test, and the first frame met is found by going down the earlier half first.

use crate::math::{Aabb, Ray};
use glam::Vec3A;

/// No later frame changes what the rays met.
pub const NEVER: u32 = u32::MAX;

/// Relative widening of a change box: the boxes come from the shapes' bounds, which hold
/// every hit the shapes' own tests find, and the slab test is widened as the hierarchy's is;
/// this covers what rounding the box's corners in another order could move.
const PAD: f32 = 1.0 / 4096.0;

/// What the later frames of a shot change, by the frame (counted in the shot) that first
/// changes it.
#[derive(Clone, Debug, Default)]
pub struct Ahead {
    /// The change boxes in order of their frames, each padded.
    boxes: Vec<(Aabb, u32)>,
    /// A complete binary tree over `boxes` (node `n`'s children `2n + 1`, `2n + 2`), each
    /// node the union of its range: leaves for the boxes, at `first_leaf` on.
    nodes: Vec<Aabb>,
    first_leaf: usize,
    /// Per material of the scene: the first frame that changes how it shades.
    materials: Vec<u32>,
    /// The first frame that changes a light or the ambient light: what every surface point
    /// reads when it is shaded.
    shading: u32,
    /// The first frame that changes the background.
    background: u32,
}

/// What one later frame changes, for [`Ahead::new`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Changed {
    /// Where a shape is before or after the change (camera-relative, as rendered).
    pub boxes: Vec<Aabb>,
    /// The materials whose shading changes (by index in the scene).
    pub materials: Vec<usize>,
    /// Whether a light or the ambient light changes.
    pub shading: bool,
    /// Whether the background changes.
    pub background: bool,
}

impl Changed {
    /// Whether nothing changes.
    pub fn is_empty(&self) -> bool {
        *self == Changed::default()
    }
}

impl Ahead {
    /// The changes `later` makes, frame `first + k` changing what `later[k]` says, for a
    /// scene of `materials` materials.
    pub fn new(first: u32, later: &[Changed], materials: usize) -> Ahead {
        let mut ahead = Ahead {
            materials: vec![NEVER; materials],
            shading: NEVER,
            background: NEVER,
            ..Ahead::default()
        };
        for (k, c) in later.iter().enumerate() {
            let frame = first.saturating_add(k as u32);
            for b in c.boxes.iter().filter(|b| !b.is_empty()) {
                ahead.boxes.push((pad(*b), frame));
            }
            for &m in &c.materials {
                if let Some(at) = ahead.materials.get_mut(m) {
                    *at = (*at).min(frame);
                }
            }
            if c.shading {
                ahead.shading = ahead.shading.min(frame);
            }
            if c.background {
                ahead.background = ahead.background.min(frame);
            }
        }
        ahead.build_tree();
        ahead
    }

    fn build_tree(&mut self) {
        let n = self.boxes.len();
        if n == 0 {
            return;
        }
        let leaves = n.next_power_of_two();
        self.first_leaf = leaves - 1;
        self.nodes = vec![Aabb::EMPTY; 2 * leaves - 1];
        for (i, (b, _)) in self.boxes.iter().enumerate() {
            self.nodes[self.first_leaf + i] = *b;
        }
        for node in (0..self.first_leaf).rev() {
            self.nodes[node] = self.nodes[2 * node + 1].union(self.nodes[2 * node + 2]);
        }
    }

    /// Whether nothing later changes anything.
    pub fn is_empty(&self) -> bool {
        self.boxes.is_empty()
            && self.shading == NEVER
            && self.background == NEVER
            && self.materials.iter().all(|&m| m == NEVER)
    }

    /// Bytes it holds.
    pub fn memory_bytes(&self) -> usize {
        self.boxes.capacity() * size_of::<(Aabb, u32)>()
            + self.nodes.capacity() * size_of::<Aabb>()
            + self.materials.capacity() * 4
    }

    /// The first frame before `before` one of whose boxes the segment of `ray` from its
    /// origin to `t_end` meets; `before` when none does.
    fn first_met(&self, ray: &Ray, t_end: f32, before: u32) -> u32 {
        if self.nodes.is_empty() || self.boxes[0].1 >= before {
            return before;
        }
        let inv = ray.dir.recip();
        let meets = |b: &Aabb| b.hit_range(ray, inv, 0.0, t_end).is_some();
        // Depth first, the earlier half first: the first leaf met is the earliest frame.
        let mut stack = [0usize; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = stack[top];
            if !meets(&self.nodes[node]) {
                continue;
            }
            if node >= self.first_leaf {
                let Some(&(_, frame)) = self.boxes.get(node - self.first_leaf) else {
                    continue;
                };
                // Leaves are met in frame order, so the first is the answer.
                return frame.min(before);
            }
            // Only leaves of frames before `before` matter: the boxes are in frame order, so
            // a right half starting at or after it is skipped.
            let right = 2 * node + 2;
            if self.leftmost(right).is_some_and(|f| f < before) {
                stack[top] = right;
                top += 1;
            }
            stack[top] = 2 * node + 1;
            top += 1;
        }
        before
    }

    /// The frame of the first box under `node`, if any.
    fn leftmost(&self, mut node: usize) -> Option<u32> {
        while node < self.first_leaf {
            node = 2 * node + 1;
        }
        self.boxes.get(node - self.first_leaf).map(|&(_, f)| f)
    }
}

/// `b` widened by [`PAD`] of its size and of its distance from the origin (the eye).
fn pad(b: Aabb) -> Aabb {
    let scale = b.extent().max(b.min.abs()).max(b.max.abs()) * PAD;
    let margin = scale.max(Vec3A::splat(f32::MIN_POSITIVE));
    Aabb {
        min: b.min - margin,
        max: b.max + margin,
    }
}

/// A worker's watch over the rays of the pixel it traces: the first later frame that changes
/// what they met so far ([`Watch::take`]).
#[derive(Clone, Debug)]
pub struct Watch {
    ahead: std::sync::Arc<Ahead>,
    until: u32,
}

impl Watch {
    /// A watch against what `ahead` says of the later frames.
    pub fn new(ahead: std::sync::Arc<Ahead>) -> Watch {
        Watch {
            ahead,
            until: NEVER,
        }
    }

    /// A ray from its origin to `t_end` (infinite: it goes on past everything).
    ///
    /// The watch's methods are out of line and cold: a render without a watch only checks
    /// that there is none, and the facade's queries stay as small as they were.
    #[cold]
    #[inline(never)]
    pub fn segment(&mut self, ray: &Ray, t_end: f32) {
        self.until = self.ahead.first_met(ray, t_end, self.until);
    }

    /// A ray that hit a surface of material `material` `t` along it: its segment, and what
    /// shading the surface reads.
    #[cold]
    #[inline(never)]
    pub fn hit(&mut self, ray: &Ray, t: f32, material: u32) {
        self.segment(ray, t);
        let ahead = &self.ahead;
        let m = ahead.materials.get(material as usize).copied();
        self.until = self.until.min(ahead.shading).min(m.unwrap_or(NEVER));
    }

    /// A ray that met nothing: it sees the background.
    #[cold]
    #[inline(never)]
    pub fn missed(&mut self, ray: &Ray) {
        self.segment(ray, f32::INFINITY);
        self.until = self.until.min(self.ahead.background);
    }

    /// The first later frame that changes what the rays met since the last call, and a fresh
    /// start for the next pixel's.
    #[inline]
    pub fn take(&mut self) -> u32 {
        std::mem::replace(&mut self.until, NEVER)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_box_at(x: f32) -> Aabb {
        Aabb::new(Vec3A::new(x, -0.5, -0.5), Vec3A::new(x + 1.0, 0.5, 0.5))
    }

    /// Boxes one unit wide along x, box k changing at frame k + 1; a ray along x from the
    /// origin ending at `t_end` meets the boxes whose x range starts before it.
    #[test]
    fn a_segment_takes_the_first_frame_of_the_boxes_it_meets() {
        let later: Vec<Changed> = (0..9)
            .map(|k| Changed {
                boxes: vec![unit_box_at(2.0 * k as f32 + 1.0)],
                ..Changed::default()
            })
            .collect();
        let ahead = Ahead::new(1, &later, 0);
        let along = Ray::new(Vec3A::ZERO, Vec3A::X);
        let mut watch = Watch::new(std::sync::Arc::new(ahead));
        // Short of the first box (x from 1 to 2).
        watch.segment(&along, 0.9);
        assert_eq!(watch.take(), NEVER);
        // Into the first.
        watch.segment(&along, 1.5);
        assert_eq!(watch.take(), 1);
        // Beside every box, past their end.
        let beside = Ray::new(Vec3A::new(0.0, 2.0, 0.0), Vec3A::X);
        watch.segment(&beside, f32::INFINITY);
        assert_eq!(watch.take(), NEVER);
        // Through the boxes from the far end backwards: the earliest frame still wins.
        let back = Ray::new(Vec3A::new(30.0, 0.0, 0.0), -Vec3A::X);
        watch.segment(&back, 14.0);
        // x from 30 down to 16 meets box 8 (x 17 to 18, frame 9) and touches box 7 (x 15 to
        // 16, frame 8) at its end.
        assert_eq!(watch.take(), 8);
        watch.segment(&back, f32::INFINITY);
        assert_eq!(watch.take(), 1);
    }

    #[test]
    fn hits_and_misses_read_the_shading_the_materials_and_the_background() {
        let later = [
            Changed::default(),
            Changed {
                materials: vec![2],
                ..Changed::default()
            },
            Changed {
                background: true,
                ..Changed::default()
            },
            Changed {
                shading: true,
                ..Changed::default()
            },
        ];
        let ahead = std::sync::Arc::new(Ahead::new(5, &later, 3));
        let mut watch = Watch::new(ahead);
        let ray = Ray::new(Vec3A::ZERO, Vec3A::Z);
        watch.hit(&ray, 1.0, 0);
        assert_eq!(watch.take(), 8);
        watch.hit(&ray, 1.0, 2);
        assert_eq!(watch.take(), 6);
        watch.missed(&ray);
        assert_eq!(watch.take(), 7);
    }

    #[test]
    fn nothing_ahead_changes_nothing() {
        let ahead = Ahead::new(1, &[Changed::default(), Changed::default()], 4);
        assert!(ahead.is_empty());
        let mut watch = Watch::new(std::sync::Arc::new(ahead));
        watch.hit(&Ray::new(Vec3A::ZERO, Vec3A::X), 3.0, 1);
        watch.missed(&Ray::new(Vec3A::ZERO, Vec3A::Y));
        assert_eq!(watch.take(), NEVER);
    }
}
