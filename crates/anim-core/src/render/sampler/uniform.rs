//! Uniform sampling: every pixel takes the same samples at the same sub-pixel offsets (a k×k
//! stratified grid for k², a Hammersley set otherwise, the centre for one) and, in a frame
//! with motion, at instants of the exposure stratified per pixel (`pattern::uniform_time`).

use super::packet::{self, BLOCK, BLOCK_H, BLOCK_W};
use super::pattern::{uniform_time, PixelPattern};
use super::{coverage, Frame, Sampled};
use crate::math::Ray;
use crate::render::compile::NO_HIT;
use crate::render::counts::RayCounts;
use crate::render::integrator::{PixelPrior, TraceState};
use crate::render::motion::Shutter;
use glam::{Vec3, Vec3A};
use rayon::prelude::*;

/// The frame's pixels, `spp` samples each, their coverage and the rays traced;
/// `on_pixels(n)` is called as each band of `n` pixels finishes.
pub(super) fn render(frame: &Frame, spp: u32, on_pixels: &(dyn Fn(u64) + Sync)) -> Sampled {
    let (width, height) = (frame.size.0 as u32, frame.size.1 as u32);
    let offsets = sample_offsets(spp);
    let mut pixels = vec![Vec3::ZERO; (width * height) as usize];
    let mut coverage = vec![0.0f32; pixels.len()];
    let band_len = (width * BLOCK_H).max(1) as usize;
    // Bands of whole rows, written where they lie in the image: each pixel depends only on
    // its own position, so the result is the same for any thread count or band order.
    let counts = pixels
        .par_chunks_mut(band_len)
        .zip(coverage.par_chunks_mut(band_len))
        .enumerate()
        .map(|(i, (band, covered))| {
            let y0 = i as u32 * BLOCK_H;
            let mut st = TraceState::default();
            if !render_band(frame, (y0, width), (band, covered), &offsets, &mut st) {
                for (k, (out, cov)) in band.iter_mut().zip(covered.iter_mut()).enumerate() {
                    let (x, y) = (k as u32 % width, y0 + k as u32 / width);
                    (*out, *cov) = uniform_pixel(frame, (x, y), &offsets, &mut st);
                }
                st.scratch.counts.primary += (band.len() * offsets.len()) as u64;
            }
            on_pixels(band.len() as u64);
            st.scratch.counts
        })
        .reduce(RayCounts::default, RayCounts::sum);
    Sampled {
        pixels,
        coverage,
        rays: counts,
        error_estimates: Vec::new(),
    }
}

/// Uniform sampling at `offsets` of the rows `y0..` of the image that `band` holds (whole
/// rows of `width` pixels), written into it with each pixel's coverage into `covered`; false
/// (and nothing traced) when packets do not apply, for the caller to trace ray by ray.
/// Counts the camera rays in `st`.
fn render_band(
    frame: &Frame,
    (y0, width): (u32, u32),
    (band, covered): (&mut [Vec3], &mut [f32]),
    offsets: &[(f32, f32)],
    st: &mut TraceState,
) -> bool {
    if !packet::packets_apply(frame) {
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
                        let i = index((x, y));
                        (band[i], covered[i]) = uniform_pixel(frame, (x, y), offsets, st);
                    }
                }
                continue;
            }
            // Each pixel adds its samples in the order of `offsets`, as the single-ray loop.
            let mut sums = [Vec3A::ZERO; BLOCK];
            let mut hits = [0u32; BLOCK];
            for &(dx, dy) in offsets {
                let rays: [_; BLOCK] = std::array::from_fn(|k| {
                    let (x, y) = at(k);
                    frame.camera.ray(x as f32 + dx, y as f32 + dy)
                });
                let traced = packet::trace_primaries(frame, &rays, st, &mut [0; BLOCK]);
                for (sum, (c, _)) in sums.iter_mut().zip(&traced) {
                    *sum += *c;
                }
                for (hit, (_, prim)) in hits.iter_mut().zip(&traced) {
                    *hit += u32::from(*prim != NO_HIT);
                }
            }
            for (k, sum) in sums.iter().enumerate() {
                band[index(at(k))] = Vec3::from(*sum * inv_spp);
            }
            for (k, hit) in hits.into_iter().enumerate() {
                covered[index(at(k))] = coverage(hit, offsets.len() as u32);
            }
        }
    }
    st.scratch.counts.primary += (band.len() * offsets.len()) as u64;
    true
}

