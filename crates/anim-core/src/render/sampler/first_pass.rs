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
pub(super) struct Sweep {
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
pub(super) struct Mark {
    /// Its tree saw a spherical light in part (`CameraSample::penumbra`).
    penumbra: bool,
    /// The radius of the lens's circle of confusion at its hit, negative nearer than the
    /// plane in focus (`PinholeCamera::blur`).
    blur: f32,
}

/// Why a pixel is refined ([`FirstPass::refinement`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Refinement {
    /// The largest tone-mapped difference (8-bit levels) between its centre and those around
    /// it (or along its streak under a moving camera).
    pub contrast: f32,
    /// Motion touches it, or its value hangs on its lens or light points.
    pub moving: bool,
    /// Its value hangs on its lens or light points: a penumbra around it, or a blur that
    /// reaches it ([`FirstPass::spread_pixels`]).
    pub spread: bool,
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
            known_of_still: known_of_still(frame),
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

    /// The first pass of a frame of a shot: the centres of `kept` (the shot's previous
    /// frame's) whose rays meet nothing that has changed since (their `until` is still to
    /// come), the others traced again, watched. Also says which centres changed (all of them
    /// without `kept`): a pixel whose neighbourhood of centres is as before decides as before.
    pub fn trace_again(
        frame: &'f Frame<'f>,
        kept: Option<KeptCentres>,
        at: u32,
    ) -> (FirstPass<'f>, KeptChanges<'f>, RayCounts) {
        let (w, h) = frame.size;
        let fresh = kept.is_none();
        let kept = kept.unwrap_or_else(|| KeptCentres::fresh(w * h, frame.shutter.is_some()));
        let moving = frame.shutter.map(|s| MovingCentre::new(frame, s));
        let until = &kept.until;
        // Traced row by row in parallel, taken in afterwards: a centre's trace reads no other.
        let rows: Vec<(Vec<Retraced>, RayCounts)> = (0..h)
            .into_par_iter()
            .map(|y| {
                let mut st = frame.trace_state(false);
                let mut row = Vec::new();
                for x in (0..w).filter(|&x| until[y * w + x] <= at) {
                    let (centre, sweep, not_clear) = match &moving {
                        None => {
                            let (centre, not_clear, _) = centre_still(frame, (x, y), &mut st);
                            (centre, Sweep::default(), not_clear)
                        }
                        Some(m) => {
                            let (centre, sweep, not_clear, _) = m.trace((x, y), &mut st);
                            (centre, sweep, not_clear)
                        }
                    };
                    row.push(Retraced {
                        at: y * w + x,
                        centre,
                        sweep,
                        not_clear,
                        until: st.scratch.take_footprint(),
                    });
                }
                st.scratch.counts.primary += row.len() as u64;
                (row, st.scratch.counts)
            })
            .collect();
        let mut kept = kept;
        let before = (!fresh).then(|| FirstPass {
            frame,
            centres: kept.centres.clone(),
            tones: kept.centres.par_iter().map(|(c, _)| tone3(*c)).collect(),
            sweeps: kept.sweeps.clone(),
            not_clear: kept.not_clear.clone(),
            known_of_still: known_of_still(frame),
            marks: vec![Mark::default(); w * h],
            spread: Vec::new(),
        });
        let mut changed = vec![fresh; w * h];
        let mut counts = RayCounts::default();
        let mut retraced = vec![false; w * h];
        for (row, c) in rows {
            counts += c;
            for r in row {
                let i = r.at;
                let sweep_now = kept.sweeps.get(i).copied().unwrap_or_default();
                let same = same_centre(kept.centres[i], r.centre)
                    && kept.not_clear[i] == r.not_clear
                    && same_sweep(&sweep_now, &r.sweep);
                changed[i] |= !same;
                retraced[i] = true;
                kept.centres[i] = r.centre;
                kept.not_clear[i] = r.not_clear;
                if let Some(s) = kept.sweeps.get_mut(i) {
                    *s = r.sweep;
                }
                kept.until[i] = r.until;
            }
        }
        let mut pass = FirstPass {
            frame,
            centres: kept.centres,
            tones: Vec::new(),
            sweeps: kept.sweeps,
            not_clear: kept.not_clear,
            known_of_still: known_of_still(frame),
            marks: vec![Mark::default(); w * h],
            spread: Vec::new(),
        };
        pass.tones = pass.centres.par_iter().map(|(c, _)| tone3(*c)).collect();
        let changes = KeptChanges {
            changed,
            retraced,
            until: kept.until,
            before,
        };
        (pass, changes, counts)
    }

