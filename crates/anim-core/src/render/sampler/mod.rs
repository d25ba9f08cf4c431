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
//! - `defocus`: which pixels of adaptive sampling's first pass a thin lens blurs.
//!
//! A camera sample may draw more than its position (and instant) from its pixel's pattern:
//! a point of the camera's lens and a point of each spherical light ([`Draws`]).

mod adaptive;
mod defocus;
mod first_pass;
mod motion;
mod packet;
pub mod pattern;
mod uniform;

pub use uniform::sample_offsets;

use super::camera::PinholeCamera;
use super::counts::RayCounts;
use super::integrator::{Integrator, PixelPrior, TraceState};
use super::motion::Shutter;
use super::settings::Sampling;
use glam::{Vec3, Vec3A};
use pattern::{light_pair, PixelPattern, LENS_PAIR};

/// One frame as a sampler sees it.
pub(super) struct Frame<'a> {
    /// The camera in the middle of the exposure.
    pub camera: &'a PinholeCamera,
    /// The exposure, when something moves during it.
    pub shutter: Option<&'a Shutter>,
    pub integrator: &'a Integrator<'a>,
    /// Width and height in pixels.
    pub size: (usize, usize),
    /// What its camera samples draw besides their position and instant.
    pub draws: Draws,
}

/// The dimensions a frame's camera samples draw from their pixel's pattern besides position
/// and instant: a point of the camera's lens, and a point of each spherical light
/// (`pattern::PixelPattern::pair`, one pair each).
#[derive(Clone, Debug, Default)]
pub(super) struct Draws {
    lens: bool,
    /// The spherical lights, by number.
    lights: Vec<usize>,
    /// How many lights the frame has.
    light_count: usize,
}

impl Draws {
    /// What the samples of a frame through `camera` of a scene lit as `integrator`'s draw.
    pub fn new(camera: &PinholeCamera, integrator: &Integrator) -> Draws {
        let lights = &integrator.scene.shading().lights;
        Draws {
            lens: camera.has_lens(),
            lights: (0..lights.len())
                .filter(|&k| lights[k].radius > 0.0)
                .collect(),
            light_count: lights.len(),
        }
    }

    /// Whether they draw anything.
    pub fn any(&self) -> bool {
        self.lens || !self.lights.is_empty()
    }

    /// Whether the camera has a lens.
    pub fn lens(&self) -> bool {
        self.lens
    }

    /// Whether some light is a sphere.
    pub fn spherical_lights(&self) -> bool {
        !self.lights.is_empty()
    }

    /// Sample `i` of `pattern`: its points of the spherical lights, into `st`, and its point
    /// of the lens, if the camera has one.
    #[inline]
    fn draw(&self, pattern: &PixelPattern, i: u32, st: &mut TraceState) -> Option<[f32; 2]> {
        if !self.lights.is_empty() {
            st.light_points.resize(self.light_count, [0.5; 2]);
            for &k in &self.lights {
                st.light_points[k] = pattern.pair(i, light_pair(k));
            }
        }
        self.lens.then(|| pattern.pair(i, LENS_PAIR))
    }
}

impl Frame<'_> {
    /// The radiance of a camera sample, and whether it hit a surface, through image position
    /// `(px, py)` of a frame whose samples draw lens or light points (`draws`), drawing them
    /// as sample `i` of `pattern`; at instant `time` in a frame with motion. The samplers call
    /// it apart from their pinhole path, and it is not inlined, so that frames that draw
    /// nothing keep that path as small as it was.
    #[inline(never)]
    pub fn trace_drawing(
        &self,
        (px, py): (f32, f32),
        time: Option<f32>,
        (pattern, i): (&PixelPattern, u32),
        prior: &PixelPrior,
        st: &mut TraceState,
    ) -> (Vec3A, bool) {
        let lens = self.draws.draw(pattern, i, st);
        let ray = match (self.shutter.zip(time), lens) {
            (None, None) => self.camera.ray(px, py),
            (None, Some(uv)) => self.camera.lens_ray(px, py, uv),
            (Some((s, t)), None) => s.ray(self.camera, px, py, t),
            (Some((s, t)), Some(uv)) => s.lens_ray(self.camera, px, py, t, uv),
        };
        let integrator = self.integrator;
        let sample = match lens {
            None => integrator.camera_sample(&ray, prior, st),
            Some(_) => integrator.lens_sample(&ray, prior, st),
        };
        (sample.radiance, sample.t.is_some())
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
