//! The frame pipeline: `anim generate` → `anim render DIR` → `scripts/encode.sh`, with skipping
//! of unchanged frames, resuming, shards and failures.

use anim::app::RenderConfig;
use anim::cli::{Cli, Command as Sub};
use anim_pipeline::frames::{self, record_path, Summary};
use assert_cmd::Command;
use clap::Parser;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// A tiny frame: a sphere moved by `x`, 16×12 pixels.
fn frame_text(x: f64, name: &str) -> String {
    format!(
        "define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20\n\
         define shape sphere ball {x} 0 -5 1 red\n\
         define light sun 5 5 5 1 1 1 1\n\
         define camera cam 60\n\
         render cam {name}.png 16 12\n"
    )
}

/// A directory of `n` frames named frame_0000.sdf ….
fn frames(n: usize) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tempdir");
    for i in 0..n {
        let name = format!("frame_{i:04}");
        std::fs::write(
            dir.path().join(format!("{name}.sdf")),
            frame_text(i as f64 * 0.1, &name),
        )
        .expect("write");
    }
    dir
}

fn args(dir: &Path, extra: &[&str]) -> RenderConfig {
    let mut argv: Vec<String> = vec![
        "anim".into(),
        "render".into(),
        dir.display().to_string(),
        "--quiet".into(),
    ];
    argv.extend(extra.iter().map(|s| s.to_string()));
    match Cli::try_parse_from(argv).expect("arguments").command {
        Sub::Render(a) => a.config(),
        _ => unreachable!("a render command"),
    }
}

/// Renders a frame directory through the library, as `anim render DIR` does.
fn run(dir: &Path, config: &RenderConfig) -> Result<Summary, Vec<anim_core::diag::Diagnostic>> {
    frames::render_dir(
        dir,
        &config.settings,
        &config.load,
        &config.frames,
        &frames::NoProgress,
    )
}

fn render(dir: &Path, extra: &[&str]) -> Summary {
    run(dir, &args(dir, extra)).expect("the directory renders")
}

#[test]
fn second_render_skips_everything_and_a_changed_frame_renders_alone() {
    let dir = frames(6);
    let first = render(dir.path(), &[]);
    assert_eq!(first.rendered.len(), 6);
    assert!(first.failed.is_empty(), "{:?}", first.failed);
    assert!(first.rays > 0);
    for i in 0..6 {
        assert!(dir.path().join(format!("frame_{i:04}.png")).is_file());
    }

    let second = render(dir.path(), &[]);
    assert!(second.rendered.is_empty(), "{:?}", second.rendered);
    assert_eq!(second.skipped.len(), 6);

    // Change one frame's scene: only it renders.
    let f3 = dir.path().join("frame_0003.sdf");
    std::fs::write(&f3, frame_text(2.0, "frame_0003")).expect("write");
    let third = render(dir.path(), &[]);
    assert_eq!(third.rendered, ["frame_0003.sdf"]);
    assert_eq!(third.skipped.len(), 5);

    // Touching a file without changing it renders nothing (a hash, not a timestamp).
    let text = std::fs::read(&f3).expect("read");
    std::fs::write(&f3, text).expect("write");
    assert!(render(dir.path(), &[]).rendered.is_empty());

    // A setting that changes pixels renders everything again; so does --force.
    assert_eq!(render(dir.path(), &["--spp", "2"]).rendered.len(), 6);
    assert!(render(dir.path(), &["--spp", "2"]).rendered.is_empty());
    assert_eq!(
        render(dir.path(), &["--spp", "2", "--force"])
            .rendered
            .len(),
        6
    );
}

