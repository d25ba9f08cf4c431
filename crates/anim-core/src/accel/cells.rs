//! Direction cells around a point: which primitives a ray passing through (or ending at)
//! that point may meet, looked up by the ray's direction. Around a light this is the light
//! buffer of classic ray tracers: a shadow ray towards the light tests the few primitives seen
//! from the light in its direction, not all of them, and walks no hierarchy.
//!
//! The directions from the centre are cut into the cells of a cube map: six faces of
//! `SIDE`×`SIDE` cells. A cell lists every primitive whose bounds meet the cone of its
//! directions widened by `MARGIN`; a ray whose line passes close enough to the centre
//! (`DirectionCells::candidates`) meets only primitives seen within that widening of its own
//! direction, so its cell answers for it. A cell that would list more than `LIST_MAX`
//! answers nothing, and the ray is left to the hierarchy.

use crate::math::Aabb;
use glam::Vec3A;

/// Cells per side of each cube face: 32 × 32 × 6 = 6 144 cells a point, about 100 KiB with
/// their lists. Finer cells see fewer primitives each, so their lists are shorter
/// (docs/benchmarks-history.md §4.6).
const SIDE: usize = 32;

/// Widening of every primitive's footprint on a face, in face coordinates (which run from −1
/// to 1 across it): half a cell. It covers a direction off by `ANGLE` radians: on a face, where
/// the major component of a unit direction is at least 1/√3, turning it by θ moves `u = d_b/d_a`
/// by at most θ·(1/d_a + 1/d_a²) < 4.9·θ while θ ≤ 0.01.
const MARGIN: f32 = 1.0 / SIDE as f32;
/// The angle `MARGIN` covers, with room for round-off: sin θ ≤ ANGLE keeps θ < 4.9·ANGLE < MARGIN.
const ANGLE: f32 = MARGIN / 6.0;
/// Primitives whose bounds come within this share of the scene's reach from the centre are
/// listed in every cell: rays pass the centre at some distance (shadow rays leave a lifted
/// origin), and only far enough from it does the direction tell where they are.
const NEAR_SHARE: f32 = 1e-3;
/// Most primitives a cell lists (two tests of four); a cell that sees more leaves its rays to
/// the hierarchy.
const LIST_MAX: usize = 8;
/// Lists are padded to a multiple of this many entries, so that they are tested four at once.
const GROUP: usize = 4;
/// `DirectionCells::cells` entry of a cell that lists nothing (it sees too much).
const TOO_MANY: u32 = u32::MAX;

/// Which primitives a ray through a point may meet, by direction (see the module doc).
#[derive(Clone, Debug)]
pub struct DirectionCells {
    centre: Vec3A,
    /// Per face (`2·axis + negative`), `SIDE` rows of `SIDE` cells: where the cell's list
    /// starts in `lists` (its length, a multiple of `GROUP`, in the low 4 bits), or `TOO_MANY`.
    cells: Box<[u32]>,
    /// The cells' lists, each padded with the caller's `pad` to a multiple of `GROUP`.
    lists: Box<[u32]>,
    /// No primitive outside those listed in every cell comes closer to the centre than
    /// `clear` (in `new`); a line passing the centre within `ANGLE·clear` is answered by cell:
    /// that distance squared.
    pass2: f32,
    /// `(clear/2)²`.
    half_clear2: f32,
}

