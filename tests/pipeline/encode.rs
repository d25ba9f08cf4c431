//! `scripts/encode.sh` and `scripts/animate.sh` as a user runs them, read back by ffprobe and
//! ffmpeg: the frame rate and the images' names come from the frames `anim generate` wrote,
//! every codec names itself as it should (keeping alpha where it can), OpenEXR and 16-bit
//! frames come out as anim's 8-bit images would, and every refusal comes before any work.

use crate::common::media::{decode, ffmpeg_for, ffprobe, stream_field};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A ball before nothing (the camera at z = 10 looks at it down −z): the background is empty,
/// so alpha is 0 there and 1 on the ball.
const BALL: &str = "define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20
define shape sphere ball 0 0 0 3 red
define light sun 5 5 5 1 1 1 1
define camera cam 60 0 0 10 0 0 -1 0 1 0
";

/// A project folder with the ball and a spec of `frames` frames at `fps` named `output`,
/// the ball moving across.
fn project(fps: &str, frames: usize, output: &str) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::write(dir.path().join("base.sdf"), BALL).expect("write");
    let spec = format!(
        "(scene: File(\"base.sdf\"), camera: \"cam\", fps: {fps}, length: Frames({frames}),
  resolution: (32, 24), output: \"{output}\",
  tracks: [(target: \"ball\", translate: [(at: 0, value: (-1, 0, 0)), (at: 0.1, value: (1, 0, 0))])])"
    );
    std::fs::write(dir.path().join("shot.ron"), spec).expect("write");
    dir
}

fn assert_ran(out: &Output, what: &str) {
    assert!(
        out.status.success(),
        "{what}:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `anim generate` of the project's spec into `name`, then `anim render` of it with `args`.
fn frames(dir: &Path, name: &str, args: &[&str]) -> PathBuf {
    let frames = dir.join(name);
    let anim = env!("CARGO_BIN_EXE_anim");
    let gen = Command::new(anim)
        .arg("generate")
        .arg(dir.join("shot.ron"))
        .arg("-o")
        .arg(&frames)
        .output()
        .expect("generate");
    assert_ran(&gen, "generate");
    let render = Command::new(anim)
        .arg("render")
        .arg(&frames)
        .args(args)
        .output()
        .expect("render");
    assert_ran(&render, "render");
    frames
}

/// `scripts/encode.sh ARGS` with PATH `path` (the system's when `None`).
fn encode(args: &[&dyn AsRef<std::ffi::OsStr>], path: Option<&str>) -> Output {
    let mut cmd = Command::new(repo().join("scripts/encode.sh"));
    cmd.args(args);
    if let Some(path) = path {
        cmd.env("PATH", path);
    }
    cmd.output().expect("encode.sh runs")
}

/// The video's frames as decoded (counted, not the container's claim) and its duration.
fn frames_and_duration(video: &Path) -> (usize, f64) {
    let probe = ffprobe(
        &[
            "-select_streams",
            "v:0",
            "-count_frames",
            "-show_entries",
            "stream=nb_read_frames:format=duration",
            "-of",
            "default=nw=1:nk=1",
        ],
        video,
    );
    let mut lines = probe.lines();
    let count = lines.next().and_then(|l| l.parse().ok()).expect("a count");
    let duration = lines
        .next()
        .and_then(|l| l.parse().ok())
        .expect("a duration");
    (count, duration)
}

#[test]
fn a_12_fps_spec_lasts_1_s_for_12_frames_without_being_told_its_rate() {
    if !ffmpeg_for("a_12_fps_spec_lasts_1_s_for_12_frames_without_being_told_its_rate") {
        return;
    }
    let dir = project("12", 12, "frame_{frame}.png");
    let frames = frames(dir.path(), "f", &[]);
    let video = dir.path().join("out.mp4");
    assert_ran(&encode(&[&frames, &video], None), "encode.sh");
    assert_eq!(stream_field(&video, "codec_name"), "h264");
    assert_eq!(stream_field(&video, "r_frame_rate"), "12/1");
    let (count, duration) = frames_and_duration(&video);
    assert_eq!(count, 12);
    // 12 frames of 1/12 s each.
    assert!((duration - 1.0).abs() < 0.0005, "duration {duration}");
}

#[test]
fn a_ratio_in_the_header_and_images_of_any_name_are_read_from_the_frames() {
    if !ffmpeg_for("a_ratio_in_the_header_and_images_of_any_name_are_read_from_the_frames") {
        return;
    }
    let dir = project("24", 3, "frame_{frame}.png");
    let frames = frames(dir.path(), "f", &[]);
    // The header of a fractional rate, as the contract of the frame files spells it; and
    // images named by no number (each frame's own render line says which is its image).
    let names = ["first", "second", "third"];
    for (i, name) in names.iter().enumerate() {
        let file = frames.join(format!("frame_{i:04}.sdf"));
        let text = std::fs::read_to_string(&file).expect("frame");
        assert!(text.starts_with(&format!("# Frame {i} of 3 (")), "{text}");
        let text = text
            .replacen(" at 24 fps)", " at 24000/1001 fps)", 1)
            .replacen(&format!("frame_{i:04}.png"), &format!("{name}.png"), 1);
        std::fs::write(&file, text).unwrap();
    }
    let render = Command::new(env!("CARGO_BIN_EXE_anim"))
        .arg("render")
        .arg(&frames)
        .output()
        .expect("render");
    assert_ran(&render, "render");
    assert!(frames.join("second.png").is_file());
    let video = dir.path().join("out.mkv");
    // Lossless, so that the frames can be told apart by their pixels.
    let out = encode(&[&frames, &video, &"--codec", &"ffv1"], None);
    assert_ran(&out, "encode.sh");
    assert_eq!(stream_field(&video, "r_frame_rate"), "24000/1001");
    let (count, duration) = frames_and_duration(&video);
    assert_eq!(count, 3);
    // Matroska keeps milliseconds: 3 · 1001/24000 s = 0.125125 s.
    assert!((duration - 0.125125).abs() < 0.0011, "duration {duration}");
    // In the frames' order: the video's second frame is second.png.
    let second = &decode(&video, "rgb24")[32 * 24 * 3..2 * 32 * 24 * 3];
    let png = decode(&frames.join("second.png"), "rgb24");
    let worst = second.iter().zip(&png).map(|(a, b)| a.abs_diff(*b)).max();
    assert!(
        worst < Some(40),
        "frame 1 is not second.png: off by {worst:?}"
    );
}

#[test]
fn shot_jpg_frames_go_through_animate_sh_to_an_mp4() {
    if !ffmpeg_for("shot_jpg_frames_go_through_animate_sh_to_an_mp4") {
        return;
    }
    let dir = project("12", 12, "shot_{frame}.jpg");
    let video = dir.path().join("shot.mp4");
    let run = Command::new(repo().join("scripts/animate.sh"))
        .arg(dir.path().join("shot.ron"))
        .arg(&video)
        .current_dir(dir.path())
        .env("ANIM", env!("CARGO_BIN_EXE_anim"))
        .env_remove("FRAMES_DIR")
        .output()
        .expect("animate.sh runs");
    assert_ran(&run, "animate.sh");
    assert!(dir.path().join("frames/shot/shot_0011.jpg").is_file());
    assert_eq!(stream_field(&video, "codec_name"), "h264");
    let (count, duration) = frames_and_duration(&video);
    assert_eq!(count, 12);
    assert!((duration - 1.0).abs() < 0.0005, "duration {duration}");
}

#[test]
fn each_codec_names_itself_and_keeps_alpha_where_it_can() {
    if !ffmpeg_for("each_codec_names_itself_and_keeps_alpha_where_it_can") {
        return;
    }
    let dir = project("12", 4, "frame_{frame}.png");
    let frames = frames(dir.path(), "f", &["--alpha"]);
    let cases = [
        ("prores", "a.mov", "prores", "yuva444p"),
        ("webm", "a.webm", "vp9", "yuv420p"),
        ("ffv1", "a.mkv", "ffv1", "bgra"),
        ("gif", "a.gif", "gif", ""),
        ("h265", "a.mp4", "hevc", "yuv420p"),
    ];
    for (codec, name, codec_name, pix_fmt) in cases {
        let video = dir.path().join(name);
        let out = encode(&[&frames, &video, &"--codec", &codec], None);
        assert_ran(&out, codec);
        assert_eq!(stream_field(&video, "codec_name"), codec_name, "{codec}");
        assert!(
            stream_field(&video, "pix_fmt").starts_with(pix_fmt),
            "{codec}: {}",
            stream_field(&video, "pix_fmt")
        );
        assert_eq!(frames_and_duration(&video).0, 4, "{codec}");
    }
    let mov = dir.path().join("a.mov");
    assert_eq!(stream_field(&mov, "profile"), "4444");
    // VP9 carries alpha in a side stream that the WebM's tag announces.
    let tags = ffprobe(
        &[
            "-show_entries",
            "stream_tags=alpha_mode",
            "-of",
            "default=nw=1",
        ],
        &dir.path().join("a.webm"),
    );
    assert_eq!(tags, "TAG:alpha_mode=1");
    // The lossless video keeps the frames' alpha: 0 in the empty corner, 255 on the ball
    // (radius 3 at distance 10 under a 60° view: it fills the middle).
    let rgba = decode(&dir.path().join("a.mkv"), "rgba");
    let alpha = |x: usize, y: usize| rgba[(y * 32 + x) * 4 + 3];
    assert_eq!((alpha(0, 0), alpha(16, 12)), (0, 255));
    // A GIF has no partial alpha: the frames are put over black, every pixel opaque.
    let gif = decode(&dir.path().join("a.gif"), "rgba");
    assert!(
        gif.chunks_exact(4).all(|p| p[3] == 255),
        "a transparent pixel"
    );
    assert_eq!(gif[..4], [0, 0, 0, 255], "the empty corner");
}

/// The first frame of `video` decoded to 8-bit RGBA.
fn first_rgba(video: &Path) -> Vec<u8> {
    decode(video, "rgba")[..32 * 24 * 4].to_vec()
}

#[test]
fn openexr_and_16_bit_frames_come_out_as_anim_s_8_bit_images() {
    if !ffmpeg_for("openexr_and_16_bit_frames_come_out_as_anim_s_8_bit_images") {
        return;
    }
    // The same frames written as 8-bit PNG (the reference: anim's own tone map), as OpenEXR
    // (linear, premultiplied) and as 16-bit PNG, tone-mapped or linear (the ball's radiance
    // stays below 1, so the linear PNG's clipping loses nothing), all with alpha; encoded
    // losslessly.
    let runs = [
        ("p8", "frame_{frame}.png", vec!["--alpha"]),
        ("exr", "frame_{frame}.exr", vec!["--alpha"]),
        (
            "exr32",
            "frame_{frame}.exr",
            vec!["--alpha", "--depth", "32"],
        ),
        ("p16", "frame_{frame}.png", vec!["--alpha", "--depth", "16"]),
        (
            "linear",
            "frame_{frame}.png",
            vec!["--alpha", "--depth", "16", "--linear"],
        ),
    ];
    let mut decoded = Vec::new();
    for (name, output, args) in &runs {
        let dir = project("12", 2, output);
        let frames = frames(dir.path(), name, args);
        let video = dir.path().join("v.mkv");
        assert_ran(&encode(&[&frames, &video, &"--codec", &"ffv1"], None), name);
        decoded.push((name, first_rgba(&video), dir));
    }
    let (_, reference, _) = &decoded[0];
    for (name, pixels, _) in &decoded[1..] {
        let worst = reference
            .iter()
            .zip(pixels)
            .map(|(a, b)| a.abs_diff(*b))
            .max();
        assert!(worst <= Some(1), "{name}: off by {worst:?} levels");
    }
}

#[test]
fn refusals_come_before_any_work() {
    if !ffmpeg_for("refusals_come_before_any_work") {
        return;
    }
    let dir = project("12", 2, "frame_{frame}.png");
    let animate = |out: &Path, extra: &[&str], path: Option<&str>| {
        let mut cmd = Command::new(repo().join("scripts/animate.sh"));
        cmd.arg(dir.path().join("shot.ron"))
            .arg(out)
            .args(extra)
            .current_dir(dir.path())
            .env("ANIM", env!("CARGO_BIN_EXE_anim"))
            .env_remove("FRAMES_DIR");
        if let Some(path) = path {
            cmd.env("PATH", path);
        }
        cmd.output().expect("animate.sh runs")
    };
    // An ffmpeg built without libx264 (it lists only FFV1), before the real one on PATH.
    let fake = dir.path().join("bin");
    std::fs::create_dir(&fake).unwrap();
    std::fs::write(
        fake.join("ffmpeg"),
        "#!/bin/sh\necho ' V....D ffv1                 FFmpeg video codec #1'\n",
    )
    .unwrap();
    use std::os::unix::fs::PermissionsExt as _;
    std::fs::set_permissions(fake.join("ffmpeg"), std::fs::Permissions::from_mode(0o755)).unwrap();
    let path = format!("{}:{}", fake.display(), std::env::var("PATH").unwrap());
    let missing = dir.path().join("no such folder/out.mp4");
    let cases: [(&Path, &[&str], Option<&str>, &str); 3] = [
        (&missing, &[], None, "no such folder does not exist"),
        (
            Path::new("out.mp4"),
            &["--codec", "mpeg9"],
            None,
            "unknown codec 'mpeg9'",
        ),
        (
            Path::new("out.mp4"),
            &[],
            Some(&path),
            "has no libx264 encoder",
        ),
    ];
    for (out, extra, path, message) in cases {
        let run = animate(out, extra, path);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(
            !run.status.success() && stderr.contains(message),
            "{stderr}"
        );
        // Nothing generated, rendered or encoded.
        assert!(!dir.path().join("frames").exists(), "{message}");
        assert!(!dir.path().join("out.mp4").exists(), "{message}");
    }
    // encode.sh on its own says the same before it reads a frame.
    let frames = dir.path().join("none");
    let run = encode(&[&frames, &missing], None);
    assert!(String::from_utf8_lossy(&run.stderr).contains("no such folder does not exist"));
    let run = encode(&[&frames, &"out.mp4"], Some(&path));
    assert!(String::from_utf8_lossy(&run.stderr).contains("has no libx264 encoder"));
}
