//! Image formats and alpha, through the binary, read back by independent readers (ffmpeg for
//! OpenEXR, the `image` crate for PNG and TGA): OpenEXR holds the radiance of the PFM, a
//! 16-bit PNG is the 8-bit image with more levels, and `--alpha` is each pixel's coverage,
//! worked out here from the geometry of the camera and the sphere.

use crate::common::hdr::read_pfm;
use crate::common::media::{decode, ffmpeg_for, planar_floats, stream_field};
use crate::common::{expected_u8, run_in};
use std::path::Path;

/// A sphere of one flat colour (ambient only: radiance Ka·ambient, the same at every point)
/// before a coloured background, seen by the default camera (at the origin, looking down −z,
/// 60° across).
const FLAT_SPHERE: &str = "\
define material flat 0.6 0.3 0.9 0 0 0 0 0 0 1
define shape sphere ball 0 0 -10 2 flat
define light l 5 5 5 1 1 1
ambient 1 1 1
background 0.8 0.7 0.1
define camera eye 60
render eye NAME 64 48
";

/// A lit sphere over a floor: radiance that varies, above 1 in the highlight.
const LIT_SPHERE: &str = "\
define material m 0.1 0.2 0.3 0.5 0.4 0.3 0.9 0.9 0.9 10
define material floor 0.2 0.3 0.44 0.6 0.6 0.6 0 0 0 1
define shape sphere ball 0 0 -10 2 m
define shape box ground -50 -4 -60 50 -3 5 floor
define light sun 0 20 -10 3 3 3
ambient 0.5 0.5 0.5
background 0.25 0.4 0.6
define camera eye 60
render eye NAME 64 48
";

const W: usize = 64;
const H: usize = 48;
/// The flat sphere's radiance.
const FLAT: [f64; 3] = [0.6, 0.3, 0.9];

/// Renders `scene` (its `NAME` replaced by `name`) in `dir` with `args`; the exit code and
/// stderr.
fn render(dir: &Path, scene: &str, name: &str, args: &[&str]) -> (i32, String) {
    std::fs::write(dir.join("scene.sdf"), scene.replace("NAME", name)).unwrap();
    run_in(dir, &[&["render", "scene.sdf", "-q"], args].concat())
}

fn rendered(dir: &Path, scene: &str, name: &str, args: &[&str]) {
    let (code, stderr) = render(dir, scene, name, args);
    assert_eq!(code, 0, "{name} {args:?}: {stderr}");
}

/// How many of the rays through pixel (x, y) at the points of a k×k grid meet the sphere of
/// radius 2 at (0, 0, −10), by the ray's distance from its centre; `None` when a ray passes
/// so close to the silhouette that the renderer's f32 may see it either way.
fn grid_hits(x: usize, y: usize, k: usize) -> Option<usize> {
    let dist = (W as f64 / 2.0) / 30f64.to_radians().tan();
    let mut hits = 0;
    for s in 0..k * k {
        let (dx, dy) = (
            ((s % k) as f64 + 0.5) / k as f64,
            ((s / k) as f64 + 0.5) / k as f64,
        );
        let d = [
            x as f64 + dx - W as f64 / 2.0,
            H as f64 / 2.0 - (y as f64 + dy),
            -dist,
        ];
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        // The centre's distance from the ray: |c × d| / |d| for c = (0, 0, −10).
        let cross = 10.0 * (d[0] * d[0] + d[1] * d[1]).sqrt() / len;
        if (cross - 2.0).abs() < 1e-4 {
            return None;
        }
        hits += usize::from(cross < 2.0);
    }
    Some(hits)
}

fn rgba(path: &Path) -> image::RgbaImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgba8()
}

