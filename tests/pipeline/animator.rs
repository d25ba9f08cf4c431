//! The animator's spec, through `anim generate` on real files: aim, orientation keys, the
//! inclusive end, curves that must stay in range, materials and visibility, reuse, the early
//! check of the base scene, and the frames of every example spec.
//!
//! Frames are read back here with a reader of the test's own (the few statements that the
//! generator writes for these specs), so that the claims are checked against the scene
//! language, not against the generator's own code.

use crate::common;
use glam::{DQuat, DVec3};
use std::path::{Path, PathBuf};

pub(crate) fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs `anim generate SPEC -o OUT --standalone` (whole frame files, which the tests read);
/// (success, stderr).
pub(crate) fn generate(spec: &Path, out: &Path) -> (bool, String) {
    let run = common::anim()
        .args(["generate", "--standalone"])
        .arg(spec)
        .arg("-o")
        .arg(out)
        .output()
        .expect("run anim");
    (
        run.status.success(),
        String::from_utf8_lossy(&run.stderr).into_owned(),
    )
}

/// Writes `files` into a new temporary directory.
pub(crate) fn project(files: &[(&str, &str)]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tempdir");
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).expect("write");
    }
    dir
}

/// The `.sdf` frames of a directory, in order.
pub(crate) fn frames(dir: &Path) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = std::fs::read_dir(dir)
        .expect("frame dir")
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".sdf"))
        .map(|n| {
            let text = std::fs::read_to_string(dir.join(&n)).expect("frame");
            (n, text)
        })
        .collect();
    out.sort();
    out
}

pub(crate) fn numbers(words: &[&str]) -> Vec<f64> {
    words
        .iter()
        .map(|w| w.parse::<f64>().unwrap_or_else(|_| panic!("number: {w}")))
        .collect()
}

/// The transform of a frame's `transform NAME …` lines for `name`, applied in order (each
/// after the ones before, docs/scene-language.md §7), to a point.
pub(crate) fn place(text: &str, name: &str, mut p: DVec3) -> DVec3 {
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        if w.len() < 3 || w[0] != "transform" || w[1] != name {
            continue;
        }
        let v = numbers(&w[3..]);
        p = match (w[2], v.as_slice()) {
            ("translate", [x, y, z]) => p + DVec3::new(*x, *y, *z),
            ("scale", [s]) => p * *s,
            ("scale", [x, y, z]) => p * DVec3::new(*x, *y, *z),
            ("rotate", [deg, x, y, z]) => {
                let axis = DVec3::new(*x, *y, *z).normalize();
                DQuat::from_axis_angle(axis, deg.to_radians()) * p
            }
            other => panic!("unexpected transform {other:?} in {line}"),
        };
    }
    p
}

/// The words of the first line of `text` that starts with `prefix`.
pub(crate) fn line_with<'t>(text: &'t str, prefix: &str) -> Vec<&'t str> {
    text.lines()
        .find(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no line `{prefix}` in\n{text}"))
        .split_whitespace()
        .collect()
}

#[test]
fn the_fly_by_camera_keeps_the_moving_ball_in_the_middle_of_every_frame() {
    let out = tempfile::tempdir().unwrap();
    let (ok, stderr) = generate(&repo().join("animations/flyby.ron"), out.path());
    assert!(ok, "{stderr}");
    assert!(stderr.is_empty(), "the example warns:\n{stderr}");
    let frames = frames(out.path());
    // `end: Inclusive`: 5 s at 24 fps is 121 frames, the last at 5 s.
    assert_eq!(frames.len(), 121);
    let mut eyes = Vec::new();
    for (name, text) in &frames {
        let cam = numbers(&line_with(text, "define camera cam")[3..]);
        let (fov, eye) = (cam[0], DVec3::new(cam[1], cam[2], cam[3]));
        let dir = DVec3::new(cam[4], cam[5], cam[6]).normalize();
        let up = DVec3::new(cam[7], cam[8], cam[9]);
        let ball = numbers(&line_with(text, "define shape sphere ball")[4..7]);
        let centre = place(text, "ball", DVec3::new(ball[0], ball[1], ball[2]));
        let render = line_with(text, "render cam");
        let (w, h) = (numbers(&render[3..4])[0], numbers(&render[4..5])[0]);
        // The pinhole of docs/shading.md §1: the image plane at (w/2)/tan(fov/2) pixels.
        let right = dir.cross(up).normalize();
        let true_up = right.cross(dir);
        let d = centre - eye;
        let focal = (w / 2.0) / (fov.to_radians() / 2.0).tan();
        let x = focal * d.dot(right) / d.dot(dir);
        let y = focal * d.dot(true_up) / d.dot(dir);
        assert!(d.dot(dir) > 0.0, "{name}: the ball is behind the camera");
        assert!(
            x.abs() <= 0.05 * w && y.abs() <= 0.05 * h,
            "{name}: the ball is at ({x:.1}, {y:.1}) px from the centre of a {w}×{h} image"
        );
        eyes.push(eye);
    }
    // The camera really flies: its eye moves far between the first and last frame.
    assert!((eyes[0] - eyes[120]).length() > 10.0);
}

