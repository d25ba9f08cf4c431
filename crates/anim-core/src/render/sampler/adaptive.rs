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
//!    neighbourhood contrast calls for (`pattern::min_samples`; more where motion, a lens or
//!    a spherical light spreads them: [`at_least`]), then doubling until the estimated error
//!    of its tone-mapped mean is at most `error` levels, or `max_spp` (a pixel spread over
//!    lens or light points is held to less error and may take more: [`goal`]).
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

use super::first_pass::{around, FirstPass, KeptCentres, Refinement};
use super::pattern::{
    self, tone3, Moments, PixelPattern, MOTION_MIN_SAMPLES, PRIOR_SAMPLES, SPREAD_ERROR_DIVISOR,
    SPREAD_MIN_SAMPLES, SPREAD_SPP_FACTOR,
};
use super::{coverage, Frame, Kept, Sampled};
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

    /// A frame of a shot, from what the shot's previous frame kept (`kept`; nothing: every
    /// pixel traced). A centre is traced again where what its rays met changes at this frame
    /// or earlier (`at`: its number in the shot), a pixel's added samples where theirs do or
    /// where a centre around it came out different, and in a frame with motion pass 3 where
    /// a pixel's pass 2 or one around it did: everything else is kept as it was, which is
    /// what tracing it would give. What this frame keeps comes back with the pixels traced
    /// again.
    pub fn render_again(
        &self,
        at: u32,
        kept: Option<Kept>,
        on_pixels: &(dyn Fn(u64) + Sync),
    ) -> (Sampled, Kept, u64) {
        let (w, h) = self.frame.size;
        let motion = self.frame.shutter.is_some() && self.max_spp > 1;
        let kept = kept.filter(|k| {
            k.passes.as_ref().is_some_and(|p| {
                p.centres.fits(w * h, self.frame.shutter.is_some())
                    && p.rest.refined.len() == if motion { w * h } else { 0 }
            })
        });
        let fresh = kept.is_none();
        let Kept {
            mut pixels,
            mut coverage,
            mut until,
            mut error_estimates,
            passes,
        } = kept.unwrap_or_else(|| Kept::fresh(w * h));
        let (centres, mut passes) = match passes {
            Some(p) => (Some(p.centres), p.rest),
            None => (None, PassesRest::fresh(w * h, motion)),
        };
        let (first, centred, mut counts) = FirstPass::trace_again(self.frame, centres, at);
        let near = |changed: &[bool], i: usize| {
            around(i % w, i / w, (w, h)).any(|r| changed[r].iter().any(|&c| c))
        };
        // Pass 2, into the pass-2 image (the final one without motion).
        let old2 = passes.refined.clone();
        // A pixel whose centres around it changed decides its samples again, unless it
        // decides them as before.
        let decides_anew = |i: usize| {
            near(&centred.changed, i)
                && centred
                    .before
                    .as_ref()
                    .is_none_or(|b| !first.decides_alike(b, i % w, i / w))
        };
        let dirty2: Vec<bool> = (0..w * h)
            .map(|i| until[i] <= at || decides_anew(i))
            .collect();
        let (pixels2, coverage2) = if motion {
            (&mut passes.refined, &mut passes.refined_coverage)
        } else {
            (&mut pixels, &mut coverage)
        };
        let refining = Refining {
            pixels: pixels2,
            coverage: coverage2,
            taken: &mut passes.taken,
            estimates: &mut error_estimates,
            until: &mut until,
        };
        counts += self.refine_again(&first, &dirty2, refining, on_pixels);
        let mut dirty3 = dirty2.clone();
        if motion {
            let bits = |v: &Vec3| v.to_array().map(f32::to_bits);
            let changed2: Vec<bool> = (0..w * h)
                .map(|i| fresh || (dirty2[i] && bits(&passes.refined[i]) != bits(&old2[i])))
                .collect();
            for (i, d) in dirty3.iter_mut().enumerate() {
                *d |= passes.recheck_until[i] <= at || near(&changed2, i);
            }
            let out = (&mut pixels[..], &mut coverage[..]);
            counts += self.recheck_again(&first, &dirty3, &mut passes, out);
        }
        let retraced = (0..w * h)
            .filter(|&i| centred.retraced[i] || dirty3[i])
            .count() as u64;
        let sampled = Sampled {
            pixels: pixels.clone(),
            coverage: coverage.clone(),
            rays: counts,
            error_estimates: error_estimates.clone(),
        };
        let kept = Kept {
            pixels,
            coverage,
            until,
            error_estimates,
            passes: Some(KeptPasses {
                centres: first.keep(centred.until),
                rest: passes,
            }),
        };
        (sampled, kept, retraced)
    }

    /// Pass 2 of a frame of a shot, for the pixels `dirty` marks, into `out`, watched.
    fn refine_again(
        &self,
        first: &FirstPass,
        dirty: &[bool],
        out: Refining,
        on_pixels: &(dyn Fn(u64) + Sync),
    ) -> RayCounts {
        let w = self.frame.size.0;
        out.pixels
            .par_chunks_mut(w)
            .zip(out.coverage.par_chunks_mut(w))
            .zip(out.taken.par_chunks_mut(w))
            .zip(out.estimates.par_chunks_mut(w))
            .zip(out.until.par_chunks_mut(w))
            .enumerate()
            .map(
                |(y, ((((row, coverage_row), taken_row), estimate_row), until_row))| {
                    let mut st = self.frame.trace_state(true);
                    let cells = row.iter_mut().zip(coverage_row).zip(taken_row);
                    for (x, (((out, cov), taken), estimate)) in cells.zip(estimate_row).enumerate()
                    {
                        if dirty[y * w + x] {
                            let p = self.refine_pixel(first, (x, y), &mut st);
                            (*out, *cov, *taken, *estimate) =
                                (p.mean, p.coverage, p.taken, p.estimate);
                            until_row[x] = st.scratch.take_footprint();
                        }
                    }
                    on_pixels(row.len() as u64);
                    st.scratch.counts
                },
            )
            .reduce(RayCounts::default, RayCounts::sum)
    }

    /// Pass 3 of a frame of a shot, for the pixels `dirty` marks: from pass 2's image and
    /// samples (in `passes`), into `pixels` and their coverage, watched into
    /// `passes.recheck_until`.
    fn recheck_again(
        &self,
        first: &FirstPass,
        dirty: &[bool],
        passes: &mut PassesRest,
        (pixels, coverage): (&mut [Vec3], &mut [f32]),
    ) -> RayCounts {
        let w = self.frame.size.0;
        let PassesRest {
            refined,
            refined_coverage,
            taken,
            recheck_until,
        } = passes;
        let tones: Vec<Vec3A> = refined.par_iter().map(|c| tone3(Vec3A::from(*c))).collect();
        pixels
            .par_chunks_mut(w)
            .zip(coverage.par_chunks_mut(w))
            .zip(recheck_until.par_chunks_mut(w))
            .enumerate()
            .map(|(y, ((row, coverage_row), until_row))| {
                let mut st = self.frame.trace_state(true);
                let cells = row.iter_mut().zip(coverage_row).zip(until_row);
                for (x, ((out, cov), until)) in cells.enumerate() {
                    let i = y * w + x;
                    if !dirty[i] {
                        continue;
                    }
                    let n = taken[i] as u32;
                    (*out, *cov) = (refined[i], refined_coverage[i]);
                    if let Some(goal) = self.rechecks(first, &tones, (x, y), n) {
                        let prior = first.prior(x, y);
                        (*out, *cov) = self.resume((*out, *cov), n, (x, y), goal, prior, &mut st);
                    }
                    *until = st.scratch.take_footprint();
                }
                st.scratch.counts
            })
            .reduce(RayCounts::default, RayCounts::sum)
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
                let mut st = self.frame.trace_state(true);
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
        let Some(refinement) = first.refinement(x, y).filter(|_| max_spp > 1) else {
            let (centre, prim) = first.centres[y * w + x];
            return Pixel {
                mean: Vec3::from(centre),
                coverage: coverage(u32::from(prim != NO_HIT), 1),
                taken: 0,
                estimate: f32::NAN,
            };
        };
        let (error, max_spp) = goal(refinement, self.error, max_spp);
        let at_least = at_least(refinement, self.error, max_spp);
        let prior = first.prior(x, y);
        let pattern = PixelPattern::new(x as u32, y as u32);
        let mut m = Moments::default();
        let mut hits = 0;
        while m.n < max_spp {
            let (radiance, hit) = self.sample((x, y), &pattern, m.n, &prior, st);
            m.add(radiance);
            hits += u32::from(hit);
            // Checked at powers of two only: there every prefix is a full net.
            if m.n >= at_least && m.n.is_power_of_two() && m.error() <= error {
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
                let mut st = self.frame.trace_state(true);
                for (x, (out, cov)) in row.iter_mut().zip(coverage_row).enumerate() {
                    let n = taken[y * w + x] as u32;
                    if let Some(goal) = self.rechecks(first, &tones, (x, y), n) {
                        let prior = first.prior(x, y);
                        (*out, *cov) = self.resume((*out, *cov), n, (x, y), goal, prior, &mut st);
                    }
                }
                st.scratch.counts
            })
            .reduce(RayCounts::default, RayCounts::sum)
    }

    /// Whether pass 3 goes on with pixel (x, y), which took `n` samples in pass 2 (`tones`:
    /// pass 2's image tone-mapped): if so, to what error target and at most how many samples.
    fn rechecks(
        &self,
        first: &FirstPass,
        tones: &[Vec3A],
        (x, y): (usize, usize),
        n: u32,
    ) -> Option<(f32, u32)> {
        // Asked first, before the neighbourhood is read: most pixels end here.
        if n == 0 || n > MOTION_MIN_SAMPLES {
            return None;
        }
        // The first pass's contrast around a pixel that motion touches (levels).
        let refinement = first.refinement(x, y).filter(|r| r.moving)?;
        let (error, max_spp) = goal(refinement, self.error, self.max_spp);
        if n >= max_spp {
            return None;
        }
        let (w, h) = self.frame.size;
        let tone = tones[y * w + x];
        let mut differs = 0.0f32;
        for near in around(x, y, (w, h)) {
            for t in &tones[near] {
                differs = differs.max((*t - tone).abs().max_element());
            }
        }
        (255.0 * differs > refinement.contrast + 2.0 * error).then_some((error, max_spp))
    }

    /// Pixel (x, y), whose `n` samples had mean `mean` and coverage `covered`, taking more of
    /// its own pattern until their error is at most `error` or they are `max_spp`.
    fn resume(
        &self,
        (mean, covered): (Vec3, f32),
        n: u32,
        (x, y): (usize, usize),
        (error, max_spp): (f32, u32),
        prior: PixelPrior,
        st: &mut TraceState,
    ) -> (Vec3, f32) {
        let pattern = PixelPattern::new(x as u32, y as u32);
        let mut m = Moments::resume(Vec3A::from(mean), n);
        // Exact: the coverage of n ≤ 255 samples is a count over n.
        let mut hits = (covered * n as f32).round() as u32;
        while m.n < max_spp {
            let (radiance, hit) = self.sample((x, y), &pattern, m.n, &prior, st);
            m.add(radiance);
            hits += u32::from(hit);
            if m.n.is_power_of_two() && m.error() <= error {
                break;
            }
        }
        st.scratch.counts.primary += (m.n - n) as u64;
        (Vec3::from(m.mean()), coverage(hits, m.n))
    }
}

