//! Rendering: compile a scene description, trace its rows in parallel (rayon), tone-map,
//! write the image.

pub mod camera;
pub mod compile;
pub mod film;
pub mod integrator;
pub mod motion;
mod packet;
pub mod primitive;
pub mod sampling;

use crate::math::Transform;
use crate::scene::{Camera, RenderJob, Scene};
use camera::{sample_offsets, CameraError, CameraRays};
use compile::RenderScene;
use glam::{DVec3, Vec3, Vec3A};
use integrator::{Integrator, KnownNear, TraceState, NO_HIT};
use motion::Shutter;
use rayon::prelude::*;
use sampling::PixelPattern;
use std::path::PathBuf;

#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Uniform sampling with this many samples per pixel; overrides everything else.
    pub spp: Option<u32>,
    /// Adaptive sampling's target standard error per pixel, in 8-bit levels.
    pub error: Option<f32>,
    /// Adaptive sampling's most samples for one pixel.
    pub max_spp: Option<u32>,
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub max_depth: u32,
    pub ppm_ascii: bool,
    /// Images go here instead of beside the scene file.
    pub out_dir: Option<PathBuf>,
    /// Honour render lines that write outside the output folder (absolute paths, `..`).
    pub allow_any_output: bool,
    /// Bytes one image may take while it is made; bigger images are refused before any
    /// allocation.
    pub max_memory: u64,
    /// Also write each image's linear radiance beside it as PFM (`film::hdr_path`).
    pub hdr: bool,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            spp: None,
            error: None,
            max_spp: None,
            width: None,
            height: None,
            max_depth: crate::limits::DEFAULT_MAX_DEPTH,
            ppm_ascii: false,
            out_dir: None,
            allow_any_output: false,
            max_memory: crate::limits::default_memory_budget(),
            hdr: false,
        }
    }
}

/// How many rays of each kind a render traced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    pub primary: u64,
    pub shadow: u64,
    pub reflected: u64,
    pub refracted: u64,
}

impl RayCounts {
    pub fn total(&self) -> u64 {
        self.primary + self.shadow + self.reflected + self.refracted
    }
}

/// Linear (HDR) radiance per pixel, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct HdrImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Vec3>,
}

impl std::ops::AddAssign for RayCounts {
    fn add_assign(&mut self, o: RayCounts) {
        self.primary += o.primary;
        self.shadow += o.shadow;
        self.reflected += o.reflected;
        self.refracted += o.refracted;
    }
}

/// How the samples of a render are placed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sampling {
    /// The same count everywhere: the centre for 1, a k×k grid for k², Hammersley otherwise.
    Uniform(u32),
    /// A centre sample everywhere, then scrambled Sobol samples where a pixel needs them.
    Adaptive { error: f32, max_spp: u32 },
}

impl Sampling {
    /// The fewest samples any pixel takes.
    pub fn least_spp(&self) -> u32 {
        match *self {
            Sampling::Uniform(n) => n,
            Sampling::Adaptive { .. } => 1,
        }
    }

    /// The most samples any pixel may take.
    pub fn max_spp(&self) -> u32 {
        match *self {
            Sampling::Uniform(n) => n,
            Sampling::Adaptive { max_spp, .. } => max_spp,
        }
    }
}

impl RenderSettings {
    /// The image size and the most samples per pixel for `job` under these settings.
    pub fn resolve(&self, job: &RenderJob) -> (u32, u32, u32) {
        (
            self.width.unwrap_or(job.width),
            self.height.unwrap_or(job.height),
            self.sampling(job).max_spp(),
        )
    }

