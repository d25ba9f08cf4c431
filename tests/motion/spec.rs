//! Motion blur in the keyframe pipeline: the spec's `shutter`, the `motion` lines of blurred
//! frames (docs/scene-language.md §10) and how `anim check` reads them.

use anim_core::math::Transform;
use anim_core::sdf::ast::{Statement, StatementKind, TransformOp};
use anim_core::sdf::LoadOptions;
use anim_core::util::Fnv64;
use assert_cmd::Command;
use glam::DVec3;
use std::path::{Path, PathBuf};

fn anim() -> Command {
    Command::cargo_bin("anim").expect("binary")
}

/// FNV-1a over the frame files of a directory, in name order.
fn frames_hash(dir: &Path) -> (usize, u64) {
    let mut names: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("frames")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "sdf"))
        .collect();
    names.sort();
    let mut h = Fnv64::default();
    for p in &names {
        h.write(&std::fs::read(p).expect("frame"));
    }
    (names.len(), h.finish())
}

/// `anim generate SPEC -o OUT --standalone`: whole frame files, which the tests read.
fn generate(spec: &Path, out: &Path) -> std::process::Output {
    anim()
        .args(["generate", "--standalone"])
        .arg(spec)
        .arg("-o")
        .arg(out)
        .output()
        .expect("run")
}

/// The frames of `spec_text` (a spec written into `dir`), in order.
fn frames(spec_text: &str, dir: &Path, name: &str) -> Vec<String> {
    let spec = dir.join(format!("{name}.ron"));
    std::fs::write(&spec, spec_text).expect("spec");
    let out = dir.join(name);
    let run = generate(&spec, &out);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let mut names: Vec<PathBuf> = std::fs::read_dir(&out)
        .expect("frames")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "sdf"))
        .collect();
    names.sort();
    names
        .iter()
        .map(|p| std::fs::read_to_string(p).expect("frame"))
        .collect()
}

// ---------------------------------------------------------------------------------------------
// shutter 0 changes nothing

/// The frames of the example specs as they were before `shutter` existed (FNV-1a of every
/// frame file in order, written by the release before motion blur).
const TODAY: [(&str, usize, u64); 3] = [
    ("orbit", 120, 0x84bf_63c3_1548_153e),
    ("motion", 120, 0x06f7_7603_2bae_1f58),
    ("lights", 120, 0x2b0e_b433_96ac_6f12),
];

/// The file a spec's `scene: File("...")` names.
fn base_scene_file(spec: &str) -> &str {
    let start = spec.find("scene: File(\"").expect("a base scene file") + "scene: File(\"".len();
    let len = spec[start..].find('"').expect("its closing quote");
    &spec[start..start + len]
}

#[test]
fn without_a_shutter_or_with_shutter_0_frames_are_unchanged() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("animations");
    let tmp = tempfile::tempdir().expect("tempdir");
    for (name, count, hash) in TODAY {
        let out = tmp.path().join(name);
        let run = generate(&root.join(format!("{name}.ron")), &out);
        assert!(run.status.success(), "{name}");
        assert_eq!(frames_hash(&out), (count, hash), "{name}");
        // The same spec with an explicit `shutter: 0`, beside a copy of its base scene (the
        // repository's tree is not written to).
        let text = std::fs::read_to_string(root.join(format!("{name}.ron"))).expect("spec");
        let with_zero = text.replacen("    fps: 24,", "    fps: 24,\n    shutter: 0,", 1);
        assert_ne!(
            with_zero, text,
            "{name}: no fps line to put the shutter after"
        );
        let copy = tmp.path().join(format!("{name}-spec"));
        std::fs::create_dir(&copy).expect("dir");
        let base = base_scene_file(&text);
        std::fs::copy(root.join(base), copy.join(base)).expect("base scene");
        let spec = copy.join(format!("{name}.ron"));
        std::fs::write(&spec, with_zero).expect("spec");
        let out0 = tmp.path().join(format!("{name}-0"));
        let run = generate(&spec, &out0);
        assert!(run.status.success(), "{name}");
        // Only the header names the spec file.
        let rename = |dir: &Path| -> Vec<String> {
            let mut names: Vec<_> = std::fs::read_dir(dir)
                .expect("dir")
                .map(|e| e.expect("entry").path())
                .filter(|p| p.extension().is_some_and(|e| e == "sdf"))
                .collect();
            names.sort();
            names
                .iter()
                .map(|p| {
                    let t = std::fs::read_to_string(p).expect("frame");
                    t.split_once('\n').expect("header").1.to_string()
                })
                .collect()
        };
        assert_eq!(rename(&out), rename(&out0), "{name}");
    }
}

// ---------------------------------------------------------------------------------------------
// The spec field