/// A base scene with one ball at the origin, a light and a camera looking at it.
pub(crate) const BALL: &str = "define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20
define shape sphere ball 0 0 0 1 red
define light sun 5 5 5 1 1 1 1
define camera cam 60 0 0 10 0 0 -1 0 1 0
";

#[test]
fn a_shot_that_ends_on_its_pose_shows_the_last_key_on_the_last_frame() {
    let spec = |end: &str| {
        format!(
            "(scene: File(\"base.sdf\"), fps: 8, length: Seconds(1), resolution: (16, 9),{end}
              tracks: [(target: \"ball\", translate: [
                  (at: 0, value: (0, 0, 0), interp: EaseOut), (at: 1, value: (-2, 0, 0))])])"
        )
    };
    let dir = project(&[
        ("base.sdf", BALL),
        ("pose.ron", &spec(" end: Inclusive,")),
        ("loop.ron", &spec("")),
    ]);
    let (ok, stderr) = generate(&dir.path().join("pose.ron"), &dir.path().join("pose"));
    assert!(ok && stderr.is_empty(), "{stderr}");
    let pose = frames(&dir.path().join("pose"));
    // length·fps + 1 frames, the last at exactly 1 s and at exactly the last key's value.
    assert_eq!(pose.len(), 9);
    let last = &pose[8].1;
    assert!(last.starts_with("# Frame 8 of 9 (t = 1 s"), "{last}");
    assert!(last.contains("transform ball translate -2 0 0\n"), "{last}");

    // The default stops one frame short (right for loops), and says which key no frame shows.
    let (ok, stderr) = generate(&dir.path().join("loop.ron"), &dir.path().join("loop"));
    assert!(ok, "{stderr}");
    let looped = frames(&dir.path().join("loop"));
    assert_eq!(looped.len(), 8);
    // EaseOut at s = 7/8: 1 − (1/8)² = 63/64 of the way: x = −2·63/64 = −1.96875.
    assert!(looped[7]
        .1
        .contains("transform ball translate -1.96875 0 0\n"));
    assert!(
        stderr.contains(
            "loop.ron:3:68: warning: this key at 1 s comes after the last frame (0.875 s)"
        ),
        "{stderr}"
    );
    assert!(stderr.contains("end: Inclusive"), "{stderr}");
}

