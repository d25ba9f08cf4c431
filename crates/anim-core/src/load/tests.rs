//! The reader as a whole: variants, transform order, composites, renders, canonical text.

use super::*;
use crate::diag::{Diagnostic, Severity};
use crate::scene::*;
use crate::sdf::{ast, parse, LoadOptions, MaterialField, MaterialLayout, TransformOrder};
use glam::{DVec3, Vec3};
use std::path::Path;

const MATERIAL: &str = "define material m 1 1 1 1 1 1 1 1 1 10\n";

fn load(text: &str) -> Loaded {
    load_with(text, &LoadOptions::default())
}

fn load_with(text: &str, opts: &LoadOptions) -> Loaded {
    match load_str(text, Path::new("scene.sdf"), opts) {
        Ok(l) => l,
        Err(ds) => panic!(
            "expected the text to load:\n{text}\n{}",
            ds.iter()
                .map(|d| d.to_string())
                .collect::<Vec<_>>()
                .join("\n")
        ),
    }
}

fn errors(text: &str) -> Vec<Diagnostic> {
    match load_str(text, Path::new("scene.sdf"), &LoadOptions::default()) {
        Ok(_) => panic!("expected errors for:\n{text}"),
        Err(ds) => ds,
    }
}

fn instance_names(scene: &crate::scene::Scene) -> Vec<String> {
    scene
        .instances
        .iter()
        .map(|i| scene.instance_name(i))
        .collect()
}

fn close(a: DVec3, b: DVec3) -> bool {
    a.abs_diff_eq(b, 1e-9)
}

/// The first instance's world transform after `ops` (transform lines on shape `s`).
fn world_of(ops: &str, order: TransformOrder) -> crate::math::Transform {
    let text = format!(
        "{MATERIAL}define shape sphere s 0 0 0 1 m\n{ops}define camera c 60\nrender c out.png 10 10\n"
    );
    let opts = LoadOptions {
        transform_order: order,
        ..LoadOptions::default()
    };
    let loaded = load_with(&text, &opts);
    let scene = &loaded.jobs[0].scene;
    *scene.transform_of(&scene.instances[0])
}

#[test]
fn world_order_applies_each_statement_after_the_earlier_ones() {
    // scale then translate: M = T·S.
    let t = world_of(
        "transform s scale 2\ntransform s translate 1 0 0\n",
        TransformOrder::World,
    );
    assert!(close(t.point(DVec3::ZERO), DVec3::new(1.0, 0.0, 0.0)));
    assert!(close(t.point(DVec3::X), DVec3::new(3.0, 0.0, 0.0)));
}

#[test]
fn local_order_composes_on_the_right() {
    // scale then translate: M = S·T.
    let t = world_of(
        "transform s scale 2\ntransform s translate 1 0 0\n",
        TransformOrder::Local,
    );
    assert!(close(t.point(DVec3::ZERO), DVec3::new(2.0, 0.0, 0.0)));
    assert!(close(t.point(DVec3::X), DVec3::new(4.0, 0.0, 0.0)));
}

#[test]
fn several_operations_on_one_line_equal_separate_lines() {
    let one = world_of(
        "transform s rotate 90 0 0 1 translate 1 2 3 scale 2 1 1\n",
        TransformOrder::World,
    );
    let three = world_of(
        "transform s rotate 90 0 0 1\ntransform s translate 1 2 3\ntransform s scale 2 1 1\n",
        TransformOrder::World,
    );
    assert!(one
        .world_from_object
        .abs_diff_eq(three.world_from_object, 1e-12));
}

#[test]
fn rotation_variants_mean_the_same_rotation() {
    let canonical = world_of("transform s rotate 30 1 0 0\n", TransformOrder::World);
    for variant in [
        "transform s rotate 30 x\n",
        "transform s rotate 30 0 0\n",
        "transform s rotatex 30\n",
        "define transform s rotate 30 1 0 0\n",
    ] {
        let t = world_of(variant, TransformOrder::World);
        assert!(
            t.world_from_object
                .abs_diff_eq(canonical.world_from_object, 1e-12),
            "{variant}"
        );
    }
}

