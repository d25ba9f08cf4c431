//! Forms of the scene language that the authors' own renderers accepted, read from the public
//! corpus files that use them: each is accepted with a warning naming the reading, is an error
//! under `--strict`, and the image it gives is not blank.

use crate::common;

use common::{anim, shared_dir};
use std::path::{Path, PathBuf};

fn corpus_file(test: &str, name: &str) -> Option<PathBuf> {
    let path = shared_dir(test)?.join("corpus/wild").join(name);
    assert!(path.is_file(), "{} is missing", path.display());
    Some(path)
}

/// `anim ARGS... FILE`: (exit code, stderr).
fn run(args: &[&str], file: &Path) -> (i32, String) {
    let out = anim().args(args).arg(file).output().expect("anim runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Checks `name`: it loads with a warning containing `reading`, `--strict` rejects it, and its
/// images at 160×120 with one sample per pixel are not blank.
fn accepted_and_drawn(name: &str, reading: &str) {
    let Some(file) = corpus_file(name, name) else {
        return;
    };
    let (code, stderr) = run(&["check"], &file);
    assert_eq!(code, 0, "{name}: {stderr}");
    assert!(
        stderr
            .lines()
            .any(|l| l.contains("warning") && l.contains(reading)),
        "{name}: no warning containing {reading:?}:\n{stderr}"
    );
    assert!(!stderr.contains("would be blank"), "{name}: {stderr}");
    let (code, stderr) = run(&["check", "--strict"], &file);
    assert_eq!(code, 1, "{name}: --strict accepted it:\n{stderr}");

    let out = tempfile::tempdir().expect("temp dir");
    let (code, stderr) = run(
        &[
            "render",
            "-q",
            "--width",
            "160",
            "--height",
            "120",
            "--spp",
            "1",
            "--out",
            out.path().to_str().expect("utf-8 temp path"),
        ],
        &file,
    );
    assert_eq!(code, 0, "{name}: {stderr}");
    let mut images = Vec::new();
    common::files_below(out.path(), &mut images);
    assert!(!images.is_empty(), "{name}: no image written");
    for path in &images {
        let img = image::open(path)
            .unwrap_or_else(|e| panic!("{name}: {}: {e}", path.display()))
            .to_rgb8();
        assert_eq!(img.dimensions(), (160, 120), "{name}");
        let first = img.get_pixel(0, 0);
        assert!(
            img.pixels().any(|p| p != first),
            "{name}: {} is one flat colour",
            path.display()
        );
    }
}

#[test]
fn camera_with_the_image_size_then_eye_and_direction() {
    accepted_and_drawn(
        "flor2468__raytracer_SoSe2019/Kugel_Scene.sdf",
        "<fov-x> <width> <height> [eye] [dir]",
    );
}

#[test]
fn camera_circling_the_scene() {
    for name in [
        "Graunarmin__Raytracer_SS17/DieSzene.txt",
        "Graunarmin__Raytracer_SS17/szene1.txt",
        "Graunarmin__Raytracer_SS17/framework1.txt",
    ] {
        accepted_and_drawn(name, "<fov-x> <angle> [center] <radius>");
    }
}

#[test]
fn camera_turned_by_zero_angles() {
    accepted_and_drawn(
        "GorgeousOne__Path-Tracer/example.sdf",
        "yaw, pitch and roll",
    );
}

#[test]
fn output_without_an_image_extension() {
    accepted_and_drawn(
        "GorgeousOne__Path-Tracer/cornell-box.sdf",
        "is no image file name",
    );
    accepted_and_drawn(
        "jacoblammert__programmiersprachen-raytracer/test0.sdf",
        "`test0.sdf` is no image file name: `test0.ppm` is written",
    );
}

#[test]
fn camera_up_along_the_view() {
    accepted_and_drawn(
        "Snoopyxxel__programmiersprachen-raytracer/initial.sdf",
        "parallel to its viewing direction: +y is up",
    );
}

#[test]
fn upright_cones_and_cylinders() {
    accepted_and_drawn(
        "AnBenLa__programmiersprachen-raytracer/chess-all-shapes.sdf",
        "[base] <height> <radius>",
    );
}

#[test]
fn a_broken_camera_skips_its_own_render_line() {
    accepted_and_drawn(
        "christiandunkel__raytracer/materials_test.sdf",
        "camera `eye2` is skipped with the render line that uses it",
    );
}

#[test]
fn lights_with_a_radius() {
    accepted_and_drawn(
        "EmilReinert__raytracer/sdf_scene.txt",
        "[pos] <radius> [color] <brightness>",
    );
}

/// The assignment's camera lines (`rotate -45 0 1 0`, then `translate 100 0 100`) leave the
/// camera looking away from the scene when each transform applies after the ones above it;
/// these files' cameras are turned as the course framework turns them, the opposite way
/// from a shape, which `auto` (the default) takes, saying so. Asked for by name, the standard
/// reading still gives the blank image, with its warning.
#[test]
fn cameras_turned_the_way_the_course_framework_turns_them() {
    for name in [
        "AnBenLa__programmiersprachen-raytracer/Simple-Scene.sdf",
        "BSVogler__Raytracer/boxtest.sdf",
        "M-Unterreiner__programmiersprachen-raytracer/simple_scene.sdf",
        "ferasalsabaa__programmiersprachen-raytracer/scene2.sdf",
    ] {
        accepted_and_drawn(name, "turned the opposite way from a shape");
        let Some(file) = corpus_file(name, name) else {
            return;
        };
        let (code, stderr) = run(&["check", "--transform-order", "world"], &file);
        assert_eq!(code, 0, "{name}: {stderr}");
        assert!(stderr.contains("would be blank"), "{name}: {stderr}");
        assert!(
            !stderr.contains("turned the opposite way"),
            "{name}: {stderr}"
        );
    }
}
