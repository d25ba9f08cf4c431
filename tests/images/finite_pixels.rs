//! No scene we ship or our users have may produce a NaN or infinite pixel: every file of
//! scenes/ and animations/ (as git tracks them) and of the shared corpus that loads is
//! rendered small, and its HDR buffer (before tone mapping could hide a NaN as 0) is checked.

use crate::common;

use anim_core::load::load_file;
use anim_core::render::{render_job, RenderSettings};
use anim_core::sdf::LoadOptions;
use std::path::PathBuf;

/// Scene files among `all`: `.sdf`, `.txt` and files without an extension (as the corpus
/// names them).
fn scene_files(all: Vec<PathBuf>, out: &mut Vec<PathBuf>) {
    out.extend(
        all.into_iter()
            .filter(|p| p.extension().is_none_or(|e| e == "sdf" || e == "txt")),
    );
}

#[test]
fn every_loadable_scene_renders_finite_pixels() {
    let mut files = Vec::new();
    for folder in ["scenes", "animations"] {
        scene_files(common::repository_files(folder), &mut files);
    }
    if let Some(shared) = common::shared_dir("finite pixels (corpus part)") {
        for set in ["corpus/wild", "corpus/wild2"] {
            let mut all = Vec::new();
            common::files_below(&shared.join(set), &mut all);
            scene_files(all, &mut files);
        }
    }
    files.sort();
    let settings = RenderSettings {
        spp: Some(1),
        width: Some(48),
        height: Some(32),
        ..RenderSettings::default()
    };
    let (mut rendered, mut images) = (0, 0);
    for file in &files {
        let Ok(loaded) = load_file(file, &LoadOptions::default()) else {
            continue;
        };
        rendered += 1;
        for job in &loaded.jobs {
            let Ok(rendered) = render_job(job, &settings, &|_| {}) else {
                continue;
            };
            let img = rendered.image;
            images += 1;
            let bad = img
                .pixels
                .iter()
                .position(|p| !p.is_finite() || p.min_element() < 0.0);
            assert!(
                bad.is_none(),
                "{}: pixel {bad:?} is {:?}",
                file.display(),
                bad.map(|i| img.pixels[i])
            );
        }
    }
    eprintln!("{rendered} files, {images} images, all pixels finite");
    assert!(rendered >= 5, "the project's own scenes load");
}