/// The error target and the most samples of a pixel refined as `refinement` says, in a frame
/// whose target is `error` and whose cap is `max_spp`: a pixel spread over lens or light points
/// is held to `SPREAD_ERROR_DIVISOR` times less error and may take `SPREAD_SPP_FACTOR` times
/// the samples, so only the pixels of a blur or a penumbra pay for them. The neighbourhood's
/// contrast still asks for its samples at the frame's target ([`at_least`]): what it guards
/// against, a feature thinner than the centres' spacing, does not depend on the lens or light.
fn goal(refinement: Refinement, error: f32, max_spp: u32) -> (f32, u32) {
    if refinement.spread {
        let cap = max_spp.saturating_mul(SPREAD_SPP_FACTOR);
        (error / SPREAD_ERROR_DIVISOR, cap)
    } else {
        (error, max_spp)
    }
}

/// Samples a pixel refined as `refinement` says takes before its own error estimate may stop
/// it, with target `error` and at most `max_spp`: what its neighbourhood's contrast calls for
/// (`pattern::min_samples`), and more where its samples spread over the exposure
/// (`MOTION_MIN_SAMPLES`) or over its lens or light points (`SPREAD_MIN_SAMPLES`).
fn at_least(refinement: Refinement, error: f32, max_spp: u32) -> u32 {
    let mut n = pattern::min_samples(refinement.contrast, error, max_spp);
    if refinement.moving {
        n = n.max(MOTION_MIN_SAMPLES);
    }
    if refinement.spread {
        n = n.max(SPREAD_MIN_SAMPLES);
    }
    n.min(max_spp)
}

