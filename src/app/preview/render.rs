//! The render workers: each takes the most wanted frame, renders it with the same library
//! calls as `anim render` (load, then `render_job`) and hands back a PNG in memory.

use super::state::{Job, Quality, Shared};
use anim_core::load::load_file;
use anim_core::render::{film, render_job, RenderSettings};
use anim_core::sdf::LoadOptions;
use image::ImageEncoder as _;
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
        shared.touch(&mut state);
    }
}

/// Frame `job` as PNG bytes, or the error as the terminal shows it.
pub fn render(job: &Job, load: &LoadOptions, settings: &RenderSettings) -> Result<Vec<u8>, String> {
    let joined = |ds: Vec<anim_core::diag::Diagnostic>| {
        ds.iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join("\n")
    };
    let loaded = load_file(&job.path, load).map_err(joined)?;
    let Some(scene) = loaded.jobs.first() else {
        return Err(format!("{}: error: no render line", job.path.display()));
    };
    let settings = match job.quality {
        Quality::Full => settings.clone(),
        Quality::Small => RenderSettings {
            width: Some(scene.width.div_ceil(SMALL_DIVISOR).max(1)),
            height: Some(scene.height.div_ceil(SMALL_DIVISOR).max(1)),
            spp: Some(1),
            ..settings.clone()
        },
    };
    let (width, height, _) = settings.resolve(scene);
    let needed = anim_core::limits::image_memory(width, height);
    if needed > settings.max_memory {
        return Err(format!(
            "{}: error: a {width}×{height} image needs more memory than allowed (--max-memory)",
            job.path.display()
        ));
    }
    let rendered = render_job(scene, &settings, &|_| {})
        .map_err(|e| format!("{}: error: camera: {e:?}", job.path.display()))?;
    encode_png(&film::to_rgb8(&rendered.image), width, height)
}

/// PNG bytes of 8-bit RGB, encoded as the renderer's film encodes its PNG files.
pub fn encode_png(rgb: &[u8], width: u32, height: u32) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    let encoder = image::codecs::png::PngEncoder::new_with_quality(
        &mut out,
        image::codecs::png::CompressionType::Fast,
        image::codecs::png::FilterType::Adaptive,
    );
    encoder
        .write_image(rgb, width, height, image::ExtendedColorType::Rgb8)
        .map_err(|e| format!("cannot encode the image: {e}"))?;
    Ok(out)
}
