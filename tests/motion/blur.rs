//! Motion blur (issue 12), shown from outside: real keyframe specs through the real binary
//! (`anim generate`, `anim render --hdr`, `scripts/animate.sh`), on small images.
//!
//! - A blurred frame equals the mean of 16 instants of its exposure (brute force), within
//!   1 level RMS after tone mapping.
//! - Frames in which nothing moves are identical with and without a shutter.
//! - A short blurred animation becomes an MP4 whose frames are smeared where things move and
//!   untouched where nothing does.

use crate::common;

use common::hdr::{mean, read_pfm, read_png, rmse, Pfm};
use common::{anim, Rgb8};
use std::path::{Path, PathBuf};

/// The stage: a still ball on the left (lit from the left, so the moving things' shadows fall
/// to the right, away from it), a box that spins about its vertical axis, a ball that slides.
const STAGE: &str = "\
define material floor 0.1 0.1 0.1  0.5 0.5 0.5  0 0 0  1
define material white 0.15 0.15 0.15  0.7 0.7 0.7  0.3 0.3 0.3  20
define material blue  0.02 0.04 0.15  0.1 0.25 0.85  0.5 0.5 0.5  30
define material red   0.15 0.02 0.02  0.8 0.12 0.1  0.6 0.6 0.6  60
ambient 0.2 0.2 0.2
background 0.05 0.05 0.1
define shape plane ground 0 -1 0  0 1 0  floor
define shape sphere still -2.8 -0.4 0  0.6 white
define shape box spinner 0.9 -1 -1.6  2.5 0.6 0  blue
define shape sphere slider -0.6 -0.5 1.5  0.5 red
define light sun -5 8 6  1 1 1  1
define camera cam 50  0 1.5 8  0 -0.25 -1  0 1 0
";

/// A keyframe spec of the stage: `fps`, `frames`, the shutter line (or none) and the tracks,
/// each keyed linearly from 0 at time 0 to its value at `end` seconds.
fn spec(
    fps: u32,
    frames: u32,
    size: (u32, u32),
    shutter: Option<&str>,
    end: f64,
    tracks: &[(&str, &str, &str)],
) -> String {
    let shutter = shutter.map_or(String::new(), |s| format!("    shutter: {s},\n"));
    let tracks: String = tracks
        .iter()
        .map(|(target, channel, value)| {
            let zero = if value.starts_with('(') { "(0, 0, 0)" } else { "0" };
            format!(
                "        (target: \"{target}\", {channel}: [(at: 0, value: {zero}), (at: {end:?}, value: {value})]),\n"
            )
        })
        .collect();
    format!(
        "(\n    scene: Inline(r#\"{STAGE}\"#),\n    camera: \"cam\",\n    fps: {fps},\n    length: Frames({frames}),\n    resolution: ({}, {}),\n{shutter}    tracks: [\n{tracks}    ],\n)\n",
        size.0, size.1
    )
}

/// Writes `text` as `dir/name.ron` and generates its frames into `dir/name/`.
fn generate(dir: &Path, name: &str, text: &str) -> PathBuf {
    let ron = dir.join(format!("{name}.ron"));
    std::fs::write(&ron, text).unwrap();
    let frames = dir.join(name);
    let out = anim()
        .arg("generate")
        .arg(&ron)
        .arg("-o")
        .arg(&frames)
        .arg("--quiet")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "anim generate {name}:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    frames
}

/// Renders frame files (images beside them) with `args`.
fn render(files: &[PathBuf], args: &[&str]) {
    let out = anim()
        .arg("render")
        .args(files)
        .args(args)
        .arg("--quiet")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "anim render:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn frame(dir: &Path, i: usize, ext: &str) -> PathBuf {
    dir.join(format!("frame_{i:04}.{ext}"))
}

/// Tone map and quantise with the renderer's own rule.
fn to_rgb8(img: &Pfm) -> Rgb8 {
    Rgb8 {
        width: img.width,
        height: img.height,
        data: img
            .pixels
            .iter()
            .flatten()
            .map(|&c| anim_core::render::film::tone_map_u8(c))
            .collect(),
    }
}

