//! Image tests: pixels compared with values derived here from the formulas of docs/shading.md, and
//! transform equivalences, all through the real binary.

use crate::common;
use common::*;

const SPHERE_SCENE: &str = "\
define material m 0.1 0.2 0.3 0.5 0.4 0.3 0.3 0.3 0.3 10
define material floor 0.2 0.3 0.44 0.6 0.6 0.6 0 0 0 1
define shape sphere ball 0 0 -10 2 m
define shape box ground -50 -4 -60 50 -3 5 floor
define light sun 0 20 -10 1 1 1 2
define light side 10 10 0 1 0.5 0.25 1.5
ambient 0.5 0.5 0.5
background 0.25 0.4 0.6
define camera eye 60
render eye image.ppm 101 101
";

#[test]
fn centre_pixel_is_the_phong_value() {
    let img = render_ppm(SPHERE_SCENE, &["--spp", "1"]);
    // The centre ray (pixel 50 of 101: through the exact image centre) meets the sphere at
    // (0,0,-8) with N = V = +z.
    let p = [0.0, 0.0, -8.0];
    let n = [0.0, 0.0, 1.0];
    let v = n;
    let (ka, kd, ks, m) = ([0.1, 0.2, 0.3], [0.5, 0.4, 0.3], [0.3, 0.3, 0.3], 10.0);
    let lights: [(V, V); 2] = [
        ([0.0, 20.0, -10.0], [2.0, 2.0, 2.0]),
        ([10.0, 10.0, 0.0], [1.5, 0.75, 0.375]),
    ];
    let mut expected = [0u8; 3];
    for ch in 0..3 {
        let mut c = ka[ch] * 0.5;
        for (pos, intensity) in lights {
            let l = unit(sub(pos, p));
            let n_dot_l = dot(n, l);
            if n_dot_l > 0.0 {
                // R = reflect(−L, N) = 2(N·L)N − L
                let r = sub(
                    [
                        2.0 * n_dot_l * n[0],
                        2.0 * n_dot_l * n[1],
                        2.0 * n_dot_l * n[2],
                    ],
                    l,
                );
                c += intensity[ch] * (kd[ch] * n_dot_l + ks[ch] * dot(r, v).max(0.0).powf(m));
            }
        }
        expected[ch] = expected_u8(c);
    }
    assert_eq!(img.at(50, 50), expected);
}

#[test]
fn shadowed_point_is_ambient_only_and_background_is_background() {
    let img = render_ppm(SPHERE_SCENE, &["--spp", "1"]);
    // Row 72 looks down at the ground just behind the ball, inside the shadow cast by the
    // light straight above it; the second light is hidden from there too (derived below).
    let dist = 50.5 / (30f64.to_radians()).tan();
    let dir = unit([0.0, -(72.5 - 50.5), -dist]);
    let t = -3.0 / dir[1];
    let hit = [0.0, -3.0, dir[2] * t];
    // Both light paths pass within the ball's radius of its centre: the point is in shadow.
    for light in [[0.0, 20.0, -10.0], [10.0, 10.0, 0.0]] {
        let d = unit(sub(light, hit));
        let to_centre = sub([0.0, 0.0, -10.0], hit);
        let along = dot(to_centre, d);
        let closest = (dot(to_centre, to_centre) - along * along).sqrt();
        assert!(
            along > 0.0 && closest < 2.0,
            "test geometry: {light:?} is not occluded"
        );
    }
    let ambient_only = [0.2 * 0.5, 0.3 * 0.5, 0.44 * 0.5].map(expected_u8);
    assert_eq!(img.at(50, 72), ambient_only);
    let background = [0.25, 0.4, 0.6].map(expected_u8);
    assert_eq!(img.at(0, 0), background);
    assert_eq!(img.at(100, 0), background);
}

#[test]
fn threads_do_not_change_a_single_byte() {
    let dir = tempfile::tempdir().unwrap();
    let a = render_in(
        dir.path(),
        "a.sdf",
        SPHERE_SCENE,
        &["--threads", "1", "--spp", "4"],
    );
    let first = std::fs::read(a.join("image.ppm")).unwrap();
    let b = render_in(
        dir.path(),
        "a.sdf",
        SPHERE_SCENE,
        &["--threads", "2", "--spp", "4"],
    );
    let second = std::fs::read(b.join("image.ppm")).unwrap();
    assert!(first == second, "--threads 1 and --threads 2 differ");
}

