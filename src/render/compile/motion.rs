//! The moving part of a render scene (docs/scene-language.md §10): shapes whose transform
//! slot moves during the exposure, each a top-level entry of the hierarchy bounded over the
//! whole exposure and placed at the time of the ray that tests it; and moving lights.
//!
//! Static geometry pays nothing: its primitives and their tests are those of a frame without
//! motion. A moving shape is placed by `Motion::slot_matrix` at the ray's time, a function of
//! that time alone, so every ray of one camera sample (primary, shadow, reflected) meets the
//! same floats, and the spawn bounds of `Primitive::surface` hold between them as for a
//! static shape.

use crate::limits::{MOTION_MAX_PLACED, MOTION_TIME_STEPS};
use crate::math::{Aabb, Ray, Transform};
use crate::render::primitive::Primitive;
use crate::scene::motion::Motion;
use crate::scene::{Instance, Scene};
use glam::{DVec3, Vec3A};
use std::cell::{Cell, RefCell};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};

/// Instants, evenly spread over the exposure, at which a moving shape's bounds are taken
/// (besides its keys' instants): between two of them its corners move along paths so little
/// curved that twice the longest chord bounds how far they stray (see [`swept_bounds`]).
const BOUND_STEPS: usize = 64;

thread_local! {
    /// The largest angle (radians, as the eye sees it) swept by the moving entries this
    /// thread's queries met since it was last cleared: adaptive sampling's first pass asks it
    /// per pixel ([`take_touched`]).
    static TOUCHED: Cell<f32> = const { Cell::new(0.0) };
    /// The moving entries this thread placed at the time of its latest ray: every ray of a
    /// camera sample (primary, shadow, reflected) has that sample's time, so each entry is
    /// placed once per sample, not once per test. Only saves work: an entry placed again at
    /// the same time is the same floats.
    static PLACED: RefCell<Placed> = RefCell::new(Placed::default());
}

/// Numbers the moving parts made, so that a thread's cache knows whose entries it holds.
static NEXT_ID: AtomicU64 = AtomicU64::new(1);

#[derive(Default)]
struct Placed {
    /// The moving part and the time (bits) the entries were placed for.
    owner: u64,
    time: u32,
    /// Bumped when the owner or time changes: an entry is valid for its own generation only.
    generation: u64,
    entries: Vec<(u64, Option<Primitive>)>,
}

/// The largest angle (radians) swept, as the eye sees it, by the moving shapes whose swept
/// bounds this thread's queries met since the last call; 0 when they met none.
pub fn take_touched() -> f32 {
    TOUCHED.with(|t| t.replace(0.0))
}

/// The moving shapes and lights of a scene.
#[derive(Clone, Debug)]
pub struct Moving {
    id: u64,
    motion: Arc<Motion>,
    instances: Arc<Vec<Instance>>,
    /// Per moving entry: its instance.
    entries: Vec<u32>,
    /// Per moving entry: the angle (radians) its motion sweeps as the eye sees it, at most.
    sweep: Vec<f32>,
    /// Per moving entry: its bounds over the exposure.
    bounds: Vec<Aabb>,
    /// Scene light positions (moved with the scene), for moving lights.
    lights: Vec<DVec3>,
    /// Entry `k` placed at instant `i` (of `MOTION_TIME_STEPS`) in cell `k·steps + i`, made
    /// by the first ray that needs it; empty when the scene has too many moving shapes for
    /// it (each worker then places them per camera sample).
    placed: Vec<OnceLock<Option<Primitive>>>,
}

/// The instant camera samples at `time` are taken at: the middle of its part of the
/// exposure (`limits::MOTION_TIME_STEPS`).
#[inline]
pub fn quantize(time: f32) -> f32 {
    (step(time) as f32 + 0.5) / MOTION_TIME_STEPS as f32
}