/// Every format anim writes, with the options it can hold, goes through the record alike:
/// the record vouches for the exact bytes, a second run skips, a damaged image renders again
/// (to the same bytes), a hold is copied byte for byte, shards split the frames, and a change
/// of `--alpha` or `--depth` renders again.
#[test]
fn every_image_format_is_recorded_skipped_held_and_sharded_alike() {
    let cases: [(&str, &[&str]); 7] = [
        ("exr", &["--alpha"]),
        ("exr", &["--depth", "32"]),
        ("png", &["--depth", "16", "--linear", "--alpha"]),
        ("tga", &["--alpha"]),
        ("jpg", &[]),
        ("bmp", &[]),
        ("ppm", &[]),
    ];
    for (ext, options) in cases {
        let dir = tempfile::tempdir().expect("tempdir");
        // Frames 1 and 2 show one scene: a hold.
        for (i, x) in [0.0, 0.5, 0.5, 1.0].into_iter().enumerate() {
            let name = format!("shot_{i}");
            let text = frame_text(x, &name).replace(".png", &format!(".{ext}"));
            std::fs::write(dir.path().join(format!("{name}.sdf")), text).expect("write");
        }
        let image = |i: usize| dir.path().join(format!("shot_{i}.{ext}"));
        let first = render(dir.path(), options);
        assert_eq!(
            first.rendered.len(),
            3,
            "{ext} {options:?}: {:?}",
            first.failed
        );
        assert_eq!(first.copied.len(), 1, "{ext}: the hold is copied");
        let bytes: Vec<Vec<u8>> = (0..4)
            .map(|i| std::fs::read(image(i)).expect("image"))
            .collect();
        assert_eq!(bytes[1], bytes[2], "{ext}: the copy is the rendered image");
        for (i, written) in bytes.iter().enumerate() {
            let record = std::fs::read_to_string(record_path(dir.path(), &format!("shot_{i}.sdf")))
                .expect("record");
            let line = format!(
                "image {} {:016x} shot_{i}.{ext}",
                written.len(),
                anim_core::util::Fnv64::of(written)
            );
            assert!(record.lines().any(|l| l == line), "{ext}: {record}");
        }
        assert_eq!(render(dir.path(), options).skipped.len(), 4, "{ext}");
        // A damaged image renders again, to the bytes it had.
        let mut damaged = bytes[3].clone();
        let middle = damaged.len() / 2;
        damaged[middle] ^= 0xff;
        std::fs::write(image(3), damaged).expect("write");
        let again = render(dir.path(), options);
        assert_eq!(again.rendered, ["shot_3.sdf"], "{ext}");
        assert_eq!(std::fs::read(image(3)).expect("image"), bytes[3], "{ext}");
        // Shards split the work; a change of the image options renders everything.
        let changed: Vec<&str> = match options.contains(&"--alpha") {
            true => options
                .iter()
                .copied()
                .filter(|o| *o != "--alpha")
                .collect(),
            false => vec!["--force"],
        };
        let halves: usize = ["1/2", "2/2"]
            .iter()
            .map(|k| {
                let shard = render(dir.path(), &[&changed[..], &["--shard", k]].concat());
                shard.rendered.len() + shard.copied.len()
            })
            .sum();
        assert_eq!(halves, 4, "{ext}: the shards render every frame once");
    }
}

/// A triangle `size` from its centre (on the view axis, 5 in front of the eye) to each side,
/// as an OBJ file.
pub(crate) fn triangle_obj(size: f64) -> String {
    format!("v -{size} -{size} -5\nv {size} -{size} -5\nv 0 {size} -5\nf 1 2 3\n")
}

#[test]
fn an_edited_mesh_renders_the_frames_that_name_it_again() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mesh = dir.path().join("tri.obj");
    std::fs::write(&mesh, triangle_obj(1.0)).expect("write");
    for (name, shape) in [
        ("frame_0000", "define shape obj tri tri.obj red"),
        ("frame_0001", "define shape sphere ball 0 0 -5 1 red"),
    ] {
        let text = frame_text(0.0, name).replace("define shape sphere ball 0 0 -5 1 red", shape);
        std::fs::write(dir.path().join(format!("{name}.sdf")), text).expect("write");
    }
    assert_eq!(render(dir.path(), &[]).rendered.len(), 2);
    assert!(render(dir.path(), &[]).rendered.is_empty());
    // The mesh changes (its bytes' length, and its time): the frame naming it renders again,
    // alone.
    std::fs::write(&mesh, triangle_obj(1.5)).expect("write");
    let again = render(dir.path(), &[]);
    assert_eq!(again.rendered, ["frame_0000.sdf"]);
    assert_eq!(again.skipped, ["frame_0001.sdf"]);
}

