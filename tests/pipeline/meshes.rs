//! The meshes generated frames name: found beside the file whose line names them, copied into
//! the frame folder when they lie outside it (so `anim render DIR` draws the frames from any
//! current directory), never over a file of the user's, and left alone when unchanged.

use super::frames::triangle_obj;
use crate::common::{anim, run_in};
use std::path::Path;
use std::time::{Duration, SystemTime};

/// A base scene beside its mesh, and a spec in another folder that animates it, in `root`.
fn mesh_project(root: &Path) {
    let scenes = root.join("scenes/meshes");
    std::fs::create_dir_all(&scenes).expect("mkdir");
    std::fs::write(scenes.join("tri.obj"), triangle_obj(2.0)).expect("obj");
    std::fs::write(
        root.join("scenes/base.sdf"),
        "define material white 0.2 0.2 0.2 0.8 0.8 0.8 0 0 0 1\n\
         define shape obj tri meshes/tri.obj white\n\
         define light sun 0 0 10 1 1 1 1\n\
         define camera cam 60\n",
    )
    .expect("base");
    std::fs::create_dir_all(root.join("specs")).expect("mkdir");
    std::fs::write(
        root.join("specs/spin.ron"),
        "(scene: File(\"../scenes/base.sdf\"), camera: \"cam\", length: Frames(2), \
         resolution: (16, 12),\n tracks: [(target: \"tri\", rotate: [(at: 0, value: 0), (at: 0.05, value: 10)])])",
    )
    .expect("spec");
}

/// `anim ARGS` run in `cwd`; its stderr, after checking that it succeeded.
fn run_ok(cwd: &Path, args: &[&Path]) -> String {
    let args: Vec<&str> = args
        .iter()
        .map(|a| a.to_str().expect("a UTF-8 path"))
        .collect();
    let (code, said) = run_in(cwd, &args);
    assert_eq!(code, 0, "{args:?}: {said}");
    said
}

fn generate(cwd: &Path, spec: &Path, out: &Path) -> String {
    run_ok(cwd, &[Path::new("generate"), spec, Path::new("-o"), out])
}