/// The part of the exposure `time` falls in.
#[inline]
fn step(time: f32) -> u32 {
    ((time * MOTION_TIME_STEPS as f32) as u32).min(MOTION_TIME_STEPS - 1)
}

impl Moving {
    /// The moving part of `scene`, if anything in it moves (geometry or lights).
    pub fn new(scene: &Scene) -> Option<Moving> {
        let motion = scene.motion.as_ref()?;
        if !(motion.moves_geometry() || motion.moves_lights()) {
            return None;
        }
        Some(Moving {
            id: NEXT_ID.fetch_add(1, Ordering::Relaxed),
            motion: motion.clone(),
            instances: scene.instances.clone(),
            entries: Vec::new(),
            sweep: Vec::new(),
            bounds: Vec::new(),
            lights: scene.lights.iter().map(|l| l.position).collect(),
            placed: Vec::new(),
        })
    }

    /// Makes room for the placed entries, once they are all added, if they fit.
    pub fn finish(&mut self) {
        let cells = self.entries.len() * MOTION_TIME_STEPS as usize;
        if cells <= MOTION_MAX_PLACED {
            self.placed = (0..cells).map(|_| OnceLock::new()).collect();
        }
    }

    /// Whether `inst` moves (it is then added with [`Moving::add`], not as a primitive).
    #[inline]
    pub fn moves(&self, inst: &Instance) -> bool {
        self.motion.moves_slot(inst.transform)
    }

    /// Adds instance `index` as a moving entry; its number and its bounds over the exposure.
    pub fn add(&mut self, index: usize) -> (u32, Aabb) {
        let k = self.entries.len() as u32;
        self.entries.push(index as u32);
        let swept = self.swept(k);
        // Seen from the eye (at the origin: rendering is camera-relative), the angle its
        // corners sweep, at most: their path over the distance to the nearest point of the
        // bounds.
        let b = swept.bounds;
        let nearest = Vec3A::ZERO.clamp(b.min, b.max).length() as f64;
        let angle = if swept.path == 0.0 {
            0.0
        } else {
            (swept.path / nearest) as f32
        };
        self.sweep
            .push(if angle.is_nan() { f32::INFINITY } else { angle });
        self.bounds.push(b);
        (k, swept.bounds)
    }

    /// Entry `k` at time `u`: its transform.
    fn transform(&self, k: u32, u: f64) -> Option<(&Instance, Transform)> {
        let inst = self
            .instances
            .get(*self.entries.get(k as usize)? as usize)?;
        Some((inst, self.motion.slot_at(inst.transform, u)))
    }

    /// Entry `k` placed at `time` (`None` where it is degenerate then).
    fn place(&self, k: u32, time: f32) -> Option<Primitive> {
        let (inst, xf) = self.transform(k, time as f64)?;
        Primitive::new(&inst.geometry, &xf, inst.material as u32).ok()
    }

    /// `f` of entry `k` placed at the ray's time; `None` where it is degenerate then.
    #[inline]
    pub fn with<R>(&self, k: u32, ray: &Ray, f: impl FnOnce(&Primitive) -> R) -> Option<R> {
        let time = ray.time;
        let swept = self.sweep.get(k as usize).copied().unwrap_or(f32::INFINITY);
        // Asked also outside a traversal (a shadow ray tries the last blocker first): only a
        // ray that meets the swept bounds counts.
        if TOUCHED.with(Cell::get) < swept
            && self.bounds.get(k as usize).is_some_and(|b| {
                b.hit_range(ray, ray.dir.recip(), 0.0, f32::INFINITY)
                    .is_some()
            })
        {
            TOUCHED.with(|t| t.set(swept));
        }
        if !self.placed.is_empty() {
            let i = step(time);
            let cell = self
                .placed
                .get(k as usize * MOTION_TIME_STEPS as usize + i as usize)?;
            return cell
                .get_or_init(|| self.place(k, (i as f32 + 0.5) / MOTION_TIME_STEPS as f32))
                .as_ref()
                .map(f);
        }
        PLACED.with_borrow_mut(|c| {
            if c.owner != self.id || c.time != time.to_bits() {
                c.owner = self.id;
                c.time = time.to_bits();
                c.generation += 1;
                if c.entries.len() != self.entries.len() {
                    c.entries.clear();
                    c.entries.resize_with(self.entries.len(), || (0, None));
                }
            }
            let generation = c.generation;
            let slot = c.entries.get_mut(k as usize)?;
            if slot.0 != generation {
                *slot = (generation, self.place(k, time));
            }
            slot.1.as_ref().map(f)
        })
    }

