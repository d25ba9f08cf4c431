//! Bounding volume hierarchy over primitives' world bounds: a binned-SAH binary tree
//! (`binary`), collapsed into the 4-wide tree that rays traverse (`wide`).

mod binary;
mod wide;

pub use wide::{Bvh, Packet};