fn read(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn modified(path: &Path) -> SystemTime {
    std::fs::metadata(path)
        .and_then(|m| m.modified())
        .expect("mtime")
}

#[test]
fn frames_from_a_project_render_alike_from_any_current_directory() {
    let project = tempfile::tempdir().expect("tempdir");
    mesh_project(project.path());
    let elsewhere = tempfile::tempdir().expect("tempdir");
    let spec = project.path().join("specs/spin.ron");
    // The same frames twice: rendered from the project, and from a folder that holds neither
    // the frames nor the mesh (the frame folder is then the only place they may read from).
    let (here, there) = (
        project.path().join("f"),
        elsewhere.path().join("out/frames"),
    );
    generate(project.path(), &spec, &here);
    generate(elsewhere.path(), &spec, &there);
    for dir in [&here, &there] {
        let frame = String::from_utf8(read(&dir.join("frame_0000.sdf"))).expect("text");
        assert!(frame.contains(" meshes/tri.obj "), "{frame}");
        let source = read(&project.path().join("scenes/meshes/tri.obj"));
        assert_eq!(read(&dir.join("meshes/tri.obj")), source);
        let listed = String::from_utf8(read(&dir.join(".anim-generated"))).expect("text");
        assert!(listed.lines().any(|l| l == "meshes/tri.obj"), "{listed}");
    }
    run_ok(project.path(), &[Path::new("render"), &here]);
    run_ok(elsewhere.path(), &[Path::new("render"), &there]);
    for frame in ["frame_0000.png", "frame_0001.png"] {
        assert_eq!(read(&here.join(frame)), read(&there.join(frame)), "{frame}");
    }
    // The triangle covers the image centre: lit, not background black.
    let img = image::open(there.join("frame_0000.png"))
        .expect("image")
        .to_rgb8();
    assert!(img.get_pixel(8, 6).0[0] > 100, "{:?}", img.get_pixel(8, 6));
}

#[test]
fn a_mesh_named_in_an_included_file_is_found_beside_that_file() {
    // The base scene and a part it includes from a sibling folder each name a `tri.obj`
    // beside themselves: two different files, whose copies take two names.
    let project = tempfile::tempdir().expect("tempdir");
    let root = project.path();
    for dir in ["scenes", "parts"] {
        std::fs::create_dir_all(root.join(dir)).expect("mkdir");
    }
    std::fs::write(root.join("scenes/tri.obj"), triangle_obj(0.5)).expect("obj");
    std::fs::write(root.join("parts/tri.obj"), triangle_obj(2.0)).expect("obj");
    std::fs::write(
        root.join("parts/part.sdfi"),
        "define shape obj big tri.obj white\n",
    )
    .expect("part");
    std::fs::write(
        root.join("scenes/base.sdf"),
        "define material white 0.2 0.2 0.2 0.8 0.8 0.8 0 0 0 1\n\
         define shape obj small tri.obj white\n\
         include ../parts/part.sdfi\n\
         define light sun 0 0 10 1 1 1 1\n\
         define camera cam 60\n",
    )
    .expect("base");
    std::fs::write(
        root.join("spin.ron"),
        "(scene: File(\"scenes/base.sdf\"), camera: \"cam\", length: Frames(2), \
         resolution: (16, 12),\n tracks: [(target: \"small\", translate: [(at: 0, value: (0, 0, 0)), (at: 0.05, value: (0.1, 0, 0))])])",
    )
    .expect("spec");
    let out = root.join("frames");
    // Generated from the project, which the include's `..` climbs into.
    generate(root, &root.join("spin.ron"), &out);
    assert_eq!(
        read(&out.join("meshes/tri.obj")),
        read(&root.join("scenes/tri.obj"))
    );
    assert_eq!(
        read(&out.join("meshes/tri-2.obj")),
        read(&root.join("parts/tri.obj"))
    );
    let elsewhere = tempfile::tempdir().expect("tempdir");
    run_ok(elsewhere.path(), &[Path::new("render"), &out]);
    // The big triangle (the part's own mesh) reaches a corner the small one does not.
    let img = image::open(out.join("frame_0000.png"))
        .expect("image")
        .to_rgb8();
    assert!(img.get_pixel(6, 8).0[0] > 100, "{:?}", img.get_pixel(6, 8));
}

#[test]
fn a_file_of_the_users_where_a_copy_would_go_is_kept_and_the_copy_named_apart() {
    let project = tempfile::tempdir().expect("tempdir");
    mesh_project(project.path());
    let out = project.path().join("frames");
    std::fs::create_dir_all(out.join("meshes")).expect("mkdir");
    std::fs::write(out.join("meshes/tri.obj"), b"the user's own").expect("write");
    generate(project.path(), &project.path().join("specs/spin.ron"), &out);
    assert_eq!(read(&out.join("meshes/tri.obj")), b"the user's own");
    let frame = String::from_utf8(read(&out.join("frame_0000.sdf"))).expect("text");
    assert!(frame.contains(" meshes/tri-2.obj "), "{frame}");
    let source = read(&project.path().join("scenes/meshes/tri.obj"));
    assert_eq!(read(&out.join("meshes/tri-2.obj")), source);
    let listed = String::from_utf8(read(&out.join(".anim-generated"))).expect("text");
    assert!(!listed.lines().any(|l| l == "meshes/tri.obj"), "{listed}");
}

#[test]
fn a_copy_is_rewritten_only_when_the_mesh_changes_and_removed_when_no_frame_names_it() {
    let project = tempfile::tempdir().expect("tempdir");
    mesh_project(project.path());
    let (spec, out) = (
        project.path().join("specs/spin.ron"),
        project.path().join("frames"),
    );
    let copy = out.join("meshes/tri.obj");
    generate(project.path(), &spec, &out);
    // An old time, which any write would replace.
    let old = SystemTime::UNIX_EPOCH + Duration::from_secs(1_000_000_000);
    let set_old = || {
        std::fs::File::options()
            .write(true)
            .open(&copy)
            .and_then(|f| f.set_modified(old))
            .expect("set the time")
    };
    set_old();
    generate(project.path(), &spec, &out);
    assert_eq!(
        modified(&copy),
        old,
        "an unchanged mesh's copy was rewritten"
    );
    // The same length, other bytes: the copy follows.
    let mesh = project.path().join("scenes/meshes/tri.obj");
    std::fs::write(&mesh, triangle_obj(3.0)).expect("write");
    assert_eq!(triangle_obj(3.0).len(), triangle_obj(2.0).len());
    generate(project.path(), &spec, &out);
    assert_eq!(read(&copy), read(&mesh));
    assert_ne!(modified(&copy), old);
    // No mesh any more: the copy and its folder go with it.
    let base = project.path().join("scenes/base.sdf");
    let text = String::from_utf8(read(&base)).expect("text");
    let sphere = "define shape sphere tri 0 0 -5 1 white";
    std::fs::write(
        &base,
        text.replace("define shape obj tri meshes/tri.obj white", sphere),
    )
    .expect("write");
    generate(project.path(), &spec, &out);
    assert!(!out.join("meshes").exists());
    assert!(out.join("frame_0001.sdf").exists());
}

#[test]
fn a_mesh_path_the_frames_cannot_spell_is_an_error_that_leaves_nothing() {
    // The mesh lies inside the frame folder, where it is named by its path, which passes
    // through a folder whose name has a space: an SDF file name cannot hold that.
    let dir = tempfile::tempdir().expect("tempdir");
    let project = dir.path().join("two words");
    mesh_project(&project);
    let done = anim()
        .arg("generate")
        .arg(project.join("specs/spin.ron"))
        .arg("-o")
        .arg(dir.path())
        .output()
        .expect("run");
    assert!(!done.status.success());
    let said = String::from_utf8_lossy(&done.stderr);
    assert!(
        said.contains("the mesh file `meshes/tri.obj` cannot be named from the frame directory"),
        "{said}"
    );
    assert!(said.contains("spin.ron:1:"), "{said}");
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .expect("dir")
        .map(|e| e.expect("entry").file_name())
        .collect();
    assert_eq!(left, ["two words"]);
}