#[test]
fn a_composite_transform_moves_every_child_alike() {
    let text = format!(
        "{MATERIAL}define shape sphere a 1 0 0 1 m\ndefine shape box b 0 0 0 1 1 1 m\n\
         define shape composite root a b\n\
         transform a translate 0 5 0\n\
         transform root rotate 90 0 0 1\ntransform root translate 10 0 0\n\
         define camera c 60\nrender c out.png 10 10\n"
    );
    let scene = &load(&text).jobs[0].scene;
    assert_eq!(scene.instances.len(), 2);
    let root = crate::math::Transform::translate(DVec3::new(10.0, 0.0, 0.0))
        .then_after(&crate::math::Transform::rotate(90.0, DVec3::Z).unwrap());
    let a = &scene.instances[0];
    let b = &scene.instances[1];
    assert_eq!(scene.instance_name(a), "root/a");
    let (a, b) = (scene.transform_of(a), scene.transform_of(b));
    // a: parent · own, where own moves it up by 5 first.
    let expected_a = root.then_after(&crate::math::Transform::translate(DVec3::new(
        0.0, 5.0, 0.0,
    )));
    assert!(a
        .world_from_object
        .abs_diff_eq(expected_a.world_from_object, 1e-12));
    assert!(b
        .world_from_object
        .abs_diff_eq(root.world_from_object, 1e-12));
    // (1, 0, 0) of b: rotated to (0, 1, 0), then moved to (10, 1, 0).
    assert!(close(b.point(DVec3::X), DVec3::new(10.0, 1.0, 0.0)));
}

#[test]
fn a_shape_in_two_composites_is_drawn_twice() {
    let text = format!(
        "{MATERIAL}define shape sphere ball 0 0 0 1 m\n\
         define shape composite left ball\ndefine shape composite right ball\n\
         define shape composite both left right\n\
         transform left translate -5 0 0\ntransform right translate 5 0 0\n\
         define camera c 60\nrender c out.png 10 10\n"
    );
    let scene = &load(&text).jobs[0].scene;
    let names: Vec<String> = scene
        .instances
        .iter()
        .map(|i| scene.instance_name(i))
        .collect();
    assert_eq!(names, ["both/left/ball", "both/right/ball"]);
    assert!(close(
        scene.transform_of(&scene.instances[0]).point(DVec3::ZERO),
        DVec3::new(-5.0, 0.0, 0.0)
    ));
    assert!(close(
        scene.transform_of(&scene.instances[1]).point(DVec3::ZERO),
        DVec3::new(5.0, 0.0, 0.0)
    ));
}

#[test]
fn root_rule() {
    // With a composite named root, only what it holds is drawn.
    let with_root = format!(
        "{MATERIAL}define shape sphere a 0 0 0 1 m\ndefine shape sphere b 0 0 0 1 m\n\
         define shape composite root a\ndefine camera c 60\nrender c o.png 1 1\n"
    );
    let names = instance_names(&load(&with_root).jobs[0].scene);
    assert_eq!(names, ["root/a"]);
    // Without it: every shape no composite contains, and uncontained composites.
    let without = format!(
        "{MATERIAL}define shape sphere a 0 0 0 1 m\ndefine shape sphere b 0 0 0 1 m\n\
         define shape sphere c 0 0 0 1 m\ndefine shape composite g a\n\
         define camera cam 60\nrender cam o.png 1 1\n"
    );
    let names = instance_names(&load(&without).jobs[0].scene);
    assert_eq!(names, ["b", "c", "g/a"]);
}

#[test]
fn one_render_line_sees_every_transform_wherever_it_stands() {
    let text = format!(
        "{MATERIAL}define shape sphere s 0 0 0 1 m\ndefine camera c 60\nrender c o.png 1 1\n\
         transform s translate 1 0 0\n"
    );
    let loaded = load(&text);
    assert!(loaded.diagnostics.is_empty(), "{:?}", loaded.diagnostics);
    let scene = &loaded.jobs[0].scene;
    let t = *scene.transform_of(&scene.instances[0]);
    assert!(close(t.point(DVec3::ZERO), DVec3::X));
}

#[test]
fn several_render_lines_see_the_transforms_before_them() {
    let text = format!(
        "define camera c 60\nrender c f0.png 1 1\n{MATERIAL}define shape sphere s 0 0 0 1 m\n\
         transform s translate 1 0 0\nrender c f1.png 1 1\n\
         transform s translate 1 0 0\ntransform c translate 0 0 5\nrender c f2.png 1 1 4\n"
    );
    let loaded = load(&text);
    let xs: Vec<f64> = loaded
        .jobs
        .iter()
        .map(|j| {
            j.scene
                .transform_of(&j.scene.instances[0])
                .point(DVec3::ZERO)
                .x
        })
        .collect();
    // Every job sees the sphere (definitions are global), moved as far as its line allows.
    assert_eq!(xs, [0.0, 1.0, 2.0]);
    let outputs: Vec<_> = loaded.jobs.iter().map(|j| j.output.clone()).collect();
    assert_eq!(
        outputs,
        ["f0.png", "f1.png", "f2.png"].map(std::path::PathBuf::from)
    );
    assert!(close(loaded.jobs[2].camera.eye, DVec3::new(0.0, 0.0, 5.0)));
    assert!(close(loaded.jobs[1].camera.eye, DVec3::ZERO));
    assert_eq!(loaded.jobs[2].samples, Some(4));
}

