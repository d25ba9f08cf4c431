//! Bounding volume hierarchy over primitives' world bounds: a binned-SAH binary tree
//! (`binary`), collapsed into the 4-wide tree that rays traverse (`wide`); and, for scenes of
//! a few primitives, which of them a ray through a given point may meet (`cells`).

mod binary;
mod cells;
mod wide;

pub use cells::DirectionCells;
pub use wide::{Bvh, Packet};