impl DirectionCells {
    /// Cells around `centre` for the primitives with (finite) bounds `bounds`, numbered by
    /// their place there; lists are padded with `pad`, a number the caller's tests never hit.
    pub fn new(centre: Vec3A, bounds: &[Aabb], pad: u32) -> DirectionCells {
        let distance = |b: &Aabb| (centre - centre.clamp(b.min, b.max)).length();
        let reach = bounds
            .iter()
            .map(|b| (centre - b.min).abs().max((centre - b.max).abs()).length())
            .fold(0.0f32, f32::max);
        let floor = NEAR_SHARE * reach;
        let mut near = Vec::new();
        let mut clear = f32::INFINITY;
        for (i, b) in bounds.iter().enumerate() {
            let d = distance(b);
            if d <= floor {
                near.push(i as u32);
            } else {
                clear = clear.min(d);
            }
        }
        // Per cell, what it sees so far (up to one past `LIST_MAX`, which marks it as seeing
        // too much): in place, without a list per cell to allocate.
        let mut seen = vec![[0u32; LIST_MAX + 1]; 6 * SIDE * SIDE];
        let mut count = vec![0u8; seen.len()];
        let mut see = |cell: usize, i: u32| {
            let n = count[cell] as usize;
            if n <= LIST_MAX {
                seen[cell][n] = i;
                count[cell] += 1;
            }
        };
        for &i in &near {
            (0..6 * SIDE * SIDE).for_each(|cell| see(cell, i));
        }
        for (i, b) in bounds.iter().enumerate() {
            if near.contains(&(i as u32)) {
                continue;
            }
            let (lo, hi) = (b.min - centre, b.max - centre);
            for face in 0..6 {
                let (axis, u_axis, v_axis) = axes(face / 2);
                // Along the face's outward axis: the box's extent, flipped for the negative face.
                let (a0, a1) = if face % 2 == 0 {
                    (lo[axis], hi[axis])
                } else {
                    (-hi[axis], -lo[axis])
                };
                let Some(us) = footprint(a0, a1, lo[u_axis], hi[u_axis]) else {
                    continue;
                };
                let Some(vs) = footprint(a0, a1, lo[v_axis], hi[v_axis]) else {
                    continue;
                };
                for v in vs.clone() {
                    for u in us.clone() {
                        see((face * SIDE + v) * SIDE + u, i as u32);
                    }
                }
            }
        }
        let mut lists = Vec::new();
        let cells = seen
            .iter()
            .zip(&count)
            .map(|(seen, &n)| {
                let n = n as usize;
                if n > LIST_MAX {
                    return TOO_MANY;
                }
                let padded = n.div_ceil(GROUP) * GROUP;
                let at = (lists.len() as u32) << 4 | padded as u32;
                lists.extend_from_slice(&seen[..n]);
                lists.resize(lists.len() + padded - n, pad);
                at
            })
            .collect();
        DirectionCells {
            centre,
            cells,
            lists: lists.into_boxed_slice(),
            pass2: (ANGLE * clear) * (ANGLE * clear),
            half_clear2: (0.5 * clear) * (0.5 * clear),
        }
    }

    /// The primitives the segment from `origin` along `dir` to `t_max` may meet, as a list
    /// padded to a multiple of four (see `new`), if its cell answers: when its line passes
    /// within `ANGLE·clear` of the centre, and it reaches past the centre on one side only.
    ///
    /// A point of the line at distance ρ ≥ `clear` from the centre lies within asin(h/ρ)
    /// of `dir` (past the foot of the perpendicular from the centre) or of `−dir` (before
    /// it), h being the line's distance from the centre; the points closer than `clear` can
    /// only be in primitives every cell lists. Points within `clear/2` of the foot along the
    /// line are closer than `clear`, so a segment that reaches no further past the foot (a
    /// shadow ray ending at its light) or starts no further before it (a ray from the centre)
    /// needs one cell.
    #[inline]
    pub fn candidates(&self, origin: Vec3A, dir: Vec3A, t_max: f32) -> Option<&[u32]> {
        let to_centre = self.centre - origin;
        let len2 = dir.length_squared();
        // |w × d|² = h²·|d|², without the cancellation of |w|² − (w·d)²/|d|².
        let off2 = to_centre.cross(dir).length_squared();
        if off2.is_nan() || off2 > self.pass2 * len2 {
            return None;
        }
        // In units of |d|²: the foot of the perpendicular, and how far the segment reaches
        // past it; each compared with `clear/2` along the line (squared, without a root).
        let foot = to_centre.dot(dir);
        let past = t_max * len2 - foot;
        let half2 = self.half_clear2 * len2;
        let beyond_half = |x: f32| x > 0.0 && x * x > half2;
        let cell = match (beyond_half(foot), beyond_half(past)) {
            (true, false) => self.cell(-dir)?,
            (false, true) => self.cell(dir)?,
            // Only the primitives every cell lists can be met (a cell's own come after them
            // in its list, but these are the same in every cell, and no cell is shorter).
            (false, false) => self.cell(dir)?,
            (true, true) => return None,
        };
        let (at, len) = ((cell >> 4) as usize, (cell & 0xF) as usize);
        self.lists.get(at..at + len)
    }

