//! Adaptive sampling's first pass: one ray through every pixel centre (exactly `--spp 1`),
//! and what the later passes read of it: which pixels are flat and keep their centre sample
//! ([`FirstPass::refinement`]), and what a refined pixel's samples may take as known of the
//! lights ([`FirstPass::prior`]). Where the frame's samples draw lens or light points, the
//! centres take the pinhole and ask spherical lights as a whole, and a pixel whose value
//! hangs on those points (a penumbra, a blur) is refined.

use super::defocus::{self, Centre};
use super::motion::{streak_pairs, MotionProbe};
use super::packet;
use super::pattern::{tone3, FLAT_CONTRAST};
use super::Frame;
use crate::math::Ray;
use crate::render::counts::RayCounts;
use crate::render::integrator::{CameraSample, KnownNear, PixelPrior, TraceState};
use crate::render::motion::Shutter;
use glam::Vec3A;
use rayon::prelude::*;

/// How a pixel's centre ray saw the motion of a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Sweep {
    /// Its rays may meet a moving shape (`Moving::met_by`), and it changes during the exposure
    /// (`MotionProbe::changes`).
    touched: bool,
    /// The ends of the streak the camera's motion draws its hit point along (pixels from
    /// its centre), along which the image must be flat for it to keep its centre sample;
    /// `None` when it sweeps too far for that (`MotionProbe::camera_sweep`).
    streak: Option<[(f32, f32); 2]>,
    /// How far along its centre ray the surface it hit lies, where its shadow rays' findings
    /// are kept for the shapes that hold still (NaN where they are not).
    depth: f32,
}

impl Default for Sweep {
    fn default() -> Self {
        Sweep {
            touched: false,
            streak: Some([(0.0, 0.0); 2]),
            depth: f32::NAN,
        }
    }
}

/// What a centre's samples draw hangs on, as the first pass saw it.
#[derive(Clone, Copy, Debug, Default)]
struct Mark {
    /// Its tree saw a spherical light in part (`CameraSample::penumbra`).
    penumbra: bool,
    /// The radius of the lens's circle of confusion at its hit, negative nearer than the
    /// plane in focus (`PinholeCamera::blur`).
    blur: f32,
}

/// What the first pass saw, per pixel (row-major).
pub(super) struct FirstPass<'f> {
    frame: &'f Frame<'f>,
    /// The centre sample's radiance and the primitive it hit.
    pub centres: Vec<(Vec3A, u32)>,
    /// The centres tone-mapped: a pixel's neighbourhood, and its streak under a moving
    /// camera, read many of them.
    tones: Vec<Vec3A>,
    /// In a frame with motion: how each centre ray saw it (empty otherwise).
    sweeps: Vec<Sweep>,
    /// The lights some shadow ray of the centre's tree did not see fully
    /// (`CameraSample::not_clear`); all of them where that is not recorded.
    not_clear: Vec<u32>,
    /// Whether the centres' shadow findings speak for the shapes that hold still, with the
    /// depth of their hits (a frame with motion whose lights hold still and whose moving
    /// shapes are few enough to ask at each sample's instant).
    known_of_still: bool,
    /// What each centre's lens and light points hang on (zeros where nothing is drawn).
    marks: Vec<Mark>,
    /// Whether a pixel's value hangs on its lens or light points: a penumbra around it, or a
    /// blur that reaches it (`defocus`). Empty when the frame draws none.
    spread: Vec<bool>,
}

impl<'f> FirstPass<'f> {
    /// Traces the centre of every pixel of `frame`.
    pub fn trace(frame: &'f Frame<'f>) -> (FirstPass<'f>, RayCounts) {
        let (w, h) = frame.size;
        let mut pass = FirstPass {
            frame,
            centres: vec![(Vec3A::ZERO, 0); w * h],
            tones: Vec::new(),
            sweeps: vec![Sweep::default(); if frame.shutter.is_some() { w * h } else { 0 }],
            not_clear: vec![u32::MAX; w * h],
            known_of_still: frame.shutter.is_some_and(|s| !s.lights_move())
                && frame.integrator.scene.plan().0.ask_moving,
            marks: vec![Mark::default(); w * h],
            spread: Vec::new(),
        };
        let counts = match frame.shutter {
            None => pass.trace_still(),
            Some(s) => pass.trace_moving(s),
        };
        pass.tones = pass.centres.par_iter().map(|(c, _)| tone3(*c)).collect();
        if frame.draws.any() {
            pass.spread = pass.spread_pixels();
        }
        (pass, counts)
    }

