//! Bounding volume hierarchy over primitives' world bounds: a binned-SAH binary tree
//! (`binary`), collapsed into the 4-wide tree that rays traverse (`wide`); for scenes of a
//! few primitives, which of them a ray through a given point may meet (`cells`); and for
//! camera rays in larger ones, which of them each part of the image may show (`tiles`).

mod binary;
mod cells;
mod tiles;
mod wide;

pub use cells::DirectionCells;
pub use tiles::{ImageTiles, ImageView};
pub use wide::{Bvh, Packet};

/// Where the segment from `origin` along `dir` up to `t_max` enters `b` (closed), by clipping
/// its parameter range in f64: what the cells' and tiles' tests hold their lists to.
#[cfg(test)]
fn segment_entry(
    b: &crate::math::Aabb,
    origin: glam::Vec3A,
    dir: glam::Vec3A,
    t_max: f64,
) -> Option<f64> {
    let (mut t0, mut t1) = (0.0f64, t_max);
    for k in 0..3 {
        let (o, d) = (origin[k] as f64, dir[k] as f64);
        let (lo, hi) = (b.min[k] as f64, b.max[k] as f64);
        if d == 0.0 {
            if o < lo || o > hi {
                return None;
            }
            continue;
        }
        let (a, c) = ((lo - o) / d, (hi - o) / d);
        t0 = t0.max(a.min(c));
        t1 = t1.min(a.max(c));
    }
    (t0 <= t1).then_some(t0)
}
