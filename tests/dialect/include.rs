//! `include <file>`: the statements of another file in place of the line, the same image as
//! the file written out whole, and every way an include can go wrong refused at its line.

use crate::common::run_in;
use std::path::Path;

const MATERIALS: &str = "\
define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20
define material grey 0.1 0.1 0.1 0.6 0.6 0.6 0 0 0 1
";
const SHAPES: &str = "\
define light key -3 6 2 1 1 1 1
define shape sphere ball 0 0 -6 1.2 red
define shape plane floor 0 -1.2 0 0 1 0 grey
";
const FRAME: &str = "\
define camera cam 60 0 0.5 0 0 0 -1 0 1 0
transform ball translate 0.5 0 0
render cam image.ppm 48 32
";

fn write(dir: &Path, name: &str, text: &str) {
    let path = dir.join(name);
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

fn render(dir: &Path, scene: &str, out: &str) -> Vec<u8> {
    let (code, err) = run_in(dir, &["render", scene, "--out", out, "--quiet"]);
    assert_eq!(code, 0, "{err}");
    std::fs::read(dir.join(out).join("image.ppm")).unwrap()
}

#[test]
fn an_included_scene_renders_as_the_file_written_whole() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    write(dir, "whole.sdf", &format!("{MATERIALS}{SHAPES}{FRAME}"));
    // Two levels, a subfolder, and a quoted name.
    write(dir, "lib/materials.sdf", MATERIALS);
    write(
        dir,
        "lib/static.sdfi",
        &format!("include materials.sdf\n{SHAPES}"),
    );
    write(
        dir,
        "split.sdf",
        &format!("include \"lib/static.sdfi\"\n{FRAME}"),
    );
    let whole = render(dir, "whole.sdf", "a");
    let split = render(dir, "split.sdf", "b");
    assert_eq!(whole, split);
    // Not a blank image: the ball is there.
    assert!(whole.len() > 48 * 32 * 3);
    let (min, max) = whole[whole.len() - 48 * 32 * 3..]
        .iter()
        .fold((255u8, 0u8), |(lo, hi), &b| (lo.min(b), hi.max(b)));
    assert!(max > min + 50, "the image is nearly one colour");
}

#[test]
fn problems_in_an_included_file_are_located_in_it() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    write(
        dir,
        "static.sdfi",
        &format!("{MATERIALS}define shape sphere odd 0 0 -6 oops red\n"),
    );
    write(dir, "scene.sdf", &format!("include static.sdfi\n{FRAME}"));
    let (code, err) = run_in(dir, &["check", "scene.sdf"]);
    assert_ne!(code, 0, "{err}");
    assert!(err.contains("static.sdfi:3:"), "{err}");
    // The line is quoted from the included file.
    assert!(
        err.contains("define shape sphere odd 0 0 -6 oops red"),
        "{err}"
    );
}

#[test]
fn every_bad_include_is_refused_at_its_line() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path().join("scene");
    let dir = root.as_path();
    write(tmp.path(), "outside.sdf", MATERIALS);
    write(dir, "folder/keep.sdf", MATERIALS);
    write(dir, "one.sdf", "include two.sdf\n");
    write(dir, "two.sdf", "include one.sdf\n");
    let cases: &[(&str, &str)] = &[
        ("include\n", "1:8: error: `include` needs the file to read"),
        (
            "include missing.sdf\n",
            "1:9: error: cannot read `missing.sdf`",
        ),
        ("include folder\n", "1:9: error: `folder` is a folder"),
        (
            "include /etc/hostname\n",
            "1:9: error: `/etc/hostname` is outside the scene's folder and the current directory",
        ),
        (
            "include ../outside.sdf\n",
            "1:9: error: `../outside.sdf` is outside the scene's folder and the current directory",
        ),
        (
            "include one.sdf\n",
            "two.sdf:1:9: error: `one.sdf` is already being read",
        ),
        (
            "include a.sdf b.sdf\n",
            "1:15: error: `include` takes one file",
        ),
    ];
    for (text, expected) in cases {
        write(dir, "case.sdf", &format!("{MATERIALS}\n{text}"));
        let (code, err) = run_in(dir, &["check", "case.sdf"]);
        assert_ne!(code, 0, "{text}: {err}");
        let shifted = expected.replacen("1:", "4:", 1);
        let expected = if expected.starts_with("two.sdf") {
            expected.to_string()
        } else {
            format!("case.sdf:{shifted}")
        };
        assert!(
            err.contains(&expected),
            "{text}: wanted `{expected}` in\n{err}"
        );
    }
}

#[test]
fn includes_nest_at_most_the_limit() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let depth = anim_core::limits::MAX_INCLUDE_DEPTH;
    // File i includes file i + 1; the last holds a light. `depth` files nest; one more does not.
    for i in 0..=depth {
        let text = if i == depth {
            "ambient 0.5 0.5 0.5\n".to_string()
        } else {
            format!("include d{}.sdf\n", i + 1)
        };
        write(dir, &format!("d{i}.sdf"), &text);
    }
    let (code, err) = run_in(dir, &["check", "d1.sdf"]);
    assert_eq!(code, 0, "{depth} files nest: {err}");
    let (code, err) = run_in(dir, &["check", "d0.sdf"]);
    assert_ne!(code, 0);
    let last = depth - 1;
    assert!(
        err.contains(&format!(
            "d{last}.sdf:1:9: error: includes nest more than {depth} files deep"
        )),
        "{err}"
    );
}