#[test]
fn a_smooth_scale_that_overshoots_through_zero_is_an_error_naming_the_frame() {
    // Keys 3 → 0.1 → 0.1 at 0, 1 and 2 s. On the segment from 1 to 2 s, Catmull-Rom's
    // tangents are (0.1 − 3)/2 = −1.45 at 1 s and 0 at 2 s (the end), so the scale is
    // 0.1 − 1.45·s(1 − s)², which is 0 where s(1 − s)² = 0.069: s ≈ 0.0817, t ≈ 1.0817 s.
    // That lies in frame 25's span (25/24 = 1.0417 s to 26/24 = 1.0833 s).
    let spec = |interp: &str| {
        format!(
            "(scene: File(\"base.sdf\"), fps: 24, length: Seconds(3), resolution: (16, 9),
  tracks: [(target: \"ball\", scale: [(at: 0, value: 3, interp: {interp}), (at: 1, value: 0.1, interp: {interp}), (at: 2, value: 0.1)])])"
        )
    };
    let dir = project(&[
        ("base.sdf", BALL),
        ("smooth.ron", &spec("Smooth")),
        ("clamped.ron", &spec("Monotone")),
    ]);
    let (ok, stderr) = generate(&dir.path().join("smooth.ron"), &dir.path().join("s"));
    assert!(!ok);
    assert!(
        stderr.contains("smooth.ron:2:72: error: at frame 25 (between t = 1.04166666667 and 1.08333333333 s) the scale of 'ball' passes through 0"),
        "{stderr}"
    );
    assert!(stderr.contains("Monotone"), "{stderr}");
    assert!(!dir.path().join("s").join("frame_0000.sdf").exists());
    // The clamped spline through the same keys stays within 0.1..3 at every frame.
    let (ok, stderr) = generate(&dir.path().join("clamped.ron"), &dir.path().join("c"));
    assert!(ok, "{stderr}");
    for (name, text) in frames(&dir.path().join("c")) {
        if let Some(line) = text.lines().find(|l| l.starts_with("transform ball scale")) {
            let s = numbers(&line.split_whitespace().collect::<Vec<_>>()[3..]);
            assert!(s.iter().all(|v| (0.1..=3.0).contains(v)), "{name}: {line}");
        }
    }
}

#[test]
fn a_720_degree_spin_turns_twice_and_orientation_keys_slerp() {
    let spec = "(scene: File(\"base.sdf\"), fps: 4, length: Seconds(2), resolution: (16, 9), end: Inclusive,
  tracks: [
    (target: \"ball\", axis: (0, 0, 1), rotate: [(at: 0, value: 0), (at: 2, value: 720)]),
    (target: \"cam\", orient: [(at: 0, value: AxisAngle((0, 1, 0), 0)), (at: 2, value: Quat(x: 0, y: 0.70710678118654757, z: 0, w: 0.70710678118654757))]),
  ])";
    let dir = project(&[("base.sdf", BALL), ("spin.ron", spec)]);
    let (ok, stderr) = generate(&dir.path().join("spin.ron"), &dir.path().join("f"));
    assert!(ok, "{stderr}");
    let frames = frames(&dir.path().join("f"));
    // 720° over 2 s is 360° a second: 90° a frame at 4 fps, two whole turns at frame 8.
    let turned: Vec<f64> = frames
        .iter()
        .map(|(_, text)| {
            text.lines()
                .find(|l| l.starts_with("transform ball rotate"))
                .map_or(0.0, |l| {
                    numbers(&l.split_whitespace().collect::<Vec<_>>()[3..4])[0]
                })
        })
        .collect();
    assert_eq!(
        turned,
        [0.0, 90.0, 180.0, 270.0, 360.0, 450.0, 540.0, 630.0, 720.0]
    );
    // The camera's orientation slerps from none to 90° about +y: 45° halfway (frame 4),
    // about +y, and turns about its own position (its default pivot).
    let half = &frames[4].1;
    let rotate: Vec<&str> = half
        .lines()
        .find(|l| l.starts_with("transform cam rotate"))
        .expect("cam turns")
        .split_whitespace()
        .collect();
    let v = numbers(&rotate[3..]);
    assert!(
        (v[0] - 45.0).abs() < 1e-9 && (DVec3::new(v[1], v[2], v[3]) - DVec3::Y).length() < 1e-9,
        "{half}"
    );
    assert!(half.contains("transform cam translate 0 0 -10\n"), "{half}");
}

#[test]
fn a_keyed_material_fades_to_glass_and_visible_hides_the_ball_for_a_while() {
    // A red ball before a bright blue background: opaque, the middle pixel is red; glass
    // (opacity 0, η 1.5) shows the background through it; hidden, the background itself.
    let base = "define material red 0.3 0 0 0.9 0 0 0 0 0 10 0 1 1.5
define shape sphere ball 0 0 0 1 red
define light sun 0 0 10 1 1 1 1
background 0 0 1
define camera cam 30 0 0 10 0 0 -1 0 1 0
";
    let spec = "(scene: File(\"base.sdf\"), fps: 4, length: Seconds(2), resolution: (24, 24), end: Inclusive,
  tracks: [
    (target: \"red\", opacity: [(at: 0, value: 1), (at: 1, value: 0)]),
    (target: \"ball\", visible: [(at: 0, value: true), (at: 1.25, value: false), (at: 1.75, value: true)]),
  ])";
    let dir = project(&[("base.sdf", base), ("fade.ron", spec)]);
    let out = dir.path().join("f");
    let (ok, stderr) = generate(&dir.path().join("fade.ron"), &out);
    assert!(ok, "{stderr}");
    let frames = frames(&out);
    // Opacity is keyed linearly: 1 − t at frame t·4, written as the material's 12th number.
    for (i, expected) in [(0, "1"), (2, "0.5"), (4, "0")] {
        let m = line_with(&frames[i].1, "define material red");
        assert_eq!(m[14], expected, "frame {i}: {m:?}");
    }
    // Hidden at 1.25 and 1.5 s (frames 5 and 6), shown again from 1.75 s.
    let shown: Vec<bool> = frames
        .iter()
        .map(|(_, t)| t.contains("define shape sphere ball"))
        .collect();
    assert_eq!(
        shown,
        [true, true, true, true, true, false, false, true, true]
    );
    let status = common::anim()
        .args(["render"])
        .arg(&out)
        .output()
        .expect("render");
    assert!(status.status.success());
    let middle = |i: usize| {
        let img = image::open(out.join(format!("frame_{i:04}.png")))
            .expect("png")
            .to_rgb8();
        img.get_pixel(12, 12).0
    };
    let opaque = middle(0);
    assert!(opaque[0] > 100 && opaque[2] < 30, "opaque: {opaque:?}");
    let glass = middle(4);
    assert!(glass[2] > 100 && glass[0] < 30, "glass: {glass:?}");
    // The background alone: blue 1, tone-mapped 1/(1+1) = 0.5 → 128.
    assert_eq!(middle(5), [0, 0, common::expected_u8(1.0)]);
}

#[test]
fn an_unknown_material_of_the_base_scene_is_reported_there_before_any_frame_is_written() {
    let base = "define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20
define shape sphere ball 0 0 0 1 blue
define light sun 5 5 5 1 1 1 1
define camera cam 60 0 0 10 0 0 -1 0 1 0
";
    let dir = project(&[
        ("base.sdf", base),
        (
            "spec.ron",
            "(scene: File(\"base.sdf\"), length: Frames(3), resolution: (8, 8))",
        ),
    ]);
    let out = dir.path().join("frames");
    let mut seen = Vec::new();
    let config = anim_pipeline::keyframe::GenerateConfig {
        spec: dir.path().join("spec.ron"),
        out: Some(out.clone()),
        standalone: false,
        frames: None,
    };
    anim_pipeline::keyframe::run_generate_reporting(&config, |warnings| {
        let written = std::fs::read_dir(&out).map_or(0, |d| d.count());
        seen = warnings.iter().map(ToString::to_string).collect();
        assert_eq!(written, 0, "frames were written before the warnings");
    })
    .expect("generates");
    assert_eq!(seen.len(), 1, "{seen:#?}");
    let base_file = dir.path().join("base.sdf");
    assert!(
        seen[0].starts_with(&format!(
            "{}:2:34: warning: unknown material `blue`",
            base_file.display()
        )),
        "{}",
        seen[0]
    );
    // The binary says it once, in the same words.
    let (ok, stderr) = generate(&dir.path().join("spec.ron"), &out);
    assert!(ok);
    assert_eq!(
        stderr.matches("unknown material `blue`").count(),
        1,
        "{stderr}"
    );
}

#[test]
fn staggered_tracks_play_one_curve_each_offset_in_time() {
    let spec = "(scene: File(\"base.sdf\"), fps: 10, length: Seconds(2), resolution: (16, 9),
  curves: [(name: \"hop\", cycle: PingPong, translate: [(at: 0, value: (0, 0, 0)), (at: 0.5, value: (0, 1, 0))])],
  tracks: [
    (target: \"ball\", curve: \"hop\"),
    (target: \"cam\", curve: \"hop\", offset: 0.2),
  ])";
    let dir = project(&[("base.sdf", BALL), ("crowd.ron", spec)]);
    let out = dir.path().join("f");
    let (ok, stderr) = generate(&dir.path().join("crowd.ron"), &out);
    assert!(ok, "{stderr}");
    let frames = frames(&out);
    let height = |text: &str, name: &str| place(text, name, DVec3::ZERO).y;
    for i in 0..frames.len() {
        // Up in 0.5 s, down in the next (ping-pong): height = triangle wave of period 1 s.
        let t = i as f64 / 10.0;
        let phase = t.rem_euclid(1.0);
        let expected = if phase <= 0.5 {
            2.0 * phase
        } else {
            2.0 - 2.0 * phase
        };
        assert!(
            (height(&frames[i].1, "ball") - expected).abs() < 1e-9,
            "frame {i}"
        );
        // The camera plays the same hop 0.2 s (two frames) later.
        if i >= 2 {
            let (later, ball) = (
                height(&frames[i].1, "cam"),
                height(&frames[i - 2].1, "ball"),
            );
            assert!((later - ball).abs() < 1e-9, "frame {i}: {later} vs {ball}");
        }
    }
}

#[test]
fn a_camera_whose_target_passes_through_its_eye_is_an_error_naming_the_frame() {
    // The camera at (0, 0, 10) looks at a point keyed from (0, 0, 0) to (0, 0, 20): at 0.5 s
    // (frame 2 at 4 fps) the point is the eye itself.
    let spec = "(scene: File(\"base.sdf\"), fps: 4, length: Seconds(1), resolution: (16, 9),
  tracks: [(target: \"cam\", look_at: Keys([(at: 0, value: (0, 0, 0)), (at: 1, value: (0, 0, 20))]))])";
    let up = "(scene: File(\"base.sdf\"), fps: 4, length: Seconds(1), resolution: (16, 9),
  tracks: [(target: \"cam\", look_at: Point((0, 0, 0)), up: (0, 0, 1))])";
    let dir = project(&[("base.sdf", BALL), ("eye.ron", spec), ("up.ron", up)]);
    let (ok, stderr) = generate(&dir.path().join("eye.ron"), &dir.path().join("a"));
    assert!(!ok);
    assert!(
        stderr.contains("eye.ron:2:37: error: at frame 2 (t = 0.5 s) camera 'cam' would look at the point where its eye is"),
        "{stderr}"
    );
    let (ok, stderr) = generate(&dir.path().join("up.ron"), &dir.path().join("b"));
    assert!(!ok);
    assert!(
        stderr.contains("up.ron:2:37: error: at frame 0 (t = 0 s) camera 'cam' would look straight along its up direction (0, 0, 1)"),
        "{stderr}"
    );
}

#[test]
fn a_bracket_left_open_is_shown_where_it_opens() {
    let spec = "(
  scene: File(\"base.sdf\"),
  length: Frames(2),
  resolution: (16, 9),
  tracks: [
    (target: \"ball\", translate: [(at: 0, value: (0, 0, 0))]
  ],
)
";
    let dir = project(&[("base.sdf", BALL), ("open.ron", spec)]);
    let (ok, stderr) = generate(&dir.path().join("open.ron"), &dir.path().join("f"));
    assert!(!ok);
    assert!(
        stderr.contains("open.ron:6:5: error: this `(` is never closed\n  |\n6 |     (target:"),
        "{stderr}"
    );
}

#[test]
fn every_example_spec_generates_the_frames_it_always_has() {
    // Each line: spec, frame count, and the 64-bit FNV-1a of every frame file's name and
    // bytes in name order (each followed by a 0xff byte), whole (`--standalone`) and split
    // (the frames with `static.sdfi`), as anim 4a69291 generated them. New fields and
    // defaults are opt-in: the frames of these specs must not change.
    let manifest = include_str!("animations.tsv");
    let out = tempfile::tempdir().unwrap();
    let fingerprint = |dir: &Path, extensions: &[&str]| {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .expect("frame dir")
            .filter_map(Result::ok)
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| extensions.iter().any(|x| n.ends_with(x)))
            .collect();
        names.sort();
        let mut h = anim_core::util::Fnv64::default();
        for name in &names {
            h.write_part(name.as_bytes());
            h.write_part(&std::fs::read(dir.join(name)).expect("frame"));
        }
        format!("{:016x}", h.finish())
    };
    for line in manifest.lines().filter(|l| !l.starts_with('#')) {
        let cols: Vec<&str> = line.split('\t').collect();
        let (spec, count) = (cols[0], cols[1].parse::<usize>().unwrap());
        let whole = out.path().join(spec);
        let (ok, stderr) = generate(&repo().join("animations").join(spec), &whole);
        assert!(ok, "{spec}: {stderr}");
        assert_eq!(frames(&whole).len(), count, "{spec}");
        assert_eq!(
            fingerprint(&whole, &[".sdf"]),
            cols[2],
            "{spec}'s frames changed"
        );
        let split = out.path().join(format!("{spec}.split"));
        let run = common::anim()
            .arg("generate")
            .arg(repo().join("animations").join(spec))
            .arg("-o")
            .arg(&split)
            .output()
            .expect("run anim");
        assert!(run.status.success(), "{spec}");
        assert_eq!(
            fingerprint(&split, &[".sdf", ".sdfi"]),
            cols[3],
            "{spec}'s split frames changed"
        );
    }
}

#[test]
fn the_new_example_specs_generate_frames_that_load_without_warnings() {
    for spec in [
        "logo.ron",
        "crowd.ron",
        "candle.ron",
        "rig.ron",
        "flythrough.ron",
    ] {
        let out = tempfile::tempdir().unwrap();
        let (ok, stderr) = generate(&repo().join("animations").join(spec), out.path());
        assert!(ok && stderr.is_empty(), "{spec}: {stderr}");
        let check = common::anim()
            .arg("check")
            .arg(out.path())
            .output()
            .expect("check");
        assert!(check.status.success(), "{spec}");
        assert!(
            check.stderr.is_empty(),
            "{spec}: {}",
            String::from_utf8_lossy(&check.stderr)
        );
    }
}

#[test]
fn animate_sh_uses_a_built_anim_without_cargo_and_the_spec_s_frames_dir() {
    let have_ffmpeg = std::process::Command::new("ffmpeg")
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !have_ffmpeg {
        use std::io::Write as _;
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED animate_sh_uses_a_built_anim_without_cargo_and_the_spec_s_frames_dir: ffmpeg is not installed (apt-get install ffmpeg); CI installs it"
        );
        return;
    }
    let spec = "(scene: File(\"base.sdf\"), fps: 4, length: Frames(3), resolution: (16, 8),
  frames_dir: \"shots/one\",
  tracks: [(target: \"ball\", translate: [(at: 0, value: (0, 0, 0)), (at: 0.5, value: (1, 0, 0))])])";
    let dir = project(&[("base.sdf", BALL), ("shot.ron", spec)]);
    // A PATH with the system's tools (ffmpeg, sed, find) but not cargo's directory.
    let path = "/usr/local/bin:/usr/bin:/bin";
    if let Some(dir) = path
        .split(':')
        .find(|d| Path::new(d).join("cargo").exists())
    {
        use std::io::Write as _;
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED animate_sh_uses_a_built_anim_without_cargo_and_the_spec_s_frames_dir: cargo is installed in {dir}, so a PATH without it cannot be made"
        );
        return;
    }
    let run = std::process::Command::new(repo().join("scripts/animate.sh"))
        .arg(dir.path().join("shot.ron"))
        .arg(dir.path().join("shot.mp4"))
        .current_dir(dir.path())
        .env("PATH", path)
        .env("ANIM", env!("CARGO_BIN_EXE_anim"))
        .env_remove("FRAMES_DIR")
        .output()
        .expect("run animate.sh");
    assert!(
        run.status.success(),
        "{}{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
    let shots = dir.path().join("shots/one");
    assert_eq!(frames(&shots).len(), 3);
    assert!(shots.join("frame_0002.png").is_file());
    assert!(dir.path().join("shot.mp4").metadata().expect("video").len() > 0);
}

#[test]
fn an_object_whose_forward_is_its_up_is_refused_before_any_frame() {
    let spec = "(scene: File(\"base.sdf\"), length: Frames(2), resolution: (16, 9),
  tracks: [(target: \"ball\", look_at: Point((0, 0, 5)), forward: (0, 1, 0))])";
    let dir = project(&[("base.sdf", BALL), ("up.ron", spec)]);
    let (ok, stderr) = generate(&dir.path().join("up.ron"), &dir.path().join("f"));
    assert!(!ok);
    assert!(
        stderr.contains("up.ron:2:65: error: `forward` (0, 1, 0) and `up` (0, 1, 0) are parallel"),
        "{stderr}"
    );
    assert!(!dir.path().join("f").exists());
}

#[test]
fn an_aimed_camera_may_only_be_moved_by_other_tracks() {
    let spec = "(scene: File(\"base.sdf\"), length: Frames(2), resolution: (16, 9),
  tracks: [
    (target: \"cam\", look_at: Object(\"ball\")),
    (target: \"cam\", scale: [(at: 0, value: 2)]),
    (target: \"cam\", look_at: Point((0, 0, 0))),
  ])";
    let dir = project(&[("base.sdf", BALL), ("cam.ron", spec)]);
    let (ok, stderr) = generate(&dir.path().join("cam.ron"), &dir.path().join("f"));
    assert!(!ok);
    assert!(
        stderr.contains("cam.ron:4:5: error: 'cam' looks at its target (`look_at` in tracks[0]): this track would turn it away"),
        "{stderr}"
    );
    assert!(
        stderr.contains("cam.ron:5:30: error: 'cam' has a `look_at` in an earlier track already"),
        "{stderr}"
    );
}