    /// `--spp` asks for uniform sampling; otherwise `--error`/`--max-spp` ask for adaptive;
    /// otherwise a render line's own sample count is the author's uniform request; with
    /// none of these, adaptive sampling with the defaults.
    pub fn sampling(&self, job: &RenderJob) -> Sampling {
        if let Some(n) = self.spp {
            return Sampling::Uniform(n.max(1));
        }
        if self.error.is_none() && self.max_spp.is_none() {
            if let Some(n) = job.samples {
                return Sampling::Uniform(n.max(1));
            }
        }
        Sampling::Adaptive {
            error: self.error.unwrap_or(crate::limits::DEFAULT_ERROR),
            max_spp: self
                .max_spp
                .unwrap_or(crate::limits::DEFAULT_MAX_SPP)
                .max(1),
        }
    }
}

/// One rendered image and what it took.
#[derive(Clone, Debug)]
pub struct Rendered {
    pub image: HdrImage,
    pub rays: RayCounts,
    /// Camera samples traced per pixel, on average.
    pub mean_spp: f64,
    /// Shapes that became degenerate once transformed (in f32) and were left out.
    pub dropped: Vec<compile::Dropped>,
}

/// The job's scene and camera moved (in f64) so that the eye sits at the origin, or `None`
/// when it already does. Rendering works in f32, which keeps about 7 digits relative to a
/// coordinate's magnitude: a scene far from the world origin would lose its detail near the
/// camera, where the picture needs it most. Moved together, the picture is the same.
fn camera_relative(job: &RenderJob) -> Option<(Scene, Camera)> {
    let eye = job.camera.eye;
    if eye == DVec3::ZERO {
        return None;
    }
    let to_camera = Transform::translate(-eye);
    // The instances are shared, not copied: only the table of transforms is.
    let mut scene = job.scene.clone();
    scene.transform_all(&to_camera);
    for light in &mut scene.lights {
        light.position -= eye;
    }
    let camera = Camera {
        eye: DVec3::ZERO,
        ..job.camera.clone()
    };
    Some((scene, camera))
}

/// Renders one job to an HDR image. `on_pixels(n)` is called as each band of `n` pixels
/// finishes.
pub fn render_job(
    job: &RenderJob,
    settings: &RenderSettings,
    on_pixels: &(dyn Fn(u64) + Sync),
) -> Result<Rendered, CameraError> {
    let (width, height, _) = settings.resolve(job);
    let rebased = camera_relative(job);
    let (scene, camera) = rebased
        .as_ref()
        .map_or((&job.scene, &job.camera), |(s, c)| (s, c));
    let shutter = scene
        .motion
        .as_ref()
        .map(|m| Shutter::new(m, camera, width, height));
    let shutter = shutter.as_ref();
    let camera = CameraRays::new(camera, width, height)?;
    let (mut scene, dropped) = RenderScene::compile(scene);
    scene.watch_from(camera.eye());
    let sampling = settings.sampling(job);
    if shutter.is_none() {
        let camera_rays = u64::from(width) * u64::from(height) * u64::from(sampling.least_spp());
        scene.watch_image(camera.view(), (width, height), camera_rays);
    }
    let integrator = Integrator {
        scene: &scene,
        max_depth: settings.max_depth,
    };
    let (pixels, counts) = match sampling {
        Sampling::Uniform(spp) => {
            render_uniform(&camera, shutter, &integrator, width, height, spp, on_pixels)
        }
        Sampling::Adaptive { error, max_spp } => render_adaptive(
            &camera,
            shutter,
            &integrator,
            (width, height),
            error,
            max_spp,
            on_pixels,
        ),
    };
    Ok(Rendered {
        image: HdrImage {
            width,
            height,
            pixels,
        },
        mean_spp: counts.primary as f64 / (width as f64 * height as f64),
        rays: counts,
        dropped,
    })
}

