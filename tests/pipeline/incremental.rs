//! Frames rendered from the frame before (`anim render DIR` tracing again only what changed)
//! are the frames rendered alone, to the byte, whatever the thread count: every example spec
//! of `animations/` and a still-camera shot whose moving ball casts a shadow, shows in a
//! mirror and is seen through glass (`bounce/`), at small sizes.

use crate::common;
use anim_pipeline::frames::record_path;
use std::path::{Path, PathBuf};

/// Small enough for every frame of every spec, large enough for the moving things to cover
/// some pixels and not others.
const SIZE: [&str; 4] = ["--width", "48", "--height", "27"];

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `anim ARGS...`, which must succeed.
fn anim(args: &[&str]) {
    let out = common::anim().args(args).output().expect("anim runs");
    assert!(
        out.status.success(),
        "anim {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The frame files of `dir`, in order.
fn frame_files(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("frames")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "sdf"))
        .collect();
    files.sort();
    files
}

/// Generates `spec` whole (`--standalone`) into `work`, renders its directory as shots with
/// one thread and with two, and every frame file alone in one process; every image of the
/// shots must be the image of its frame alone, to the byte. Returns the frames and how many
/// of them the two-thread run traced from the frame before (its records say so).
fn shots_against_alone(spec: &Path, work: &Path, extra: &[&str]) -> (usize, usize) {
    let frames = work.join("frames");
    let dir = frames.to_str().expect("a UTF-8 path");
    anim(&[
        "generate",
        "--standalone",
        "--quiet",
        "-o",
        dir,
        spec.to_str().unwrap(),
    ]);
    let files = frame_files(&frames);
    let out = |name: &str| work.join(name).to_str().unwrap().to_string();
    for (threads, to) in [("1", out("one")), ("2", out("two"))] {
        let mut args = vec!["render", dir, "--quiet", "--threads", threads, "--out", &to];
        args.extend(SIZE.iter().chain(extra));
        anim(&args);
    }
    let alone = out("alone");
    let mut args = vec!["render", "--quiet", "--out", &alone];
    args.extend(SIZE.iter().chain(extra));
    let names: Vec<String> = files.iter().map(|f| f.display().to_string()).collect();
    args.extend(names.iter().map(String::as_str));
    anim(&args);
    let mut traced_from_before = 0;
    for file in &files {
        let sdf = file.file_name().unwrap().to_str().unwrap();
        let png = sdf.replace(".sdf", ".png");
        let expected = std::fs::read(work.join("alone").join(&png)).expect("the frame alone");
        for run in ["one", "two"] {
            let got = std::fs::read(work.join(run).join(&png)).expect("the frame of the shot");
            assert!(
                got == expected,
                "{}: {png} ({run} thread(s)) differs",
                spec.display()
            );
        }
        let record = std::fs::read_to_string(record_path(&work.join("two"), sdf)).expect("record");
        traced_from_before += record.lines().any(|l| l.starts_with("incremental ")) as usize;
    }
    (files.len(), traced_from_before)
}

#[test]
fn every_example_spec_renders_its_frames_from_the_frame_before_as_alone() {
    let mut specs: Vec<PathBuf> = std::fs::read_dir(repo().join("animations"))
        .expect("animations/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    specs.sort();
    let mut traced_from_before = 0;
    for spec in &specs {
        let work = tempfile::tempdir().expect("tempdir");
        traced_from_before += shots_against_alone(spec, work.path(), &[]).1;
    }
    // crowd.ron, logo.ron and the still start of blur.ron hold their cameras still: the
    // comparison above is of frames that were traced from the frame before.
    assert!(traced_from_before > 100, "{traced_from_before} frames");
}

/// The still-camera shot of `bounce/`, as generated, with motion blur, and sampled uniformly.
#[test]
fn a_ball_in_shadow_mirror_and_glass_renders_from_the_frame_before_as_alone() {
    let spec = repo().join("tests/pipeline/bounce/bounce.ron");
    let text = std::fs::read_to_string(&spec).expect("bounce.ron");
    let blurred = text.replacen("fps: 24,", "fps: 24,\n    shutter: 0.5,", 1);
    assert_ne!(blurred, text, "bounce.ron names its fps");
    for (spec_text, extra) in [
        (&text, &[][..]),
        (&blurred, &[][..]),
        (&text, &["--spp", "4"][..]),
    ] {
        let work = tempfile::tempdir().expect("tempdir");
        std::fs::copy(
            repo().join("tests/pipeline/bounce/bounce.sdf"),
            work.path().join("bounce.sdf"),
        )
        .expect("copy");
        let spec = work.path().join("bounce.ron");
        std::fs::write(&spec, spec_text).expect("write");
        let (frames, traced_from_before) = shots_against_alone(&spec, work.path(), extra);
        // One shot: every frame but the first traced from the one before, except the frames
        // that repeat the one before them (the held end), which are copied.
        assert_eq!(frames, 48);
        assert!(
            traced_from_before >= frames - 3,
            "{traced_from_before} of {frames} ({extra:?})"
        );
    }
}