#[test]
fn transforms_after_the_last_of_several_renders_are_reported() {
    let text = format!(
        "{MATERIAL}define shape sphere s 0 0 0 1 m\ndefine camera c 60\n\
         render c a.png 1 1\nrender c b.png 1 1\ntransform s translate 1 0 0\n"
    );
    let loaded = load(&text);
    assert_eq!(loaded.diagnostics.len(), 1);
    let d = &loaded.diagnostics[0];
    assert_eq!(d.severity, Severity::Warning);
    assert_eq!(d.loc.as_ref().map(|l| l.line), Some(6));
    assert!(d.message.contains("after the last render"));
}

#[test]
fn without_a_render_line_the_first_camera_is_rendered_with_a_warning() {
    let loaded = load("define camera side 45 1 2 3 0 0 -1 0 1 0\ndefine camera top 60\n");
    assert_eq!(loaded.jobs.len(), 1);
    let job = &loaded.jobs[0];
    assert_eq!(job.camera.name, "side");
    assert_eq!((job.width, job.height), (800, 600));
    assert_eq!(job.output, std::path::PathBuf::from("scene.png"));
    assert!(loaded.diagnostics[0]
        .message
        .contains("no render statement"));
    // No camera at all: the default one.
    let loaded = load("ambient 0.1 0.1 0.1\n");
    assert_eq!(loaded.jobs[0].camera.fov_x_deg, 60.0);
    assert_eq!(loaded.jobs[0].camera.dir, DVec3::NEG_Z);
}

#[test]
fn cameras_and_lights_follow_their_transforms() {
    let text = "define camera c 90 0 0 0 0 0 -1 0 1 0\n\
                transform c rotate 90 0 1 0\ntransform c translate 0 0 10\n\
                define light l 1 0 0 1 1 1 2\ntransform l translate 0 3 0\n\
                render c o.png 1 1\n";
    let job = &load(text).jobs[0];
    assert!(close(job.camera.eye, DVec3::new(0.0, 0.0, 10.0)));
    // -z turned 90° about y looks along -x; up stays y.
    assert!(close(job.camera.dir, DVec3::NEG_X));
    assert!(close(job.camera.up, DVec3::Y));
    let light = &job.scene.lights[0];
    assert!(close(light.position, DVec3::new(1.0, 3.0, 0.0)));
    assert_eq!(light.intensity, Vec3::splat(2.0));
}

#[test]
fn lights_in_every_form() {
    let text = "define light a 0 0 0 1 0.5 0 2\n\
                define light b 0 0 0 1 1 1\n\
                define light c 0 0 0 1 1 1 10 20 30\n\
                define light d 0 0 0 0.1 0.2 0.3 0.5 0.5 0.5\n\
                define light diffuse e 0 0 0 0.25 0.25 0.25\n\
                define light ambient amb 0.05 0.05 0.05\n\
                define camera cam 60\nrender cam o.png 1 1\n";
    let loaded = load(text);
    let scene = &loaded.jobs[0].scene;
    let by_name = |n: &str| {
        scene
            .lights
            .iter()
            .find(|l| l.name == n)
            .map(|l| l.intensity)
    };
    assert_eq!(by_name("a"), Some(Vec3::new(2.0, 1.0, 0.0)));
    assert_eq!(by_name("b"), Some(Vec3::ONE));
    assert_eq!(by_name("c"), Some(Vec3::new(10.0, 20.0, 30.0)));
    assert_eq!(by_name("d"), Some(Vec3::splat(0.5)));
    assert_eq!(by_name("e"), Some(Vec3::splat(0.25)));
    // The lecture form's La adds to the ambient light set by `define light ambient`.
    assert!(scene.ambient.abs_diff_eq(Vec3::new(0.15, 0.25, 0.35), 1e-6));
    // Both 9-number readings are explained, once each.
    let nine: Vec<_> = loaded
        .diagnostics
        .iter()
        .filter(|d| d.message.contains("9-number"))
        .collect();
    assert_eq!(nine.len(), 2);
}