/// Frame 1 of a 12 fps spec with `shutter: 0.5` (open from 1/12 s to 1/8 s) against the mean
/// of 16 instants of that exposure: the midpoints of its 16 equal parts. A 768 fps spec (64×)
/// puts its odd frames 65, 67, …, 95 exactly there. Midpoints rather than the starts of the
/// parts (which 32× the fps would give) keep the brute-force mean unbiased: starts lag the
/// true mean by half a part, 1/32 of the exposure's motion. Both specs key the same straight
/// lines over the same 1/6 s, so they describe the same motion.
fn blurred_frame_matches_sixteen_instants(tracks: &[(&str, &str, &str)]) -> f64 {
    let dir = tempfile::tempdir().unwrap();
    let size = (64, 40);
    let end = 1.0 / 6.0;
    let blurred = generate(
        dir.path(),
        "blurred",
        &spec(12, 2, size, Some("0.5"), end, tracks),
    );
    let instants = generate(
        dir.path(),
        "instants",
        &spec(768, 128, size, None, end, tracks),
    );
    // Enough samples that noise is far below the 1-level tolerance: 1024 for the blurred
    // pixel (time included), 16 × 256 for the mean.
    render(&[frame(&blurred, 1, "sdf")], &["--spp", "1024", "--hdr"]);
    let files: Vec<PathBuf> = (0..16)
        .map(|k| frame(&instants, 65 + 2 * k, "sdf"))
        .collect();
    render(&files, &["--spp", "256", "--hdr"]);
    let brute = mean(
        &(0..16)
            .map(|k| read_pfm(&frame(&instants, 65 + 2 * k, "pfm")))
            .collect::<Vec<_>>(),
    );
    let image = read_png(&frame(&blurred, 1, "png"));
    // The PNG is the radiance file tone-mapped: the two outputs agree.
    let own = to_rgb8(&read_pfm(&frame(&blurred, 1, "pfm")));
    assert_eq!(own.data, image.data, "the PNG is not its PFM tone-mapped");
    let expected = to_rgb8(&brute);
    // The instants differ from each other, or the comparison would prove nothing.
    let first = to_rgb8(&read_pfm(&frame(&instants, 65, "pfm")));
    let last = to_rgb8(&read_pfm(&frame(&instants, 95, "pfm")));
    assert!(
        rmse(&first, &last) > 5.0,
        "the exposure hardly moves anything: RMSE {} between its ends",
        rmse(&first, &last)
    );
    rmse(&image, &expected)
}

#[test]
fn a_blurred_frame_is_the_mean_of_sixteen_instants() {
    // Over the exposure the box turns 60° and the ball slides 0.75.
    let e = blurred_frame_matches_sixteen_instants(&[
        ("spinner", "rotate", "240"),
        ("slider", "translate", "(3, 0, 0)"),
    ]);
    eprintln!("objects moving: RMSE {e:.3} levels against 16 instants");
    assert!(e <= 1.0, "RMSE {e:.3} levels against 16 instants");
}

#[test]
fn a_blurred_frame_with_a_moving_camera_is_the_mean_of_sixteen_instants() {
    // The camera slides 0.5 sideways and rises 0.25 during the exposure, with the objects
    // moving too.
    let e = blurred_frame_matches_sixteen_instants(&[
        ("spinner", "rotate", "240"),
        ("slider", "translate", "(3, 0, 0)"),
        ("cam", "translate", "(2, 1, 0)"),
    ]);
    eprintln!("camera moving: RMSE {e:.3} levels against 16 instants");
    assert!(e <= 1.0, "RMSE {e:.3} levels against 16 instants");
}