#[test]
fn max_input_counts_a_file_and_everything_it_includes() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let big = format!("{MATERIALS}{SHAPES}{}", "# padding\n".repeat(40));
    write(dir, "static.sdfi", &big);
    let scene = format!("include static.sdfi\n{FRAME}");
    write(dir, "scene.sdf", &scene);
    let both = (big.len() + scene.len()).to_string();
    let less = (big.len() + scene.len() - 1).to_string();
    let (code, err) = run_in(dir, &["check", "scene.sdf", "--max-input", &both]);
    assert_eq!(code, 0, "{err}");
    let (code, err) = run_in(dir, &["check", "scene.sdf", "--max-input", &less]);
    assert_ne!(code, 0);
    assert!(err.contains("scene.sdf:1:9: error:"), "{err}");
    assert!(err.contains("--max-input"), "{err}");
}

#[test]
fn a_named_pipe_is_refused_without_waiting() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let made = std::process::Command::new("mkfifo")
        .arg(dir.join("pipe.sdfi"))
        .status()
        .is_ok_and(|s| s.success());
    if !made {
        return;
    }
    write(dir, "scene.sdf", &format!("include pipe.sdfi\n{FRAME}"));
    let (code, err) = run_in(dir, &["check", "scene.sdf"]);
    assert_ne!(code, 0);
    assert!(
        err.contains("scene.sdf:1:9: error: `pipe.sdfi` is not a regular file"),
        "{err}"
    );
}

#[test]
fn files_outside_the_scene_folder_are_read_from_inside_the_current_directory_or_with_the_flag() {
    let tmp = tempfile::tempdir().unwrap();
    let project = tmp.path();
    write(project, "shared/materials.sdf", MATERIALS);
    write(
        project,
        "shared/tri.obj",
        "v 0 0 -4\nv 1 0 -4\nv 0 1 -4\nf 1 2 3\n",
    );
    write(
        project,
        "scenes/scene.sdf",
        &format!(
            "include ../shared/materials.sdf\n{SHAPES}define shape obj mesh ../shared/tri.obj red\n{FRAME}"
        ),
    );
    // From the project: both files are inside the current directory.
    let (code, err) = run_in(project, &["check", "scenes/scene.sdf"]);
    assert_eq!(code, 0, "{err}");
    // From the scene's own folder: both are outside the scene's folder and the current one.
    let scenes = project.join("scenes");
    let (code, err) = run_in(&scenes, &["check", "scene.sdf"]);
    assert_ne!(code, 0);
    assert!(
        err.contains("scene.sdf:1:9: error: `../shared/materials.sdf` is outside"),
        "{err}"
    );
    let (code, err) = run_in(&scenes, &["check", "scene.sdf", "--allow-any-input"]);
    assert_eq!(code, 0, "{err}");
    // The mesh alone.
    write(
        project,
        "scenes/mesh.sdf",
        &format!("{MATERIALS}{SHAPES}define shape obj mesh ../shared/tri.obj red\n{FRAME}"),
    );
    let (code, err) = run_in(&scenes, &["check", "mesh.sdf"]);
    assert_ne!(code, 0);
    assert!(
        err.contains("mesh.sdf:6:1: error: mesh file `../shared/tri.obj` is outside"),
        "{err}"
    );
    assert!(
        !err.contains("v 0 0 -4"),
        "the file's content is quoted: {err}"
    );
}

/// `motion` lines in an included file may name the including file's shapes, as `transform`
/// lines may: the file renders as the one written whole. A name neither file defines is
/// still refused, at its line in the included file.
#[test]
fn motion_lines_of_an_included_file_name_the_including_files_shapes() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let motion = "motion ball 0 translate 0 0 0\nmotion ball 1 translate 0.8 0 0\n";
    write(
        dir,
        "whole.sdf",
        &format!("{MATERIALS}{SHAPES}{motion}{FRAME}"),
    );
    write(dir, "moves.sdfi", motion);
    write(
        dir,
        "parts.sdf",
        &format!("{MATERIALS}{SHAPES}include moves.sdfi\n{FRAME}"),
    );
    assert_eq!(render(dir, "parts.sdf", "b"), render(dir, "whole.sdf", "a"));
    write(dir, "typo.sdfi", "motion bal 0 translate 0 0 0\n");
    write(
        dir,
        "typo.sdf",
        &format!("{MATERIALS}{SHAPES}include typo.sdfi\n{FRAME}"),
    );
    let (code, err) = run_in(dir, &["check", "typo.sdf"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("typo.sdfi:1:8: error: motion of 'bal', which is not a shape"),
        "{err}"
    );
    assert!(err.contains("did you mean `ball`?"), "{err}");
}