    /// Entry `k`'s bounds over the whole exposure.
    fn swept(&self, k: u32) -> Swept {
        let Some(inst) = self
            .entries
            .get(k as usize)
            .and_then(|&i| self.instances.get(i as usize))
        else {
            return Swept {
                bounds: Aabb::EMPTY,
                path: 0.0,
            };
        };
        let mut instants: Vec<f64> = (0..=BOUND_STEPS)
            .map(|s| s as f64 / BOUND_STEPS as f64)
            .collect();
        instants.extend(self.motion.slot_instants(inst.transform));
        let Ok(local) = Primitive::new(&inst.geometry, &Transform::IDENTITY, 0) else {
            return Swept {
                bounds: Aabb::EMPTY,
                path: 0.0,
            };
        };
        swept_bounds(&instants, |u| {
            Some((local.bounds, self.motion.slot_at(inst.transform, u)))
        })
    }

    /// Where light `k` is at `time`.
    #[inline]
    pub fn light_position(&self, k: usize, time: f32) -> Vec3A {
        let p = self.lights.get(k).map_or(DVec3::ZERO, |&p| {
            self.motion.light_position(k, p, time as f64)
        });
        Vec3A::from(p.as_vec3())
    }

    pub fn memory_bytes(&self) -> usize {
        self.entries.capacity() * 4
            + self.lights.capacity() * 24
            + self.placed.capacity() * std::mem::size_of::<OnceLock<Option<Primitive>>>()
    }
}

/// Bounds of a moving box over the exposure: `placed(u)` gives the box in its own space and
/// its transform at `u` (`None` where degenerate). The union of the boxes at `instants`
/// (0 and 1 among them), each widened by twice the longest path a corner takes between two
/// neighbouring instants (its chord).
///
/// Why it holds: a point of the shape is an affine combination of the box's corners, so
/// between two instants it strays from where it was at the nearer one by at most the longest
/// path a corner takes in that span. Between instants 1/64 of the exposure apart (and every
/// key instant), a corner's path is a smooth curve (a constant-speed turn combined with a
/// straight slide and a steady stretch) that turns far less than a half circle, and the path
/// of a curve turning by less than 180° is at most π/2 times its chord: twice the chord
/// covers it with room to spare. `motion_bounds_hold` (proptest) checks it.
pub fn swept_bounds(instants: &[f64], placed: impl Fn(f64) -> Option<(Aabb, Transform)>) -> Swept {
    let mut instants: Vec<f64> = instants
        .iter()
        .copied()
        .filter(|u| (0.0..=1.0).contains(u))
        .collect();
    instants.extend([0.0, 1.0]);
    instants.sort_by(f64::total_cmp);
    instants.dedup();
    let mut all = Aabb::EMPTY;
    let mut margin = 0.0f64;
    let mut paths = [0.0f64; 8];
    let mut previous: Option<[DVec3; 8]> = None;
    for &u in &instants {
        let Some((local, xf)) = placed(u) else {
            previous = None;
            continue;
        };
        if !local.is_finite() {
            return Swept {
                bounds: Aabb::new(Vec3A::NEG_INFINITY, Vec3A::INFINITY),
                path: f64::INFINITY,
            };
        }
        let corners = local.corners().map(|c| xf.point(c.as_dvec3()));
        for c in corners {
            all = all.union_point(Vec3A::from(c.as_vec3()));
        }
        if let Some(before) = previous {
            for ((a, b), path) in before.iter().zip(&corners).zip(&mut paths) {
                margin = margin.max(a.distance(*b));
                *path += a.distance(*b);
            }
        }
        previous = Some(corners);
    }
    let path = paths.into_iter().fold(0.0, f64::max);
    if all.is_empty() {
        return Swept { bounds: all, path };
    }
    // Twice the longest chord, and a relative margin for the f32 rounding of the corners.
    let pad = Vec3A::splat((2.0 * margin) as f32)
        + (all.min.abs().max(all.max.abs()) + all.extent()) * 1e-5;
    Swept {
        bounds: Aabb::new(all.min - pad, all.max + pad),
        path,
    }
}