#[test]
fn ambient_and_background_variants() {
    for (line, expected) in [
        ("ambient 0.1 0.2 0.3", Vec3::new(0.1, 0.2, 0.3)),
        ("ambient 0.5", Vec3::splat(0.5)),
        ("define ambient 0.1 0.2 0.3", Vec3::new(0.1, 0.2, 0.3)),
        ("define ambient 0.5", Vec3::splat(0.5)),
        ("define ambient amb 1 1 1 0.2", Vec3::splat(0.2)),
        ("ambient amb 0.1 0.2 0.3", Vec3::new(0.1, 0.2, 0.3)),
        (
            "define light ambient amb 0.1 0.2 0.3",
            Vec3::new(0.1, 0.2, 0.3),
        ),
    ] {
        let loaded = load(&format!("{line}\ndefine camera c 60\nrender c o.png 1 1\n"));
        assert!(
            loaded.jobs[0].scene.ambient.abs_diff_eq(expected, 1e-6),
            "{line}"
        );
    }
    for line in [
        "background 0.1 0.2 0.3",
        "define background 0.1 0.2 0.3",
        "define backgroundcolor 0.1 0.2 0.3",
    ] {
        let loaded = load(&format!("{line}\ndefine camera c 60\nrender c o.png 1 1\n"));
        assert_eq!(
            loaded.jobs[0].scene.background,
            Vec3::new(0.1, 0.2, 0.3),
            "{line}"
        );
    }
}

#[test]
fn materials_read_their_extras_by_the_field_list() {
    let text = "define material a 1 1 1 1 1 1 1 1 1 10\n\
                define material b 1 1 1 1 1 1 1 1 1 10 0.5\n\
                define material c 1 1 1 1 1 1 1 1 1 10 0.5 0.25 1.5\n\
                define camera cam 60\nrender cam o.png 1 1\n";
    let materials = &load(text).jobs[0].scene.materials;
    assert_eq!(
        (
            materials[0].reflectivity,
            materials[0].opacity,
            materials[0].ior
        ),
        (0.0, 1.0, 1.0)
    );
    assert_eq!(materials[1].reflectivity, 0.5);
    assert_eq!(
        (
            materials[2].reflectivity,
            materials[2].opacity,
            materials[2].ior
        ),
        (0.5, 0.25, 1.5)
    );
    let opts = LoadOptions {
        material_fields: MaterialLayout::Fields(vec![
            MaterialField::Reflectivity,
            MaterialField::Transparency,
            MaterialField::Ior,
        ]),
        ..LoadOptions::default()
    };
    let materials = &load_with(text, &opts).jobs[0].scene.materials;
    assert_eq!(materials[2].opacity, 0.75);
}

#[test]
fn shapes_in_every_layout() {
    let text = format!(
        "{MATERIAL}define shape box b 1 1 1 -1 -1 -1 m\n\
         define shape sphere neg 0 0 0 -2 m\n\
         define shape cylinder cy 0 0 0 0 1 0 0.5 m\n\
         define shape cone co 0 0 0 0 1 0 0.5 m\n\
         define shape triangle t 0 0 0 1 0 0 0 1 0 m\n\
         define shape plane p 0 0 0 0 1 0 m\n\
         define shape sphere mf m 0 0 0 1\n\
         define sphere ds 0 0 0 1 m\n\
         define camera c 60\nrender c o.png 1 1\n"
    );
    let scene = &load(&text).jobs[0].scene;
    assert_eq!(scene.instances.len(), 8);
    assert!(matches!(
        scene.instances[1].geometry,
        Geometry::Sphere { radius, .. } if radius == 2.0
    ));
}

#[test]
fn degenerate_shapes_are_dropped_and_their_transforms_ignored() {
    let text = format!(
        "{MATERIAL}define shape sphere zero 0 0 0 0 m\n\
         define shape cylinder flat 0 0 0 0 0 0 1 m\n\
         define shape triangle line 0 0 0 1 1 1 2 2 2 m\n\
         define shape sphere ok 0 0 0 1 m\n\
         transform zero translate 1 0 0\n\
         define shape composite g zero ok\n\
         define camera c 60\nrender c o.png 1 1\n"
    );
    let loaded = load(&text);
    let names = instance_names(&loaded.jobs[0].scene);
    assert_eq!(names, ["g/ok"]);
    assert_eq!(
        loaded
            .diagnostics
            .iter()
            .filter(|d| d.message.contains("dropped"))
            .count(),
        3
    );
}

#[test]
fn render_variants() {
    let cases = [
        ("render eye image . ppm 480 320", "image.ppm", (480, 320)),
        ("render eye image .ppm 480 320", "image.ppm", (480, 320)),
        ("render eye 800 700 out.ppm", "out.ppm", (800, 700)),
        ("render eye 480 320", "scene.png", (480, 320)),
        ("render out.ppm 480 320 16 3 5", "out.ppm", (480, 320)),
        ("define render out.ppm 500 500", "out.ppm", (500, 500)),
        ("define renderer out.ppm 500 500", "out.ppm", (500, 500)),
        ("renderer out.ppm", "out.ppm", (800, 600)),
    ];
    for (line, output, size) in cases {
        let loaded = load(&format!("define camera eye 60\n{line}\n"));
        let job = &loaded.jobs[0];
        assert_eq!(job.output, std::path::PathBuf::from(output), "{line}");
        assert_eq!((job.width, job.height), size, "{line}");
        assert_eq!(job.camera.name, "eye", "{line}");
    }
}

