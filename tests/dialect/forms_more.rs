//! More forms that other readers of the language accept, each on a small file of our own that
//! reproduces what real files do: read with a located warning that names the reading, an
//! error under `--strict`, and an image that shows the scene. Template placeholders, which no
//! reading can give a value, are a located error that names the placeholder.

use crate::common::{read_ppm, run_in};

const HEAD: &str = "\
define material red 0.2 0 0 1 0 0 0.5 0.5 0.5 20
define material green 0 0.2 0 0 1 0 0.5 0.5 0.5 20
define light sun 0 10 10 1 1 1 1
ambient 0.2 0.2 0.2
";

/// Loads `body` (after the materials and light) with a warning at `at` containing
/// `reading`, refused under `--strict`; returns the 40×30 image it renders to `image.ppm`.
fn read_with_warning(body: &str, at: &str, reading: &str) -> crate::common::Rgb8 {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("scene.sdf"), format!("{HEAD}{body}")).unwrap();
    let (code, err) = run_in(dir, &["check", "scene.sdf"]);
    assert_eq!(code, 0, "{err}");
    let wanted = format!("scene.sdf:{at}: warning: ");
    assert!(
        err.lines()
            .any(|l| l.starts_with(&wanted) && l.contains(reading)),
        "no `{wanted}…{reading}` in\n{err}"
    );
    let (code, err) = run_in(dir, &["check", "scene.sdf", "--strict"]);
    assert_ne!(code, 0, "--strict accepted it:\n{err}");
    let (code, err) = run_in(dir, &["render", "scene.sdf", "--quiet"]);
    assert_eq!(code, 0, "{err}");
    read_ppm(&dir.join("image.ppm"))
}

/// Whether the pixel at (x, y) is lit red (the red material), rather than background.
fn red_at(image: &crate::common::Rgb8, x: usize, y: usize) -> bool {
    let [r, g, b] = image.at(x, y);
    r > 60 && g < 40 && b < 40
}

const CAMERA: &str = "define camera eye 60 0 0 0 0 0 -1 0 1 0\nrender eye image.ppm 40 30\n";

#[test]
fn numbers_glued_by_a_sign_are_read_as_a_stream_reader_reads_them() {
    // A box from (-1, -1, -6) to (1, 1, -4): `1-4` would otherwise be refused as a
    // malformed number.
    let image = read_with_warning(
        &format!("define shape box b -1 -1 -6 1 1-4 red\n{CAMERA}"),
        "5:31",
        "`1-4` read as 2 numbers, `1` `-4`",
    );
    assert!(red_at(&image, 20, 15), "the box is not drawn");
}

/// A loader that reads its file as a stream of words (`file >> x`) takes a number glued to
/// the next statement's first word as the number, then that statement: the material ends at
/// `20` and `ambient 1 1 1` lights the sphere, which has no other light. Read with the
/// newline put back, the file gives the same image, byte for byte.
#[test]
fn a_number_glued_to_the_next_statement_is_read_as_a_stream_reader_reads_it() {
    let scene = |joint: &str| {
        format!(
            "define material lit 0.5 0 0 0 0 0 0 0 0 20{joint}ambient 1 1 1\n\
             define shape sphere s 0 0 -5 1 lit\n{CAMERA}"
        )
    };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("scene.sdf"), scene("")).unwrap();
    std::fs::write(
        dir.join("whole.sdf"),
        scene("\n").replace("image.ppm", "whole.ppm"),
    )
    .unwrap();
    let (code, err) = run_in(dir, &["render", "whole.sdf"]);
    assert_eq!(code, 0, "{err}");
    let (code, err) = run_in(dir, &["render", "scene.sdf"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains(
            "scene.sdf:1:41: warning: `20ambient` read as the number `20` and then a new statement from `ambient`"
        ),
        "{err}"
    );
    let (glued, whole) = (
        read_ppm(&dir.join("image.ppm")),
        read_ppm(&dir.join("whole.ppm")),
    );
    assert_eq!(glued.data, whole.data);
    // Ka·I_ambient = 0.5 in red: c/(c+1) = 1/3 of 255.
    assert_eq!(glued.at(20, 15), [85, 0, 0]);
    let (code, _) = run_in(dir, &["check", "scene.sdf", "--strict"]);
    assert_ne!(code, 0);
}

