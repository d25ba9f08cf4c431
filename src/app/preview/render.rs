//! The render workers: each takes the most wanted frame and renders it into memory through the
//! pipeline's one way from a scene file to an image (`frames::render_to_memory`, as `anim
//! render` does), at the quality the preview asks for, as a PNG.

use super::state::{Drawing, Job, Quality, Shared};
use anim_core::diag::Diagnostic;
use anim_core::render::film::ImageFormat;
use anim_core::render::RenderSettings;
use anim_core::scene::RenderJob;
use anim_core::sdf::LoadOptions;
use anim_pipeline::frames::{self, Encoded, ImageSink, NoProgress};
use std::time::Duration;

/// The small pass draws frames at this fraction of their size (each side).
const SMALL_DIVISOR: u32 = 4;

/// Renders frames until the preview stops.
pub fn worker(shared: &Shared, load: &LoadOptions, settings: &RenderSettings) {
    loop {
        let job = {
            let mut state = shared.lock();
            loop {
                if state.stop {
                    return;
                }
                if let Some(job) = state.next_job() {
                    break job;
                }
                state = shared.wait(&shared.work, state, Duration::from_millis(500));
            }
        };
        let result = render(&job, load, settings);
        let mut state = shared.lock();
        state.finish(&job, result);
        shared.publish(state);
    }
}

/// Frame `job` as a PNG with the warnings `anim render` gives it, or every diagnostic as the
/// terminal shows them.
pub fn render(job: &Job, load: &LoadOptions, settings: &RenderSettings) -> Result<Drawing, String> {
    let joined = |ds: &[Diagnostic]| {
        ds.iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join("\n")
    };
    let mut draft = Draft {
        quality: job.quality,
        settings,
        png: None,
    };
    let drawn = frames::render_to_memory(&job.path, load, &mut draft, &NoProgress)
        .map_err(|ds| joined(&ds))?;
    match draft.png {
        Some(png) => Ok(Drawing {
            png,
            warnings: drawn.warnings,
        }),
        None => Err(format!("{}: error: no render line", job.path.display())),
    }
}

/// What the preview asks of a frame's file: its first image (the page shows one per frame),
/// as a PNG, small or as `anim render` draws it.
struct Draft<'a> {
    quality: Quality,
    settings: &'a RenderSettings,
    png: Option<Vec<u8>>,
}

impl ImageSink for Draft<'_> {
    type Target = ();

    fn settings(&self, index: usize, job: &RenderJob) -> Option<RenderSettings> {
        if index > 0 {
            return None;
        }
        Some(match self.quality {
            Quality::Full => self.settings.clone(),
            Quality::Small => RenderSettings {
                width: Some(job.width.div_ceil(SMALL_DIVISOR).max(1)),
                height: Some(job.height.div_ceil(SMALL_DIVISOR).max(1)),
                spp: Some(1),
                ..self.settings.clone()
            },
        })
    }

    fn check(
        &mut self,
        _job: &RenderJob,
        _settings: &RenderSettings,
        _warnings: &mut Vec<Diagnostic>,
    ) -> Result<((), ImageFormat), Vec<Diagnostic>> {
        Ok(((), ImageFormat::Png))
    }

    fn take(&mut self, _job: &RenderJob, (): (), image: Encoded) -> Result<(), Vec<Diagnostic>> {
        self.png = Some(image.image);
        Ok(())
    }
}