#[test]
fn frames_without_motion_are_identical_with_any_shutter() {
    let dir = tempfile::tempdir().unwrap();
    // The ball holds still until 0.25 s, then slides: at 12 fps with the shutter at 0.5, the
    // exposures of frames 0–2 end by 5/24 s, before it moves; frame 3's is after.
    let tracks = "        (target: \"slider\", translate: [(at: 0, value: (0, 0, 0)), (at: 0.25, value: (0, 0, 0)), (at: 0.5, value: (3, 0, 0))]),\n";
    let make = |shutter: &str| {
        format!(
            "(\n    scene: Inline(r#\"{STAGE}\"#),\n    fps: 12,\n    length: Frames(6),\n    resolution: (48, 30),\n{shutter}    tracks: [\n{tracks}    ],\n)\n"
        )
    };
    let specs = [
        ("none", String::new()),
        ("zero", "    shutter: 0,\n".to_string()),
        ("half", "    shutter: 0.5,\n".to_string()),
    ];
    let mut images = Vec::new();
    for (name, shutter) in &specs {
        let frames = generate(dir.path(), name, &make(shutter));
        let out = anim()
            .arg("render")
            .arg(&frames)
            .arg("--quiet")
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        images.push(
            (0..6)
                .map(|i| std::fs::read(frame(&frames, i, "png")).unwrap())
                .collect::<Vec<_>>(),
        );
    }
    assert_eq!(images[0], images[1], "shutter: 0 changed the images");
    for (i, (half, none)) in images[2].iter().zip(&images[0]).take(3).enumerate() {
        assert!(
            half == none,
            "frame {i}: nothing moves during its exposure, yet shutter 0.5 changed its image"
        );
    }
    assert!(
        images[2][4] != images[0][4],
        "frame 4 moves during its exposure, yet its blurred image is the unblurred one"
    );
}

fn have(tool: &str) -> bool {
    std::process::Command::new(tool)
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success())
}

#[test]
fn a_blurred_animation_becomes_a_video_smeared_only_where_things_move() {
    if !have("ffmpeg") || !have("ffprobe") {
        use std::io::Write as _;
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED a_blurred_animation_becomes_a_video_smeared_only_where_things_move: ffmpeg/ffprobe are not installed (apt-get install ffmpeg); CI installs them"
        );
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tracks = [
        ("spinner", "rotate", "240"),
        ("slider", "translate", "(3, 0, 0)"),
    ];
    let end = 1.0 / 6.0;
    let ron = dir.path().join("short.ron");
    std::fs::write(&ron, spec(24, 4, (96, 54), Some("0.5"), end, &tracks)).unwrap();
    let frames = dir.path().join("frames");
    let video = dir.path().join("short.mp4");
    // The test's own build of anim, so the script does not build a release one.
    let run = std::process::Command::new(repo.join("scripts/animate.sh"))
        .arg(&ron)
        .arg(&video)
        .env("ANIM", env!("CARGO_BIN_EXE_anim"))
        .env("FRAMES_DIR", &frames)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "animate.sh:\n{}{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
    let probe = std::process::Command::new("ffprobe")
        .args(["-v", "error", "-count_frames", "-select_streams", "v:0"])
        .args([
            "-show_entries",
            "stream=codec_name,nb_read_frames",
            "-of",
            "default=nw=1",
        ])
        .arg(&video)
        .output()
        .unwrap();
    let probe = String::from_utf8_lossy(&probe.stdout).into_owned();
    assert!(probe.contains("codec_name=h264"), "{probe}");
    assert!(probe.contains("nb_read_frames=4"), "{probe}");

    // Each blurred frame against the unblurred instant at the middle of its exposure (the
    // instant the frame file states): frame i of 24 fps is open from i/24 s for 1/48 s, so
    // its middle is frame 4i + 1 of the same motion at 96 fps.
    let middles = generate(
        dir.path(),
        "middles",
        &spec(96, 16, (96, 54), None, end, &tracks),
    );
    let files: Vec<PathBuf> = (0..4).map(|i| frame(&middles, 4 * i + 1, "sdf")).collect();
    render(&files, &[]);
    for i in 0..4 {
        let blurred = read_png(&frame(&frames, i, "png"));
        let sharp = read_png(&frame(&middles, 4 * i + 1, "png"));
        let (w, h) = (blurred.width, blurred.height);
        // The still ball's quarter of the image: nothing there moves, nor does the camera.
        let mut still = 0u8;
        for y in 0..h {
            for x in 0..w / 4 {
                let (a, b) = (blurred.at(x, y), sharp.at(x, y));
                for c in 0..3 {
                    still = still.max(a[c].abs_diff(b[c]));
                }
            }
        }
        assert!(
            still <= 1,
            "frame {i}: the still quarter differs by {still} levels from the unblurred instant"
        );
        // Where things move, the smear shows.
        let mut smeared = 0;
        for y in 0..h {
            for x in w / 4..w {
                let (a, b) = (blurred.at(x, y), sharp.at(x, y));
                if (0..3).any(|c| a[c].abs_diff(b[c]) >= 16) {
                    smeared += 1;
                }
            }
        }
        eprintln!(
            "frame {i}: still quarter within {still}, {smeared} pixels smeared by ≥ 16 levels"
        );
        assert!(
            smeared >= 40,
            "frame {i}: only {smeared} pixels differ by 16 levels or more from the unblurred instant"
        );
    }
}