    /// The entry of the cell direction `d` falls in, or `None` if it lists nothing, or `d` is
    /// zero or NaN.
    #[inline]
    fn cell(&self, d: Vec3A) -> Option<u32> {
        let a = d.abs();
        // The major axis, and the components along the face's `u` and `v` (`axes`).
        let (major, u, v, face) = if a.x >= a.y && a.x >= a.z {
            (d.x, d.y, d.z, 0)
        } else if a.y >= a.z {
            (d.y, d.z, d.x, 2)
        } else {
            (d.z, d.x, d.y, 4)
        };
        if major == 0.0 || !a.is_finite() {
            return None;
        }
        let face = face + (major < 0.0) as usize;
        let scale = (0.5 * SIDE as f32) / major.abs();
        // |u|, |v| ≤ |major|: the index is in 0..=SIDE (SIDE only for the face's far edge).
        let index = |c: f32| ((c * scale + 0.5 * SIDE as f32) as i32).min(SIDE as i32 - 1) as usize;
        let cell = self.cells[(face * SIDE + index(v)) * SIDE + index(u)];
        (cell != TOO_MANY).then_some(cell)
    }

    /// Share of the cells that list their primitives (the rest leave rays to the hierarchy).
    #[cfg(test)]
    fn listed_share(&self) -> f32 {
        self.cells.iter().filter(|&&c| c != TOO_MANY).count() as f32 / self.cells.len() as f32
    }

    /// Bytes the cells and their lists hold.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>() + (self.cells.len() + self.lists.len()) * 4
    }
}

/// A face's outward axis and the axes of its `u` and `v`.
#[inline(always)]
fn axes(axis: usize) -> (usize, usize, usize) {
    (axis, (axis + 1) % 3, (axis + 2) % 3)
}