const BASE: &str = r#"define material m 0.1 0.1 0.1 0.7 0.7 0.7 0.2 0.2 0.2 20
define shape plane ground 0 -1 0 0 1 0 m
define shape box spinner -0.5 -1 -0.5 0.5 0 0.5 m
define shape sphere ball -2 -0.5 0 0.5 m
define shape sphere still 2 -0.5 0 0.5 m
define shape box block -0.3 0 -3.3 0.3 0.6 -2.7 m
define shape composite pair block
define light sun 0 8 4 1 1 1 1
define camera cam 60 0 1 8 0 -0.1 -1 0 1 0
render cam out.png 32 18"#;

fn spec(fps: u32, shutter: &str, tracks: &str) -> String {
    format!(
        "(\n    scene: Inline(r#\"{BASE}\"#),\n    fps: {fps},\n    shutter: {shutter},\n    length: Seconds(1),\n    resolution: (32, 18),\n    tracks: [{tracks}],\n)\n"
    )
}

const TRACKS: &str = r#"
        (target: "spinner", axis: (0, 1, 0), rotate: [(at: 0, value: 0), (at: 1, value: 720)]),
        (target: "ball", translate: [(at: 0, value: (0, 0, 0), interp: EaseInOut), (at: 1, value: (4, 0, -1))]),
        (target: "pair", scale: [(at: 0, value: 1, interp: Smooth), (at: 0.5, value: 1.5, interp: Smooth), (at: 1, value: 0.8)]),
        (target: "pair", axis: (0, 1, 0), rotate: [(at: 0, value: 0), (at: 1, value: 90)]),
        (target: "sun", translate: [(at: 0, value: (0, 0, 0)), (at: 1, value: (-3, 0, 0))]),
        (target: "cam", translate: [(at: 0, value: (0, 0, 0)), (at: 1, value: (1, 0, -1))], rotate: [(at: 0, value: 0), (at: 1, value: 20)], axis: (0, 1, 0)),
    "#;