/// A scene whose radiance is known where nothing is hit (the background) and which is not
/// symmetric top to bottom (a ball in the upper left), so a flipped row order shows.
const HDR_SCENE: &str = "\
define material white 0.1 0.1 0.1  0.7 0.7 0.7  0 0 0  1
background 0.5 2 0.25
define shape sphere ball -1.2 0.8 0 0.6 white
define light sun 0 5 5  1 1 1  1
define camera cam 60  0 0 5  0 0 -1  0 1 0
render cam image.png 40 30
render cam other.ppm 40 30
";

#[test]
fn hdr_writes_the_radiance_beside_each_image() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.sdf");
    std::fs::write(&scene, HDR_SCENE.replace("other.ppm", "other.bmp")).unwrap();
    render(std::slice::from_ref(&scene), &["--spp", "4", "--hdr"]);
    let png = read_png(&dir.path().join("image.png"));
    let pfm = read_pfm(&dir.path().join("image.pfm"));
    assert_eq!((pfm.width, pfm.height), (40, 30));
    assert_eq!(
        to_rgb8(&pfm).data,
        png.data,
        "the PFM tone-mapped is not the PNG"
    );
    // The background is the exact radiance stated; the ball is up and to the left.
    assert_eq!(pfm.pixels[pfm.pixels.len() - 1], [0.5, 2.0, 0.25]);
    assert_eq!(pfm.pixels[39], [0.5, 2.0, 0.25]);
    assert_ne!(pfm.pixels[10 * 40 + 10], [0.5, 2.0, 0.25]);
    assert!(dir.path().join("other.pfm").is_file());
    // Nothing half-written is left behind.
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            // The marks that vouch for the radiance files anim wrote.
            ".anim-cache",
            "image.pfm",
            "image.png",
            "other.bmp",
            "other.pfm",
            "scene.sdf"
        ]
    );

    // Two images of one stem would write one radiance file: refused before rendering.
    let clash = dir.path().join("clash");
    std::fs::create_dir(&clash).unwrap();
    std::fs::write(
        clash.join("scene.sdf"),
        HDR_SCENE.replace("other.ppm", "image.ppm"),
    )
    .unwrap();
    let out = anim()
        .arg("render")
        .arg(clash.join("scene.sdf"))
        .arg("--hdr")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(stderr.contains("scene.sdf:7:1:"), "{stderr}");
    assert!(stderr.contains("image.pfm"), "{stderr}");
    assert!(!clash.join("image.png").exists());
}

#[test]
fn hdr_files_of_frames_are_part_of_the_render_record() {
    let dir = tempfile::tempdir().unwrap();
    let frames = generate(
        dir.path(),
        "frames",
        &spec(
            12,
            2,
            (24, 16),
            None,
            1.0 / 6.0,
            &[("slider", "translate", "(3, 0, 0)")],
        ),
    );
    let run = |args: &[&str]| {
        let out = anim()
            .arg("render")
            .arg(&frames)
            .args(args)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(out.status.success(), "{stderr}");
        stderr
    };
    let first = run(&["--spp", "1"]);
    assert!(first.contains("2 rendered, 0 skipped"), "{first}");
    assert!(!frame(&frames, 0, "pfm").exists());
    // Asking for the radiance is a different setting: every frame renders again.
    let hdr = run(&["--spp", "1", "--hdr"]);
    assert!(hdr.contains("2 rendered, 0 skipped"), "{hdr}");
    assert!(frame(&frames, 1, "pfm").is_file());
    assert!(run(&["--spp", "1", "--hdr"]).contains("0 rendered, 2 skipped"));
    // A lost radiance file is written again, like a lost image.
    std::fs::remove_file(frame(&frames, 1, "pfm")).unwrap();
    let again = run(&["--spp", "1", "--hdr"]);
    assert!(again.contains("1 rendered, 1 skipped"), "{again}");
    assert!(frame(&frames, 1, "pfm").is_file());
}
