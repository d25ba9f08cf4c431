//! The keyframe spec: parsing, located errors, interpolation values, the orbit camera and how
//! keyed transforms compose with the base scene's own.

use anim_core::diag::Diagnostic;
use anim_core::scene::RenderJob;
use anim_core::sdf::ast::StatementKind;
use anim_core::sdf::LoadOptions;
use anim_pipeline::keyframe::generate::{BaseScene, Generator};
use anim_pipeline::keyframe::interp::{sample, Interp, Key};
use anim_pipeline::keyframe::orbit::pose_at;
use anim_pipeline::keyframe::spec_file::{self, Animation, Orbit, Source};
use glam::{DVec3, Vec3};
use std::path::Path;

// ---------------------------------------------------------------------------------------------
// A small base scene

/// The base file places the ball (radius 1) at (5, 0, 0); the crate spans 1..3 × 0..2 × 1..3;
/// the camera sits at (0, 0, 10) by its own transform.
const BASE: &str = "\
define material red 0.1 0.1 0.1 0.8 0 0 0 0 0 1
define shape sphere ball 0 0 0 1 red
transform ball translate 5 0 0
define shape box crate 1 0 1 3 2 3 red
define shape composite group ball crate
define light sun 0 10 0 1 1 1 1
define camera cam 60 0 0 0 0 0 -1 0 1 0
transform cam translate 0 0 10
";

fn base() -> BaseScene {
    let (statements, diags) =
        anim_core::sdf::parse(BASE, Path::new("base.sdf"), &LoadOptions::default());
    assert!(diags.is_empty(), "{diags:?}");
    BaseScene::new(statements)
}

const HEADER: &str =
    "scene: Inline(\"\"),\n    fps: 24,\n    length: Seconds(5),\n    resolution: (64, 36),\n";