    /// What this first pass keeps for the shot's next frame, with the footprints of its
    /// centres.
    pub fn keep(self, until: Vec<u32>) -> KeptCentres {
        KeptCentres {
            centres: self.centres,
            not_clear: self.not_clear,
            sweeps: self.sweeps,
            until,
        }
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
                    (*px, *nc, *mk) = centre_still(frame, (x, y), &mut st);
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
        let moving = MovingCentre::new(frame, shutter);
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
                    (*px, *sw, *nc, *mk) = moving.trace((x, y), &mut st);
                }
                st.scratch.counts.primary += row.len() as u64;
                st.scratch.counts
            })
            .reduce(RayCounts::default, RayCounts::sum)
    }

    /// Whether pixel (x, y) is refined, and if so why ([`Refinement`]); `None` if it is flat
    /// and keeps its centre sample. Flat: all nine centres around it hit one surface within
    /// `FLAT_CONTRAST` levels, no centre ray around it met something moving, under a moving
    /// camera the image is flat along its streak, and its value hangs on no lens or light
    /// point.
    pub fn refinement(&self, x: usize, y: usize) -> Option<Refinement> {
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
        let spread = self.spread(x, y);
        moving |= spread;
        let flat = !moving && !other_surface && 255.0 * contrast.max(streak.bias) <= FLAT_CONTRAST;
        (!flat).then_some(Refinement {
            contrast: 255.0 * contrast.max(streak.contrast),
            moving,
            spread,
        })
    }

    /// Whether pixel (x, y)'s value hangs on its lens or light points.
    fn spread(&self, x: usize, y: usize) -> bool {
        self.spread
            .get(y * self.frame.size.0 + x)
            .copied()
            .unwrap_or(false)
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
        // A lens sends a blurred pixel's samples to points of its circle of confusion, beyond
        // the centres around it, so what their shadow rays saw does not speak for them.
        if self.frame.draws.lens() && self.spread(x, y) {
            return PixelPrior::NONE;
        }
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

    /// Whether pixel (x, y) decides its samples from this first pass as from `other` (of the
    /// same frame's size): whether it is refined and from what contrast, what its samples
    /// take as known of the lights, and, kept, its centre. Then its pixel is the same,
    /// whatever changed around it, as long as its own samples' rays meet the same things.
    pub fn decides_alike(&self, other: &FirstPass, x: usize, y: usize) -> bool {
        let refinement = |p: &FirstPass| {
            p.refinement(x, y)
                .map(|r| (r.contrast.to_bits(), r.moving, r.spread))
        };
        let prior = |p: &FirstPass| {
            let prior = p.prior(x, y);
            let near = prior.near.map(|n| {
                let span = n.seen_from.map(|(_, span)| span.map(f32::to_bits));
                (n.depth.0.to_bits(), n.depth.1.to_bits(), span)
            });
            (prior.known_clear, near)
        };
        let centre = |p: &FirstPass| {
            let (c, surface) = p.centres[y * p.frame.size.0 + x];
            (c.to_array().map(f32::to_bits), surface)
        };
        let (mine, theirs) = (refinement(self), refinement(other));
        mine == theirs
            && prior(self) == prior(other)
            && (mine.is_some() || centre(self) == centre(other))
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

/// The centre sample of pixel (`x`, `y`) of a frame in which nothing moves, ray by ray: its
/// radiance and the surface it hit (`RenderScene::surface_key`), the lights its tree did not
/// see fully, and what its lens and light points hang on.
pub(super) fn centre_still(
    frame: &Frame,
    (x, y): (usize, usize),
    st: &mut TraceState,
) -> ((Vec3A, u32), u32, Mark) {
    let ray = frame.camera.ray(x as f32 + 0.5, y as f32 + 0.5);
    let integrator = frame.integrator;
    let sample = integrator.camera_sample(&ray, &PixelPrior::NONE, st);
    let surface = integrator.scene.surface_key(sample.prim);
    let mark = mark(frame, &ray, &sample);
    ((sample.radiance, surface), sample.not_clear, mark)
}

/// How the centres of a frame with motion are traced: what the first pass keeps of their
/// shadow rays, and the probe that asks whether a pixel changes during the exposure.
pub(super) struct MovingCentre<'f> {
    frame: &'f Frame<'f>,
    shutter: &'f Shutter,
    probe: MotionProbe<'f>,
    /// The centres' shadow findings are kept for the shapes that hold still.
    of_still: bool,
    /// The centres' shadow findings are kept at all.
    shadows_hold: bool,
}

impl<'f> MovingCentre<'f> {
    pub(super) fn new(frame: &'f Frame<'f>, shutter: &'f Shutter) -> Self {
        // A light a centre's shadow rays saw fully stays so only while it holds still.
        // Then, where the moving shapes are few enough to ask at each sample's instant, what
        // they saw is kept as news of the shapes that hold still, with how far the centre's
        // hit is (see `KnownNear`); otherwise, only while the camera holds still too (so
        // that the refined samples hit near the centres), for centres none of whose rays may
        // meet anything moving.
        let of_still = frame.integrator.scene.plan().0.ask_moving;
        MovingCentre {
            frame,
            shutter,
            probe: MotionProbe::new(frame, shutter),
            of_still,
            shadows_hold: !shutter.lights_move() && (of_still || !shutter.camera_moves()),
        }
    }

    /// The centre of pixel (`x`, `y`) at the middle of the exposure, watched for the moving
    /// shapes its rays may meet: its radiance and surface, how it saw the motion, the lights
    /// its tree did not see fully (all of them where that is not kept), and what its lens and
    /// light points hang on. Counts the probe's camera rays, not the centre's.
    pub(super) fn trace(
        &self,
        (x, y): (usize, usize),
        st: &mut TraceState,
    ) -> ((Vec3A, u32), Sweep, u32, Mark) {
        let frame = self.frame;
        let ray = frame.camera.ray(x as f32 + 0.5, y as f32 + 0.5);
        let integrator = frame.integrator;
        let sample = integrator.camera_sample_swept(&ray, &PixelPrior::NONE, st);
        let px = (sample.radiance, integrator.scene.surface_key(sample.prim));
        let mark = mark(frame, &ray, &sample);
        let mut sw = Sweep::default();
        let mut nc = u32::MAX;
        let swept = sample.swept;
        if self.shadows_hold && (self.of_still || swept == 0.0) {
            nc = sample.not_clear;
            if self.of_still {
                sw.depth = sample.t.unwrap_or(f32::NAN);
            }
        }
        let (x, y) = (x as u32, y as u32);
        sw.touched = swept > 0.0 && self.probe.changes((x, y), px, swept, st);
        if self.shutter.camera_moves() {
            sw.streak = self.probe.camera_sweep(x, y, sample.t);
        }
        (px, sw, nc, mark)
    }
}

/// What the first pass of a frame of a shot keeps for the next: per pixel its centre, the
/// lights its tree did not see fully, how it saw the motion (in a frame with motion), and
/// the first later frame that changes what its rays met.
pub(super) struct KeptCentres {
    centres: Vec<(Vec3A, u32)>,
    not_clear: Vec<u32>,
    sweeps: Vec<Sweep>,
    until: Vec<u32>,
}

impl KeptCentres {
    /// Nothing kept: every centre is traced (its `until` is frame 0).
    fn fresh(pixels: usize, motion: bool) -> KeptCentres {
        KeptCentres {
            centres: vec![(Vec3A::ZERO, 0); pixels],
            not_clear: vec![u32::MAX; pixels],
            sweeps: vec![Sweep::default(); if motion { pixels } else { 0 }],
            until: vec![0; pixels],
        }
    }

    /// Whether these are the centres of a frame of `pixels` pixels, with motion or without.
    pub(super) fn fits(&self, pixels: usize, motion: bool) -> bool {
        self.centres.len() == pixels && (self.sweeps.len() == pixels) == motion
    }
}

/// What [`FirstPass::trace_again`] found, per pixel, and the first pass it started from.
pub(super) struct KeptChanges<'f> {
    /// Whether the centre is not what it was (every centre, where nothing was kept).
    pub changed: Vec<bool>,
    /// Whether the centre was traced again.
    pub retraced: Vec<bool>,
    /// The first later frame that changes what the centre's rays met.
    pub until: Vec<u32>,
    /// The first pass of the frame before (`None` where nothing was kept).
    pub before: Option<FirstPass<'f>>,
}

