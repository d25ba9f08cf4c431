//! Rendering: compile a scene description, trace it on rayon tiles, tone-map, write the image.
//! PLACEHOLDER bodies: being written now; the signatures are the contract.

use crate::diag::Diagnostic;
use crate::scene::RenderJob;
use crate::sdf::LoadOptions;
use glam::Vec3;
use std::path::{Path, PathBuf};

/// Samples per pixel when neither `--spp` nor the render statement says.
pub const DEFAULT_SPP: u32 = 4;

#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Overrides the render statement's sample count.
    pub spp: Option<u32>,
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub max_depth: u32,
    pub ppm_ascii: bool,
    /// Images go here instead of beside the scene file.
    pub out_dir: Option<PathBuf>,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            spp: None,
            width: None,
            height: None,
            max_depth: 8,
            ppm_ascii: false,
            out_dir: None,
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

/// What rendering one scene file produced.
#[derive(Clone, Debug)]
pub struct FileOutcome {
    pub outputs: Vec<PathBuf>,
    pub warnings: Vec<Diagnostic>,
    pub rays: RayCounts,
}

/// Renders one job to an HDR image.
pub fn render_job(_job: &RenderJob, _settings: &RenderSettings) -> (HdrImage, RayCounts) {
    todo!()
}

/// Loads a scene file, renders every image it asks for and writes them atomically.
/// `show_progress`: draw a progress bar on a terminal for renders longer than about a second.
pub fn render_file(
    _path: &Path,
    _load: &LoadOptions,
    _settings: &RenderSettings,
    _show_progress: bool,
) -> Result<FileOutcome, Vec<Diagnostic>> {
    todo!()
}

pub mod primitive;