/// Every pixel takes the same `spp` samples at the same sub-pixel offsets (and, in a frame
/// with motion, at instants of the exposure stratified per pixel: `sampling::uniform_time`).
fn render_uniform(
    camera: &CameraRays,
    shutter: Option<&Shutter>,
    integrator: &Integrator,
    width: u32,
    height: u32,
    spp: u32,
    on_pixels: &(dyn Fn(u64) + Sync),
) -> (Vec<Vec3>, RayCounts) {
    let offsets = sample_offsets(spp);
    let mut pixels = vec![Vec3::ZERO; (width * height) as usize];
    // Bands of whole rows, written where they lie in the image: each pixel depends only on
    // its own position, so the result is the same for any thread count or band order.
    let rows = packet::BLOCK_H;
    let counts = pixels
        .par_chunks_mut((width * rows).max(1) as usize)
        .enumerate()
        .map(|(i, band)| {
            let y0 = i as u32 * rows;
            let mut st = TraceState::default();
            let packed = shutter.is_none()
                && packet::render_band(camera, integrator, (y0, width), band, &offsets, &mut st);
            if !packed {
                for (k, out) in band.iter_mut().enumerate() {
                    let (x, y) = (k as u32 % width, y0 + k as u32 / width);
                    *out = uniform_pixel(camera, shutter, integrator, (x, y), &offsets, &mut st);
                }
                st.counts.primary += (band.len() * offsets.len()) as u64;
            }
            on_pixels(band.len() as u64);
            st.counts
        })
        .reduce(RayCounts::default, add_counts);
    (pixels, counts)
}

/// Pixel (`x`, `y`) of uniform sampling ray by ray: the mean of its samples at `offsets`
/// (in a frame with motion, at the instants `sampling::uniform_time` gives them), added in
/// that order, as the camera packets add theirs. Does not count the camera rays.
pub(super) fn uniform_pixel(
    camera: &CameraRays,
    shutter: Option<&Shutter>,
    integrator: &Integrator,
    (x, y): (u32, u32),
    offsets: &[(f32, f32)],
    st: &mut TraceState,
) -> Vec3 {
    let mut sum = Vec3A::ZERO;
    for (i, &(dx, dy)) in offsets.iter().enumerate() {
        let (px, py) = (x as f32 + dx, y as f32 + dy);
        let ray = match shutter {
            None => camera.ray(px, py),
            Some(s) => {
                let n = offsets.len() as u32;
                s.ray(camera, px, py, sampling::uniform_time(x, y, i as u32, n))
            }
        };
        sum += integrator.trace_primary(&ray, st).0;
    }
    Vec3::from(sum * (1.0 / offsets.len() as f32))
}

/// How a pixel's centre ray saw the motion of a frame (adaptive sampling's first pass).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Sweep {
    /// Its rays may meet a moving shape (`Moving::met_by`), and it changes during the exposure
    /// (`Shutter::changes`).
    touched: bool,
    /// The ends of the streak the camera's motion draws its hit point along (pixels from
    /// its centre), along which the image must be flat for it to keep its centre sample;
    /// `None` when it sweeps too far for that (`Shutter::camera_sweep`).
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

fn add_counts(mut a: RayCounts, b: RayCounts) -> RayCounts {
    a += b;
    a
}