#[test]
fn an_interrupted_run_resumes_with_only_the_missing_frames() {
    let dir = frames(5);
    assert_eq!(render(dir.path(), &[]).rendered.len(), 5);

    // Frame 1: the image and its record are gone (the run died before rendering it).
    std::fs::remove_file(dir.path().join("frame_0001.png")).expect("rm");
    std::fs::remove_file(record_path(dir.path(), "frame_0001.sdf")).expect("rm");
    // Frame 2: died while writing — a stray temporary file, and an image without a record.
    std::fs::write(
        dir.path().join(".frame_0002.png.4242.tmp"),
        b"\x89PNG partial",
    )
    .expect("write");
    std::fs::remove_file(record_path(dir.path(), "frame_0002.sdf")).expect("rm");
    // Frame 4: its image was truncated behind the record's back.
    let f4 = dir.path().join("frame_0004.png");
    let bytes = std::fs::read(&f4).expect("read");
    std::fs::write(&f4, &bytes[..bytes.len() / 2]).expect("truncate");

    let resumed = render(dir.path(), &[]);
    assert_eq!(
        resumed.rendered,
        ["frame_0001.sdf", "frame_0002.sdf", "frame_0004.sdf"]
    );
    assert_eq!(resumed.skipped, ["frame_0000.sdf", "frame_0003.sdf"]);
    assert_eq!(std::fs::read(&f4).expect("read").len(), bytes.len());
}

#[test]
fn shards_together_render_every_frame_exactly_once() {
    let dir = frames(10);
    let mut all: Vec<String> = Vec::new();
    for k in 1..=3 {
        let s = render(dir.path(), &["--shard", &format!("{k}/3")]);
        // Contiguous runs, as even as can be: frames i of 10 with ⌊3i/10⌋ = k − 1.
        let expected: Vec<String> = (0..10)
            .filter(|i| i * 3 / 10 == k - 1)
            .map(|i| format!("frame_{i:04}.sdf"))
            .collect();
        assert_eq!(s.rendered, expected, "shard {k}/3");
        assert_eq!(s.total, 10);
        all.extend(s.rendered);
    }
    all.sort();
    let every: Vec<String> = (0..10).map(|i| format!("frame_{i:04}.sdf")).collect();
    assert_eq!(all, every);
    // The shards' records make a whole run find nothing left to do.
    assert_eq!(render(dir.path(), &[]).skipped.len(), 10);
}

#[test]
fn frames_are_taken_in_natural_order() {
    let dir = tempfile::tempdir().expect("tempdir");
    for n in [1, 2, 10, 11] {
        let name = format!("f_{n}");
        std::fs::write(
            dir.path().join(format!("{name}.sdf")),
            // Each its own scene, so that none is a copy of another.
            frame_text(n as f64 * 0.1, &name),
        )
        .expect("write");
    }
    // Natural order is f_1, f_2, f_10, f_11: shard 2/2 takes the second half.
    let s = render(dir.path(), &["--shard", "2/2"]);
    assert_eq!(s.rendered, ["f_10.sdf", "f_11.sdf"]);
}

#[test]
fn images_and_records_go_to_out() {
    let dir = frames(3);
    let out = tempfile::tempdir().expect("tempdir");
    let s = render(dir.path(), &["--out", &out.path().display().to_string()]);
    assert_eq!(s.rendered.len(), 3);
    assert!(out.path().join("frame_0002.png").is_file());
    assert!(record_path(out.path(), "frame_0002.sdf").is_file());
    assert!(!dir.path().join("frame_0002.png").exists());
    let s = render(dir.path(), &["--out", &out.path().display().to_string()]);
    assert_eq!(s.skipped.len(), 3);
}