/// The cells, along one side of a face, of a box's points in front of the face: `c/a` over
/// `a ∈ [a0, a1]` with `a > 0` and `c ∈ [c0, c1]`, widened by `MARGIN`; `None` when none
/// of the box lies in front, or its footprint misses the face.
fn footprint(a0: f32, a1: f32, c0: f32, c1: f32) -> Option<std::ops::Range<usize>> {
    if a1.is_nan() || a1 <= 0.0 {
        return None;
    }
    let (lo, hi) = if a0 > 0.0 {
        ((c0 / a0).min(c0 / a1), (c1 / a0).max(c1 / a1))
    } else {
        // Points up to the plane through the centre: the ratio grows without bound there
        // unless the box lies on one side of the axis.
        (
            if c0 >= 0.0 {
                c0 / a1
            } else {
                f32::NEG_INFINITY
            },
            if c1 <= 0.0 { c1 / a1 } else { f32::INFINITY },
        )
    };
    let (lo, hi) = (lo - MARGIN, hi + MARGIN);
    if hi < -1.0 || lo > 1.0 {
        return None;
    }
    let index = |c: f32| (((c.max(-1.0) + 1.0) * (0.5 * SIDE as f32)) as usize).min(SIDE - 1);
    Some(index(lo)..index(hi) + 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Ray;
    use proptest::prelude::*;

    fn vec3() -> impl Strategy<Value = Vec3A> {
        (-10.0f32..10.0, -10.0f32..10.0, -10.0f32..10.0).prop_map(|(x, y, z)| Vec3A::new(x, y, z))
    }

    fn boxes() -> impl Strategy<Value = Vec<Aabb>> {
        prop::collection::vec((vec3(), (0.0f32..3.0, 0.0f32..3.0, 0.0f32..3.0)), 1..=32).prop_map(
            |v| {
                v.into_iter()
                    .map(|(c, (x, y, z))| Aabb::new(c, c + Vec3A::new(x, y, z)))
                    .collect()
            },
        )
    }

    /// Whether the answer of `candidates` offers primitive `i` (no list offers everything).
    fn offered(list: Option<&[u32]>, i: usize) -> bool {
        list.is_none_or(|l| l.contains(&(i as u32)))
    }

    /// Whether the segment meets the box (closed).
    fn meets(b: &Aabb, origin: Vec3A, dir: Vec3A, t_max: f32) -> bool {
        super::super::segment_entry(b, origin, dir, t_max as f64).is_some()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// The hardest segments: aimed at a point on one box's surface (where a cell's
        /// boundary may cut it), passing the centre as far off as `candidates` still answers
        /// by cell, and ending at the foot of the perpendicular, like a shadow ray. Every box
        /// met is offered.
        #[test]
        fn a_segment_grazing_a_box_on_its_way_to_the_centre_is_offered_it(
            centre in vec3(),
            bounds in boxes(),
            pick in 0usize..32,
            on_face in (0usize..6, 0.0f32..=1.0, 0.0f32..=1.0),
            beyond in 1.0f32..3.0,
            off in (vec3(), 0.0f32..=1.0),
        ) {
            let cells = DirectionCells::new(centre, &bounds, bounds.len() as u32);
            let b = bounds[pick % bounds.len()];
            let (face, s, t) = on_face;
            let (axis, u, v) = axes(face / 2);
            let mut p = b.min;
            p[axis] = if face % 2 == 0 { b.min[axis] } else { b.max[axis] };
            p[u] = b.min[u] + s * (b.max[u] - b.min[u]);
            p[v] = b.min[v] + t * (b.max[v] - b.min[v]);
            let along = p - centre;
            prop_assume!(along.length() > 1e-3);
            let side = off.0.cross(along);
            prop_assume!(side.length() > 1e-6);
            let pass = if cells.pass2.is_finite() { cells.pass2.sqrt() } else { 1.0 };
            let from = centre + along * beyond + side * (off.1 * pass / side.length());
            let dir = (centre - from).normalize();
            let t_max = (centre - from).dot(dir);
            let list = cells.candidates(from, dir, t_max);
            for (i, b) in bounds.iter().enumerate() {
                if meets(b, from, dir, t_max) {
                    prop_assert!(offered(list, i), "box {} {:?} met but not offered", i, b);
                }
            }
        }

        /// What `MARGIN` is for: a direction looked up just beside a cell boundary is offered
        /// a box seen `ANGLE` away from it on the other side (a point of the box, the
        /// smallest box there is, at any distance).
        #[test]
        fn a_cell_answers_for_every_direction_within_the_angle(
            face in 0usize..6,
            boundary in 0usize..=SIDE,
            beside in -1e-4f32..1e-4,
            v in -1.0f32..1.0,
            turn in 0.0f32..std::f32::consts::TAU,
            distance in 0.1f32..100.0,
        ) {
            let (axis, u_axis, v_axis) = axes(face / 2);
            let u = (-1.0 + 2.0 * boundary as f32 / SIDE as f32 + beside).clamp(-1.0, 1.0);
            let mut d = Vec3A::ZERO;
            d[axis] = if face % 2 == 0 { 1.0 } else { -1.0 };
            d[u_axis] = u;
            d[v_axis] = v;
            let d = d.normalize();
            // Turned by just under ANGLE about an axis at right angles to d.
            let across = d.any_orthonormal_pair();
            let axis_of_turn = across.0 * turn.cos() + across.1 * turn.sin();
            let e = glam::Quat::from_axis_angle(axis_of_turn.into(), ANGLE * 0.999) * glam::Vec3::from(d);
            let point = Vec3A::from(e) * distance;
            let cells = DirectionCells::new(Vec3A::ZERO, &[Aabb::new(point, point)], 1);
            let entry = cells.cell(d).expect("one primitive is not too many");
            prop_assert_eq!(entry & 0xF, 4);
            prop_assert_eq!(cells.lists[(entry >> 4) as usize], 0);
        }

        /// Shadow rays: from a point lifted a little off anywhere, towards the centre and
        /// ending at the foot of the perpendicular from it, as `Integrator::visibility`
        /// casts them. Every box the segment meets is among the candidates.
        #[test]
        fn a_segment_towards_the_centre_is_offered_every_box_it_meets(
            centre in vec3(),
            bounds in boxes(),
            from in vec3(),
            lift in vec3(),
            lift_scale in 0.0f32..1e-3,
        ) {
            let cells = DirectionCells::new(centre, &bounds, bounds.len() as u32);
            let to = centre - from;
            prop_assume!(to.length() > 1e-3);
            let dir = to / to.length();
            let ray = Ray::new(from + lift * lift_scale, dir);
            let t_max = (centre - ray.origin).dot(dir);
            let list = cells.candidates(ray.origin, ray.dir, t_max);
            for (i, b) in bounds.iter().enumerate() {
                if meets(b, ray.origin, ray.dir, t_max) {
                    prop_assert!(offered(list, i), "box {} {:?} met but not offered", i, b);
                }
            }
        }

        /// Rays from the centre (camera rays from the eye), and lines passing near it both
        /// ways: every box met is offered.
        #[test]
        fn rays_through_the_centre_are_offered_every_box_they_meet(
            centre in vec3(),
            bounds in boxes(),
            dir in vec3(),
            back in 0.0f32..20.0,
            t_max in 0.0f32..40.0,
        ) {
            prop_assume!(dir.length() > 1e-3);
            let cells = DirectionCells::new(centre, &bounds, bounds.len() as u32);
            let origin = centre - dir * (back / dir.length());
            let list = cells.candidates(origin, dir, t_max);
            for (i, b) in bounds.iter().enumerate() {
                if meets(b, origin, dir, t_max) {
                    prop_assert!(offered(list, i), "box {} {:?} met but not offered", i, b);
                }
            }
        }
    }

    #[test]
    fn a_cell_holds_only_what_is_seen_through_it() {
        // Two boxes on either side of the centre: a ray towards the centre from beyond one
        // is offered that one, not the other.
        let left = Aabb::new(Vec3A::new(-5.0, -1.0, -1.0), Vec3A::new(-4.0, 1.0, 1.0));
        let right = Aabb::new(Vec3A::new(4.0, -1.0, -1.0), Vec3A::new(5.0, 1.0, 1.0));
        let cells = DirectionCells::new(Vec3A::ZERO, &[left, right], 9);
        let from = Vec3A::new(-8.0, 0.1, 0.0);
        let dir = (-from).normalize();
        let listed = cells.candidates(from, dir, from.length());
        assert_eq!(listed, Some(&[0, 9, 9, 9][..]));
        // From above, towards the centre: neither.
        let from = Vec3A::new(0.0, 8.0, 0.0);
        assert_eq!(cells.candidates(from, Vec3A::NEG_Y, 8.0), Some(&[][..]));
        // A line passing far from the centre is left to the hierarchy.
        let from = Vec3A::new(0.0, 8.0, 3.0);
        assert_eq!(cells.candidates(from, Vec3A::NEG_Y, 8.0), None);
        // So is a segment reaching far past the centre on both sides.
        let from = Vec3A::new(-8.0, 0.0, 0.0);
        assert_eq!(cells.candidates(from, Vec3A::X, 16.0), None);
        // A ray from the centre takes the cell of its own direction.
        assert_eq!(
            cells.candidates(Vec3A::ZERO, Vec3A::X, 100.0),
            Some(&[1, 9, 9, 9][..])
        );
    }

    #[test]
    fn a_box_around_the_centre_is_listed_in_every_cell() {
        let room = Aabb::new(Vec3A::splat(-6.0), Vec3A::splat(6.0));
        let ball = Aabb::new(Vec3A::new(2.0, 2.0, 2.0), Vec3A::new(3.0, 3.0, 3.0));
        let cells = DirectionCells::new(Vec3A::ZERO, &[room, ball], 2);
        let from = Vec3A::new(0.0, -5.0, 0.0);
        assert_eq!(
            cells.candidates(from, Vec3A::Y, 5.0),
            Some(&[0, 2, 2, 2][..])
        );
        let towards_ball = Vec3A::splat(2.5).normalize();
        assert_eq!(
            cells.candidates(Vec3A::ZERO, towards_ball, 10.0),
            Some(&[0, 1, 2, 2][..])
        );
    }

    #[test]
    fn a_cell_that_sees_too_much_lists_nothing() {
        // LIST_MAX + 1 small boxes one behind the other along +x.
        let boxes: Vec<Aabb> = (0..=LIST_MAX)
            .map(|k| {
                let x = 2.0 + k as f32;
                Aabb::new(Vec3A::new(x, -0.1, -0.1), Vec3A::new(x + 0.5, 0.1, 0.1))
            })
            .collect();
        let cells = DirectionCells::new(Vec3A::ZERO, &boxes, 99);
        assert_eq!(cells.candidates(Vec3A::ZERO, Vec3A::X, 100.0), None);
        let cells = DirectionCells::new(Vec3A::ZERO, &boxes[..LIST_MAX], 99);
        let listed = cells.candidates(Vec3A::ZERO, Vec3A::X, 100.0).unwrap();
        assert_eq!(listed, &[0, 1, 2, 3, 4, 5, 6, 7][..]);
        assert!(cells.listed_share() > 0.9);
    }
}
