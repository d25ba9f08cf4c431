//! Frames rendered from the frame before (`anim render DIR` tracing again only what changed)
//! are the frames rendered alone, to the byte, whatever the thread count: every example spec
//! of `animations/`, a still-camera shot whose moving ball casts a shadow, shows in a mirror
//! and is seen through glass (`bounce/`), and a sphere moving among thousands, its shadow on
//! those behind it, at small sizes.

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

/// Issue 41's own case, small: one matte sphere in front of 2,000 matte spheres scattered in
/// depth (scripts/bench/gen-animations.sh's `mover100k-plain` at a fiftieth of the spheres,
/// each larger by the cube root of 50 so that they fill as much of the box), sliding across
/// with its shadow falling on the spheres behind it, the camera still, 8 frames.
#[test]
fn a_sphere_among_thousands_renders_from_the_frame_before_as_alone() {
    const SPHERES: u32 = 2_000;
    let work = tempfile::tempdir().expect("tempdir");
    let mut scene = String::from(
        "define material matte 0.2 0.3 0.6 0.5 0.6 0.9 0.3 0.3 0.3 20\n\
         define light key 40 60 40 1 1 1 1\n\
         define light fill -50 20 10 0.5 0.5 0.6 1\n\
         ambient 0.1 0.1 0.1\n",
    );
    let scale = (100_000.0 / f64::from(SPHERES)).cbrt();
    // A fixed linear congruential sequence (Knuth's MMIX constants): the same scene every run.
    let mut state: u64 = 1;
    let mut uniform = |lo: f64, hi: f64| {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((state >> 11) as f64 / (1u64 << 53) as f64)
    };
    for n in 0..SPHERES {
        let (x, y, z) = (
            uniform(-60.0, 60.0),
            uniform(-35.0, 35.0),
            uniform(-160.0, -40.0),
        );
        let r = uniform(0.1, 0.5) * scale;
        scene += &format!("define shape sphere s{n} {x:.3} {y:.3} {z:.3} {r:.4} matte\n");
    }
    scene += "define shape sphere mover -20 -4 -36 4.5 matte\n\
              define camera eye 60 0 10 60 0 -0.15 -1 0 1 0\n";
    std::fs::write(work.path().join("crowd.sdf"), scene).expect("write");
    let spec = work.path().join("mover.ron");
    std::fs::write(
        &spec,
        r#"(
    scene: File("crowd.sdf"),
    camera: "eye",
    fps: 24,
    length: Frames(8),
    resolution: (320, 180),
    tracks: [(target: "mover", translate: [(at: 0, value: (0, 0, 0)), (at: 0.3, value: (8, 0, 0))])],
)"#,
    )
    .expect("write");
    let (frames, traced_from_before) = shots_against_alone(&spec, work.path(), &[]);
    assert_eq!((frames, traced_from_before), (8, 7));
    // Each frame after the first traced again some of its pixels, not all: the shot took the
    // others from the frame before.
    for file in &frame_files(&work.path().join("frames"))[1..] {
        let sdf = file.file_name().unwrap().to_str().unwrap();
        let record =
            std::fs::read_to_string(record_path(&work.path().join("two"), sdf)).expect("record");
        let line = record
            .lines()
            .find(|l| l.starts_with("incremental "))
            .expect("traced from the frame before");
        let counts: Vec<u64> = line
            .split_whitespace()
            .skip(1)
            .take(2)
            .map(|n| n.parse().expect("a count"))
            .collect();
        assert!(
            counts[0] > 0 && counts[0] < counts[1],
            "{sdf}: {line} (pixels traced again, of all)"
        );
    }
}
