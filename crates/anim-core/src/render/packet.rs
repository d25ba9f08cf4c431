//! Camera rays traced in packets: the rays of a small block of pixels share their origin and
//! nearly their direction, so one walk of the hierarchy serves them all
//! (`RenderScene::closest_packet`); each is then shaded on its own. Every ray's closest hit
//! is the single-ray one to the bit and each pixel sums its samples in the same order, so the
//! image is the one the single-ray loops in `render` make.

use super::camera::CameraRays;
use super::integrator::{Integrator, TraceState, NO_HIT};
use glam::{Vec3, Vec3A};

/// A packet of the uniform path: `BLOCK_W × BLOCK_H` pixels, one sample position each.
/// The uniform path hands out work a row of packets at a time (`BLOCK_H` rows).
/// 4×4 walks the tree once for twice the rays of 4×2 at little more cost per node (grid10k
/// 1280×720: 3.3 % fewer instructions; 8×2 and 8×4 saved less, and 8×4 cost random100k 2 %).
const BLOCK_W: u32 = 4;
pub const BLOCK_H: u32 = 4;
const BLOCK: usize = (BLOCK_W * BLOCK_H) as usize;
/// A packet of adaptive sampling's first pass (one row at a time): this many pixels of a row.
const ROW_RUN: usize = 8;

/// Whether camera rays are traced in packets: when the scene's hierarchy is deep enough to
/// be worth it. Frames with motion never come here (`render` keeps them on the single-ray
/// loops: the rays of a block sample different instants).
pub fn packets_apply(integrator: &Integrator) -> bool {
    integrator.scene.packets_pay()
}

/// Radiance and hit primitive ([`NO_HIT`] for the background) of each camera ray, as
/// `Integrator::trace_primary` gives them one by one.
/// Each ray's radiance and primitive, and in `not_clear` the lights some shadow ray of its
/// tree did not see fully (`TraceState::not_clear`), as `Integrator::trace_primary` leaves it.
fn trace_primaries<const N: usize>(
    integrator: &Integrator,
    rays: &[crate::math::Ray; N],
    st: &mut TraceState,
    not_clear: &mut [u32; N],
) -> [(Vec3A, u32); N] {
    let hits = integrator.scene.closest_seen_packet(rays);
    let mut out = [(integrator.scene.background, NO_HIT); N];
    for (r, hit) in hits.iter().enumerate() {
        st.not_clear = 0;
        if let Some((prim, hit)) = hit {
            out[r] = (integrator.shade(&rays[r], *prim, hit, 0, 1.0, st), *prim);
        }
        not_clear[r] = st.not_clear;
    }
    out
}

/// Uniform sampling at `offsets` of the rows `y0..` of the image that `band` holds (whole
/// rows of `width` pixels), written into it; false (and nothing traced) when packets do not
/// apply, for the caller to trace ray by ray. Counts the camera rays in `st`.
pub fn render_band(
    camera: &CameraRays,
    integrator: &Integrator,
    (y0, width): (u32, u32),
    band: &mut [Vec3],
    offsets: &[(f32, f32)],
    st: &mut TraceState,
) -> bool {
    if !packets_apply(integrator) {
        return false;
    }
    let y1 = y0 + (band.len() / width.max(1) as usize) as u32;
    let inv_spp = 1.0 / offsets.len() as f32;
    let index = |(x, y): (u32, u32)| (y - y0) as usize * width as usize + x as usize;
    for by in (y0..y1).step_by(BLOCK_H as usize) {
        for bx in (0..width).step_by(BLOCK_W as usize) {
            let at = |k: usize| (bx + k as u32 % BLOCK_W, by + k as u32 / BLOCK_W);
            if bx + BLOCK_W > width || by + BLOCK_H > y1 {
                // A partial block at the image's edge: ray by ray.
                for y in by..(by + BLOCK_H).min(y1) {
                    for x in bx..(bx + BLOCK_W).min(width) {
                        band[index((x, y))] =
                            super::uniform_pixel(camera, None, integrator, (x, y), offsets, st);
                    }
                }
                continue;
            }
            // Each pixel adds its samples in the order of `offsets`, as the single-ray loop.
            let mut sums = [Vec3A::ZERO; BLOCK];
            for &(dx, dy) in offsets {
                let rays: [_; BLOCK] = std::array::from_fn(|k| {
                    let (x, y) = at(k);
                    camera.ray(x as f32 + dx, y as f32 + dy)
                });
                let traced = trace_primaries(integrator, &rays, st, &mut [0; BLOCK]);
                for (sum, (c, _)) in sums.iter_mut().zip(&traced) {
                    *sum += *c;
                }
            }
            for (k, sum) in sums.iter().enumerate() {
                band[index(at(k))] = Vec3::from(*sum * inv_spp);
            }
        }
    }
    st.counts.primary += (band.len() * offsets.len()) as u64;
    true
}

/// Adaptive sampling's first pass over row `y`: one ray through every pixel centre, its
/// radiance and hit primitive into `row`, the lights its tree did not see fully into
/// `not_clear` (as the ray-by-ray pass records them, so that refinement does not depend on
/// which pass traced the row). False (and nothing traced) when packets do not
/// apply. Counts the camera rays in `st`.
pub fn trace_centres(
    camera: &CameraRays,
    integrator: &Integrator,
    y: usize,
    row: &mut [(Vec3A, u32)],
    not_clear: &mut [u32],
    st: &mut TraceState,
) -> bool {
    if !packets_apply(integrator) {
        return false;
    }
    let ray = |x: usize| camera.ray(x as f32 + 0.5, y as f32 + 0.5);
    let done = row.len() - row.len() % ROW_RUN;
    let runs = row[..done]
        .chunks_exact_mut(ROW_RUN)
        .zip(not_clear.chunks_exact_mut(ROW_RUN));
    for (c, (chunk, nc)) in runs.enumerate() {
        let rays: [_; ROW_RUN] = std::array::from_fn(|k| ray(c * ROW_RUN + k));
        let nc: &mut [u32; ROW_RUN] = nc.try_into().expect("a run of ROW_RUN");
        chunk.copy_from_slice(&trace_primaries(integrator, &rays, st, nc));
    }
    for (x, (px, nc)) in row.iter_mut().zip(not_clear).enumerate().skip(done) {
        st.not_clear = 0;
        *px = integrator.trace_primary(&ray(x), st);
        *nc = st.not_clear;
    }
    st.counts.primary += row.len() as u64;
    true
}
