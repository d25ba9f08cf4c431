//! The keyframe spec: parsing, located errors, interpolation values, the orbit camera and how
//! keyed transforms compose with the base scene's own.

use anim::anim::generate::{ops_matrix, BaseScene, Generator};
use anim::anim::interp::{sample, Interp, Key};
use anim::anim::orbit::pose_at;
use anim::anim::spec::{self, Animation, Orbit, Source};
use anim::diag::{Diagnostic, Loc};
use anim::scene::Geometry;
use anim::sdf::ast::{CameraDef, LightDef, NameRef, Statement, StatementKind, TransformOp};
use glam::{DMat4, DVec3, Vec3};
use std::path::Path;
use std::sync::Arc;

// ---------------------------------------------------------------------------------------------
// A small base scene built statement by statement (independent of the SDF reader).

fn loc() -> Loc {
    Loc {
        file: Arc::from(Path::new("base.sdf")),
        line: 1,
        col: 1,
    }
}

fn st(kind: StatementKind) -> Statement {
    Statement::new(kind, loc())
}

fn name(n: &str) -> NameRef {
    NameRef {
        name: n.to_string(),
        loc: loc(),
    }
}

fn base() -> BaseScene {
    BaseScene::new(vec![
        st(StatementKind::Shape {
            name: "ball".into(),
            geometry: Geometry::Sphere {
                center: DVec3::ZERO,
                radius: 1.0,
            },
            material: name("red"),
        }),
        // The base file places the ball at (5, 0, 0).
        st(StatementKind::Transform {
            target: name("ball"),
            ops: vec![TransformOp::Translate(DVec3::new(5.0, 0.0, 0.0))],
        }),
        st(StatementKind::Shape {
            name: "crate".into(),
            geometry: Geometry::Box {
                p1: DVec3::new(1.0, 0.0, 1.0),
                p2: DVec3::new(3.0, 2.0, 3.0),
            },
            material: name("red"),
        }),
        st(StatementKind::Composite {
            name: "group".into(),
            children: vec![name("ball"), name("crate")],
        }),
        st(StatementKind::Light(LightDef {
            name: "sun".into(),
            position: DVec3::new(0.0, 10.0, 0.0),
            color: Vec3::ONE,
            brightness: 1.0,
        })),
        st(StatementKind::Camera(CameraDef {
            name: "cam".into(),
            fov_x_deg: 60.0,
            eye: DVec3::ZERO,
            dir: DVec3::NEG_Z,
            up: DVec3::Y,
        })),
        st(StatementKind::Transform {
            target: name("cam"),
            ops: vec![TransformOp::Translate(DVec3::new(0.0, 0.0, 10.0))],
        }),
    ])
}

const HEADER: &str =
    "scene: Inline(\"\"),\n    fps: 24,\n    length: Seconds(5),\n    resolution: (64, 36),\n";

/// Parses and validates `text` against [`base`]; errors rendered as text.
fn check(text: &str) -> Result<Animation, Vec<String>> {
    let src = Source::new(Path::new("spec.ron"), text.to_string());
    let parsed = spec::parse(&src).map_err(|d| vec![d.to_string()])?;
    spec::validate(&parsed, &base(), &src)
        .map_err(|ds| ds.iter().map(Diagnostic::to_string).collect())
}