#[test]
fn exr_holds_the_radiance_of_the_pfm_in_half_and_float() {
    if !ffmpeg_for("exr_holds_the_radiance_of_the_pfm_in_half_and_float") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for (depth, tolerance) in [("16", 1e-3), ("32", 0.0)] {
        rendered(
            dir.path(),
            LIT_SPHERE,
            "frame.exr",
            &["--hdr", "--depth", depth],
        );
        let exr = dir.path().join("frame.exr");
        assert_eq!(stream_field(&exr, "codec_name"), "exr");
        let pfm = read_pfm(&dir.path().join("frame.pfm"));
        let decoded = planar_floats(&decode(&exr, "gbrpf32le"), W * H, 3);
        let mut highest = 0.0f32;
        for (i, (exr, pfm)) in decoded.iter().zip(&pfm.pixels).enumerate() {
            for c in 0..3 {
                // Half floats keep 11 significant bits where they are normal (above 2^-14).
                assert!(pfm[c] == 0.0 || pfm[c] > 2f32.powi(-14), "{}", pfm[c]);
                let error = (exr[c] - pfm[c]).abs();
                assert!(
                    error <= tolerance * pfm[c],
                    "--depth {depth}, pixel {i}, channel {c}: {} against {}",
                    exr[c],
                    pfm[c]
                );
                highest = highest.max(pfm[c]);
            }
        }
        assert!(highest > 1.0, "the highlight is brighter than 8 bits hold");
    }
}

#[test]
fn a_16_bit_png_is_the_8_bit_image_with_more_levels_or_linear() {
    let dir = tempfile::tempdir().unwrap();
    rendered(dir.path(), LIT_SPHERE, "eight.png", &["--hdr"]);
    rendered(dir.path(), LIT_SPHERE, "deep.png", &["--depth", "16"]);
    rendered(
        dir.path(),
        LIT_SPHERE,
        "linear.png",
        &["--depth", "16", "--linear"],
    );
    let eight = rgba(&dir.path().join("eight.png"));
    for name in ["deep.png", "linear.png"] {
        let bytes = std::fs::read(dir.path().join(name)).unwrap();
        // IHDR's bit depth (byte 24) and colour type (25: 2 is RGB).
        assert_eq!((bytes[24], bytes[25]), (16, 2), "{name}");
        let linear_mark = &bytes[33 + 4..33 + 12] == b"gAMA\x00\x01\x86\xa0";
        assert_eq!(linear_mark, name == "linear.png", "{name}'s gAMA chunk");
    }
    let deep = image::open(dir.path().join("deep.png")).unwrap().to_rgb16();
    let mut same = 0;
    for (d, e) in deep.pixels().zip(eight.pixels()) {
        for c in 0..3 {
            let scaled = f64::from(d.0[c]) / 257.0;
            assert!((scaled - f64::from(e.0[c])).abs() <= 1.0, "{d:?} {e:?}");
            same += usize::from(scaled.round() as u8 == e.0[c]);
        }
    }
    assert_eq!(
        same,
        W * H * 3,
        "rounded to 8 bits, every level is the 8-bit one"
    );
    let pfm = read_pfm(&dir.path().join("eight.pfm"));
    let linear = image::open(dir.path().join("linear.png"))
        .unwrap()
        .to_rgb16();
    for (l, p) in linear.pixels().zip(&pfm.pixels) {
        for c in 0..3 {
            let expected = (65535.0 * f64::from(p[c]).clamp(0.0, 1.0)).round();
            assert!((f64::from(l.0[c]) - expected).abs() <= 1.0, "{l:?} {p:?}");
        }
    }
}

/// With `--spp 16` (a 4×4 grid in each pixel) the alpha of every pixel is the share of its
/// 16 rays that meet the sphere, and its colour is the sphere's own: the background is not in
/// it, however little of the pixel the sphere covers.
#[test]
fn alpha_is_the_share_of_a_pixel_the_sphere_covers_and_leaves_the_background_out() {
    let dir = tempfile::tempdir().unwrap();
    rendered(
        dir.path(),
        FLAT_SPHERE,
        "ball.png",
        &["--alpha", "--spp", "16"],
    );
    let png = rgba(&dir.path().join("ball.png"));
    let colour = FLAT.map(expected_u8);
    let mut partial = 0;
    for (x, y, p) in png.enumerate_pixels() {
        let Some(hits) = grid_hits(x as usize, y as usize, 4) else {
            continue;
        };
        let alpha = (255.0 * hits as f64 / 16.0).round() as u8;
        assert_eq!(p.0[3], alpha, "alpha of pixel ({x}, {y})");
        let expected = if hits == 0 { [0; 3] } else { colour };
        assert_eq!(
            p.0[..3],
            expected,
            "colour of pixel ({x}, {y}), {hits} of 16 covered"
        );
        partial += usize::from(hits > 0 && hits < 16);
    }
    assert!(partial > 20, "{partial} edge pixels");
    // TGA holds the same straight RGBA.
    rendered(
        dir.path(),
        FLAT_SPHERE,
        "ball.tga",
        &["--alpha", "--spp", "16"],
    );
    assert_eq!(rgba(&dir.path().join("ball.tga")), png);
}