#[test]
fn dreieck_is_a_triangle() {
    let image = read_with_warning(
        &format!("define shape dreieck t -2 -2 -5 2 -2 -5 0 2 -5 red\n{CAMERA}"),
        "5:14",
        "`dreieck` read as `triangle`",
    );
    assert!(red_at(&image, 20, 16), "the triangle is not drawn");
}

#[test]
fn amblight_is_the_ambient_light() {
    // No light but the ambient one: without it the sphere would be black.
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let text = "define material red 1 0 0 1 0 0 0 0 0 1\n\
                define shape sphere s 0 0 -5 1 red\n\
                define amblight 1 1 1\n"
        .to_string()
        + CAMERA;
    std::fs::write(dir.join("scene.sdf"), text).unwrap();
    let (code, err) = run_in(dir, &["render", "scene.sdf"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("scene.sdf:3:8: warning: `define amblight` read as `ambient`"),
        "{err}"
    );
    assert!(red_at(&read_ppm(&dir.join("image.ppm")), 20, 15));
}

#[test]
fn a_render_line_may_name_its_job_before_the_camera() {
    let image = read_with_warning(
        "define shape sphere s 0 0 -5 1 red\n\
         define camera eye 60 0 0 0 0 0 -1 0 1 0\n\
         render job1 eye image.ppm 40 30\n",
        "7:8",
        "`job1` is no camera but `eye` is",
    );
    assert!(red_at(&image, 20, 15));
}

#[test]
fn a_camera_with_the_field_of_view_last_after_eye_and_direction() {
    // `name eye(3) dir(3) fov`, looking along +x at a sphere there.
    let image = read_with_warning(
        "define shape sphere s 5 0 0 1 red\n\
         define camera eye 0 0 0 1 0 0 60\n\
         render eye image.ppm 40 30\n",
        "6:31",
        "the field of view last",
    );
    assert!(red_at(&image, 20, 15));
}

#[test]
fn a_camera_whose_direction_is_zero_is_its_field_of_view_alone() {
    // 11 numbers with a zero direction: renderers that read only the fov looked along -z
    // from the origin.
    let image = read_with_warning(
        "define shape sphere s 0 0 -5 1 red\n\
         define camera eye 60 0 0 3 0 0 0 0 1 0 1\n\
         render eye image.ppm 40 30\n",
        "6:28",
        "read as its field of view alone, at the origin looking along -z",
    );
    assert!(red_at(&image, 20, 15));
}

#[test]
fn shapes_of_one_name_are_all_drawn_and_the_name_is_the_last() {
    // Two spheres named `s`; the transform moves the second (green) one only.
    let image = read_with_warning(
        &format!(
            "define shape sphere s -1.5 0 -5 0.8 red\n\
             define shape sphere s 1.5 0 -5 0.8 green\n\
             transform s translate 0 10 0\n{CAMERA}"
        ),
        "6:21",
        "both are drawn, and the name refers to this one",
    );
    // The red one stays where it was written (left of the centre).
    assert!(red_at(&image, 11, 15), "the first sphere is not drawn");
    // The green one moved out of the view.
    let [_, g, _] = image.at(28, 15);
    assert!(
        g < 40,
        "the transform did not move the last sphere of the name"
    );
}

#[test]
fn a_template_placeholder_is_an_error_that_names_it() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(
        dir.join("scene.sdf"),
        format!(
            "{HEAD}define shape sphere s 0 0 -5 1 red\ntransform s rotate {{{{ANGLE_0}}}} 0 0 1\n{CAMERA}"
        ),
    )
    .unwrap();
    let (code, err) = run_in(dir, &["check", "scene.sdf"]);
    assert_ne!(code, 0);
    assert!(
        err.contains("scene.sdf:6:20: error: `{{ANGLE_0}}` is a template placeholder"),
        "{err}"
    );
    // Written with spaces inside, it is named whole.
    std::fs::write(
        dir.join("spaced.sdf"),
        format!("{HEAD}define shape sphere s 0 0 {{{{ Z }}}} 1 red\n{CAMERA}"),
    )
    .unwrap();
    let (code, err) = run_in(dir, &["check", "spaced.sdf"]);
    assert_ne!(code, 0);
    assert!(
        err.contains("spaced.sdf:5:27: error: `{{ Z }}` is a template placeholder"),
        "{err}"
    );
}

