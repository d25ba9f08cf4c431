//! OBJ meshes (`define shape obj`) through the real binary: pixels derived from the formulas
//! of docs/shading.md for flat and smooth normals, meshes under transforms and in composites
//! drawn like the equivalent boxes, errors located in the OBJ file, and the bunny scene.

use crate::common;
use common::*;
use std::path::Path;

/// `Ka·I_a + I·(Kd·max(N·L,0) + Ks·max(R·V,0)^m)` for the material and the one unshadowed
/// light of [`HEAD`] (docs/shading.md §2).
fn phong(p: V, n: V, v: V) -> [u8; 3] {
    let [ka, kd, ks] = MATERIAL;
    let (light, intensity, m, ambient) = ([3.0, 4.0, 3.0], 1.5, 10.0, 0.5);
    let l = unit(sub(light, p));
    let n_dot_l = dot(n, l);
    let r = sub(n.map(|x| 2.0 * n_dot_l * x), l);
    std::array::from_fn(|ch| {
        let mut c = ka[ch] * ambient;
        if n_dot_l > 0.0 {
            c += intensity * (kd[ch] * n_dot_l + ks[ch] * dot(r, v).max(0.0).powf(m));
        }
        expected_u8(c)
    })
}

const MATERIAL: [[f64; 3]; 3] = [[0.1, 0.2, 0.3], [0.6, 0.5, 0.4], [0.3, 0.3, 0.3]];
const HEAD: &str = "\
define material m 0.1 0.2 0.3 0.6 0.5 0.4 0.3 0.3 0.3 10
define light sun 3 4 3 1 1 1 1.5
ambient 0.5 0.5 0.5
background 0 0 0
define camera eye 60
";

/// Writes the files, renders `scene.sdf` (which writes `image.ppm`) and reads the image.
fn render_with(files: &[(&str, &str)], scene: &str, args: &[&str]) -> Rgb8 {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    let out = render_in(dir.path(), "scene.sdf", scene, args);
    read_ppm(&out.join("image.ppm"))
}

/// A triangle in the plane z = −9 around the view axis; the centre ray meets it at (0,0,−9)
/// with barycentric weights (¼, ¼, ½).
const TRIANGLE: &str = "v -4 -4 -9\nv 4 -4 -9\nv 0 4 -9\n";

#[test]
fn flat_triangle_centre_is_the_phong_value() {
    let obj = format!("{TRIANGLE}f 1 2 3\n");
    let scene = format!("{HEAD}define shape obj tri tri.obj m\nrender eye image.ppm 11 11\n");
    let img = render_with(&[("tri.obj", &obj)], &scene, &["--spp", "1"]);
    let p = [0.0, 0.0, -9.0];
    let expected = phong(p, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]);
    assert_eq!(img.at(5, 5), expected);
}

#[test]
fn smooth_triangle_centre_uses_the_interpolated_normal() {
    // Vertex normals need not be unit length in the file; they are normalised, then weighed.
    let obj = format!("{TRIANGLE}vn 0 0 2\nvn 0 0 1\nvn 0 1 1\nf 1//1 2//2 3//3\n");
    let scene = format!("{HEAD}define shape obj tri tri.obj m\nrender eye image.ppm 11 11\n");
    let img = render_with(&[("tri.obj", &obj)], &scene, &["--spp", "1"]);
    let c = unit([0.0, 1.0, 1.0]);
    let n = unit([0.0, 0.5 * c[1], 0.25 + 0.25 + 0.5 * c[2]]);
    let p = [0.0, 0.0, -9.0];
    let expected = phong(p, n, [0.0, 0.0, 1.0]);
    let flat = phong(p, [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]);
    assert_ne!(
        expected, flat,
        "test geometry: the normals must make a difference"
    );
    assert_eq!(img.at(5, 5), expected);
}

/// The cube [−1, 1]³ as six quads, counter-clockwise seen from outside.
const CUBE: &str = "\
v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1
f 1 4 3 2\nf 5 6 7 8\nf 1 5 8 4\nf 2 3 7 6\nf 1 2 6 5\nf 4 8 7 3
";

/// Renders the same scene twice, once with `cube` an OBJ cube and once a box, and returns
/// (largest channel difference, differing pixels, lit pixels of the mesh image).
fn mesh_against_box(rest: &str) -> (u8, usize, usize) {
    let render = |shape: &str| {
        let scene = format!("{HEAD}{shape}\n{rest}render eye image.ppm 64 48\n");
        render_with(&[("cube.obj", CUBE)], &scene, &["--spp", "1"])
    };
    let mesh = render("define shape obj cube cube.obj m");
    let boxed = render("define shape box cube -1 -1 -1 1 1 1 m");
    let (max, differing) = compare(&mesh, &boxed);
    let lit = mesh.data.chunks(3).filter(|p| p != &[0, 0, 0]).count();
    (max, differing, lit)
}

