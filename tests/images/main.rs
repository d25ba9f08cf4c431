//! The image contract: what the renderer draws, through the real binary, checked against
//! pixels derived from the formulas of docs/shading.md, against equivalent scenes, against the
//! golden manifest of every scene we ship, or for being finite at all. A test belongs here
//! when its claim is about the pixels of a still image (motion blur has tests/motion/).
//!
//! - `render_pixels`: Phong values, shadows, thread independence and transform equivalences.
//! - `golden`: every shipped scene, generated frame and corpus file, rendered small, against
//!   the fingerprints of `golden/manifest.tsv` (not one pixel may change by accident).
//! - `glass_edges`: glass where surfaces meet, and rays grazing faces and edges.
//! - `finite_pixels`: no scene we ship or our users have renders a NaN or infinite pixel.
//! - `distributed`: spherical and spot lights and the thin lens against their geometry;
//!   radius 0 and aperture 0 as the point light and the pinhole to the byte.
//! - `adaptive`: where adaptive anti-aliasing puts its samples; the uniform modes unchanged.
//! - `mesh`: OBJ meshes drawn like the formulas and like the equivalent boxes; OBJ errors.
//! - `instancing`: shared composites kept once, and drawn to the bytes of their flattened
//!   rewrite.
//! - `formats`: OpenEXR against the PFM, 16-bit PNG against the 8-bit one, and `--alpha`
//!   against each pixel's coverage worked out from the geometry.

#[path = "../common/mod.rs"]
mod common;

mod adaptive;
mod distributed;
mod finite_pixels;
mod formats;
mod glass_edges;
mod golden;
mod instancing;
mod mesh;
mod render_pixels;