/// What [`swept_bounds`] finds of a moving box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Swept {
    pub bounds: Aabb,
    /// The longest way a corner of the box travels over the exposure (through the instants).
    pub path: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::motion::MotionKeys;
    use proptest::prelude::*;

    fn trs(t: [f64; 3], degrees: f64, axis: [f64; 3], s: [f64; 3]) -> Transform {
        Transform::translate(t.into())
            .then_after(&Transform::rotate(degrees, axis.into()).expect("axis"))
            .then_after(&Transform::scale(s.into()).expect("scale"))
    }

    proptest! {
        /// The swept bounds hold the box at every instant, turns of up to 180° between two
        /// keys and a parent's motion carrying the child included.
        #[test]
        fn motion_bounds_hold(
            t in prop::array::uniform3(prop::array::uniform3(-5.0f64..5.0)),
            d in prop::array::uniform3(-180.0f64..180.0),
            axis in prop::array::uniform3(0.1f64..1.0),
            s in prop::array::uniform3(0.5f64..2.0),
            parent_turn in -180.0f64..180.0,
            u in prop::collection::vec(0.0f64..1.0, 16),
        ) {
            let local = Aabb::new(Vec3A::new(-1.0, -0.5, -0.2), Vec3A::new(1.0, 0.5, 2.0));
            let keys = [0.0, 0.5, 1.0];
            let child: Vec<(f64, Transform)> = (0..3)
                .map(|k| (keys[k], trs(t[k], d[k], axis, [s[k], 1.0, s[(k + 1) % 3]])))
                .collect();
            let child = MotionKeys::new(DVec3::new(0.0, 0.0, 0.9), &child).expect("keys");
            let spin = |deg: f64| trs([3.0, 0.0, 0.0], deg, [0.0, 1.0, 0.0], [1.0; 3]);
            let parent = MotionKeys::new(
                DVec3::ZERO,
                &[(0.0, spin(0.0)), (1.0, spin(parent_turn))],
            )
            .expect("keys");
            let at = |u: f64| {
                let m = parent.matrix_at(u) * child.matrix_at(u);
                Transform { world_from_object: m, object_from_world: m.inverse() }
            };
            let instants: Vec<f64> = (0..=BOUND_STEPS).map(|k| k as f64 / BOUND_STEPS as f64).collect();
            let bounds = swept_bounds(&instants, |u| Some((local, at(u)))).bounds;
            for u in u {
                for c in local.corners() {
                    let p = Vec3A::from(at(u).point(c.as_dvec3()).as_vec3());
                    prop_assert!(
                        p.cmpge(bounds.min).all() && p.cmple(bounds.max).all(),
                        "{p} outside {bounds:?} at {u}"
                    );
                }
            }
        }
    }

    #[test]
    fn quantized_times_are_the_middles_of_their_parts() {
        let n = MOTION_TIME_STEPS as f32;
        assert_eq!(quantize(0.0), 0.5 / n);
        assert_eq!(quantize(1.0), (n - 0.5) / n);
        assert_eq!(quantize(0.5), (n / 2.0 + 0.5) / n);
        assert_eq!(quantize(quantize(0.3)), quantize(0.3));
    }
}