#[test]
fn transformed_mesh_is_drawn_like_the_transformed_box() {
    // Non-uniform scale and a rotation: the mesh keeps its matrix (object-space path).
    let (max, differing, lit) = mesh_against_box(
        "transform cube scale 1.5 0.7 1\ntransform cube rotate 35 1 1 0\ntransform cube translate 0.5 0 -8\n",
    );
    assert!(
        lit > 300,
        "the cube covers the image centre: {lit} lit pixels"
    );
    // Only pixels whose ray grazes an edge may go either way.
    assert!(
        differing <= lit / 50,
        "{differing} of {lit} pixels differ (by up to {max})"
    );
}

#[test]
fn mesh_inside_a_composite_is_drawn_like_a_box_there() {
    let (max, differing, lit) = mesh_against_box(
        "define shape sphere ball 2.5 0 0 1 m\ndefine shape composite pair cube ball\n\
         transform pair rotate 30 0 1 0\ntransform pair scale 0.8\ntransform pair translate -1 0.3 -5\n",
    );
    assert!(lit > 300, "{lit} lit pixels");
    assert!(
        differing <= lit / 50,
        "{differing} of {lit} pixels differ (by up to {max})"
    );
}

/// Runs `anim check` on a scene that reads `mesh.obj` holding `obj`; returns stderr.
fn check_failure(obj: Option<&str>, shape_line: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    if let Some(obj) = obj {
        std::fs::write(dir.path().join("mesh.obj"), obj).unwrap();
    }
    let scene = dir.path().join("scene.sdf");
    std::fs::write(
        &scene,
        format!("{HEAD}{shape_line}\nrender eye image.ppm 8 8\n"),
    )
    .unwrap();
    let output = anim()
        .arg("render")
        .arg(&scene)
        .arg("--out")
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    assert_eq!(
        output.status.code(),
        Some(1),
        "an error, not a panic or success"
    );
    String::from_utf8_lossy(&output.stderr).into_owned()
}

fn assert_located(stderr: &str, place: &str, text: &str) {
    let line = stderr
        .lines()
        .find(|l| l.contains(place))
        .unwrap_or_else(|| panic!("no diagnostic at {place}:\n{stderr}"));
    assert!(line.contains("error") && line.contains(text), "{line}");
}

#[test]
fn errors_inside_the_obj_point_at_its_own_line() {
    let shape = "define shape obj thing mesh.obj m";
    let cases: &[(&str, &str, &str)] = &[
        (
            "v 0 0 0\nv 1 0 0\n# a comment\nf 1 2 7\n",
            "mesh.obj:4:7:",
            "vertex 7",
        ),
        (
            "v 0 0 0\nv 1 NaN 0\nv 0 1 0\nf 1 2 3\n",
            "mesh.obj:2:5:",
            "not a finite number",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 zero\nf 1 2 3\n",
            "mesh.obj:3:7:",
            "expected the vertex's z coordinate (a number), found 'zero'",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5\nf 1 2 3\n",
            "mesh.obj:4:7:",
            "expected the texture coordinate v (a number), found end of line",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 up 1\nf 1 2 3\n",
            "mesh.obj:4:6:",
            "expected the normal's y component (a number), found 'up'",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n",
            "mesh.obj:4:7:",
            "count from 1",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 -4 3\n",
            "mesh.obj:4:5:",
            "relative",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3/1/1/1\n",
            "mesh.obj:4:7:",
            "v/vt/vn",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\n",
            "mesh.obj:5:16:",
            "normal 2",
        ),
    ];
    for (obj, place, text) in cases {
        let stderr = check_failure(Some(obj), shape);
        assert_located(&stderr, place, text);
    }
}

#[test]
fn whole_file_problems_point_at_the_statement() {
    let shape = "define shape obj thing mesh.obj m";
    let stderr = check_failure(None, shape);
    assert_located(&stderr, "scene.sdf:6:1:", "`mesh.obj` cannot be read");
    let stderr = check_failure(Some("v 0 0 0\nv 1 0 0\nl 1 2\n"), shape);
    assert_located(&stderr, "scene.sdf:6:1:", "holds no triangles");
    let stderr = check_failure(Some("v 0 0 0\n"), "define shape obj thing mesh.obj m extra");
    assert_located(&stderr, "scene.sdf:6:", "found 4 words");
}

#[test]
fn the_short_form_of_other_renderers_is_skipped_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let scene = format!("{HEAD}define shape obj superhot\nrender eye image.ppm 8 8\n");
    let out = render_in(dir.path(), "scene.sdf", &scene, &["--spp", "1"]);
    assert!(out.join("image.ppm").exists());
}

#[test]
fn the_bunny_scene_renders_a_bunny() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    anim()
        .arg("render")
        .arg(root.join("scenes/bunny.sdf"))
        .arg("--out")
        .arg(dir.path())
        .args(["--width", "96", "--height", "64", "--spp", "1", "--quiet"])
        .assert()
        .success();
    let img = image::open(dir.path().join("bunny.png")).unwrap().to_rgb8();
    // The bunny's clay colour is red over blue; the floor and sky are not.
    let clay = img
        .pixels()
        .filter(|p| p[0] as u32 > p[2] as u32 + 20)
        .count();
    let total = (img.width() * img.height()) as usize;
    assert!(clay > total / 20, "{clay} of {total} pixels show the bunny");
}