fn one_error(text: &str) -> String {
    match check(text) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => {
            assert_eq!(e.len(), 1, "{e:#?}");
            e[0].clone()
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Located errors

#[test]
fn unknown_field_is_located_with_a_suggestion() {
    let text = format!("(\n    {HEADER}    tracks: [\n        (target: \"ball\", transalte: [(at: 0, value: (0, 0, 0))]),\n    ],\n)");
    let e = one_error(&text);
    assert!(
        e.starts_with("spec.ron:7:26: error: unknown field `transalte` in a track"),
        "{e}"
    );
    assert!(e.contains("did you mean `translate`?"), "{e}");
    assert!(e.contains("^^^^^^^^^"), "{e}");
}

#[test]
fn misspelt_top_level_field_is_an_error_not_ignored() {
    let text = format!("(\n    {HEADER}    fsp: 30,\n)");
    let e = one_error(&text);
    assert!(
        e.starts_with("spec.ron:6:5: error: unknown field `fsp` in the spec"),
        "{e}"
    );
}

#[test]
fn wrong_type_is_located() {
    let text = "(\n    scene: Inline(\"\"),\n    fps: \"24\",\n    length: Seconds(5),\n    resolution: (64, 36),\n)";
    let e = one_error(text);
    assert!(
        e.starts_with("spec.ron:3:10: error: expected a number (in `fps`)"),
        "{e}"
    );
    let text = "(\n    scene: Inline(\"\"),\n    fps: 24,\n    length: Seconds(5),\n    resolution: (64.5, 36),\n)";
    let e = one_error(text);
    assert!(
        e.starts_with("spec.ron:5:18: error: expected a whole number, found `64.5`"),
        "{e}"
    );
    let text = format!(
        "(\n    {HEADER}    tracks: [(target: \"ball\", translate: [(at: 0, value: 5)])],\n)"
    );
    let e = one_error(&text);
    assert!(e.starts_with("spec.ron:6:59: error: expected three numbers (x, y, z), found the unsigned integer `5`"), "{e}");
}

#[test]
fn unknown_variant_is_located_with_a_suggestion() {
    let text = format!(
        "(\n    {HEADER}    tracks: [(target: \"ball\", translate: [(at: 0, value: (0, 0, 0), interp: EaseInOt)])],\n)"
    );
    let e = one_error(&text);
    assert!(
        e.starts_with("spec.ron:6:77: error: unknown variant `EaseInOt`"),
        "{e}"
    );
    assert!(e.contains("did you mean `EaseInOut`?"), "{e}");
}

#[test]
fn unknown_target_is_located_with_a_suggestion() {
    let text = format!(
        "(\n    {HEADER}    tracks: [\n        (\n            target: \"bal\",\n            translate: [(at: 0, value: (0, 0, 0))],\n        ),\n    ],\n)"
    );
    let e = one_error(&text);
    assert!(
        e.starts_with("spec.ron:8:21: error: the base scene has no shape, composite, camera or light named 'bal'"),
        "{e}"
    );
    assert!(e.contains("did you mean 'ball'?"), "{e}");
}

#[test]
fn unsorted_keys_are_located_at_the_late_key() {
    let text = format!(
        "(\n    {HEADER}    tracks: [(target: \"ball\", rotate: [\n        (at: 2, value: 0),\n        (at: 1, value: 90),\n    ])],\n)"
    );
    let e = one_error(&text);
    assert!(
        e.starts_with("spec.ron:8:14: error: keys must be in time order: this key at 1 s follows a key at 2 s"),
        "{e}"
    );
}

#[test]
fn key_after_the_end_is_located() {
    let text = format!("(\n    {HEADER}    tracks: [(target: \"sun\", brightness: [(at: 0, value: 1), (at: 6, value: 2)])],\n)");
    let e = one_error(&text);
    assert!(
        e.starts_with(
            "spec.ron:6:67: error: the key at 6 s is after the end of the animation (5 s)"
        ),
        "{e}"
    );
}

#[test]
fn channel_on_the_wrong_kind_of_target() {
    let text =
        format!("(\n    {HEADER}    tracks: [(target: \"ball\", fov: [(at: 0, value: 40)])],\n)");
    let e = one_error(&text);
    assert!(
        e.contains("'ball' is a shape: `fov` can only be keyed on cameras"),
        "{e}"
    );
}

#[test]
fn unknown_camera_is_located() {
    let text = format!("(\n    {HEADER}    camera: \"cma\",\n)");
    let e = one_error(&text);
    assert!(
        e.starts_with("spec.ron:6:13: error: the base scene has no camera named 'cma'"),
        "{e}"
    );
    assert!(e.contains("did you mean 'cam'?"), "{e}");
}

#[test]
fn syntax_error_is_located() {
    let text = format!("(\n    {HEADER}    tracks: [(target: \"ball\" rotate: [])],\n)");
    let e = one_error(&text);
    assert!(e.starts_with("spec.ron:6:30: error:"), "{e}");
}

#[test]
fn several_problems_are_all_reported() {
    let text = format!(
        "(\n    {HEADER}    tracks: [(target: \"nope\", rotate: [(at: -1, value: 0)]), (target: \"sun\", fov: [(at: 0, value: 1)])],\n)"
    );
    let errors = check(&text).expect_err("invalid");
    assert_eq!(errors.len(), 3, "{errors:#?}");
}

#[test]
fn defaults_and_frame_count() {
    let a = check(&format!("(\n    {HEADER})")).expect("valid");
    assert_eq!(a.fps, 24);
    assert_eq!(a.frames, 120);
    assert_eq!(a.camera, "cam");
    assert_eq!(a.output.image(7, a.digits()), "frame_0007.png");
    assert_eq!(a.output.sdf(7, a.digits()), "frame_0007.sdf");
    let a = check("(scene: Inline(\"\"), fps: 30, length: Frames(12345), resolution: (8, 8), output: \"shot-{frame}.ppm\")")
        .expect("valid");
    assert_eq!(a.output.image(42, a.digits()), "shot-00042.ppm");
}

#[test]
fn lengths_and_rates_must_be_whole_frames() {
    let base = "(\n    scene: Inline(\"\"),\n    resolution: (64, 36),\n";
    let e = one_error(&format!("{base}    length: Seconds(1.3),\n)"));
    assert!(
        e.starts_with("spec.ron:4:21: error: 1.3 s at 24 fps is 31.2 frames"),
        "{e}"
    );
    let e = one_error(&format!("{base}    length: Frames(2.5),\n)"));
    assert!(
        e.starts_with("spec.ron:4:20: error: the number of frames must be a whole number"),
        "{e}"
    );
    let e = one_error(&format!("{base}    length: Frames(2),\n    fps: 29.97,\n)"));
    assert!(
        e.starts_with("spec.ron:5:10: error: fps must be a whole number from 1 to 1000, not 29.97"),
        "{e}"
    );
}

#[test]
fn bad_output_patterns() {
    for (pattern, needle) in [
        ("frame.png", "must contain `{frame}`"),
        ("a/{frame}.png", "file name, not a path"),
        ("{frame}.sdf", "image extension"),
        ("my frame {frame}.png", "space"),
    ] {
        let e = one_error(&format!("(\n    {HEADER}    output: \"{pattern}\",\n)"));
        assert!(e.starts_with("spec.ron:6:13: error:"), "{e}");
        assert!(e.contains(needle), "{e}");
    }
}

// ---------------------------------------------------------------------------------------------
// Interpolation at known times

fn keys(points: &[(f64, f64, Interp)]) -> Vec<Key<f64>> {
    points
        .iter()
        .map(|&(at, value, interp)| Key { at, value, interp })
        .collect()
}

fn approx(a: Option<f64>, b: f64) {
    let a = a.expect("a value");
    assert!((a - b).abs() < 1e-12, "{a} != {b}");
}

#[test]
fn interpolation_modes_at_known_times() {
    // A segment from 10 at t = 2 to 20 at t = 4; t = 3 is s = 0.5, t = 2.5 is s = 0.25.
    let seg = |mode| keys(&[(2.0, 10.0, mode), (4.0, 20.0, Interp::Linear)]);
    approx(sample(&seg(Interp::Step), 3.9, false), 10.0);
    approx(sample(&seg(Interp::Step), 4.0, false), 20.0);
    approx(sample(&seg(Interp::Linear), 2.5, false), 12.5);
    // EaseIn: 10 + 10·s² = 10 + 10·0.0625
    approx(sample(&seg(Interp::EaseIn), 2.5, false), 10.625);
    // EaseOut: 10 + 10·(1 − (1 − s)²) = 10 + 10·0.4375
    approx(sample(&seg(Interp::EaseOut), 2.5, false), 14.375);
    // EaseInOut: 10 + 10·(3s² − 2s³) = 10 + 10·(0.1875 − 0.03125)
    approx(sample(&seg(Interp::EaseInOut), 2.5, false), 11.5625);
    approx(sample(&seg(Interp::EaseInOut), 3.0, false), 15.0);
    // Two-key Smooth segment: one-sided tangents = the chord, so it is linear.
    approx(sample(&seg(Interp::Smooth), 2.5, false), 12.5);
    // Before the first key and after the last, the end values hold.
    approx(sample(&seg(Interp::Linear), 0.0, false), 10.0);
    approx(sample(&seg(Interp::Linear), 5.0, false), 20.0);
}

#[test]
fn catmull_rom_uses_neighbouring_keys() {
    // Keys (0, 0), (1, 2), (3, 2), (4, 0), all Smooth. Tangent at key 1:
    // (2 − 0)/(3 − 0) = 2/3; at key 2: (0 − 2)/(4 − 1) = −2/3. Segment 1→2 (h = 2) at s = 0.5:
    // h00 = 0.5, h10 = 0.125, h01 = 0.5, h11 = −0.125 →
    // 0.5·2 + 0.125·2·(2/3) + 0.5·2 − 0.125·2·(−2/3) = 2 + 1/3.
    let k = keys(&[
        (0.0, 0.0, Interp::Smooth),
        (1.0, 2.0, Interp::Smooth),
        (3.0, 2.0, Interp::Smooth),
        (4.0, 0.0, Interp::Smooth),
    ]);
    approx(sample(&k, 2.0, false), 2.0 + 1.0 / 3.0);
    approx(sample(&k, 1.0, false), 2.0);
    approx(sample(&k, 3.0, false), 2.0);
}

#[test]
fn looping_channels_repeat_and_wrap_their_tangents() {
    // Period 2 s. Looping, the tangent at key 0 is the slope between key 1 (t = 1, v = 1) and
    // key 1 of the previous cycle (t = −1, v = 1): 0, so the seam has no corner.
    let k = keys(&[
        (0.0, 0.0, Interp::Smooth),
        (1.0, 1.0, Interp::Smooth),
        (2.0, 0.0, Interp::Smooth),
    ]);
    // At t = 0.5 (s = 0.5, h = 1): m0 = 0 (wrapped), m1 = (0 − 0)/2 = 0 → 0.5·0 + 0.5·1 = 0.5.
    approx(sample(&k, 0.5, true), 0.5);
    // t = 4.5 is t = 0.5 two periods later.
    approx(sample(&k, 4.5, true), 0.5);
    // Not looping, the end tangent is one-sided (1 per second):
    // 0.125·1 + 0.5·1 = 0.625.
    approx(sample(&k, 0.5, false), 0.625);
    approx(sample(&k, 4.5, false), 0.0);
}

// ---------------------------------------------------------------------------------------------
// The orbit camera

#[test]
fn orbit_camera_keeps_radius_and_height_and_looks_at_the_centre() {
    let o = Orbit {
        center: DVec3::new(0.5, 1.0, -2.0),
        radius: 9.0,
        height: 3.5,
        turns: 1.0,
        start_angle: 0.0,
        look_at: DVec3::new(0.5, 1.0, -2.0),
        interp: Interp::Linear,
    };
    for i in 0..120 {
        let t = i as f64 / 24.0;
        let p = pose_at(&o, t, 5.0).expect("pose");
        let rel = p.eye - o.center;
        assert!(((rel.x * rel.x + rel.z * rel.z).sqrt() - 9.0).abs() < 1e-9);
        assert!((rel.y - 3.5).abs() < 1e-12);
        assert!(p.dir.normalize().dot((o.center - p.eye).normalize()) > 1.0 - 1e-12);
        // Constant speed: 3° per frame (one turn in 120 frames).
        let angle = rel.x.atan2(rel.z).to_degrees().rem_euclid(360.0);
        assert!(
            (angle - 3.0 * i as f64).abs() < 1e-9,
            "{angle} at frame {i}"
        );
    }
}

#[test]
fn orbit_replaces_the_camera_pose_and_its_transforms() {
    let text = format!("(\n    {HEADER}    orbit: (center: (0, 0, 0), radius: 4, height: 1),\n)");
    let anim = check(&text).expect("valid");
    let src = Source::new(Path::new("spec.ron"), text);
    let b = base();
    let g = Generator::new(&b, &anim, &src);
    let statements = g.frame_statements(30).expect("frame");
    // The base file's `transform cam translate 0 0 10` would move the camera off the orbit.
    assert!(!statements.iter().any(
        |s| matches!(&s.kind, StatementKind::Transform { target, .. } if target.name == "cam")
    ));
    let cam = statements
        .iter()
        .find_map(|s| match &s.kind {
            StatementKind::Camera(c) => Some(c.clone()),
            _ => None,
        })
        .expect("camera");
    // Frame 30 of 120 is a quarter turn: the eye is on the +x side.
    assert!(
        (cam.eye - DVec3::new(4.0, 1.0, 0.0)).length() < 1e-9,
        "{:?}",
        cam.eye
    );
    assert!((cam.dir.normalize() - DVec3::new(-4.0, -1.0, 0.0).normalize()).length() < 1e-9);
}

// ---------------------------------------------------------------------------------------------
// Composition with the base file's transforms

/// The world matrix of `target` after frame `i`: its transform statements in order.
fn final_matrix(statements: &[Statement], target: &str) -> DMat4 {
    let ops: Vec<TransformOp> = statements
        .iter()
        .filter_map(|s| match &s.kind {
            StatementKind::Transform { target: t, ops } if t.name == target => Some(ops.clone()),
            _ => None,
        })
        .flatten()
        .collect();
    ops_matrix(&ops)
}

fn frame(text: &str, i: usize) -> Vec<Statement> {
    let anim = check(text).expect("valid");
    let src = Source::new(Path::new("spec.ron"), text.to_string());
    let b = base();
    let g = Generator::new(&b, &anim, &src);
    g.frame_statements(i).expect("frame")
}

#[test]
fn keyed_rotation_and_scale_act_about_the_objects_own_centre() {
    // The base file put the ball at (5, 0, 0). Turning it 90° and doubling it must leave its
    // centre where it is (a spin, not an orbit about the origin).
    let text = format!(
        "(\n    {HEADER}    tracks: [(target: \"ball\", rotate: [(at: 0, value: 90)], scale: [(at: 0, value: 2)])],\n)"
    );
    let m = final_matrix(&frame(&text, 0), "ball");
    assert!((m.transform_point3(DVec3::ZERO) - DVec3::new(5.0, 0.0, 0.0)).length() < 1e-9);
    // A point on the sphere's +x side goes to the −z side, twice as far out.
    let p = m.transform_point3(DVec3::new(1.0, 0.0, 0.0));
    assert!((p - DVec3::new(5.0, 0.0, -2.0)).length() < 1e-9, "{p:?}");
}

#[test]
fn keyed_translation_adds_to_the_base_placement_in_parent_axes() {
    let text = format!(
        "(\n    {HEADER}    tracks: [(target: \"ball\", translate: [(at: 0, value: (0, 0, 0)), (at: 4, value: (0, 4, 0))])],\n)"
    );
    // Frame 24 is t = 1 s: a quarter of the way.
    let m = final_matrix(&frame(&text, 24), "ball");
    assert!((m.transform_point3(DVec3::ZERO) - DVec3::new(5.0, 1.0, 0.0)).length() < 1e-9);
}

#[test]
fn composite_pivot_is_the_centre_of_its_children() {
    // group = ball (bounds 4..6 × −1..1 × −1..1) + crate (1..3 × 0..2 × 1..3):
    // bounds 1..6 × −1..2 × −1..3, centre (3.5, 0.5, 1). A half turn about y keeps it fixed.
    let text = format!(
        "(\n    {HEADER}    tracks: [(target: \"group\", rotate: [(at: 0, value: 180)])],\n)"
    );
    let m = final_matrix(&frame(&text, 0), "group");
    let c = DVec3::new(3.5, 0.5, 1.0);
    assert!((m.transform_point3(c) - c).length() < 1e-9);
}

#[test]
fn explicit_pivot_turns_a_light_around_a_point() {
    let text = format!(
        "(\n    {HEADER}    tracks: [(target: \"sun\", pivot: (0, 0, 0), axis: (1, 0, 0), rotate: [(at: 0, value: 90)], brightness: [(at: 0, value: 0.5)], color: [(at: 0, value: (1, 0.5, 0))])],\n)"
    );
    let statements = frame(&text, 0);
    let m = final_matrix(&statements, "sun");
    // (0, 10, 0) turned 90° about +x goes to (0, 0, 10).
    assert!(
        (m.transform_point3(DVec3::new(0.0, 10.0, 0.0)) - DVec3::new(0.0, 0.0, 10.0)).length()
            < 1e-9
    );
    let light = statements
        .iter()
        .find_map(|s| match &s.kind {
            StatementKind::Light(l) => Some(l.clone()),
            _ => None,
        })
        .expect("light");
    assert_eq!(light.brightness, 0.5);
    assert_eq!(light.color, Vec3::new(1.0, 0.5, 0.0));
}

#[test]
fn ambient_and_fov_keys_are_set_in_place() {
    let text = format!(
        "(\n    {HEADER}    ambient: [(at: 0, value: 0), (at: 5, value: 1)],\n    tracks: [(target: \"cam\", fov: [(at: 0, value: 30), (at: 5, value: 80)])],\n)"
    );
    let statements = frame(&text, 60); // t = 2.5 s, halfway
    let ambient = statements
        .iter()
        .find_map(|s| match s.kind {
            StatementKind::Ambient(a) => Some(a),
            _ => None,
        })
        .expect("an ambient statement is added");
    assert_eq!(ambient, Vec3::splat(0.5));
    let fov = statements
        .iter()
        .find_map(|s| match &s.kind {
            StatementKind::Camera(c) => Some(c.fov_x_deg),
            _ => None,
        })
        .expect("camera");
    assert_eq!(fov, 55.0);
    // The frame ends with its own render line.
    match &statements.last().expect("statements").kind {
        StatementKind::Render(r) => {
            assert_eq!(r.output, "frame_0060.png");
            assert_eq!((r.width, r.height), (64, 36));
            assert_eq!(r.camera.name, "cam");
        }
        other => panic!("last statement is {other}"),
    }
}

#[test]
fn scale_through_zero_is_reported_at_the_frame() {
    let text = format!("(\n    {HEADER}    tracks: [(target: \"ball\", scale: [(at: 0, value: 1), (at: 2, value: -1)])],\n)");
    let anim = check(&text).expect("keys themselves are fine");
    let src = Source::new(Path::new("spec.ron"), text.clone());
    let b = base();
    let g = Generator::new(&b, &anim, &src);
    let e = g
        .frame_statements(24)
        .expect_err("t = 1 s is scale 0")
        .to_string();
    assert!(
        e.starts_with(
            "spec.ron:6:38: error: at frame 24 (t = 1 s) the scale of 'ball' passes through 0"
        ),
        "{e}"
    );
}

#[test]
fn frames_are_deterministic() {
    let text = format!(
        "(\n    {HEADER}    orbit: (center: (0, 0, 0), radius: 4, height: 1),\n    tracks: [(target: \"ball\", rotate: [(at: 0, value: 0, interp: Smooth), (at: 2, value: 33), (at: 5, value: 360)])],\n)"
    );
    let anim = check(&text).expect("valid");
    let src = Source::new(Path::new("spec.ron"), text.clone());
    let b = base();
    let g = Generator::new(&b, &anim, &src);
    for i in [0, 17, 119] {
        assert_eq!(
            g.frame_text(i).expect("frame"),
            g.frame_text(i).expect("frame")
        );
    }
    // Numbers are written tidily: a quarter turn puts the eye at exactly x = 4.
    let text30 = g.frame_text(30).expect("frame");
    assert!(
        text30.contains("define camera cam 60 4 1 0 -4 -1 0 0 1 0"),
        "{text30}"
    );
}