#[test]
fn strict_mode_turns_warnings_into_errors() {
    let text = "efine shape sphere s 0 0 0 1 m\ndefine camera c 60\nrender c o.png 1 1\n";
    let lenient = load(text);
    assert_eq!(lenient.diagnostics.len(), 1);
    let strict = LoadOptions {
        strict: true,
        ..LoadOptions::default()
    };
    let ds = load_str(text, Path::new("scene.sdf"), &strict).unwrap_err();
    assert_eq!(ds.len(), 1);
    assert!(ds[0].is_error());
}

#[test]
fn errors_do_not_cascade_from_a_rejected_definition() {
    // The material line is wrong; the shape using it must not add "unknown material".
    let ds = errors(
        "define material m 1 1 1 1 1 1 1 1 1 1O\ndefine shape sphere s 0 0 0 1 m\n\
         transform s translate 1 0 0\ndefine camera c 60\nrender c o.png 1 1\n",
    );
    assert_eq!(ds.len(), 1, "{ds:?}");
    assert_eq!(ds[0].message, "expected a number, found '1O'");
}

#[test]
fn composite_cycles_and_explosions_are_errors_not_hangs() {
    let text = format!(
        "{MATERIAL}define shape sphere s 0 0 0 1 m\ndefine shape composite a s\n\
         define shape composite b a\ndefine shape composite a b\n\
         define camera c 60\nrender c o.png 1 1\n"
    );
    let ds = errors(&text);
    assert!(
        ds.iter().any(|d| d.message.contains("contains itself")),
        "{ds:?}"
    );

    let mut text = format!("{MATERIAL}define shape sphere s0 0 0 0 1 m\n");
    for k in 1..=33 {
        text.push_str(&format!(
            "define shape composite s{k} s{prev} s{prev}\n",
            prev = k - 1
        ));
    }
    text.push_str("define camera c 60\nrender c o.png 1 1\n");
    // 2^33 shapes, too many to instance: refused from its counts under a budget of 1 GiB.
    let opts = LoadOptions {
        max_memory: 1 << 30,
        ..LoadOptions::default()
    };
    let ds = load_str(&text, Path::new("scene.sdf"), &opts).unwrap_err();
    let want = format!(
        "the composite tree expands to 8589934592 shapes, which need about {} of memory, more than the 1.0 GiB allowed (`s33` is the largest part)",
        crate::util::human_bytes(crate::limits::scene_memory(1 << 33))
    );
    assert!(ds.iter().any(|d| d.message == want), "{ds:?}");
}

#[test]
fn canonical_text_reads_back_to_the_same_jobs() {
    let text = "define material red 1 0 0 1 0 0 1 0 0 10 0.5\n\
                define material glass 0.1 0.1 0.1 0 0 0 1 1 1 200 0 0.1 1.5\n\
                define shape sphere ball red 0 0 -10 2\n\
                define shape box b 1 1 1 -1 -1 -1 glass\n\
                define shape composite root ball b\n\
                define light sun 0 10 0 1 1 1 0.5 0.5 0.5\n\
                define light ambient amb 0.1 0.1 0.1\n\
                camera eye 45 0 0 5 0 0 -1 0 1 0\n\
                transform ball rotate 30 x translate 1 2 3\n\
                transform root scale 2\n\
                background 0.1 0.2 0.3\n\
                render eye image . ppm 64 48 4\n";
    let path = Path::new("scene.sdf");
    let opts = LoadOptions::default();
    let (statements, _) = parse(text, path, &opts);
    let canonical: String = statements.iter().map(|s| format!("{s}\n")).collect();
    let first = load(text);
    let second = load(&canonical);
    assert_eq!(first.jobs.len(), second.jobs.len());
    for (a, b) in first.jobs.iter().zip(&second.jobs) {
        assert_eq!(a.scene.materials, b.scene.materials);
        assert_eq!(a.scene.lights, b.scene.lights);
        assert_eq!(a.scene.ambient, b.scene.ambient);
        assert_eq!(a.scene.background, b.scene.background);
        assert_eq!(a.camera, b.camera);
        assert_eq!(
            (&a.output, a.width, a.height, a.samples),
            (&b.output, b.width, b.height, b.samples)
        );
        let strip = |j: &RenderJob| -> Vec<_> {
            j.scene
                .instances
                .iter()
                .map(|i| {
                    (
                        j.scene.instance_name(i),
                        i.geometry.clone(),
                        i.material,
                        *j.scene.transform_of(i),
                    )
                })
                .collect()
        };
        assert_eq!(strip(a), strip(b));
    }
    // Reading the canonical text again gives the same text.
    let (again, _) = parse(&canonical, path, &opts);
    let canonical_again: String = again.iter().map(|s| format!("{s}\n")).collect();
    assert_eq!(canonical, canonical_again);
}

