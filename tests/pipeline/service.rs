//! The one way from a scene file to images in memory (`frames::render_to_memory`, which
//! `anim render` and `anim preview` both take), and the files a frame's fingerprint follows
//! (`frames::referenced_files`, `frames::frame_hash`).

use anim_core::diag::Diagnostic;
use anim_core::render::film::{self, ImageFormat};
use anim_core::render::{render_job, RenderSettings};
use anim_core::scene::RenderJob;
use anim_core::sdf::LoadOptions;
use anim_pipeline::frames::{self, Encoded, ImageSink, NoProgress};
use std::path::{Path, PathBuf};

/// Takes every image the file asks for (or only its first) as PNG, counting its calls.
#[derive(Default)]
struct Collect {
    settings: RenderSettings,
    first_only: bool,
    checked: usize,
    taken: Vec<Vec<u8>>,
}

impl ImageSink for Collect {
    type Target = ();

    fn settings(&self, index: usize, _job: &RenderJob) -> Option<RenderSettings> {
        (!self.first_only || index == 0).then(|| self.settings.clone())
    }

    fn check(
        &mut self,
        _job: &RenderJob,
        _settings: &RenderSettings,
        _warnings: &mut Vec<Diagnostic>,
    ) -> Result<((), ImageFormat), Vec<Diagnostic>> {
        self.checked += 1;
        Ok(((), ImageFormat::Png))
    }

    fn take(&mut self, _job: &RenderJob, (): (), image: Encoded) -> Result<(), Vec<Diagnostic>> {
        self.taken.push(image.image);
        Ok(())
    }
}

const BALL: &str = "define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20\n\
                    define shape sphere ball 0 0 -5 1 red\n\
                    define light sun 5 5 5 1 1 1 1\n\
                    define camera cam 60\n";

fn scene(dir: &Path, text: &str) -> PathBuf {
    let path = dir.join("scene.sdf");
    std::fs::write(&path, text).unwrap();
    path
}

fn texts(diagnostics: &[Diagnostic]) -> Vec<String> {
    diagnostics.iter().map(ToString::to_string).collect()
}

#[test]
fn each_image_is_the_tone_mapped_render_encoded_as_png() {
    let dir = tempfile::tempdir().unwrap();
    let path = scene(
        dir.path(),
        &format!("{BALL}render cam a.png 16 12\nrender cam b.png 8 6\n"),
    );
    let mut sink = Collect::default();
    let drawn =
        frames::render_to_memory(&path, &LoadOptions::default(), &mut sink, &NoProgress).unwrap();
    assert!(drawn.warnings.is_empty(), "{:?}", texts(&drawn.warnings));
    let loaded = anim_core::load::load_file(&path, &LoadOptions::default()).unwrap();
    assert_eq!(sink.taken.len(), 2);
    for (job, png) in loaded.jobs.iter().zip(&sink.taken) {
        let rendered = render_job(job, &RenderSettings::default(), &|_| {}).unwrap();
        let decoded = image::load_from_memory(png).unwrap().to_rgb8();
        assert_eq!(decoded.dimensions(), (job.width, job.height));
        assert_eq!(decoded.as_raw(), &film::to_rgb8(&rendered.image));
    }
    let rays = drawn.rays.primary;
    assert!(rays >= 16 * 12 + 8 * 6, "{rays} camera rays");
}

