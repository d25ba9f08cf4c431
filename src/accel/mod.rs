//! Bounding volume hierarchy.
