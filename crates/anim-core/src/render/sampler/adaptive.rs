//! Adaptive sampling, in two passes over the image (three with motion).
//!
//! 1. One ray through every pixel centre (exactly `--spp 1`), keeping the primitive it hit
//!    ([`FirstPass`]).
//! 2. A pixel whose 3×3 neighbourhood of centres shows one surface and at most
//!    `FLAT_CONTRAST` levels of contrast keeps its centre value: on such a surface the
//!    shading is smooth and the centre is the pixel mean up to its curvature. This holds for
//!    a mirror showing a flat wall as much as for the wall, so secondary rays alone do not
//!    force more samples; an edge in the reflection shows as contrast. Every other pixel
//!    drops its centre sample and takes scrambled Sobol samples, at least as many as its
//!    neighbourhood contrast calls for (`pattern::min_samples`), then doubling until the
//!    estimated error of its tone-mapped mean is at most `error` levels, or `max_spp`.
//!
//! The neighbourhood test is what catches features thinner than the base spacing: a sliver
//! seen by one centre marks all eight pixels around it. Pass 2 reads only the finished pass 1
//! and writes each pixel from its own position, so the image does not depend on the thread
//! count, and each pixel's pattern depends on its position only, so it does not crawl from
//! frame to frame of an animation. What pass 1 learned of the lights around a pixel goes to
//! the integrator with the samples of its first error check, as a [`PixelPrior`]
//! (`pattern::PRIOR_SAMPLES`).
//!
//! In a frame with motion, the first pass takes the middle of the exposure and the samples of
//! pass 2 carry instants (`PixelPattern::time`). A pixel is not flat when the rays of a centre
//! sample around it may meet a moving shape at some instant, nor when the camera's motion
//! sweeps its hit point across a neighbourhood whose two halves do not average to its centre.
//! Such a pixel takes at least `MOTION_MIN_SAMPLES`, and pass 3 ([`Adaptive::recheck_motion`])
//! goes on with those whose samples all agreed but whose neighbours show otherwise
//! (docs/scene-language.md §10).

use super::first_pass::{around, FirstPass};
use super::pattern::{self, tone3, Moments, PixelPattern, MOTION_MIN_SAMPLES, PRIOR_SAMPLES};
use super::{coverage, Frame, Sampled};
use crate::render::compile::NO_HIT;
use crate::render::counts::RayCounts;
use crate::render::integrator::{PixelPrior, TraceState};
use glam::{Vec3, Vec3A};
use rayon::prelude::*;

/// Pass 2's result, per pixel (row-major), and the rays it traced.
struct Refined {
    pixels: Vec<Vec3>,
    coverage: Vec<f32>,
    /// Samples taken, up to 255 (0: the pixel kept its centre).
    taken: Vec<u8>,
    estimates: Vec<f32>,
    rays: RayCounts,
}

/// One pixel after pass 2.
struct Pixel {
    mean: Vec3,
    coverage: f32,
    /// Samples taken, up to 255 (0: it kept its centre).
    taken: u8,
    /// The estimate of its error where it stopped (NaN when it kept its centre).
    estimate: f32,
}

/// Adaptive sampling of one frame.
pub(super) struct Adaptive<'f> {
    pub frame: &'f Frame<'f>,
    /// The target error of a refined pixel, in 8-bit levels.
    pub error: f32,
    /// The most samples one pixel may take.
    pub max_spp: u32,
}

