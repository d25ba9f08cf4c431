//! What a render is asked for: image size, sampling, depth, output options and the memory
//! budget ([`RenderSettings`]), and how it resolves against a render line ([`Sampling`]).

use crate::scene::RenderJob;
use std::path::PathBuf;

/// The options of a render, from the command line or a caller.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Uniform sampling with this many samples per pixel; overrides everything else.
    pub spp: Option<u32>,
    /// Adaptive sampling's target standard error per pixel, in 8-bit levels.
    pub error: Option<f32>,
    /// Adaptive sampling's most samples for one pixel.
    pub max_spp: Option<u32>,
    /// Every image's width, overriding the render statements'.
    pub width: Option<u32>,
    /// Every image's height, overriding the render statements'.
    pub height: Option<u32>,
    /// Most reflected or refracted bounces of a camera ray.
    pub max_depth: u32,
    /// Write `.ppm` images as ASCII (P3) rather than binary (P6).
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
    /// Bits per channel of the image files (`--depth`); `None`: each format's default
    /// (`film::Encoding`).
    pub depth: Option<u8>,
    /// Write linear radiance rather than the tone map's values (`--linear`).
    pub linear: bool,
    /// Give the images an alpha channel: each pixel's coverage (`--alpha`).
    pub alpha: bool,
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
            depth: None,
            linear: false,
            alpha: false,
        }
    }
}

/// How the samples of a render are placed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sampling {
    /// The same count everywhere: the centre for 1, a k×k grid for k², Hammersley otherwise.
    Uniform(u32),
    /// A centre sample everywhere, then scrambled Sobol samples where a pixel needs them.
    Adaptive {
        /// The target error of a refined pixel, in 8-bit levels.
        error: f32,
        /// The most samples one pixel may take.
        max_spp: u32,
    },
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