    /// Per pixel, whether its value hangs on its lens or light points: a centre around it
    /// saw a spherical light in part, or the lens's blur reaches it.
    fn spread_pixels(&self) -> Vec<bool> {
        let (w, h) = self.frame.size;
        let mut spread = if self.frame.draws.lens() {
            defocus::blurred((w, h), |i| Centre {
                blur: self.marks[i].blur,
                prim: self.centres[i].1,
                tone: self.tones[i],
            })
        } else {
            vec![false; w * h]
        };
        if self.frame.draws.spherical_lights() {
            for (i, out) in spread.iter_mut().enumerate() {
                let (x, y) = (i % w, i / w);
                *out =
                    *out || around(x, y, (w, h)).any(|r| self.marks[r].iter().any(|m| m.penumbra));
            }
        }
        spread
    }

    /// The centres of a frame in which nothing moves, a row at a time (in packets where the
    /// scene's plan says so).
    fn trace_still(&mut self) -> RayCounts {
        let frame = self.frame;
        let w = frame.size.0;
        self.centres
            .par_chunks_mut(w)
            .zip(self.not_clear.par_chunks_mut(w))
            .zip(self.marks.par_chunks_mut(w))
            .enumerate()
            .map(|(y, ((row, not_clear_row), mark_row))| {
                let mut st = trace_state(frame);
                if packet::trace_centres(frame, y, row, not_clear_row, &mut st) {
                    return st.scratch.counts;
                }
                let pixels = row.iter_mut().zip(not_clear_row).zip(mark_row);
                for (x, ((px, nc), mk)) in pixels.enumerate() {
                    let ray = frame.camera.ray(x as f32 + 0.5, y as f32 + 0.5);
                    let sample = frame
                        .integrator
                        .camera_sample(&ray, &PixelPrior::NONE, &mut st);
                    *px = (sample.radiance, sample.prim);
                    *nc = sample.not_clear;
                    *mk = mark(frame, &ray, &sample);
                }
                st.scratch.counts.primary += row.len() as u64;
                st.scratch.counts
            })
            .reduce(RayCounts::default, RayCounts::sum)
    }

    /// The centres of a frame with motion, at the middle of the exposure, each watched for
    /// the moving shapes its rays may meet.
    fn trace_moving(&mut self, shutter: &Shutter) -> RayCounts {
        let frame = self.frame;
        let w = frame.size.0;
        // A light a centre's shadow rays saw fully stays so only while it holds still.
        // Then, where the moving shapes are few enough to ask at each sample's instant, what
        // they saw is kept as news of the shapes that hold still, with how far the centre's
        // hit is (see `KnownNear`); otherwise, only while the camera holds still too (so
        // that the refined samples hit near the centres), for centres none of whose rays may
        // meet anything moving.
        let of_still = frame.integrator.scene.plan().0.ask_moving;
        let probe = MotionProbe::new(frame, shutter);
        let shadows_hold = !shutter.lights_move() && (of_still || !shutter.camera_moves());
        self.centres
            .par_chunks_mut(w)
            .zip(self.sweeps.par_chunks_mut(w))
            .zip(self.not_clear.par_chunks_mut(w))
            .zip(self.marks.par_chunks_mut(w))
            .enumerate()
            .map(|(y, (((row, sweep_row), not_clear_row), mark_row))| {
                let mut st = trace_state(frame);
                let pixels = row
                    .iter_mut()
                    .zip(sweep_row)
                    .zip(not_clear_row)
                    .zip(mark_row);
                for (x, (((px, sw), nc), mk)) in pixels.enumerate() {
                    let (x, y) = (x as u32, y as u32);
                    let ray = frame.camera.ray(x as f32 + 0.5, y as f32 + 0.5);
                    let sample =
                        frame
                            .integrator
                            .camera_sample_swept(&ray, &PixelPrior::NONE, &mut st);
                    *px = (sample.radiance, sample.prim);
                    *mk = mark(frame, &ray, &sample);
                    let swept = sample.swept;
                    if shadows_hold && (of_still || swept == 0.0) {
                        *nc = sample.not_clear;
                        if of_still {
                            sw.depth = sample.t.unwrap_or(f32::NAN);
                        }
                    }
                    sw.touched = swept > 0.0 && probe.changes((x, y), *px, swept, &mut st);
                    if shutter.camera_moves() {
                        sw.streak = probe.camera_sweep(x, y, sample.t);
                    }
                }
                st.scratch.counts.primary += row.len() as u64;
                st.scratch.counts
            })
            .reduce(RayCounts::default, RayCounts::sum)
    }