impl Adaptive<'_> {
    /// The frame's pixels and the rays traced; `on_pixels(n)` is called as each row of `n`
    /// pixels is refined.
    pub fn render(&self, on_pixels: &(dyn Fn(u64) + Sync)) -> Sampled {
        let (first, mut counts) = FirstPass::trace(self.frame);
        let mut refined = self.refine(&first, on_pixels);
        counts += refined.rays;
        if self.frame.shutter.is_some() && self.max_spp > 1 {
            counts += self.recheck_motion(&first, &mut refined);
        }
        Sampled {
            pixels: refined.pixels,
            coverage: refined.coverage,
            rays: counts,
            error_estimates: refined.estimates,
        }
    }

    /// Sample `i` of pixel (x, y)'s own pattern (its position, and its instant, lens point
    /// and light points where the frame has them): its radiance, and whether it hit a
    /// surface. The first `PRIOR_SAMPLES` take what `prior` knows of the lights; the others
    /// trace every shadow ray.
    fn sample(
        &self,
        (x, y): (usize, usize),
        pattern: &PixelPattern,
        i: u32,
        prior: &PixelPrior,
        st: &mut TraceState,
    ) -> (Vec3A, bool) {
        let (dx, dy) = pattern.sample(i);
        let (px, py) = (x as f32 + dx, y as f32 + dy);
        let frame = self.frame;
        let prior = if i < PRIOR_SAMPLES {
            prior
        } else {
            &PixelPrior::NONE
        };
        if frame.draws.any() {
            let time = frame.shutter.map(|_| pattern.time(i));
            return frame.trace_drawing((px, py), time, (pattern, i), prior, st);
        }
        let ray = match frame.shutter {
            None => frame.camera.ray(px, py),
            Some(s) => s.ray(frame.camera, px, py, pattern.time(i)),
        };
        let sample = frame.integrator.camera_sample(&ray, prior, st);
        (sample.radiance, sample.t.is_some())
    }

    /// Pass 2: every pixel, its centre kept or refined, with the samples it took for pass 3.
    fn refine(&self, first: &FirstPass, on_pixels: &(dyn Fn(u64) + Sync)) -> Refined {
        let (w, h) = self.frame.size;
        let mut pixels = vec![Vec3::ZERO; w * h];
        let mut coverage = vec![0.0f32; w * h];
        let mut taken = vec![0u8; w * h];
        let mut estimates = vec![f32::NAN; w * h];
        let rays = pixels
            .par_chunks_mut(w)
            .zip(coverage.par_chunks_mut(w))
            .zip(taken.par_chunks_mut(w))
            .zip(estimates.par_chunks_mut(w))
            .enumerate()
            .map(|(y, (((row, coverage_row), taken_row), estimate_row))| {
                let mut st = TraceState::refining();
                let cells = row.iter_mut().zip(coverage_row).zip(taken_row);
                for (x, (((out, cov), taken), estimate)) in cells.zip(estimate_row).enumerate() {
                    let p = self.refine_pixel(first, (x, y), &mut st);
                    (*out, *cov, *taken, *estimate) = (p.mean, p.coverage, p.taken, p.estimate);
                }
                on_pixels(row.len() as u64);
                st.scratch.counts
            })
            .reduce(RayCounts::default, RayCounts::sum);
        Refined {
            pixels,
            coverage,
            taken,
            estimates,
            rays,
        }
    }

    /// Pixel (x, y) after pass 2.
    fn refine_pixel(
        &self,
        first: &FirstPass,
        (x, y): (usize, usize),
        st: &mut TraceState,
    ) -> Pixel {
        let (w, max_spp) = (self.frame.size.0, self.max_spp);
        let Some((contrast, moving)) = first.refinement(x, y).filter(|_| max_spp > 1) else {
            let (centre, prim) = first.centres[y * w + x];
            return Pixel {
                mean: Vec3::from(centre),
                coverage: coverage(u32::from(prim != NO_HIT), 1),
                taken: 0,
                estimate: f32::NAN,
            };
        };
        let mut at_least = pattern::min_samples(contrast, self.error, max_spp);
        if moving {
            at_least = at_least.max(MOTION_MIN_SAMPLES).min(max_spp);
        }
        let prior = first.prior(x, y);
        let pattern = PixelPattern::new(x as u32, y as u32);
        let mut m = Moments::default();
        let mut hits = 0;
        while m.n < max_spp {
            let (radiance, hit) = self.sample((x, y), &pattern, m.n, &prior, st);
            m.add(radiance);
            hits += u32::from(hit);
            // Checked at powers of two only: there every prefix is a full net.
            if m.n >= at_least && m.n.is_power_of_two() && m.error() <= self.error {
                break;
            }
        }
        st.scratch.counts.primary += m.n as u64;
        Pixel {
            mean: Vec3::from(m.mean()),
            coverage: coverage(hits, m.n),
            taken: m.n.min(u8::MAX as u32) as u8,
            estimate: m.error(),
        }
    }

    /// Pass 3, in a frame with motion. A pixel that motion touches and whose samples all
    /// agreed stops at `MOTION_MIN_SAMPLES`, though something moving may have covered it for
    /// a part of the exposure that none of its instants fell in (a shadow's blurred end, a
    /// thin edge). Its neighbours' samples tell: where its mean differs from a neighbour's by
    /// more than the first pass's contrast around it and twice the error target, it goes on
    /// with its own pattern, doubling its samples until the new half agrees with the old
    /// (`Moments::resume`) or it reaches `max_spp`. Reads only pass 2's finished image, so
    /// the result does not depend on the order pixels are visited in.
    fn recheck_motion(&self, first: &FirstPass, refined: &mut Refined) -> RayCounts {
        let w = self.frame.size.0;
        let pixels = &mut refined.pixels;
        let taken = &refined.taken;
        let tones: Vec<Vec3A> = pixels.par_iter().map(|c| tone3(Vec3A::from(*c))).collect();
        pixels
            .par_chunks_mut(w)
            .zip(refined.coverage.par_chunks_mut(w))
            .enumerate()
            .map(|(y, (row, coverage_row))| {
                let mut st = TraceState::refining();
                for (x, (out, cov)) in row.iter_mut().zip(coverage_row).enumerate() {
                    let n = taken[y * w + x] as u32;
                    if self.rechecks(first, &tones, (x, y), n) {
                        let prior = first.prior(x, y);
                        (*out, *cov) = self.resume((*out, *cov), n, (x, y), prior, &mut st);
                    }
                }
                st.scratch.counts
            })
            .reduce(RayCounts::default, RayCounts::sum)
    }

    /// Whether pass 3 goes on with pixel (x, y), which took `n` samples in pass 2 (`tones`:
    /// pass 2's image tone-mapped).
    fn rechecks(&self, first: &FirstPass, tones: &[Vec3A], (x, y): (usize, usize), n: u32) -> bool {
        if n == 0 || n > MOTION_MIN_SAMPLES || n >= self.max_spp {
            return false;
        }
        // The first pass's contrast around a pixel that motion touches (levels).
        let Some((contrast, true)) = first.refinement(x, y) else {
            return false;
        };
        let (w, h) = self.frame.size;
        let tone = tones[y * w + x];
        let mut differs = 0.0f32;
        for near in around(x, y, (w, h)) {
            for t in &tones[near] {
                differs = differs.max((*t - tone).abs().max_element());
            }
        }
        255.0 * differs > contrast + 2.0 * self.error
    }

    /// Pixel (x, y), whose `n` samples had mean `mean` and coverage `covered`, taking more of
    /// its own pattern.
    fn resume(
        &self,
        (mean, covered): (Vec3, f32),
        n: u32,
        (x, y): (usize, usize),
        prior: PixelPrior,
        st: &mut TraceState,
    ) -> (Vec3, f32) {
        let pattern = PixelPattern::new(x as u32, y as u32);
        let mut m = Moments::resume(Vec3A::from(mean), n);
        // Exact: the coverage of n ≤ 255 samples is a count over n.
        let mut hits = (covered * n as f32).round() as u32;
        while m.n < self.max_spp {
            let (radiance, hit) = self.sample((x, y), &pattern, m.n, &prior, st);
            m.add(radiance);
            hits += u32::from(hit);
            if m.n.is_power_of_two() && m.error() <= self.error {
                break;
            }
        }
        st.scratch.counts.primary += (m.n - n) as u64;
        (Vec3::from(m.mean()), coverage(hits, m.n))
    }
}