const LIT: &str = "\
define material m 0.2 0.2 0.2 0.7 0.5 0.3 0.4 0.4 0.4 20
define light l 5 8 5 1 1 1 1.5
ambient 0.3 0.3 0.3
define camera eye 50
";

#[test]
fn translated_and_scaled_box_equals_the_box_written_in_place() {
    let moved = format!(
        "{LIT}define shape box b 0 0 0 1 1 1 m\ntransform b scale 2 3 1\ntransform b translate -1 -1.5 -8\nrender eye image.ppm 80 60\n"
    );
    let direct =
        format!("{LIT}define shape box b -1 -1.5 -8 1 1.5 -7 m\nrender eye image.ppm 80 60\n");
    let (max, _) = compare(
        &render_ppm(&moved, &["--spp", "1"]),
        &render_ppm(&direct, &["--spp", "1"]),
    );
    assert_eq!(max, 0);
}

#[test]
fn rotated_box_equals_the_box_with_swapped_extents() {
    // A quarter turn about z maps [0,2]×[0,1] to [−1,0]×[0,2]; this one goes through the
    // object-space (matrix) path, so allow one LSB on a few pixels.
    let moved = format!(
        "{LIT}define shape box b 0 0 -1 2 1 0 m\ntransform b rotate 90 0 0 1\ntransform b translate 0 -1 -6\nrender eye image.ppm 80 60\n"
    );
    let direct = format!("{LIT}define shape box b -1 -1 -7 0 1 -6 m\nrender eye image.ppm 80 60\n");
    let (max, differing) = compare(
        &render_ppm(&moved, &["--spp", "1"]),
        &render_ppm(&direct, &["--spp", "1"]),
    );
    assert!(
        max <= 1 && differing < 80 * 60 / 100,
        "max {max}, {differing} pixels differ"
    );
}

#[test]
fn non_uniformly_scaled_sphere_has_the_ellipsoid_silhouette() {
    let sdf = format!(
        "{LIT}background 0 0 0\ndefine shape sphere s 0 0 0 1 m\ntransform s scale 3 1.5 1\ntransform s translate 0.5 0 -10\nrender eye image.ppm 120 90\n"
    );
    let img = render_ppm(&sdf, &["--spp", "1"]);
    let dist = 60.0 / (25f64.to_radians()).tan();
    let mut checked = 0;
    for y in 0..90 {
        for x in 0..120 {
            let d = unit([x as f64 + 0.5 - 60.0, 45.0 - (y as f64 + 0.5), -dist]);
            // Ray in the ellipsoid's unit-sphere space: o' = (−0.5/3, 0, 10), d' = d / (3,1.5,1).
            let o = [-0.5 / 3.0, 0.0, 10.0];
            let dd = [d[0] / 3.0, d[1] / 1.5, d[2]];
            let a = dot(dd, dd);
            let b = dot(o, dd);
            let c = dot(o, o) - 1.0;
            let disc = b * b - a * c;
            if disc.abs() < 1e-3 {
                continue; // on the silhouette itself
            }
            let lit = img.at(x, y) != [0, 0, 0];
            assert_eq!(lit, disc > 0.0, "pixel ({x},{y}) disc {disc}");
            checked += 1;
        }
    }
    assert!(checked > 120 * 90 * 9 / 10);
}

#[test]
fn transform_on_a_composite_equals_it_on_each_child() {
    let shapes = "define shape sphere s 0 0 0 1 m\ndefine shape box b 1 -1 -1 2 0 1 m\n";
    let ops = ["rotate 30 0 1 1", "scale 1 2 1", "translate 0 0 -8"];
    let on_composite = format!(
        "{LIT}{shapes}define shape composite root s b\n{}render eye image.ppm 80 60\n",
        ops.iter()
            .map(|o| format!("transform root {o}\n"))
            .collect::<String>()
    );
    let on_children = format!(
        "{LIT}{shapes}{}render eye image.ppm 80 60\n",
        ops.iter()
            .map(|o| format!("transform s {o}\ntransform b {o}\n"))
            .collect::<String>()
    );
    let (max, differing) = compare(
        &render_ppm(&on_composite, &["--spp", "1"]),
        &render_ppm(&on_children, &["--spp", "1"]),
    );
    assert!(
        max <= 1 && differing < 20,
        "max {max}, {differing} pixels differ"
    );
}