    /// Whether pixel (x, y) is refined, and if so the largest tone-mapped difference (8-bit
    /// levels) between its centre and those around it and whether motion (or a penumbra, or
    /// a blur: [`FirstPass::spread_pixels`]) touches it; `None` if it is flat and keeps its
    /// centre sample. Flat: all nine centres around it hit one surface within
    /// `FLAT_CONTRAST` levels, no centre ray around it met something moving, under a moving
    /// camera the image is flat along its streak, and its value hangs on no lens or light
    /// point.
    pub fn refinement(&self, x: usize, y: usize) -> Option<(f32, bool)> {
        let (w, h) = self.frame.size;
        let prim = self.centres[y * w + x].1;
        let tone = self.tones[y * w + x];
        let mut contrast = 0.0f32;
        let mut other_surface = false;
        let mut moving = false;
        for near in around(x, y, (w, h)) {
            for (t, (_, p)) in self.tones[near.clone()]
                .iter()
                .zip(&self.centres[near.clone()])
            {
                other_surface |= *p != prim;
                contrast = contrast.max((*t - tone).abs().max_element());
            }
            if !self.sweeps.is_empty() {
                moving |= self.sweeps[near].iter().any(|s| s.touched);
            }
        }
        let streak = match self.sweeps.get(y * w + x).map(|s| s.streak) {
            None => Streak::default(),
            Some(None) => {
                moving = true;
                Streak::default()
            }
            Some(Some(ends)) => self.streak(x, y, ends),
        };
        other_surface |= streak.other_surface;
        // A pixel whose value hangs on its lens or light points spreads its samples over more
        // dimensions than its position, as one that motion touches does over time.
        moving |= self.spread.get(y * w + x).copied().unwrap_or(false);
        let flat = !moving && !other_surface && 255.0 * contrast.max(streak.bias) <= FLAT_CONTRAST;
        (!flat).then_some((255.0 * contrast.max(streak.contrast), moving))
    }

    /// The centres along the streak from (x, y) to `ends` that the camera's motion draws:
    /// the pixel's value is the mean of what the streak's two halves show, flat when every
    /// pair of points that far along the two halves averages to the centre (a steady
    /// gradient does), though the points themselves may differ more.
    fn streak(&self, x: usize, y: usize, ends: [(f32, f32); 2]) -> Streak {
        let (w, h) = self.frame.size;
        let (prim, tone) = (self.centres[y * w + x].1, self.tones[y * w + x]);
        let at = |(px, py): (i64, i64)| {
            (px >= 0 && py >= 0 && px < w as i64 && py < h as i64)
                .then(|| py as usize * w + px as usize)
        };
        let mut streak = Streak::default();
        let mut seen = |i: usize| {
            streak.other_surface |= self.centres[i].1 != prim;
            let d = self.tones[i] - tone;
            streak.contrast = streak.contrast.max(d.abs().max_element());
            d
        };
        let mut bias = 0.0f32;
        for [a, b] in streak_pairs(x, y, ends) {
            let (a, b) = (at(a).map(&mut seen), at(b).map(&mut seen));
            let pair = match (a, b) {
                (Some(a), Some(b)) => (a + b) * 0.5,
                (Some(d), None) | (None, Some(d)) => d,
                (None, None) => Vec3A::ZERO,
            };
            bias = bias.max(pair.abs().max_element());
        }
        Streak { bias, ..streak }
    }

