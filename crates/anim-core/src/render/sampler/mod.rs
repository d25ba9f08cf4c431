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
use super::counts::RayCounts;
use super::integrator::Integrator;
use super::motion::Shutter;
use super::settings::Sampling;
use glam::Vec3;

/// One frame as a sampler sees it.
pub(super) struct Frame<'a> {
    /// The camera in the middle of the exposure.
    pub camera: &'a PinholeCamera,
    /// The exposure, when something moves during it.
    pub shutter: Option<&'a Shutter>,
    pub integrator: &'a Integrator<'a>,
    /// Width and height in pixels.
    pub size: (usize, usize),
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