#[test]
fn build_checks_statements_made_by_a_program() {
    let path = Path::new("gen.sdf");
    let opts = LoadOptions::default();
    let (mut statements, diags) = parse(
        &format!(
            "{MATERIAL}define shape sphere s 0 0 0 1 m\ndefine camera c 60\nrender c o.png 1 1\n"
        ),
        path,
        &opts,
    );
    assert!(diags.is_empty());
    assert_eq!(build(&statements, path, &opts).unwrap().jobs.len(), 1);
    // A generator writing a zero scale gets an error from `build`, not a broken matrix.
    let loc = statements[1].loc.clone();
    statements.push(ast::Statement::new(
        ast::StatementKind::Transform {
            target: ast::NameRef {
                name: "s".to_string(),
                loc: loc.clone(),
            },
            ops: vec![ast::TransformOp::Scale(DVec3::ZERO)],
        },
        loc,
    ));
    let ds = build(&statements, path, &opts).unwrap_err();
    assert!(ds.iter().any(|d| d.is_error()));
}

mod fuzz {
    use super::*;
    use proptest::prelude::*;

    /// Tokens that reach every branch of the parser: keywords, names, good and bad numbers.
    fn token() -> impl Strategy<Value = String> {
        prop_oneof![
            4 => prop::sample::select(vec![
                "define", "material", "shape", "sphere", "box", "triangle", "cylinder", "cone",
                "plane", "composite", "obj", "light", "ambient", "diffuse", "camera",
                "transform", "translate", "rotate", "scale", "render", "renderer", "background",
                "backgroundcolor", "view", "rotatez", "x", "y", "root", "a", "b", "m", "eye",
                "image", ".", "ppm", "out.png", "scene.sdf", "#", "//",
            ])
            .prop_map(str::to_string),
            4 => prop::sample::select(vec![
                "0", "1", "-1", ".5", "2", "90", "200", "1e9", "1e-300", "1e12", "-0", "nan",
                "1O", "1.0f", "+3", "1e999",
            ])
            .prop_map(str::to_string),
            1 => "\\PC{0,5}",
        ]
    }

    fn line() -> impl Strategy<Value = String> {
        (
            prop::collection::vec(token(), 0..16),
            prop::sample::select(vec![" ", "\t", "  "]),
            prop::sample::select(vec!["\n", "\r\n"]),
        )
            .prop_map(|(tokens, sep, end)| tokens.join(sep) + end)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(400))]

        #[test]
        fn no_token_soup_makes_the_reader_panic(lines in prop::collection::vec(line(), 0..14)) {
            let text: String = lines.concat();
            for opts in [
                LoadOptions::default(),
                LoadOptions { strict: true, transform_order: TransformOrder::Local, ..LoadOptions::default() },
            ] {
                let result = load_str(&text, Path::new("fuzz.sdf"), &opts);
                let diagnostics = match &result {
                    Ok(l) => &l.diagnostics,
                    Err(ds) => ds,
                };
                // Every error points into the text (but for the file-wide note that there
                // is no render line, an error under --strict).
                for d in diagnostics.iter().filter(|d| d.is_error()) {
                    prop_assert!(
                        d.loc.is_some() || d.message.starts_with("no render statement"),
                        "{}",
                        d
                    );
                }
                if let Ok(loaded) = result {
                    for job in &loaded.jobs {
                        prop_assert!(job.camera.eye.is_finite() && job.camera.dir.is_finite());
                        for i in job.scene.instances.iter() {
                            let t = job.scene.transform_of(i);
                            prop_assert!(t.world_from_object.is_finite());
                            prop_assert!(t.object_from_world.is_finite());
                        }
                    }
                }
            }
        }

        #[test]
        fn no_text_at_all_makes_the_reader_panic(text in "\\PC{0,300}") {
            let _ = load_str(&text, Path::new("fuzz.sdf"), &LoadOptions::default());
        }
    }
}