/// Adaptive sampling (see `sampling`), in two passes over the image (three with motion).
///
/// 1. One ray through every pixel centre (exactly `--spp 1`), keeping the primitive it hit.
/// 2. A pixel whose 3×3 neighbourhood of centres shows one surface and at most
///    `FLAT_CONTRAST` levels of contrast keeps its centre value: on such a surface the
///    shading is smooth and the centre is the pixel mean up to its curvature. This holds for
///    a mirror showing a flat wall as much as for the wall, so secondary rays alone do not
///    force more samples; an edge in the reflection shows as contrast. Every other pixel
///    drops its centre sample and takes scrambled Sobol samples, at least as many as its
///    neighbourhood contrast calls for (`sampling::min_samples`), then doubling until the
///    estimated error of its tone-mapped mean is at most `error` levels, or `max_spp`.
///
/// The neighbourhood test is what catches features thinner than the base spacing: a sliver
/// seen by one centre marks all eight pixels around it. Pass 2 reads only the finished pass 1
/// and writes each pixel from its own position, so the image does not depend on the thread
/// count, and each pixel's pattern depends on its position only, so it does not crawl from
/// frame to frame of an animation.
///
/// In a frame with motion, the first pass takes the middle of the exposure and the samples of
/// pass 2 carry instants (`PixelPattern::time`). A pixel is not flat when the rays of a centre
/// sample around it may meet a moving shape at some instant, nor when the camera's motion
/// sweeps its hit point across a neighbourhood whose two halves do not average to its centre.
/// Such a pixel takes at least `MOTION_MIN_SAMPLES`, and pass 3 (`recheck_motion`) goes on
/// with those whose samples all agreed but whose neighbours show otherwise
/// (docs/scene-language.md §10).
fn render_adaptive(
    camera: &CameraRays,
    shutter: Option<&Shutter>,
    integrator: &Integrator,
    (width, height): (u32, u32),
    error: f32,
    max_spp: u32,
    on_pixels: &(dyn Fn(u64) + Sync),
) -> (Vec<Vec3>, RayCounts) {
    let (w, h) = (width as usize, height as usize);
    let mut base = vec![(Vec3A::ZERO, NO_HIT); w * h];
    // Per pixel, in a frame with motion: how its centre ray saw the motion (`Sweep`).
    let mut sweeps = vec![Sweep::default(); if shutter.is_some() { w * h } else { 0 }];
    // Per pixel: the lights some shadow ray of its centre's tree did not see fully
    // (`TraceState::not_clear`); all of them where that is not recorded.
    let mut not_clear = vec![u32::MAX; w * h];
    let base_counts = match shutter {
        None => base
            .par_chunks_mut(w)
            .zip(not_clear.par_chunks_mut(w))
            .enumerate()
            .map(|(y, (row, not_clear_row))| {
                let mut st = TraceState::default();
                if packet::trace_centres(camera, integrator, y, row, not_clear_row, &mut st) {
                    return st.counts;
                }
                for (x, (px, nc)) in row.iter_mut().zip(not_clear_row).enumerate() {
                    let ray = camera.ray(x as f32 + 0.5, y as f32 + 0.5);
                    st.not_clear = 0;
                    *px = integrator.trace_primary(&ray, &mut st);
                    *nc = st.not_clear;
                }
                st.counts.primary += row.len() as u64;
                st.counts
            })
            .reduce(RayCounts::default, add_counts),
        Some(s) => base
            .par_chunks_mut(w)
            .zip(sweeps.par_chunks_mut(w))
            .zip(not_clear.par_chunks_mut(w))
            .enumerate()
            .map(|(y, ((row, sweep_row), not_clear_row))| {
                let mut st = TraceState::default();
                // A light a centre's shadow rays saw fully stays so only while it holds still.
                // Then, where the moving shapes are few enough to ask at each sample's
                // instant, what they saw is kept as news of the shapes that hold still, with
                // how far the centre's hit is (see `known_clear_near`); otherwise, only while
                // the camera holds still too (so that the refined samples hit near the
                // centres), for centres none of whose rays may meet anything moving.
                let of_still = integrator.scene.answers_moving_blocks();
                let shadows_hold = !s.lights_move() && (of_still || !s.camera_moves());
                let pixels = row.iter_mut().zip(sweep_row).zip(not_clear_row);
                for (x, ((px, sw), nc)) in pixels.enumerate() {
                    let ray = camera.ray(x as f32 + 0.5, y as f32 + 0.5);
                    compile::motion::watch();
                    st.not_clear = 0;
                    let (colour, prim, t) = integrator.trace_primary_hit(&ray, &mut st);
                    *px = (colour, prim);
                    let swept = compile::motion::take_touched();
                    if shadows_hold && (of_still || swept == 0.0) {
                        *nc = st.not_clear;
                        if of_still {
                            sw.depth = t.unwrap_or(f32::NAN);
                        }
                    }
                    sw.touched = swept > 0.0
                        && s.changes(
                            integrator,
                            camera,
                            (x as u32, y as u32),
                            *px,
                            swept,
                            &mut st,
                        );
                    if s.camera_moves() {
                        sw.streak = s.camera_sweep(camera, x as u32, y as u32, t);
                    }
                }
                st.counts.primary += row.len() as u64;
                st.counts
            })
            .reduce(RayCounts::default, add_counts),
    };

    let base = &base;
    let sweeps = &sweeps;
    // Each centre tone-mapped once: a pixel's neighbourhood, and its streak under a moving
    // camera, read many of them.
    let tones: Vec<Vec3A> = base.par_iter().map(|(c, _)| sampling::tone3(*c)).collect();
    let tones = &tones;
    let not_clear = &not_clear;
    let known_of_still =
        shutter.is_some_and(|s| !s.lights_move()) && integrator.scene.answers_moving_blocks();
    let view_moves = shutter.is_some_and(|s| s.camera_moves());
    // The lights that every shadow ray of the centres around (x, y) saw fully: a refined
    // pixel's samples take them as visible, without shadow rays, where their camera rays
    // hit. A shadow edge inside the pixel that none of the nine centres' trees met is lost,
    // as the flat test loses a sliver between centres (BENCHMARKS.md §4.4: RMSE +0.002 to
    // +0.003 on the rooms for 10 % of their shadow rays, 17 % of the showcase's; taken at
    // every depth it skipped more but cost the held-out room 0.035).
    let known_clear = |x: usize, y: usize| -> u32 {
        let mut seen = 0;
        for near in around(x, y, (w, h)) {
            for nc in &not_clear[near] {
                seen |= nc;
            }
        }
        !seen
    };
    // In a frame with motion whose centres kept their shadow rays' findings for the shapes
    // that hold still: the range of distances of the hits of the centres around (x, y), and
    // under a moving camera the span of those centres in the image. A sample whose hit lies
    // outside them may see the lights past other shapes, so it takes none as known
    // (`KnownNear`).
    let known_clear_near = |x: usize, y: usize| -> Option<KnownNear> {
        if !known_of_still {
            return None;
        }
        let mut depth = (f32::INFINITY, f32::NEG_INFINITY);
        for near in around(x, y, (w, h)) {
            for s in &sweeps[near] {
                // NaN (no depth kept) leaves the range as it is.
                depth = (depth.0.min(s.depth), depth.1.max(s.depth));
            }
        }
        let seen_from = view_moves.then(|| {
            let first = |c: usize| c.saturating_sub(1) as f32 + 0.5;
            let last = |c: usize, n: usize| (c + 1).min(n - 1) as f32 + 0.5;
            let span = [first(x), first(y), last(x, w), last(y, h)];
            (camera.clone(), span)
        });
        Some(KnownNear { depth, seen_from })
    };
    // The largest tone-mapped difference (8-bit levels) between the centre of (x, y) and the
    // centres around it, or None if the pixel is flat and keeps its centre sample.
    let edge_contrast = |x: usize, y: usize| -> Option<(f32, bool)> {
        let prim = base[y * w + x].1;
        let tone = tones[y * w + x];
        let mut contrast = 0.0f32;
        let mut other_surface = false;
        // In a moving frame, a pixel next to one whose centre ray met something moving is not
        // flat, and the image must be flat along the streak the camera's motion draws.
        let mut moving = false;
        for near in around(x, y, (w, h)) {
            for (t, (_, p)) in tones[near.clone()].iter().zip(&base[near.clone()]) {
                other_surface |= *p != prim;
                contrast = contrast.max((*t - tone).abs().max_element());
            }
            if !sweeps.is_empty() {
                moving |= sweeps[near].iter().any(|s| s.touched);
            }
        }
        // Along the streak, the pixel's value is the mean of what its two halves show: flat
        // when every pair of points that far along the two halves averages to the centre
        // (a steady gradient does), though the points themselves may differ more.
        let mut streak_bias = 0.0f32;
        let mut streak_contrast = 0.0f32;
        match sweeps.get(y * w + x).map(|s| s.streak) {
            None => {}
            Some(None) => moving = true,
            Some(Some(ends)) => {
                let at = |(px, py): (i64, i64)| {
                    (px >= 0 && py >= 0 && px < w as i64 && py < h as i64)
                        .then(|| py as usize * w + px as usize)
                };
                let mut seen = |i: usize| {
                    other_surface |= base[i].1 != prim;
                    let d = tones[i] - tone;
                    streak_contrast = streak_contrast.max(d.abs().max_element());
                    d
                };
                for [a, b] in Shutter::streak_pairs(x, y, ends) {
                    let (a, b) = (at(a).map(&mut seen), at(b).map(&mut seen));
                    let bias = match (a, b) {
                        (Some(a), Some(b)) => (a + b) * 0.5,
                        (Some(d), None) | (None, Some(d)) => d,
                        (None, None) => Vec3A::ZERO,
                    };
                    streak_bias = streak_bias.max(bias.abs().max_element());
                }
            }
        }
        let flat = !moving
            && !other_surface
            && 255.0 * contrast.max(streak_bias) <= sampling::FLAT_CONTRAST;
        (!flat).then_some((255.0 * contrast.max(streak_contrast), moving))
    };

    // Sample `i` of pixel (x, y)'s own pattern, after `know`.
    let sample = |(x, y): (usize, usize), pattern: &PixelPattern, i: u32, st: &mut TraceState| {
        let (dx, dy) = pattern.sample(i);
        let (px, py) = (x as f32 + dx, y as f32 + dy);
        let ray = match shutter {
            None => camera.ray(px, py),
            Some(s) => s.ray(camera, px, py, pattern.time(i)),
        };
        integrator.trace_primary(&ray, st).0
    };
    // What a pixel's samples know of the lights before they trace (`TraceState`).
    let know = |x: usize, y: usize, st: &mut TraceState| {
        st.known_clear = known_clear(x, y);
        st.known_clear_near = known_clear_near(x, y);
    };

    let mut pixels = vec![Vec3::ZERO; w * h];
    // Per pixel: the samples pass 2 took, up to 255 (0: it kept its centre), for pass 3.
    let mut taken = vec![0u8; w * h];
    let refine_counts = pixels
        .par_chunks_mut(w)
        .zip(taken.par_chunks_mut(w))
        .enumerate()
        .map(|(y, (row, taken_row))| {
            let mut st = TraceState::refining();
            for (x, out) in row.iter_mut().enumerate() {
                let Some((contrast, moving)) = edge_contrast(x, y).filter(|_| max_spp > 1) else {
                    *out = Vec3::from(base[y * w + x].0);
                    continue;
                };
                let mut at_least = sampling::min_samples(contrast, error, max_spp);
                if moving {
                    at_least = at_least.max(sampling::MOTION_MIN_SAMPLES).min(max_spp);
                }
                know(x, y, &mut st);
                let pattern = PixelPattern::new(x as u32, y as u32);
                let mut m = sampling::Moments::default();
                while m.n < max_spp {
                    m.add(sample((x, y), &pattern, m.n, &mut st));
                    // Checked at powers of two only: there every prefix is a full net.
                    if m.n >= at_least && m.n.is_power_of_two() && m.error() <= error {
                        break;
                    }
                }
                st.counts.primary += m.n as u64;
                *out = Vec3::from(m.mean());
                taken_row[x] = m.n.min(u8::MAX as u32) as u8;
            }
            on_pixels(row.len() as u64);
            st.counts
        })
        .reduce(RayCounts::default, add_counts);
    let mut counts = add_counts(base_counts, refine_counts);
    if shutter.is_some() && max_spp > 1 {
        let motion_contrast = |x: usize, y: usize| {
            edge_contrast(x, y)
                .filter(|&(_, moving)| moving)
                .map(|(contrast, _)| contrast)
        };
        let frame = (&taken[..], (w, h));
        counts += recheck_motion(
            &mut pixels,
            frame,
            error,
            max_spp,
            motion_contrast,
            (&know, &sample),
        );
    }
    (pixels, counts)
}