/// Whether the centres of `frame` keep their shadow rays' findings as news of the shapes
/// that hold still, with the depth of their hits (a frame with motion whose lights hold
/// still and whose moving shapes are few enough to ask at each sample's instant).
fn known_of_still(frame: &Frame) -> bool {
    frame.shutter.is_some_and(|s| !s.lights_move()) && frame.integrator.scene.plan().0.ask_moving
}

/// A centre traced again, to be taken into the first pass.
struct Retraced {
    at: usize,
    centre: (Vec3A, u32),
    sweep: Sweep,
    not_clear: u32,
    until: u32,
}

/// Whether two centres are the same to the bit.
fn same_centre(a: (Vec3A, u32), b: (Vec3A, u32)) -> bool {
    a.1 == b.1 && a.0.to_array().map(f32::to_bits) == b.0.to_array().map(f32::to_bits)
}

/// Whether two centres saw the motion the same, to the bit.
fn same_sweep(a: &Sweep, b: &Sweep) -> bool {
    let bits = |s: &Sweep| {
        let ends = s.streak.map(|e| e.map(|(x, y)| (x.to_bits(), y.to_bits())));
        (s.touched, ends, s.depth.to_bits())
    };
    bits(a) == bits(b)
}

/// A worker's trace state for the centres of `frame`: spherical lights asked as a whole.
fn trace_state(frame: &Frame) -> TraceState {
    if frame.draws.spherical_lights() {
        // Never watched: frames that draw are not traced as frames of a shot
        // (`sampler::render_again`).
        TraceState::asking_whole_lights()
    } else {
        frame.trace_state(false)
    }
}

/// What centre `sample` of `frame` (of the pinhole ray `ray`) hangs on.
fn mark(frame: &Frame, ray: &Ray, sample: &CameraSample) -> Mark {
    // The background lies beyond everything: the lens spreads what lies in front of it over
    // it as far as a point at infinity spreads.
    let blur = match sample.t {
        _ if !frame.draws.lens() => 0.0,
        Some(t) => frame.camera.blur(ray.at(t)),
        None => frame.camera.blur_at_infinity(),
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