#[test]
fn render_file_names_and_cameras_may_look_like_numbers() {
    let loaded = load("define camera 1 60\nrender 1 001.png 8 8\nrender 1 out/2.ppm 4 4\n");
    let outputs: Vec<_> = loaded.jobs.iter().map(|j| j.output.clone()).collect();
    assert_eq!(
        outputs,
        ["001.png", "out/2.ppm"].map(std::path::PathBuf::from)
    );
    assert_eq!(loaded.jobs[0].camera.name, "1");
    // A malformed number is still reported as one.
    let ds = errors("define camera eye 60\nrender eye out.png 48O 320\n");
    assert_eq!(ds[0].message, "expected a number, found '48O'");
}

#[test]
fn camera_with_only_an_eye_and_light_without_position() {
    let loaded = load(
        "ambient 0.1 0.1 0.1\ndefine light amb .3 .2 .6 5\ndefine camera c 60 10 0 0\nrender c out.png 8 8\n",
    );
    let job = &loaded.jobs[0];
    assert_eq!(job.camera.eye, DVec3::new(10.0, 0.0, 0.0));
    assert_eq!(job.camera.dir, DVec3::NEG_Z);
    // 0.1 set, plus (.3, .2, .6)·5 added.
    assert!(
        (job.scene.ambient - Vec3::new(1.6, 1.1, 3.1))
            .abs()
            .max_element()
            < 1e-6
    );
    assert!(job.scene.lights.is_empty());
}

// ----- forms other renderers accepted (the author-intent issue) ---------------------------

fn warnings(loaded: &Loaded) -> String {
    loaded
        .diagnostics
        .iter()
        .map(|d| d.to_string())
        .collect::<Vec<_>>()
        .join("\n")
}

fn auto() -> LoadOptions {
    LoadOptions {
        material_fields: MaterialLayout::Auto,
        ..LoadOptions::default()
    }
}

#[test]
fn define_renderer_names_its_camera() {
    let l = load(&format!(
        "{MATERIAL}define camera eye 60\ndefine renderer eye out.ppm 32 24\n"
    ));
    assert_eq!(l.jobs.len(), 1);
    let job = &l.jobs[0];
    assert_eq!(
        (job.camera.name.as_str(), job.width, job.height),
        ("eye", 32, 24)
    );
    assert_eq!(job.output, Path::new("out.ppm"));
}

#[test]
fn a_bad_render_line_rejects_only_its_own_image() {
    let l = load(&format!(
        "{MATERIAL}define camera a 60\ndefine camera b 60\nrender a one.png 0 8\nrender b two.png 8 8\n"
    ));
    assert_eq!(l.jobs.len(), 1);
    assert!(
        warnings(&l).contains("this render line is skipped"),
        "{}",
        warnings(&l)
    );
    // Alone, it is still an error.
    let ds = errors(&format!(
        "{MATERIAL}define camera a 60\nrender a one.png 0 8\n"
    ));
    assert!(ds.iter().any(Diagnostic::is_error));
}

#[test]
fn an_unknown_render_camera_means_the_only_one() {
    let l = load(&format!(
        "{MATERIAL}define camera eye 60\nrender bob out.png 8 8\n"
    ));
    assert_eq!(l.jobs[0].camera.name, "eye");
}

#[test]
fn transform_camera_moves_the_only_camera() {
    let l = load(&format!(
        "{MATERIAL}define camera eye 60\ntransform camera translate 0 0 5\nrender eye out.png 8 8\n"
    ));
    assert!(close(l.jobs[0].camera.eye, DVec3::new(0.0, 0.0, 5.0)));
}

#[test]
fn ten_number_lights_carry_ambient_diffuse_and_brightness() {
    let l = load(&format!(
        "{MATERIAL}define light l 0 5 0 0.1 0.2 0.3 1 1 1 2\ndefine camera eye 60\nrender eye out.png 8 8\n"
    ));
    let scene = &l.jobs[0].scene;
    assert_eq!(scene.lights[0].intensity, Vec3::splat(2.0));
    assert_eq!(scene.ambient, Vec3::new(0.1, 0.2, 0.3));
}

#[test]
fn a_camera_without_up_looks_with_y_up() {
    let l = load(&format!(
        "{MATERIAL}define camera eye 60 0 0 0 1 0 0\nrender eye out.png 8 8\n"
    ));
    assert!(close(l.jobs[0].camera.up, DVec3::Y));
    assert!(close(l.jobs[0].camera.dir, DVec3::X));
}

#[test]
fn a_name_after_the_material_is_the_shapes_name() {
    let l = load(&format!(
        "{MATERIAL}define shape sphere 0 0 -5 1 m ball\ndefine camera eye 60\nrender eye out.png 8 8\n"
    ));
    let scene = &l.jobs[0].scene;
    assert_eq!(scene.instance_name(&scene.instances[0]), "ball");
}