#[test]
fn a_box_with_an_axis_after_its_corners_is_the_box() {
    let image = read_with_warning(
        &format!("define shape box b -1 -1 -6 1 1 -4 0 1 0 red\n{CAMERA}"),
        "5:36",
        "three numbers after the box's corners",
    );
    assert!(red_at(&image, 20, 15), "the box is not drawn");
}

#[test]
fn a_material_without_its_exponent_is_read_with_m_0() {
    // `[Ka] [Kd] [Ks]` and nothing more: m is what a stream reader leaves, 0.
    let image = read_with_warning(
        &format!(
            "define material bare 0.2 0 0 1 0 0 0 0 0\n\
             define shape sphere s 0 0 -5 1 bare\n{CAMERA}"
        ),
        "5:41",
        "a material with 9 numbers has no exponent m: read as 0",
    );
    assert!(red_at(&image, 20, 15));
}

#[test]
fn a_camera_turned_as_the_course_framework_turns_it() {
    // The assignment's extended example: turned like a shape, this camera looks away from
    // the sphere; turned the opposite way, it looks at it.
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(
        dir.join("scene.sdf"),
        format!(
            "{HEAD}define shape sphere s 0 0 -100 50 red\n\
             define camera eye 60\n\
             transform eye rotate -45 0 1 0\n\
             transform eye translate 100 0 100\n\
             render eye image.ppm 40 30\n"
        ),
    )
    .unwrap();
    let (code, err) = run_in(dir, &["render", "scene.sdf"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("scene.sdf:7:1: warning: camera `eye` turned the opposite way from a shape"),
        "{err}"
    );
    let image = read_ppm(&dir.join("image.ppm"));
    let lit = (0..40)
        .flat_map(|x| (0..30).map(move |y| (x, y)))
        .filter(|&(x, y)| red_at(&image, x, y))
        .count();
    assert!(lit > 40, "the sphere is not in view ({lit} red pixels)");
    // Asked for by name, the camera turns like a shape and sees nothing.
    let (code, err) = run_in(dir, &["check", "scene.sdf", "--transform-order", "world"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("would be blank"), "{err}");
}

/// `anim render` of `body` after the materials and light: its stderr.
fn render_warnings(body: &str) -> String {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("scene.sdf"), format!("{HEAD}{body}")).unwrap();
    let (code, err) = run_in(dir, &["render", "scene.sdf"]);
    assert_eq!(code, 0, "{err}");
    err
}

#[test]
fn an_image_of_nearly_one_colour_says_why() {
    // The camera inside a sphere that only the ambient light shows (the light is outside):
    // all one colour, but not black.
    let err = render_warnings(&format!("define shape sphere big 0 0 0 5 red\n{CAMERA}"));
    assert!(
        err.contains(
            "is one colour over 100.0 % of its pixels: the camera is inside an object `big`"
        ),
        "{err}"
    );
    // A speck far away.
    let err = render_warnings(&format!(
        "define shape sphere speck 0 0 -30 1 red\n{CAMERA}"
    ));
    assert!(err.contains("cover almost none of it"), "{err}");
    // A field of view of one degree (radians were meant) on a surface of one colour.
    let err = render_warnings(
        "define material flat 1 0 0 0 0 0 0 0 0 1\n\
         define shape sphere s 0 0 -5 1 flat\n\
         define camera eye 1 0 0 0 0 0 -1 0 1 0\n\
         render eye image.ppm 40 30\n",
    );
    assert!(err.contains("under 2° (radians? 1 rad is 57.3°)"), "{err}");
    // A picture with something in it says nothing of the kind.
    let err = render_warnings(&format!("define shape sphere s 0 0 -5 1 red\n{CAMERA}"));
    assert!(!err.contains("one colour"), "{err}");
}