/// The 3×3 neighbourhood of pixel (x, y) in a `w`×`h` image, clipped to it: per row, the
/// range of its pixels' indices (row-major).
fn around(
    x: usize,
    y: usize,
    (w, h): (usize, usize),
) -> impl Iterator<Item = std::ops::Range<usize>> {
    (y.saturating_sub(1)..(y + 2).min(h))
        .map(move |ny| ny * w + x.saturating_sub(1)..ny * w + (x + 2).min(w))
}

/// Sets what a pixel's samples know of the lights (`TraceState::known_clear`).
type Know<'a> = dyn Fn(usize, usize, &mut TraceState) + Sync + 'a;
/// Sample `i` of a pixel's own pattern: its radiance.
type Sample<'a> = dyn Fn((usize, usize), &PixelPattern, u32, &mut TraceState) -> Vec3A + Sync + 'a;

/// Pass 3 of adaptive sampling in a frame with motion. A pixel that motion touches and whose
/// samples all agreed stops at `MOTION_MIN_SAMPLES`, though something moving may have covered
/// it for a part of the exposure that none of its instants fell in (a shadow's blurred end, a
/// thin edge). Its neighbours' samples tell: where its mean differs from a neighbour's by
/// more than the first pass's contrast around it (`motion_contrast`, levels; `None` where
/// motion does not touch it) and twice the error target, it goes on with its own pattern
/// (`sample`, after `know`), doubling its samples until the new half agrees with the old
/// (`Moments::resume`) or it reaches `max_spp`. Reads only pass 2's finished image, so the result
/// does not depend on the order pixels are visited in.
fn recheck_motion(
    pixels: &mut [Vec3],
    (taken, (w, h)): (&[u8], (usize, usize)),
    error: f32,
    max_spp: u32,
    motion_contrast: impl Fn(usize, usize) -> Option<f32> + Sync,
    (know, sample): (&Know<'_>, &Sample<'_>),
) -> RayCounts {
    let tones: Vec<Vec3A> = pixels
        .par_iter()
        .map(|c| sampling::tone3(Vec3A::from(*c)))
        .collect();
    let tones = &tones;
    pixels
        .par_chunks_mut(w)
        .enumerate()
        .map(|(y, row)| {
            let mut st = TraceState::refining();
            for (x, out) in row.iter_mut().enumerate() {
                let n = taken[y * w + x] as u32;
                if n == 0 || n > sampling::MOTION_MIN_SAMPLES || n >= max_spp {
                    continue;
                }
                let Some(contrast) = motion_contrast(x, y) else {
                    continue;
                };
                let tone = tones[y * w + x];
                let mut differs = 0.0f32;
                for near in around(x, y, (w, h)) {
                    for t in &tones[near] {
                        differs = differs.max((*t - tone).abs().max_element());
                    }
                }
                if 255.0 * differs <= contrast + 2.0 * error {
                    continue;
                }
                know(x, y, &mut st);
                let pattern = PixelPattern::new(x as u32, y as u32);
                let mut m = sampling::Moments::resume(Vec3A::from(*out), n);
                while m.n < max_spp {
                    m.add(sample((x, y), &pattern, m.n, &mut st));
                    if m.n.is_power_of_two() && m.error() <= error {
                        break;
                    }
                }
                st.counts.primary += (m.n - n) as u64;
                *out = Vec3::from(m.mean());
            }
            st.counts
        })
        .reduce(RayCounts::default, add_counts)
}

#[cfg(test)]
mod tests;