#[test]
fn a_failing_frame_does_not_stop_the_others() {
    let dir = frames(4);
    std::fs::write(
        dir.path().join("frame_0002.sdf"),
        "define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20\ndefine shape sphere ball 0 0 -5 1O red\ndefine camera cam 60\nrender cam frame_0002.png 16 12\n",
    )
    .expect("write");
    let s = render(dir.path(), &[]);
    assert_eq!(
        s.rendered,
        ["frame_0000.sdf", "frame_0001.sdf", "frame_0003.sdf"]
    );
    assert_eq!(s.failed.len(), 1);
    assert_eq!(s.failed[0].0, "frame_0002.sdf");
    let loc = s.failed[0].1[0].loc.clone().expect("located");
    assert_eq!(loc.line, 2);
    assert!(!record_path(dir.path(), "frame_0002.sdf").exists());

    // The binary: non-zero exit, the summary lists the failure with file:line:col.
    let out = Command::cargo_bin("anim")
        .expect("binary")
        .args(["render"])
        .arg(dir.path())
        .output()
        .expect("run");
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("1 frame failed:"), "{stderr}");
    let located = format!("{}:2:", dir.path().join("frame_0002.sdf").display());
    assert!(stderr.contains(&located), "{stderr}");
    assert!(
        stderr.contains("0 rendered, 3 skipped (unchanged), 1 failed"),
        "{stderr}"
    );
}

#[test]
fn an_empty_directory_is_an_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    let e = run(dir.path(), &args(dir.path(), &[])).expect_err("no frames");
    assert!(e[0].to_string().contains("no .sdf files"), "{}", e[0]);
}

// ---------------------------------------------------------------------------------------------
// anim generate

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn generate_reports_located_spec_errors() {
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::copy(
        repo().join("animations/showcase.sdf"),
        dir.path().join("showcase.sdf"),
    )
    .expect("copy");
    let cases = [
        // unknown field
        ("(scene: File(\"showcase.sdf\"), length: Frames(3), resolution: (8, 8), fsp: 3)", "spec.ron:1:70: error: unknown field `fsp`"),
        // wrong type
        ("(scene: File(\"showcase.sdf\"), length: Frames(3), resolution: (8, \"8\"))", "spec.ron:1:66: error: expected a whole number"),
        // unknown target
        (
            "(scene: File(\"showcase.sdf\"), length: Frames(3), resolution: (8, 8),\n tracks: [(target: \"lense\", rotate: [(at: 0, value: 1)])])",
            "spec.ron:2:20: error: the base scene has no shape, composite, camera, light or material named 'lense'",
        ),
        // unsorted keys
        (
            "(scene: File(\"showcase.sdf\"), length: Seconds(1), resolution: (8, 8),\n tracks: [(target: \"lens\", rotate: [(at: 0.5, value: 1), (at: 0.25, value: 2)])])",
            "spec.ron:2:63: error: keys must be in time order",
        ),
        // missing base scene
        ("(scene: File(\"nope.sdf\"), length: Frames(3), resolution: (8, 8))", "spec.ron:1:14: error: cannot read the base scene"),
    ];
    for (text, expected) in cases {
        let spec = dir.path().join("spec.ron");
        std::fs::write(&spec, text).expect("write");
        let out = Command::cargo_bin("anim")
            .expect("binary")
            .current_dir(dir.path())
            .args(["generate", "spec.ron"])
            .output()
            .expect("run");
        assert!(!out.status.success(), "{text}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.starts_with(expected), "{text}\n{stderr}");
    }
    assert!(
        !dir.path().join("frames").exists(),
        "nothing is written for a bad spec"
    );
}

#[test]
fn generate_errors_in_an_inline_scene_point_into_the_spec() {
    let dir = tempfile::tempdir().expect("tempdir");
    let spec = dir.path().join("inline.ron");
    std::fs::write(
        &spec,
        "(\n  scene: Inline(r#\"\ndefine camera cam 60\ndefine shape sphere s 0 0 -5 1O nomat\n\"#),\n  length: Frames(2),\n  resolution: (8, 8),\n)\n",
    )
    .expect("write");
    let out = Command::cargo_bin("anim")
        .expect("binary")
        .arg("generate")
        .arg(&spec)
        .output()
        .expect("run");
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    let expected = format!("{}:4:", spec.display());
    assert!(stderr.starts_with(&expected), "{stderr}");
}

#[test]
fn generate_is_deterministic_atomic_and_trims_old_frames() {
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::copy(
        repo().join("animations/showcase.sdf"),
        dir.path().join("showcase.sdf"),
    )
    .expect("copy");
    let spec = dir.path().join("spin.ron");
    let write_spec = |frames: u32| {
        std::fs::write(
            &spec,
            format!(
                "(scene: File(\"showcase.sdf\"), length: Frames({frames}), resolution: (8, 8),\n tracks: [(target: \"lens\", rotate: [(at: 0, value: 0, interp: EaseInOut), (at: 0.25, value: 90)])])"
            ),
        )
        .expect("write")
    };
    write_spec(12);
    let run = || {
        let out = Command::cargo_bin("anim")
            .expect("binary")
            .arg("generate")
            .arg(&spec)
            .output()
            .expect("run");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let said = run();
    let frames_dir = dir.path().join("frames/spin");
    assert!(said.contains("wrote 12 frames"), "{said}");
    let first: Vec<Vec<u8>> = (0..12)
        .map(|i| std::fs::read(frames_dir.join(format!("frame_{i:04}.sdf"))).expect("frame"))
        .collect();
    run();
    for (i, bytes) in first.iter().enumerate() {
        assert_eq!(
            &std::fs::read(frames_dir.join(format!("frame_{i:04}.sdf"))).expect("frame"),
            bytes
        );
    }
    // No temporary files are left behind.
    let names: Vec<String> = std::fs::read_dir(&frames_dir)
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.contains(".tmp")), "{names:?}");
    // A shorter animation removes the frames it wrote past its end, so they are not rendered
    // by mistake; an image anim did not write is left alone (the renderer removes its own, see
    // tests/hostile/hardening.rs).
    std::fs::write(frames_dir.join("frame_0011.png"), b"not anim's").expect("write");
    write_spec(8);
    let said = run();
    assert!(said.contains("wrote 8 frames"), "{said}");
    assert!(!frames_dir.join("frame_0008.sdf").exists());
    assert!(!frames_dir.join("frame_0011.sdf").exists());
    assert!(frames_dir.join("frame_0011.png").exists());
    assert!(frames_dir.join("frame_0007.sdf").exists());
}

