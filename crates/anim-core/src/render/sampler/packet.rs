//! Camera rays traced in packets: the rays of a small block of pixels share their origin and
//! nearly their direction, so one walk of the hierarchy serves them all
//! (`RenderScene::intersect_camera_packet`); each is then shaded on its own. Every ray's closest hit is the single-ray one to the bit and each pixel sums its
//! samples in the same order, so the image is the one the single-ray loops make. Frames with
//! motion never come here: the rays of a block sample different instants.
//!
//! Packets, one home per layer: `crate::accel::wide::packet` (the shared walk of the
//! hierarchy), `crate::render::geometry::packet` (closest hits of a packet) and
//! `crate::render::sampler::packet` (camera rays of a block of pixels, traced together).

use super::Frame;
use crate::math::Ray;
use crate::render::integrator::{PixelPrior, TraceState};
use glam::Vec3A;

/// A packet of the uniform path: `BLOCK_W × BLOCK_H` pixels, one sample position each.
/// The uniform path hands out work a row of packets at a time (`BLOCK_H` rows).
/// 4×4 walks the tree once for twice the rays of 4×2 at little more cost per node; wider
/// blocks saved less, and cost the scenes of scattered spheres (docs/benchmarks-history.md
/// §9.6).
pub(super) const BLOCK_W: u32 = 4;
pub const BLOCK_H: u32 = 4;
pub(super) const BLOCK: usize = (BLOCK_W * BLOCK_H) as usize;
/// A packet of adaptive sampling's first pass (one row at a time): this many pixels of a row.
const ROW_RUN: usize = 8;

/// Whether the camera rays of `frame` are traced in packets (the scene's plan says whether
/// its hierarchy is deep enough for it to pay): not where its samples draw lens or light
/// points, which are the pixel's own.
pub(super) fn packets_apply(frame: &Frame) -> bool {
    frame.shutter.is_none() && frame.integrator.scene.plan().1.camera_packets && !frame.draws.any()
}

/// Each camera ray's radiance and primitive, and in `not_clear` the lights some shadow ray
/// of its tree did not see fully, as `Integrator::camera_sample` gives them one by one.
pub(super) fn trace_primaries<const N: usize>(
    frame: &Frame,
    rays: &[Ray; N],
    st: &mut TraceState,
    not_clear: &mut [u32; N],
) -> [(Vec3A, u32); N] {
    let integrator = frame.integrator;
    let hits = integrator
        .scene
        .intersect_camera_packet(rays, &mut st.scratch);
    let mut out = [(Vec3A::ZERO, 0); N];
    for (r, hit) in hits.iter().enumerate() {
        let sample = integrator.shade_camera_hit(&rays[r], hit.as_ref(), &PixelPrior::NONE, st);
        out[r] = (sample.radiance, sample.prim);
        not_clear[r] = sample.not_clear;
    }
    out
}

/// Adaptive sampling's first pass over row `y`: one ray through every pixel centre, its
/// radiance and hit primitive into `row`, the lights its tree did not see fully into
/// `not_clear` (as the ray-by-ray pass records them, so that refinement does not depend on
/// which pass traced the row). False (and nothing traced) when packets do not
/// apply. Counts the camera rays in `st`.
pub fn trace_centres(
    frame: &Frame,
    y: usize,
    row: &mut [(Vec3A, u32)],
    not_clear: &mut [u32],
    st: &mut TraceState,
) -> bool {
    if !packets_apply(frame) {
        return false;
    }
    let ray = |x: usize| frame.camera.ray(x as f32 + 0.5, y as f32 + 0.5);
    let done = row.len() - row.len() % ROW_RUN;
    let runs = row[..done]
        .chunks_exact_mut(ROW_RUN)
        .zip(not_clear.chunks_exact_mut(ROW_RUN));
    for (c, (chunk, nc)) in runs.enumerate() {
        let rays: [_; ROW_RUN] = std::array::from_fn(|k| ray(c * ROW_RUN + k));
        let nc: &mut [u32; ROW_RUN] = nc.try_into().expect("a run of ROW_RUN");
        chunk.copy_from_slice(&trace_primaries(frame, &rays, st, nc));
    }
    for (x, (px, nc)) in row.iter_mut().zip(not_clear).enumerate().skip(done) {
        let sample = frame
            .integrator
            .camera_sample(&ray(x), &PixelPrior::NONE, st);
        *px = (sample.radiance, sample.prim);
        *nc = sample.not_clear;
    }
    st.scratch.counts.primary += row.len() as u64;
    true
}