    /// What the samples added to pixel (x, y) know of the lights: those that every shadow ray
    /// of the centres around it saw fully, taken as visible where their camera rays hit. A
    /// shadow edge inside the pixel that none of the nine centres' trees met is lost, as the
    /// flat test loses a sliver between centres (docs/benchmarks-history.md §4.4).
    pub fn prior(&self, x: usize, y: usize) -> PixelPrior {
        let (w, h) = self.frame.size;
        let mut seen = 0;
        for near in around(x, y, (w, h)) {
            for nc in &self.not_clear[near] {
                seen |= nc;
            }
        }
        PixelPrior {
            known_clear: !seen,
            near: self.known_near(x, y),
        }
    }

    /// In a frame with motion whose centres kept their shadow rays' findings for the shapes
    /// that hold still: the range of distances of the hits of the centres around (x, y), and
    /// under a moving camera the span of those centres in the image. A sample whose hit lies
    /// outside them may see the lights past other shapes, so it takes none as known.
    fn known_near(&self, x: usize, y: usize) -> Option<KnownNear> {
        if !self.known_of_still {
            return None;
        }
        let (w, h) = self.frame.size;
        let mut depth = (f32::INFINITY, f32::NEG_INFINITY);
        for near in around(x, y, (w, h)) {
            for s in &self.sweeps[near] {
                // NaN (no depth kept) leaves the range as it is.
                depth = (depth.0.min(s.depth), depth.1.max(s.depth));
            }
        }
        let view_moves = self.frame.shutter.is_some_and(|s| s.camera_moves());
        let seen_from = view_moves.then(|| {
            let first = |c: usize| c.saturating_sub(1) as f32 + 0.5;
            let last = |c: usize, n: usize| (c + 1).min(n - 1) as f32 + 0.5;
            let span = [first(x), first(y), last(x, w), last(y, h)];
            (self.frame.camera.clone(), span)
        });
        Some(KnownNear { depth, seen_from })
    }
}

/// A worker's trace state for the centres of `frame`: spherical lights asked as a whole.
fn trace_state(frame: &Frame) -> TraceState {
    if frame.draws.spherical_lights() {
        TraceState::asking_whole_lights()
    } else {
        TraceState::default()
    }
}

/// What centre `sample` of `frame` (of the pinhole ray `ray`) hangs on.
fn mark(frame: &Frame, ray: &Ray, sample: &CameraSample) -> Mark {
    let blur = match sample.t {
        Some(t) if frame.draws.lens() => frame.camera.blur(ray.at(t)),
        _ => 0.0,
    };
    Mark {
        penumbra: sample.penumbra,
        blur,
    }
}

/// What the pixels along a streak show ([`FirstPass::streak`]), in tone-mapped units.
#[derive(Clone, Copy, Debug, Default)]
struct Streak {
    /// How far the worst pair's mean lies from the centre.
    bias: f32,
    /// How far the farthest pixel lies from the centre.
    contrast: f32,
    /// Whether some pixel shows another surface.
    other_surface: bool,
}

/// The 3×3 neighbourhood of pixel (x, y) in a `w`×`h` image, clipped to it: per row, the
/// range of its pixels' indices (row-major).
pub(super) fn around(
    x: usize,
    y: usize,
    (w, h): (usize, usize),
) -> impl Iterator<Item = std::ops::Range<usize>> {
    (y.saturating_sub(1)..(y + 2).min(h))
        .map(move |ny| ny * w + x.saturating_sub(1)..ny * w + (x + 2).min(w))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::mem::size_of;

    /// The memory budget's cost of a pixel (`limits::IMAGE_BYTES_PER_PIXEL`) covers every
    /// buffer the adaptive sampler keeps per pixel at its peak.
    #[test]
    fn the_budget_per_pixel_covers_the_sampler_s_buffers() {
        let first_pass = size_of::<(Vec3A, u32)>()
            + size_of::<Vec3A>()
            + size_of::<u32>()
            + size_of::<Mark>()
            + size_of::<bool>();
        let refined =
            size_of::<glam::Vec3>() + size_of::<f32>() + size_of::<u8>() + size_of::<f32>();
        let motion = size_of::<Sweep>() + size_of::<Vec3A>();
        let per_pixel = (first_pass + refined + motion) as u64;
        assert!(
            per_pixel <= crate::limits::IMAGE_BYTES_PER_PIXEL,
            "{per_pixel} bytes a pixel"
        );
    }
}
