//! Samplers: where each pixel's camera samples go and when a pixel has enough. Each traces
//! its samples through the frame's camera and the integrator into the pixels of the film.
//!
//! - `uniform`: the same samples in every pixel.
//! - `adaptive`: one sample in every pixel, then more where the first pass says a pixel
//!   needs them (`first_pass`), at the points of each pixel's own scrambled Sobol pattern
//!   ([`pattern`]). What the first pass learned travels to the integrator as a value, the
//!   `PixelPrior` of the first samples it adds (`pattern::PRIOR_SAMPLES`).
//!   In a frame with motion, `motion` answers what the first pass asks of it.
//! - `packet`: camera rays of still frames, traced a block at a time.

mod adaptive;
mod first_pass;
mod motion;
mod packet;
pub mod pattern;
mod uniform;

pub use uniform::sample_offsets;

use super::camera::PinholeCamera;
use super::compile::Scratch;
use super::counts::RayCounts;
use super::footprint::Ahead;
use super::integrator::{Integrator, TraceState};
use super::motion::Shutter;
use super::settings::Sampling;
use glam::Vec3;
use std::sync::Arc;

/// One frame as a sampler sees it.
pub(super) struct Frame<'a> {
    /// The camera in the middle of the exposure.
    pub camera: &'a PinholeCamera,
    /// The exposure, when something moves during it.
    pub shutter: Option<&'a Shutter>,
    pub integrator: &'a Integrator<'a>,
    /// Width and height in pixels.
    pub size: (usize, usize),
    /// In a frame of a shot, what the later frames change: every pixel's rays are watched
    /// against it (`crate::render::footprint`), one pixel at a time.
    pub ahead: Option<Arc<Ahead>>,
}

impl Frame<'_> {
    /// A worker's state for tracing this frame's camera samples (`refining`: adaptive
    /// sampling's added samples, `TraceState::refining`), watching in a frame of a shot.
    fn trace_state(&self, refining: bool) -> TraceState {
        let mut st = if refining {
            TraceState::refining()
        } else {
            TraceState::default()
        };
        if self.ahead.is_some() {
            st.scratch = Scratch::watching(self.ahead.clone());
        }
        st
    }
}

/// What a sampler made of a frame.
pub(super) struct Sampled {
    /// Linear radiance, row-major from the top.
    pub pixels: Vec<Vec3>,
    /// Per pixel, the fraction of its camera samples that hit a surface (see
    /// `Rendered::coverage`).
    pub coverage: Vec<f32>,
    pub rays: RayCounts,
    /// Adaptive sampling's estimate of each pixel's error (see `Rendered::error_estimates`);
    /// empty for uniform sampling.
    pub error_estimates: Vec<f32>,
}

/// The pixels of `frame` sampled as `sampling` says, and the rays traced; `on_pixels(n)` is
/// called as each band of `n` pixels finishes.
pub(super) fn render(
    frame: &Frame,
    sampling: Sampling,
    on_pixels: &(dyn Fn(u64) + Sync),
) -> Sampled {
    match sampling {
        Sampling::Uniform(spp) => uniform::render(frame, spp, on_pixels),
        Sampling::Adaptive { error, max_spp } => adaptive::Adaptive {
            frame,
            error,
            max_spp,
        }
        .render(on_pixels),
    }
}

/// The fraction of `n` camera samples that hit a surface, `hits` of them: exactly 0 or 1
/// where none or all did.
fn coverage(hits: u32, n: u32) -> f32 {
    hits as f32 / n as f32
}

/// What a frame of a shot keeps for the next: its pixels and their coverage, per pixel the
/// first later frame of the shot that changes what the rays of its samples met (adaptive
/// sampling: the samples it added to its centre), and adaptive sampling's passes.
pub(super) struct Kept {
    pixels: Vec<Vec3>,
    coverage: Vec<f32>,
    until: Vec<u32>,
    error_estimates: Vec<f32>,
    passes: Option<adaptive::KeptPasses>,
}

impl Kept {
    /// Nothing kept, for `pixels` pixels: every one is traced (its `until` is frame 0).
    fn fresh(pixels: usize) -> Kept {
        Kept {
            pixels: vec![Vec3::ZERO; pixels],
            coverage: vec![0.0; pixels],
            until: vec![0; pixels],
            error_estimates: vec![f32::NAN; pixels],
            passes: None,
        }
    }
}

/// Frame `at` of a shot, sampled as `sampling` says, from what the shot's previous frame
/// kept (`None`: every pixel traced); what it keeps for the next frame, and how many pixels
/// it traced again. The pixels are those of a render of the frame alone, to the bit.
pub(super) fn render_again(
    frame: &Frame,
    sampling: Sampling,
    at: u32,
    kept: Option<Kept>,
    on_pixels: &(dyn Fn(u64) + Sync),
) -> (Sampled, Kept, u64) {
    let pixels = frame.size.0 * frame.size.1;
    let kept = kept.filter(|k| k.pixels.len() == pixels);
    match sampling {
        Sampling::Uniform(spp) => {
            let kept = kept.filter(|k| k.passes.is_none());
            let kept = kept.map(|k| (k.pixels, k.coverage, k.until));
            let again = uniform::render_again(frame, spp, at, kept, on_pixels);
            let sampled = Sampled {
                pixels: again.pixels.clone(),
                coverage: again.coverage.clone(),
                rays: again.rays,
                error_estimates: Vec::new(),
            };
            let kept = Kept {
                pixels: again.pixels,
                coverage: again.coverage,
                until: again.until,
                error_estimates: Vec::new(),
                passes: None,
            };
            (sampled, kept, again.retraced)
        }
        Sampling::Adaptive { error, max_spp } => adaptive::Adaptive {
            frame,
            error,
            max_spp,
        }
        .render_again(at, kept, on_pixels),
    }
}