#[test]
fn undefined_materials_are_magenta_and_name_every_shape() {
    let l = load(
        "define shape sphere a 0 0 -5 1 red\ndefine shape sphere b 0 0 -9 1 red\n\
         define camera eye 60\nrender eye out.png 8 8\n",
    );
    let scene = &l.jobs[0].scene;
    assert_eq!(scene.instances.len(), 2);
    let m = &scene.materials[scene.instances[0].material];
    assert_eq!(m.kd, Vec3::new(1.0, 0.0, 1.0));
    let w = warnings(&l);
    assert_eq!(w.matches("unknown material").count(), 1, "{w}");
    assert!(w.contains("`a`, `b`"), "{w}");
}

#[test]
fn f_suffixed_numbers_are_read() {
    let l = load(&format!(
        "{MATERIAL}define shape sphere s 0 0 -5 1.5f m\ndefine camera eye 60\nrender eye out.png 8 8\n"
    ));
    assert_eq!(
        l.jobs[0].scene.instances[0].geometry,
        Geometry::Sphere {
            center: DVec3::new(0.0, 0.0, -5.0),
            radius: 1.5
        }
    );
}

#[test]
fn implausible_values_are_warned() {
    let l = load(
        "define material m -1 0 0 1 1 1 1 1 1 10\ndefine light l 0 5 0 1 1 1 -2\n\
         define shape box b 0 0 0 0 0 1 m\ndefine shape box flat 0 0 0 1 1 0 m\n\
         define camera eye 60\nrender eye out.png 8 8\n",
    );
    let w = warnings(&l);
    assert!(w.contains("negative Ka"), "{w}");
    assert!(w.contains("negative colour or brightness"), "{w}");
    assert!(w.contains("box `b` has zero size on 2 axes"), "{w}");
    assert!(!w.contains("box `flat`"), "{w}");
}

#[test]
fn every_invisible_material_is_reported_and_same_outputs_warned() {
    // Read in the standard layout (inference would take the zeros for transparency).
    let standard = LoadOptions {
        material_fields: MaterialLayout::standard(),
        ..LoadOptions::default()
    };
    let l = load_with(
        "define material a 1 1 1 1 1 1 1 1 1 10 0 0 1\ndefine material b 1 1 1 1 1 1 1 1 1 10 0 0 1\n\
         define camera eye 60\nrender eye out.png 8 8\nrender eye out.png 8 8\n",
        &standard,
    );
    let w = warnings(&l);
    assert!(w.contains("material `a` is invisible"), "{w}");
    assert!(w.contains("material `b` is invisible"), "{w}");
    assert!(w.contains("also writes `out.png`"), "{w}");
}

#[test]
fn inferred_layouts_read_the_materials_as_meant() {
    // Transparency written where the default expects opacity: 0 means opaque.
    let text = "define material a 1 1 1 1 1 1 1 1 1 10 0 0 1\n\
                define material b 1 1 1 1 1 1 1 1 1 10 0.2 0 1\n\
                define camera eye 60\nrender eye out.png 8 8\n";
    let l = load_with(text, &auto());
    let parsed = parse(text, Path::new("scene.sdf"), &auto()).0;
    let opacities: Vec<f32> = parsed
        .iter()
        .filter_map(|s| match &s.kind {
            ast::StatementKind::Material(m) => Some(m.opacity),
            _ => None,
        })
        .collect();
    assert_eq!(opacities, [1.0, 1.0]);
    let w = warnings(&l);
    assert_eq!(w.matches("are read as").count(), 1, "{w}");
    assert!(w.contains("transparency"), "{w}");
    // An explicit list wins.
    let explicit = LoadOptions {
        material_fields: MaterialLayout::Fields(vec![
            MaterialField::Reflectivity,
            MaterialField::Opacity,
            MaterialField::Ior,
        ]),
        ..LoadOptions::default()
    };
    assert!(!warnings(&load_with(text, &explicit)).contains("are read as"));
    // ior then opacity after m (12 numbers), m last (13 numbers), percentages.
    for (line, want) in [
        ("10 1.5 0.5", "m ior opacity"),
        ("0.3 1 0 60", "reflectivity ior transparency m`"),
        ("20 50 100 1.5", "percentages"),
        ("30 0.1 1 1.2 0.5", "glossiness"),
    ] {
        let text = format!(
            "define material a 1 1 1 1 1 1 1 1 1 {line}\ndefine camera eye 60\nrender eye out.png 8 8\n"
        );
        let w = warnings(&load_with(&text, &auto()));
        assert!(w.contains(want), "{line}: {w}");
    }
}