/// Pixel (`x`, `y`) ray by ray: the mean of its samples at `offsets` (in a frame with
/// motion, at the instants `uniform_time` gives them), added in that order, as the camera
/// packets add theirs, and its coverage. Does not count the camera rays. Always inlined: its
/// two callers are the hot loops of uniform sampling, and the drawing path beside it would
/// otherwise tip the compiler into a call per pixel.
#[inline(always)]
pub(super) fn uniform_pixel(
    frame: &Frame,
    (x, y): (u32, u32),
    offsets: &[(f32, f32)],
    st: &mut TraceState,
) -> (Vec3, f32) {
    if frame.draws.any() {
        return drawing_pixel(frame, (x, y), offsets, st);
    }
    let (mut sum, mut hits) = (Vec3A::ZERO, 0u32);
    for (i, &(dx, dy)) in offsets.iter().enumerate() {
        let (px, py) = (x as f32 + dx, y as f32 + dy);
        let ray = match frame.shutter {
            None => frame.camera.ray(px, py),
            Some(s) => {
                let sample = (i as u32, offsets.len() as u32);
                exposure_ray(frame, s, ((x, y), (px, py)), sample)
            }
        };
        let sample = frame.integrator.camera_sample(&ray, &PixelPrior::NONE, st);
        sum += sample.radiance;
        hits += u32::from(sample.t.is_some());
    }
    let inv_spp = 1.0 / offsets.len() as f32;
    (
        Vec3::from(sum * inv_spp),
        coverage(hits, offsets.len() as u32),
    )
}

/// The camera ray of sample `i` of `n` of pixel (`x`, `y`), through (`px`, `py`), at its
/// instant of the exposure. Out of line: inlined, the compiler works out the hash of each
/// pixel's instants ahead of its loop of samples, for still frames too.
#[inline(never)]
fn exposure_ray(
    frame: &Frame,
    shutter: &Shutter,
    ((x, y), (px, py)): ((u32, u32), (f32, f32)),
    (i, n): (u32, u32),
) -> Ray {
    shutter.ray(frame.camera, px, py, uniform_time(x, y, i, n))
}

/// [`uniform_pixel`] of a frame whose samples draw lens and light points: sample `i` draws
/// them as the pixel's pattern gives them by index. Apart, and not inlined, so that frames
/// that draw none keep the loop above as small as it was.
#[inline(never)]
fn drawing_pixel(
    frame: &Frame,
    (x, y): (u32, u32),
    offsets: &[(f32, f32)],
    st: &mut TraceState,
) -> (Vec3, f32) {
    let (mut sum, mut hits) = (Vec3A::ZERO, 0u32);
    let n = offsets.len() as u32;
    let pattern = PixelPattern::new(x, y);
    for (i, &(dx, dy)) in (0..).zip(offsets) {
        let (px, py) = (x as f32 + dx, y as f32 + dy);
        let time = frame.shutter.map(|_| uniform_time(x, y, i, n));
        let prior = &PixelPrior::NONE;
        let (radiance, hit) = frame.trace_drawing((px, py), time, (&pattern, i), prior, st);
        sum += radiance;
        hits += u32::from(hit);
    }
    (Vec3::from(sum * (1.0 / n as f32)), coverage(hits, n))
}

/// Sub-pixel sample positions in [0,1)²: a k×k stratified grid when `n = k²`, otherwise a
/// Hammersley set. Fixed, so renders are reproducible.
pub fn sample_offsets(n: u32) -> Vec<(f32, f32)> {
    let n = n.max(1);
    if n == 1 {
        return vec![(0.5, 0.5)];
    }
    let k = (n as f64).sqrt().round() as u32;
    if k * k == n {
        let step = 1.0 / k as f32;
        return (0..n)
            .map(|i| (((i % k) as f32 + 0.5) * step, ((i / k) as f32 + 0.5) * step))
            .collect();
    }
    (0..n)
        .map(|i| {
            (
                (i as f32 + 0.5) / n as f32,
                (i.reverse_bits() as f64 / 4294967296.0) as f32,
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stratified_grid_for_squares() {
        let s = sample_offsets(4);
        assert_eq!(
            s,
            vec![(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)]
        );
        assert_eq!(sample_offsets(1), vec![(0.5, 0.5)]);
        let h = sample_offsets(10);
        assert_eq!(h.len(), 10);
        assert!(h
            .iter()
            .all(|&(x, y)| (0.0..1.0).contains(&x) && (0.0..1.0).contains(&y)));
    }
}
