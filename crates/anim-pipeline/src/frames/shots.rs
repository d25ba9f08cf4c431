//! The frames of a directory cut into shots (`anim_core::render::shot`): runs of frames in
//! order, each of one image, from one camera that holds still, each changing from the one
//! before only what a shot can follow. A worker renders a shot's frames one after another,
//! each tracing again only what may differ from the frame before; the frames of a long shot
//! share the threads by their rows, and separate shots go to separate workers, as single
//! frames always did.
//!
//! To cut them, every frame to render is loaded once beforehand and compared with the one
//! before it (in parallel, by contiguous stretches): what each changes is what the shot's
//! earlier frames watch their rays against. A frame whose file changes between this look and
//! its render is traced in full (`Shot::render` checks what it was told).

use anim_core::render::footprint::Changed;
use anim_core::render::shot::{changes, Shot};
use anim_core::render::RenderSettings;
use anim_core::scene::RenderJob;
use anim_core::sdf::LoadOptions;
use rayon::prelude::*;
use std::path::PathBuf;

/// Frames of one shot, by their place in the caller's list, and what each after the first
/// changes from the one before.
pub(super) struct ShotPlan {
    pub frames: Vec<usize>,
    later: Vec<Changed>,
}

impl ShotPlan {
    /// The shot that renders these frames; `None` for a frame alone, which renders as any
    /// single image does.
    pub fn shot(&self) -> Option<Shot> {
        (self.frames.len() > 1).then(|| Shot::new(self.later.clone()))
    }
}

/// Frames at `paths` (in order) cut into shots, each frame in one. A frame that cannot be
/// loaded, or asks for other than one image, is a shot of its own.
pub(super) fn plan_shots(
    paths: &[PathBuf],
    settings: &RenderSettings,
    load: &LoadOptions,
) -> Vec<ShotPlan> {
    let n = paths.len();
    // Stretches of frames for the workers to load, each starting with the frame before it
    // (loaded twice) so that what every frame changes is found.
    let stretch = n.div_ceil(2 * rayon::current_num_threads()).max(1);
    let starts: Vec<usize> = (0..n).step_by(stretch).collect();
    let follows: Vec<Option<Changed>> = starts
        .par_iter()
        .flat_map_iter(|&start| {
            let end = (start + stretch).min(n);
            let mut before = start.checked_sub(1).and_then(|i| job_of(&paths[i], load));
            (start..end).map(move |i| {
                let job = job_of(&paths[i], load);
                let change = match (&before, &job) {
                    (Some(a), Some(b)) => changes(a, b, settings),
                    _ => None,
                };
                before = job;
                change
            })
        })
        .collect();
    let mut plans: Vec<ShotPlan> = Vec::new();
    for (i, change) in follows.into_iter().enumerate() {
        match (change, plans.last_mut()) {
            (Some(change), Some(plan)) => {
                plan.frames.push(i);
                plan.later.push(change);
            }
            _ => plans.push(ShotPlan {
                frames: vec![i],
                later: Vec::new(),
            }),
        }
    }
    plans
}

/// Every frame its own shot (`--no-incremental`).
pub(super) fn alone(n: usize) -> Vec<ShotPlan> {
    (0..n)
        .map(|i| ShotPlan {
            frames: vec![i],
            later: Vec::new(),
        })
        .collect()
}

/// The one image of the frame at `path`, if it loads and has exactly one.
fn job_of(path: &std::path::Path, load: &LoadOptions) -> Option<RenderJob> {
    let loaded = anim_core::load::load_file(path, load).ok()?;
    let [job] = <[RenderJob; 1]>::try_from(loaded.jobs).ok()?;
    Some(job)
}