#[test]
fn local_transform_order_composes_the_other_way() {
    // world: scale then translate = T·S: the unit sphere is centred at (0,0,-10).
    // local: M ← M·T, so translate is applied first, then scaled: centre at (0,0,-20).
    let sdf = format!(
        "{LIT}define shape sphere s 0 0 0 1 m\ntransform s scale 2\ntransform s translate 0 0 -10\nrender eye image.ppm 80 60\n"
    );
    let world = render_ppm(&sdf, &["--spp", "1"]);
    let local = render_ppm(&sdf, &["--spp", "1", "--transform-order", "local"]);
    let direct_world = render_ppm(
        &format!("{LIT}define shape sphere s 0 0 -10 2 m\nrender eye image.ppm 80 60\n"),
        &["--spp", "1"],
    );
    let direct_local = render_ppm(
        &format!("{LIT}define shape sphere s 0 0 -20 2 m\nrender eye image.ppm 80 60\n"),
        &["--spp", "1"],
    );
    assert!(compare(&world, &direct_world).0 <= 1);
    assert!(compare(&local, &direct_local).0 <= 1);
    assert!(
        compare(&world, &local).1 > 100,
        "the two orders must give different images"
    );
}

/// Centre of mass of the non-background pixels.
fn centroid(img: &Rgb8) -> (f64, f64) {
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
    for y in 0..img.height {
        for x in 0..img.width {
            if img.at(x, y) != [0, 0, 0] {
                sx += x as f64 + 0.5;
                sy += y as f64 + 0.5;
                n += 1.0;
            }
        }
    }
    assert!(n > 0.0, "nothing visible");
    (sx / n, sy / n)
}

#[test]
fn camera_and_object_directions() {
    let base = "define material m 1 1 1 0 0 0 0 0 0 1\nambient 1 1 1\ndefine camera eye 60\n";
    let at = |pos: &str, cam_ops: &str| {
        render_ppm(
            &format!(
                "{base}define shape sphere s {pos} 1 m\n{cam_ops}render eye image.ppm 64 48\n"
            ),
            &["--spp", "1"],
        )
    };
    let (x, y) = centroid(&at("4 0 -10", ""));
    assert!(
        x > 40.0 && (y - 24.0).abs() < 0.5,
        "+x is right of centre: {x},{y}"
    );
    let (x, y) = centroid(&at("0 4 -10", ""));
    assert!(
        y < 12.0 && (x - 32.0).abs() < 0.5,
        "+y is above centre: {x},{y}"
    );
    // Turning the camera 90° about +y makes it look along −x.
    let (x, y) = centroid(&at("-10 0 0", "transform eye rotate 90 0 1 0\n"));
    assert!(
        (x - 32.0).abs() < 0.5 && (y - 24.0).abs() < 0.5,
        "rotated view: {x},{y}"
    );
    // Moving the camera right moves the object left in the picture.
    let (x, _) = centroid(&at("0 0 -10", "transform eye translate 3 0 0\n"));
    assert!(x < 20.0, "translated view: {x}");
    // eye/dir/up form: looking along +x from the origin with z up.
    let img = render_ppm(
        &format!("{base}define shape sphere s 10 0 3 1 m\ndefine camera side 60 0 0 0 1 0 0 0 0 1\nrender side image.ppm 64 48\n"),
        &["--spp", "1"],
    );
    let (x, y) = centroid(&img);
    assert!(
        (x - 32.0).abs() < 0.5 && y < 20.0,
        "up vector respected: {x},{y}"
    );
}

#[test]
fn a_shape_lost_to_f32_underflow_is_reported_not_silently_dropped() {
    // Each factor is acceptable on its own, but together they scale the radius to 1e-48,
    // below the smallest f32: the renderer cannot place the sphere and must say so.
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.sdf");
    let scales = "transform tiny scale 1e-8\n".repeat(6);
    std::fs::write(
        &scene,
        format!("define material m 1 1 1 1 1 1 0 0 0 1\ndefine shape sphere tiny 0 0 0 1 m\n{scales}define camera c 60\nrender c x.png 8 8\n"),
    )
    .unwrap();
    let out = anim()
        .arg("render")
        .arg(&scene)
        .arg("--out")
        .arg(dir.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("scene.sdf:2:1: warning: shape 'tiny' is degenerate once transformed"),
        "{stderr}"
    );
}