#[test]
fn committed_animations_generate_frames_that_load() {
    for (spec, frames) in [("orbit", 120), ("motion", 120), ("lights", 120)] {
        let out = tempfile::tempdir().expect("tempdir");
        let args = match Cli::try_parse_from([
            "anim",
            "generate",
            &repo()
                .join(format!("animations/{spec}.ron"))
                .display()
                .to_string(),
            "-o",
            &out.path().display().to_string(),
        ])
        .expect("arguments")
        .command
        {
            Sub::Generate(a) => a.config(),
            _ => unreachable!("a generate command"),
        };
        let report = anim_pipeline::keyframe::run_generate(&args).unwrap_or_else(|e| {
            panic!(
                "{spec}: {}",
                e.iter()
                    .map(|d| d.to_string())
                    .collect::<Vec<_>>()
                    .join("\n")
            )
        });
        assert_eq!(report.frames, frames, "{spec}");
        assert!(report.warnings.is_empty(), "{spec}: {:?}", report.warnings);
        for i in [0, frames / 2, frames - 1] {
            let path = out.path().join(format!("frame_{i:04}.sdf"));
            let loaded = anim_core::load::load_file(&path, &Default::default())
                .unwrap_or_else(|e| panic!("{}: {e:?}", path.display()));
            assert_eq!(loaded.jobs.len(), 1);
            assert_eq!(
                loaded.jobs[0].output,
                PathBuf::from(format!("frame_{i:04}.png"))
            );
        }
    }
    // orbit.ron has a field named `fps`, at 24.
    let orbit = std::fs::read_to_string(repo().join("animations/orbit.ron")).expect("spec");
    assert!(orbit.lines().any(|l| l.trim() == "fps: 24,"));
}

// ---------------------------------------------------------------------------------------------
// The whole job: generate → render (real binary) → encode → ffprobe

fn have(tool: &str) -> bool {
    std::process::Command::new(tool)
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success())
}