/// Where pass 2 of a frame of a shot writes: per pixel its value, its coverage, the samples
/// it took, the estimate of its error and the first later frame that changes what its samples met.
struct Refining<'a> {
    pixels: &'a mut [Vec3],
    coverage: &'a mut [f32],
    taken: &'a mut [u8],
    estimates: &'a mut [f32],
    until: &'a mut [u32],
}

/// What adaptive sampling keeps of a frame of a shot for the next, besides its pixels: its
/// first pass and the rest of its passes.
pub(super) struct KeptPasses {
    centres: KeptCentres,
    rest: PassesRest,
}

/// Per pixel, the samples pass 2 took; in a frame with motion also pass 2's image and
/// coverage, which pass 3 goes on from, and the first later frame that changes what pass 3's samples met.
struct PassesRest {
    refined: Vec<Vec3>,
    refined_coverage: Vec<f32>,
    taken: Vec<u8>,
    recheck_until: Vec<u32>,
}

impl PassesRest {
    /// Nothing kept, for `pixels` pixels (with motion: pass 3 too).
    fn fresh(pixels: usize, motion: bool) -> PassesRest {
        let with_motion = if motion { pixels } else { 0 };
        PassesRest {
            refined: vec![Vec3::ZERO; with_motion],
            refined_coverage: vec![0.0; with_motion],
            taken: vec![0; pixels],
            recheck_until: vec![0; with_motion],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::sampler::pattern::MIN_SAMPLES;

    /// A penumbra pixel among centres that agree (no contrast around it) has nothing in its
    /// neighbourhood to ask for samples, and its first samples may all see the whole light:
    /// it still takes the spread minimum before its estimate may stop it.
    #[test]
    fn a_pixel_spread_over_lens_or_light_points_takes_the_spread_minimum_however_calm() {
        let calm = |moving, spread| Refinement {
            contrast: 0.0,
            moving,
            spread,
        };
        assert_eq!(at_least(calm(false, false), 2.0, 32), MIN_SAMPLES);
        assert_eq!(at_least(calm(true, false), 2.0, 32), MOTION_MIN_SAMPLES);
        assert_eq!(at_least(calm(true, true), 2.0, 32), SPREAD_MIN_SAMPLES);
        // Never more than the pixel may take.
        assert_eq!(at_least(calm(true, true), 2.0, 8), 8);
        // A strong edge around it asks for more than the minimum, as anywhere:
        // (0.2·100/2)^(4/3) ≈ 21.5, rounded up to 32.
        let edge = Refinement {
            contrast: 100.0,
            ..calm(true, true)
        };
        assert_eq!(at_least(edge, 2.0, 64), 32);
    }

    /// Only a pixel spread over lens or light points is held to the smaller target and the
    /// larger cap, with or without motion; the others keep the frame's.
    #[test]
    fn a_spread_pixel_is_held_to_a_quarter_of_the_error_and_four_times_the_samples() {
        let refinement = |moving, spread| Refinement {
            contrast: 0.0,
            moving,
            spread,
        };
        assert_eq!(goal(refinement(false, false), 2.0, 32), (2.0, 32));
        assert_eq!(goal(refinement(true, false), 2.0, 32), (2.0, 32));
        assert_eq!(goal(refinement(false, true), 2.0, 32), (0.5, 128));
        assert_eq!(goal(refinement(true, true), 1.0, 16), (0.25, 64));
        // A cap that cannot grow further stays the largest count.
        assert_eq!(goal(refinement(false, true), 2.0, u32::MAX).1, u32::MAX);
    }
}