/// Adaptive sampling (the default): background pixels have alpha 0, pixels well inside the
/// sphere 255, and the pixels its edge crosses something in between.
#[test]
fn adaptive_alpha_is_0_outside_255_inside_and_between_on_the_edge() {
    let dir = tempfile::tempdir().unwrap();
    rendered(
        dir.path(),
        LIT_SPHERE.replace("define shape box", "# no").as_str(),
        "ball.png",
        &["--alpha"],
    );
    let png = rgba(&dir.path().join("ball.png"));
    let (mut inside, mut outside, mut edge) = (0, 0, 0);
    for (x, y, p) in png.enumerate_pixels() {
        // The share of the pixel the sphere covers, from a fine 16×16 grid.
        let Some(hits) = grid_hits(x as usize, y as usize, 16) else {
            continue;
        };
        let share = hits as f64 / 256.0;
        let a = p.0[3];
        match share {
            0.0 => {
                assert_eq!(a, 0, "background pixel ({x}, {y})");
                outside += 1;
            }
            1.0 => {
                assert_eq!(a, 255, "inside pixel ({x}, {y})");
                inside += 1;
            }
            s if (0.1..=0.9).contains(&s) => {
                assert!(
                    0 < a && a < 255,
                    "edge pixel ({x}, {y}): {s} covered, alpha {a}"
                );
                edge += 1;
            }
            _ => {}
        }
    }
    assert!(
        inside > 100 && outside > 1000 && edge > 20,
        "{inside} {outside} {edge}"
    );
}

/// OpenEXR's alpha is premultiplied: red, green and blue are the sphere's radiance times the
/// coverage, and the background is not in them.
#[test]
fn exr_alpha_is_premultiplied() {
    if !ffmpeg_for("exr_alpha_is_premultiplied") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    rendered(
        dir.path(),
        FLAT_SPHERE,
        "ball.exr",
        &["--alpha", "--spp", "16", "--depth", "32"],
    );
    let exr = dir.path().join("ball.exr");
    assert_eq!(stream_field(&exr, "pix_fmt"), "gbrapf32le");
    let pixels = planar_floats(&decode(&exr, "gbrapf32le"), W * H, 4);
    for (i, p) in pixels.iter().enumerate() {
        let Some(hits) = grid_hits(i % W, i / W, 4) else {
            continue;
        };
        let a = hits as f64 / 16.0;
        assert!(
            (f64::from(p[3]) - a).abs() < 1e-6,
            "pixel {i}: alpha {}",
            p[3]
        );
        for c in 0..3 {
            let expected = a * FLAT[c];
            assert!(
                (f64::from(p[c]) - expected).abs() < 1e-5,
                "pixel {i}: {p:?}"
            );
        }
    }
}

/// What a format cannot hold is an error at the render line, before anything is written.
#[test]
fn a_format_that_cannot_hold_what_is_asked_is_refused_at_its_render_line() {
    let dir = tempfile::tempdir().unwrap();
    for (name, args, says) in [
        ("a.jpg", &["--alpha"][..], "no alpha channel"),
        ("a.bmp", &["--depth", "16"][..], "8 bits per channel"),
        ("a.png", &["--depth", "32"][..], "8 or 16 bits"),
        ("a.png", &["--linear"][..], "--linear needs --depth 16"),
        (
            "a.exr",
            &["--depth", "8"][..],
            "16-bit (half) or 32-bit floats",
        ),
    ] {
        let (code, stderr) = render(dir.path(), FLAT_SPHERE, name, args);
        assert_eq!(code, 1, "{name} {args:?}");
        assert!(
            stderr.contains(&format!("scene.sdf:7:1: error: '{name}': ")) && stderr.contains(says),
            "{name} {args:?}: {stderr}"
        );
        assert!(!dir.path().join(name).exists(), "{name} was written");
    }
}