fn ffprobe(args: &[&str], file: &Path) -> String {
    let out = std::process::Command::new("ffprobe")
        .args(["-v", "error"])
        .args(args)
        .arg(file)
        .output()
        .expect("ffprobe runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).trim().to_string()
}

#[test]
fn orbit_becomes_a_five_second_h264_video() {
    if !have("ffmpeg") || !have("ffprobe") {
        // Written to the stderr handle itself, which the test harness does not capture, so
        // the skip shows in a normal `cargo test` run.
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED orbit_becomes_a_five_second_h264_video: ffmpeg/ffprobe are not installed (apt-get install ffmpeg); CI installs them"
        );
        return;
    }
    let tmp = tempfile::tempdir().expect("tempdir");
    let frames = tmp.path().join("frames");
    let gen = Command::cargo_bin("anim")
        .expect("binary")
        .arg("generate")
        .arg(repo().join("animations/orbit.ron"))
        .arg("-o")
        .arg(&frames)
        .output()
        .expect("generate runs");
    assert!(
        gen.status.success(),
        "{}",
        String::from_utf8_lossy(&gen.stderr)
    );
    assert!(String::from_utf8_lossy(&gen.stdout).contains("wrote 120 frames"));

    let render = Command::cargo_bin("anim")
        .expect("binary")
        .arg("render")
        .arg(&frames)
        .args(["--width", "160", "--height", "90"])
        .output()
        .expect("render runs");
    let stderr = String::from_utf8_lossy(&render.stderr);
    assert!(render.status.success(), "{stderr}");
    assert!(
        stderr.contains("120 rendered, 0 skipped (unchanged), 0 failed"),
        "{stderr}"
    );

    let video = tmp.path().join("animation.mp4");
    let enc = std::process::Command::new(repo().join("scripts/encode.sh"))
        .arg(&frames)
        .arg(&video)
        .output()
        .expect("encode.sh runs");
    assert!(
        enc.status.success(),
        "{}",
        String::from_utf8_lossy(&enc.stderr)
    );
    assert!(String::from_utf8_lossy(&enc.stdout).contains("120 frames"));

    let stream = ffprobe(
        &[
            "-select_streams",
            "v:0",
            "-count_frames",
            "-show_entries",
            "stream=codec_name,pix_fmt,r_frame_rate,nb_read_frames,width,height",
            "-of",
            "default=nw=1",
        ],
        &video,
    );
    for expected in [
        "codec_name=h264",
        "pix_fmt=yuv420p",
        "r_frame_rate=24/1",
        "nb_read_frames=120",
        "width=160",
        "height=90",
    ] {
        assert!(
            stream.lines().any(|l| l == expected),
            "{expected} not in\n{stream}"
        );
    }
    let duration: f64 = ffprobe(
        &[
            "-show_entries",
            "format=duration",
            "-of",
            "default=nw=1:nk=1",
        ],
        &video,
    )
    .parse()
    .expect("a duration");
    assert!((duration - 5.0).abs() < 0.0005, "duration {duration}");
}

#[test]
fn documented_examples_generate() {
    let doc = std::fs::read_to_string(repo().join("README.md")).expect("README.md");
    let dir = tempfile::tempdir().expect("tempdir");
    for base in ["showcase.sdf", "motion.sdf"] {
        std::fs::copy(repo().join("animations").join(base), dir.path().join(base)).expect("copy");
    }
    let blocks: Vec<&str> = doc
        .split("```ron\n")
        .skip(1)
        .filter_map(|b| b.split("```").next())
        .collect();
    assert!(blocks.len() >= 2, "the doc has its RON examples");
    for (i, block) in blocks.iter().enumerate() {
        let spec = dir.path().join(format!("example{i}.ron"));
        std::fs::write(&spec, block).expect("write");
        let out = Command::cargo_bin("anim")
            .expect("binary")
            .arg("generate")
            .arg(&spec)
            .arg("-o")
            .arg(dir.path().join(format!("frames{i}")))
            .output()
            .expect("run");
        assert!(
            out.status.success(),
            "example {i}:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}