/// Parses and validates `text` against [`base`]; errors rendered as text.
fn check(text: &str) -> Result<Animation, Vec<String>> {
    let src = Source::new(Path::new("spec.ron"), text.to_string());
    let parsed = spec_file::parse(&src)
        .map_err(|ds| ds.iter().map(Diagnostic::to_string).collect::<Vec<_>>())?;
    spec_file::validate(&parsed, &base(), &src)
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
    let text = "(\n    scene: Inline(\"\"),\n    fps: true,\n    length: Seconds(5),\n    resolution: (64, 36),\n)";
    let e = one_error(text);
    assert!(
        e.starts_with("spec.ron:3:10: error: expected a number of frames per second or a ratio \"A/B\", found the boolean `true` (in `fps`)"),
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
    assert!(e.starts_with("spec.ron:6:58: error: expected three numbers (x, y, z), found the unsigned integer `5`"), "{e}");
    assert!(
        e.ends_with(
            "value: 5)])],\n  |                                                          ^"
        ),
        "{e}"
    );
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

/// The caret line of a rendered diagnostic: where it starts and how many carets.
fn caret(e: &str) -> (usize, usize) {
    let line = e
        .lines()
        .find(|l| l.trim_start().starts_with("| ") && l.contains('^'))
        .unwrap_or_else(|| panic!("no caret in {e}"));
    let after_bar = &line[line.find("| ").expect("gutter") + 2..];
    let start = after_bar.find('^').expect("caret");
    (
        start + 1,
        after_bar[start..].chars().take_while(|&c| c == '^').count(),
    )
}

#[test]
fn carets_cover_exactly_the_bad_text() {
    let e = one_error(&format!("(\n    {HEADER}    fps: 30,\n)"));
    assert!(
        e.starts_with("spec.ron:6:5: error: the field `fps` is given twice"),
        "{e}"
    );
    assert_eq!(caret(&e), (5, 3), "{e}");
    let e = one_error(&format!(
        "(\n    {HEADER}    tracks: [(target: \"ball\", rotate: [(at: 0, value: 1, interp: Smoth)])],\n)"
    ));
    assert_eq!(caret(&e), (66, 5), "{e}");
    let e = one_error("(\n    scene: Inline(\"\"),\n    fps: \"24\",\n    length: Seconds(5),\n    resolution: (64, 36),\n)");
    assert!(e.contains("not \"24\""), "{e}");
    assert_eq!(caret(&e), (10, 4), "{e}");
}

#[test]
fn unknown_target_is_located_with_a_suggestion() {
    let text = format!(
        "(\n    {HEADER}    tracks: [\n        (\n            target: \"bal\",\n            translate: [(at: 0, value: (0, 0, 0))],\n        ),\n    ],\n)"
    );
    let e = one_error(&text);
    assert!(
        e.starts_with("spec.ron:8:21: error: the base scene has no shape, composite, camera, light or material named 'bal'"),
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
    assert_eq!(a.fps.to_string(), "24");
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
    let e = one_error(&format!("{base}    length: Frames(2),\n    fps: 24.5,\n)"));
    assert!(
        e.starts_with("spec.ron:5:10: error: fps must be a whole number from 1 to 1000, an NTSC rate (23.976, 29.97, 59.94) or a ratio \"A/B\", not 24.5"),
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

/// Frame `i` of the spec `text`, loaded by the real scene builder as the renderer will.
fn frame(text: &str, i: usize) -> RenderJob {
    let anim = check(text).expect("valid");
    let src = Source::new(Path::new("spec.ron"), text.to_string());
    let b = base();
    let frame_text = Generator::new(&b, &anim, &src)
        .frame_text(i)
        .expect("frame");
    let mut loaded =
        anim_core::load::load_str(&frame_text, Path::new("frame.sdf"), &LoadOptions::default())
            .unwrap_or_else(|e| panic!("{frame_text}\n{e:?}"));
    assert_eq!(loaded.jobs.len(), 1);
    loaded.jobs.remove(0)
}

/// Where the object-space point `p` of instance `name` (`group/ball`) ends up in the world.
fn world_point(job: &RenderJob, name: &str, p: DVec3) -> DVec3 {
    let instance = job
        .scene
        .instances
        .iter()
        .find(|inst| job.scene.instance_name(inst) == name)
        .unwrap_or_else(|| panic!("no instance {name}"));
    job.scene.transform_of(instance).point(p)
}

fn assert_near(got: DVec3, want: DVec3) {
    assert!((got - want).length() < 1e-9, "{got:?} != {want:?}");
}

#[test]
fn keyed_translation_adds_to_the_base_placement_in_parent_axes() {
    let text = format!(
        "(\n    {HEADER}    tracks: [(target: \"ball\", translate: [(at: 0, value: (0, 0, 0)), (at: 2, value: (0, 2, 0))])],\n)"
    );
    // The key is reached at t = 2 s (frame 48): the centre (5, 0, 0) has moved by (0, 2, 0).
    let job = frame(&text, 48);
    assert_near(
        world_point(&job, "group/ball", DVec3::ZERO),
        DVec3::new(5.0, 2.0, 0.0),
    );
    // Halfway there at t = 1 s, moving linearly.
    let job = frame(&text, 24);
    assert_near(
        world_point(&job, "group/ball", DVec3::ZERO),
        DVec3::new(5.0, 1.0, 0.0),
    );
    // The crate is not keyed and stays where the base file put it.
    let corner = DVec3::new(1.0, 0.0, 1.0);
    assert_near(world_point(&job, "group/crate", corner), corner);
}

#[test]
fn keyed_rotation_and_scale_act_about_the_objects_own_centre() {
    // Turning the ball 90° about +y and doubling it must leave its centre at (5, 0, 0): a spin,
    // not an orbit about the origin.
    let text = format!(
        "(\n    {HEADER}    tracks: [(target: \"ball\", rotate: [(at: 0, value: 90)], scale: [(at: 0, value: 2)])],\n)"
    );
    let job = frame(&text, 0);
    assert_near(
        world_point(&job, "group/ball", DVec3::ZERO),
        DVec3::new(5.0, 0.0, 0.0),
    );
    // +90° about +y takes +x to −z: the sphere's +x pole goes to the −z side, twice as far out.
    assert_near(
        world_point(&job, "group/ball", DVec3::X),
        DVec3::new(5.0, 0.0, -2.0),
    );
    assert_near(
        world_point(&job, "group/ball", DVec3::Z),
        DVec3::new(7.0, 0.0, 0.0),
    );
}

#[test]
fn composite_pivot_is_the_centre_of_its_children() {
    // group = ball (bounds 4..6 × −1..1 × −1..1) + crate (1..3 × 0..2 × 1..3):
    // bounds 1..6 × −1..2 × −1..3, centre (3.5, 0.5, 1). A half turn about y through it maps
    // (x, y, z) to (7 − x, y, 2 − z).
    let text = format!(
        "(\n    {HEADER}    tracks: [(target: \"group\", rotate: [(at: 0, value: 180)])],\n)"
    );
    let job = frame(&text, 0);
    assert_near(
        world_point(&job, "group/ball", DVec3::ZERO),
        DVec3::new(2.0, 0.0, 2.0),
    );
    assert_near(
        world_point(&job, "group/crate", DVec3::new(1.0, 0.0, 1.0)),
        DVec3::new(6.0, 0.0, 1.0),
    );
}

#[test]
fn explicit_pivot_turns_a_light_around_a_point() {
    let text = format!(
        "(\n    {HEADER}    tracks: [(target: \"sun\", pivot: (0, 0, 0), axis: (1, 0, 0), rotate: [(at: 0, value: 90)], brightness: [(at: 0, value: 0.5)], color: [(at: 0, value: (1, 0.5, 0))])],\n)"
    );
    let job = frame(&text, 0);
    let sun = &job.scene.lights[0];
    // (0, 10, 0) turned 90° about +x goes to (0, 0, 10).
    assert_near(sun.position, DVec3::new(0.0, 0.0, 10.0));
    // Intensity is brightness · colour.
    assert_eq!(sun.intensity, Vec3::new(0.5, 0.25, 0.0));
}

#[test]
fn orbit_eye_follows_the_circle_whatever_the_base_transforms() {
    let text = format!("(\n    {HEADER}    orbit: (center: (0, 0, 0), radius: 4, height: 1),\n)");
    // One turn in 120 frames: 3° per frame, from the +z side towards +x. The base file's
    // `transform cam translate 0 0 10` must not move the eye off the circle.
    for i in [0, 17, 30, 60, 101] {
        let job = frame(&text, i);
        let theta = (3.0 * i as f64).to_radians();
        let eye = DVec3::new(4.0 * theta.sin(), 1.0, 4.0 * theta.cos());
        assert_near(job.camera.eye, eye);
        assert_near(job.camera.dir.normalize(), -eye.normalize());
    }
}

#[test]
fn ambient_and_fov_keys_are_set_in_place() {
    let text = format!(
        "(\n    {HEADER}    ambient: [(at: 0, value: 0), (at: 5, value: 1)],\n    tracks: [(target: \"cam\", fov: [(at: 0, value: 30), (at: 5, value: 80)])],\n)"
    );
    let job = frame(&text, 60); // t = 2.5 s, halfway
    assert_eq!(job.scene.ambient, Vec3::splat(0.5));
    assert_eq!(job.camera.fov_x_deg, 55.0);
    assert_eq!(job.output, Path::new("frame_0060.png"));
    assert_eq!((job.width, job.height), (64, 36));
    assert_eq!(job.camera.name, "cam");
    // The base placement of the camera is kept when nothing moves it.
    assert_near(job.camera.eye, DVec3::new(0.0, 0.0, 10.0));
}

#[test]
fn scale_through_zero_is_reported_at_the_frame() {
    let text = format!("(\n    {HEADER}    tracks: [(target: \"ball\", scale: [(at: 0, value: 1), (at: 2, value: -1)])],\n)");
    let anim = check(&text).expect("keys themselves are fine");
    let src = Source::new(Path::new("spec.ron"), text.clone());
    let b = base();
    let g = Generator::new(&b, &anim, &src);
    let errors = g.frame_statements(24).expect_err("t = 1 s is scale 0");
    assert_eq!(errors.len(), 1, "{errors:#?}");
    let e = errors[0].to_string();
    assert!(
        e.starts_with(
            "spec.ron:6:39: error: at frame 24 (between t = 1 and 1.04166666667 s) the scale of 'ball' passes through 0"
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

/// A base scene written for another material layout keeps its meaning in the frames:
/// generate reads it as `anim render` reads a file (layout inferred), and the frames, printed
/// in the standard layout, read back the same whichever way they are read.
#[test]
fn frames_keep_the_materials_of_a_base_scene_in_another_layout() {
    let dir = tempfile::tempdir().unwrap();
    // `m reflectivity transparency ior`: 0 transparency is opaque, which the standard
    // layout would read as opacity 0 (invisible).
    std::fs::write(
        dir.path().join("base.sdf"),
        "define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20 0 0 1\n\
         define material blue 0 0 0.2 0.1 0.1 0.8 0.3 0.3 0.3 10 0.2 0 1\n\
         define shape sphere ball 0 0 -5 1 red\n\
         define light sun 5 5 5 1 1 1 1\n\
         define camera cam 60\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("spec.ron"),
        "(scene: File(\"base.sdf\"), length: Frames(1), resolution: (8, 6))\n",
    )
    .unwrap();
    let config = anim_pipeline::keyframe::GenerateConfig {
        spec: dir.path().join("spec.ron"),
        out: Some(dir.path().join("frames")),
        standalone: false,
        frames: None,
    };
    anim_pipeline::keyframe::run_generate(&config).unwrap_or_else(|e| panic!("{e:?}"));
    let frame = dir.path().join("frames/frame_0000.sdf");
    let text = std::fs::read_to_string(&frame).unwrap();
    for layout in [
        anim_core::sdf::MaterialLayout::Auto,
        anim_core::sdf::MaterialLayout::standard(),
    ] {
        let opts = LoadOptions {
            material_fields: layout.clone(),
            ..LoadOptions::default()
        };
        let loaded = anim_core::load::load_str(&text, &frame, &opts)
            .unwrap_or_else(|e| panic!("{layout:?}: {e:?}\n{text}"));
        let red = &loaded.jobs[0].scene.materials[0];
        assert_eq!(
            (red.opacity, red.reflectivity, red.ior),
            (1.0, 0.0, 1.0),
            "{layout:?}\n{text}"
        );
    }
}