#[test]
fn an_image_too_large_for_the_budget_is_refused_at_its_render_line_before_any_renders() {
    let dir = tempfile::tempdir().unwrap();
    let path = scene(
        dir.path(),
        &format!("{BALL}render cam a.png 16 12\nrender cam b.png 4000 3000\n"),
    );
    let settings = RenderSettings {
        // What the small image needs and not the large one.
        max_memory: anim_core::limits::image_memory(16, 12) * 2,
        ..RenderSettings::default()
    };
    let mut sink = Collect {
        settings: settings.clone(),
        ..Collect::default()
    };
    let errors = frames::render_to_memory(&path, &LoadOptions::default(), &mut sink, &NoProgress)
        .unwrap_err();
    let shown = texts(&errors).join("\n");
    assert!(
        shown.contains("scene.sdf:6:1: error: a 4000×3000 image needs about"),
        "{shown}"
    );
    assert!(shown.contains("--max-memory raises the limit"), "{shown}");
    assert!(sink.taken.is_empty(), "an image was rendered");
    // An image the sink leaves out is not judged.
    let mut first = Collect {
        settings,
        first_only: true,
        ..Collect::default()
    };
    frames::render_to_memory(&path, &LoadOptions::default(), &mut first, &NoProgress).unwrap();
    assert_eq!((first.checked, first.taken.len()), (1, 1));
}

#[test]
fn the_warnings_are_the_files_then_the_blank_images_then_the_dropped_shapes() {
    let dir = tempfile::tempdir().unwrap();
    // The short form of a mesh is skipped as the file is read; six factors of 1e-8 take the
    // sphere's radius below the smallest f32, which leaves nothing to see.
    let scales = "transform tiny scale 1e-8\n".repeat(6);
    let path = scene(
        dir.path(),
        &format!(
            "define shape obj whatever.obj\n\
             define material m 0 0 0 0.8 0.8 0.8 0 0 0 1\n\
             define shape sphere tiny 0 0 -5 1 m\n{scales}\
             define camera cam 60\nrender cam a.png 8 6\n"
        ),
    );
    let mut sink = Collect::default();
    let drawn =
        frames::render_to_memory(&path, &LoadOptions::default(), &mut sink, &NoProgress).unwrap();
    let shown = texts(&drawn.warnings);
    let at = |needle: &str| {
        shown
            .iter()
            .position(|w| w.contains(needle))
            .unwrap_or_else(|| panic!("no {needle:?} in {shown:#?}"))
    };
    let file = at("scene.sdf:1:14: warning: a mesh needs a name");
    let blank = at("scene.sdf:11:1: warning: the image `a.png` would be blank");
    let dropped = at("scene.sdf:3:1: warning: shape 'tiny' is degenerate once transformed");
    assert!(file < blank && blank < dropped, "{shown:#?}");
    assert_eq!(sink.taken.len(), 1);
}

#[test]
fn a_frame_refers_to_its_includes_to_any_depth_and_their_meshes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("a.sdfi"), "include b.sdfi\n").unwrap();
    std::fs::write(
        d.join("b.sdfi"),
        "define material m 1 1 1 1 1 1 0 0 0 1\ndefine shape obj t m.obj m\n",
    )
    .unwrap();
    std::fs::write(d.join("m.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let frame = scene(
        d,
        "include a.sdfi\ninclude missing.sdfi\ndefine camera cam 60\nrender cam f.png 8 6\n",
    );
    let referenced = frames::referenced_files(&frame, &LoadOptions::default());
    let names: Vec<&Path> = referenced
        .iter()
        .map(|p| p.strip_prefix(d).unwrap())
        .collect();
    // Depth first, as the loader reads them; a file not there yet is listed all the same.
    let expected = ["a.sdfi", "b.sdfi", "m.obj", "missing.sdfi"];
    assert_eq!(names, expected.map(Path::new));
    // The fingerprint follows the file two includes deep, and the mesh's size.
    let hash = || {
        let bytes = std::fs::read(&frame).unwrap();
        frames::frame_hash(&bytes, &frame, "settings", &LoadOptions::default())
    };
    let first = hash();
    std::fs::write(
        d.join("b.sdfi"),
        "define material m 1 0 0 1 1 1 0 0 0 1\ndefine shape obj t m.obj m\n",
    )
    .unwrap();
    let second = hash();
    assert_ne!(first, second, "an edit two includes deep");
    std::fs::write(d.join("m.obj"), "v 0 0 0\nv 2 0 0\nv 0 2 0\nf 1 2 3\n").unwrap();
    assert_ne!(second, hash(), "an edit of the mesh");
}