#[test]
fn a_shutter_outside_0_to_1_is_a_located_error() {
    let tmp = tempfile::tempdir().expect("tempdir");
    for bad in ["1.5", "-0.25", "2"] {
        let text = spec(24, bad, "");
        let path = tmp.path().join("spec.ron");
        std::fs::write(&path, &text).expect("spec");
        let run = generate(&path, &tmp.path().join("out"));
        assert!(!run.status.success(), "{bad} accepted");
        let (line, col) = text
            .lines()
            .enumerate()
            .find_map(|(i, l)| {
                l.find("shutter")
                    .map(|c| (i + 1, c + 1 + "shutter: ".len()))
            })
            .expect("shutter line");
        let stderr = String::from_utf8_lossy(&run.stderr);
        let want = format!(
            "spec.ron:{line}:{col}: error: shutter must be 0 (no motion blur) or a fraction of the frame interval greater than 0 and at most 1, not {}",
            bad.parse::<f64>().expect("number")
        );
        assert!(stderr.contains(&want), "{bad}: {stderr}");
        assert!(!tmp.path().join("out").exists(), "{bad}: frames written");
    }
    for good in ["0", "0.5", "1", "1e-3"] {
        let path = tmp.path().join("ok.ron");
        std::fs::write(&path, spec(24, good, TRACKS)).expect("spec");
        let run = generate(&path, &tmp.path().join(format!("ok-{good}")));
        assert!(
            run.status.success(),
            "{good}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Blurred frames

fn statements(text: &str) -> Vec<Statement> {
    let (statements, diags) =
        anim_core::sdf::parse(text, Path::new("frame.sdf"), &LoadOptions::default());
    assert!(diags.is_empty(), "{diags:?}\n{text}");
    statements
}

fn op(o: &TransformOp) -> Transform {
    match *o {
        TransformOp::Translate(v) => Transform::translate(v),
        TransformOp::Rotate { degrees, axis } => Transform::rotate(degrees, axis).expect("axis"),
        TransformOp::Scale(s) => Transform::scale(s).expect("scale"),
    }
}

/// `name`'s transform statements composed (each applies after the ones before it).
fn placed(statements: &[Statement], name: &str) -> Transform {
    statements
        .iter()
        .filter_map(|s| match &s.kind {
            StatementKind::Transform { target, ops } if target.name == name => Some(ops),
            _ => None,
        })
        .flatten()
        .fold(Transform::IDENTITY, |m, o| op(o).then_after(&m))
}

/// `name`'s motion lines: (u, transform).
fn motion(statements: &[Statement], name: &str) -> Vec<(f64, Transform)> {
    statements
        .iter()
        .filter_map(|s| match &s.kind {
            StatementKind::Motion(m) if m.target.name == name => Some((
                m.at,
                m.ops
                    .iter()
                    .fold(Transform::IDENTITY, |t, o| op(o).then_after(&t)),
            )),
            _ => None,
        })
        .collect()
}

fn close(a: &Transform, b: &Transform) -> bool {
    a.world_from_object.abs_diff_eq(b.world_from_object, 1e-8)
}

/// Lines of a frame that state the scene: no comments, no motion, no render line.
fn scene_lines(text: &str) -> Vec<&str> {
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("motion ") && !l.starts_with("render "))
        .collect()
}

/// Numbers of two lines agree to 1e-9 (relative), words exactly.
fn same_line(a: &str, b: &str) -> bool {
    let (wa, wb): (Vec<&str>, Vec<&str>) = (a.split(' ').collect(), b.split(' ').collect());
    wa.len() == wb.len()
        && wa.iter().zip(&wb).all(|(x, y)| {
            x == y
                || matches!((x.parse::<f64>(), y.parse::<f64>()), (Ok(p), Ok(q)) if (p - q).abs() <= 1e-9 * p.abs().max(q.abs()).max(1.0))
        })
}

#[test]
fn a_blurred_frame_states_the_middle_and_its_motion_reaches_every_instant() {
    let tmp = tempfile::tempdir().expect("tempdir");
    // A frame at 12 fps with the shutter open all the interval spans two frames at 24 fps:
    // its middle is the odd one, its open and close the even ones around it.
    let blurred = frames(&spec(12, "1", TRACKS), tmp.path(), "blurred");
    let instants = frames(&spec(24, "0", TRACKS), tmp.path(), "instants");
    assert_eq!((blurred.len(), instants.len()), (12, 24));
    let names = ["spinner", "ball", "still", "pair", "block", "sun", "cam"];
    for (i, frame) in blurred.iter().enumerate().take(11) {
        assert!(frame
            .lines()
            .nth(1)
            .is_some_and(|l| l.starts_with("# Shutter open")));
        let (a, b) = (scene_lines(frame), scene_lines(&instants[2 * i + 1]));
        assert_eq!(a.len(), b.len(), "frame {i}");
        for (x, y) in a.iter().zip(&b) {
            assert!(same_line(x, y), "frame {i}: `{x}` vs `{y}`");
        }
        let here = statements(frame);
        for name in names {
            let keys = motion(&here, name);
            if name == "still" || name == "block" {
                assert!(keys.is_empty(), "{name} does not move itself");
                continue;
            }
            assert!(
                keys.len() >= 3,
                "frame {i}: {name} has {} instants",
                keys.len()
            );
            assert!(keys.windows(2).all(|w| w[0].0 < w[1].0));
            assert_eq!((keys[0].0, keys[keys.len() - 1].0), (0.0, 1.0));
            let base = placed(&here, name);
            for (u, delta) in keys {
                let t = 2.0 * i as f64 + 2.0 * u;
                if t.fract() != 0.0 {
                    continue;
                }
                let there = placed(&statements(&instants[t as usize]), name);
                assert!(
                    close(&delta.then_after(&base), &there),
                    "frame {i}, {name} at u = {u}"
                );
            }
        }
    }
}

#[test]
fn fast_turns_are_cut_into_steps_of_at_most_10_degrees() {
    let tmp = tempfile::tempdir().expect("tempdir");
    // 720°/s at 12 fps with the shutter open throughout: 60° per exposure.
    let blurred = frames(&spec(12, "1", TRACKS), tmp.path(), "fast");
    let here = statements(&blurred[3]);
    let keys = motion(&here, "spinner");
    assert_eq!(keys.len(), 7, "{keys:?}");
    let centre = DVec3::new(0.0, -0.5, 0.0);
    let corner = DVec3::new(0.5, -0.5, 0.5);
    let base = placed(&here, "spinner");
    for w in keys.windows(2) {
        let (a, b) = (w[0].1.then_after(&base), w[1].1.then_after(&base));
        // The centre stays put; a corner turns 10° about it.
        assert!(a.point(centre).abs_diff_eq(b.point(centre), 1e-9));
        let (pa, pb) = (
            a.point(corner) - a.point(centre),
            b.point(corner) - b.point(centre),
        );
        let angle = pa.angle_between(pb).to_degrees();
        assert!((angle - 10.0).abs() < 1e-6, "{angle}");
    }
}

#[test]
fn the_orbiting_camera_moves_along_its_circle() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let orbit = |fps: u32, shutter: &str| {
        format!(
            "(\n    scene: Inline(r#\"{BASE}\"#),\n    fps: {fps},\n    shutter: {shutter},\n    length: Seconds(1),\n    resolution: (32, 18),\n    orbit: (center: (0, 0, 0), radius: 8, height: 2, turns: 1, look_at: (0, -0.5, 0)),\n)\n"
        )
    };
    let blurred = frames(&orbit(12, "1"), tmp.path(), "orbit-blur");
    let instants = frames(&orbit(24, "0"), tmp.path(), "orbit-now");
    let camera = |s: &[Statement]| {
        s.iter()
            .find_map(|s| match &s.kind {
                StatementKind::Camera(c) if c.name == "cam" => Some(c.clone()),
                _ => None,
            })
            .expect("camera")
    };
    for (i, frame) in blurred.iter().enumerate().take(11) {
        let here = statements(frame);
        let cam = camera(&here);
        let keys = motion(&here, "cam");
        // 30° per exposure: 4 steps of 7.5°.
        assert_eq!(keys.len(), 5, "frame {i}");
        for (u, delta) in keys {
            let t = 2.0 * i as f64 + 2.0 * u;
            if t.fract() != 0.0 {
                continue;
            }
            let there = camera(&statements(&instants[t as usize]));
            assert!(
                delta.point(cam.eye).abs_diff_eq(there.eye, 1e-8),
                "frame {i} u {u}"
            );
            let dir = delta.vector(cam.dir).normalize();
            assert!(
                dir.abs_diff_eq(there.dir.normalize(), 1e-8),
                "frame {i} u {u}"
            );
        }
    }
}

#[test]
fn blurred_frames_pass_a_strict_check_and_still_scenes_stay_plain() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let blurred = frames(&spec(24, "0.5", TRACKS), tmp.path(), "strict");
    assert!(blurred.iter().all(|f| f.contains("\nmotion ")));
    let run = anim()
        .args(["check", "--strict"])
        .arg(tmp.path().join("strict"))
        .output()
        .expect("run");
    let all = format!(
        "{}{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(run.status.success(), "{all}");
    assert!(
        !all.contains(": warning") && !all.contains(": error") && all.contains("24 ok"),
        "{all}"
    );
    // Nothing moves: no motion lines (a keyed colour is not motion).
    let still = frames(
        &spec(
            24,
            "0.5",
            r#"(target: "sun", brightness: [(at: 0, value: 1), (at: 1, value: 2)])"#,
        ),
        tmp.path(),
        "still",
    );
    assert!(still.iter().all(|f| !f.contains("\nmotion ")));
}

// ---------------------------------------------------------------------------------------------
// Reading motion lines

fn check(text: &str) -> String {
    let tmp = tempfile::tempdir().expect("tempdir");
    let path = tmp.path().join("scene.sdf");
    std::fs::write(&path, text).expect("scene");
    let run = anim()
        .args(["check", "--strict"])
        .arg(&path)
        .output()
        .expect("run");
    format!(
        "{}{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    )
}

#[test]
fn motion_lines_read_back_as_written() {
    let line = "motion ball 0.25 translate 1 -2 0.5 rotate 30 0 1 0 scale 2 1 0.5";
    let s = statements(&format!("{BASE}\n{line}\n"));
    let written: Vec<String> = s
        .iter()
        .filter(|s| matches!(s.kind, StatementKind::Motion(_)))
        .map(|s| s.to_string())
        .collect();
    assert_eq!(written, [line]);
    let bare = statements(&format!("{BASE}\nmotion ball 0.5\n"));
    assert!(motion(&bare, "ball")[0].1.is_identity());
}

#[test]
fn bad_motion_lines_are_located_errors() {
    let cases = [
        ("motion bal 0.5 translate 1 0 0", "scene.sdf:11:8: error: motion of 'bal', which is not a shape, composite, camera or light of this file"),
        ("motion ball 1.5", "scene.sdf:11:13: error: the fraction of the exposure must be from 0 to 1, not 1.5"),
        ("motion ball 0.5 translate 1 0", "scene.sdf:11:27: error: `translate` takes 3 numbers, found 2"),
        ("motion ball 0.5 rotate 30 0 0 0", "scene.sdf:11:24: error: a rotation needs a non-zero axis"),
        ("motion ball 0.5 scale 0", "scene.sdf:11:23: error: a scale of 0 cannot be undone"),
        ("motion ball 0.5 turn 30 0 1 0", "scene.sdf:11:17: error: expected translate, rotate or scale, found 'turn'"),
        ("motion ball", "scene.sdf:11:12: error: expected the fraction of the exposure (0 to 1), found end of line"),
        ("motion ball x", "scene.sdf:11:13: error: expected a number, found 'x'"),
    ];
    for (line, want) in cases {
        let out = check(&format!("{BASE}\n{line}\n"));
        assert!(out.contains(want), "{line}:\n{out}");
    }
    let out = check(&format!(
        "{BASE}\nmotion ball 0.5\nmotion ball 0.5 translate 1 0 0\n"
    ));
    assert!(
        out.contains("scene.sdf:12:8: error: the motion of 'ball' at 0.5 comes after one at 0.5"),
        "{out}"
    );
    let out = check(&format!("{BASE}\nmotion bal 0.5\n"));
    assert!(out.contains("did you mean `ball`?"), "{out}");
}
