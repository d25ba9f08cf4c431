//! Spherical lights, spot lights and the thin lens (docs/shading.md §1.1, §2.1, §2.2), against
//! the geometry they are defined by: a light of radius 0 and a lens of aperture 0 are today's
//! point light and pinhole to the byte; a converged soft shadow agrees with the point light's
//! image where the whole light is visible and in the umbra, and its penumbra is as wide as the
//! cones from the floor to the light and to the ball say; a spot is the point light inside its
//! inner cone and ambient only outside its outer cone; a lens keeps the plane in focus as sharp
//! as the pinhole and blurs another plane over its circle of confusion, and adaptive sampling
//! through it is as bright as the converged image over a blurred shadow's rim.

use crate::common;
use common::*;

/// Floor and ball: kd only, so the view direction plays no part.
const KA: f64 = 0.2;
const KD: f64 = 0.8;
const AMBIENT: f64 = 0.3;
const LIGHT: V = [-6.0, 10.0, -10.0];
const LIGHT_RADIUS: f64 = 1.5;
const BALL: V = [0.0, 3.0, -10.0];
const BALL_RADIUS: f64 = 1.0;

/// An overhead camera over the floor: pixel columns run along +x, rows along +z, and the
/// middle row lies over z = −10, through the ball's and the light's centres.
const EYE: V = [2.0, 25.0, -10.0];
const FOV: f64 = 60.0;
const W: usize = 321;
const H: usize = 121;

/// The shadow scene; `light` is what follows the light's 7 numbers.
fn shadow_scene(light: &str, lens: &str) -> String {
    format!(
        "define material matte {KA} {KA} {KA} {KD} {KD} {KD} 0 0 0 1
define shape box ground -60 -1 -60 60 0 60 matte
define shape sphere ball {} {} {} {BALL_RADIUS} matte
define light key {} {} {} 1 1 1 1 {light}
ambient {AMBIENT} {AMBIENT} {AMBIENT}
background 0 0 0
define camera eye {FOV} {} {} {} 0 -1 0 0 0 -1
{lens}
render eye image.ppm {W} {H}
",
        BALL[0], BALL[1], BALL[2], LIGHT[0], LIGHT[1], LIGHT[2], EYE[0], EYE[1], EYE[2]
    )
}

/// The image-plane distance in pixels.
fn plane_distance() -> f64 {
    (W as f64 / 2.0) / (FOV.to_radians() / 2.0).tan()
}

/// Where the overhead camera's ray through image position (`x`, `y`) meets the floor.
fn floor_point(x: f64, y: f64) -> V {
    let scale = EYE[1] / plane_distance();
    [
        EYE[0] + (x - W as f64 / 2.0) * scale,
        0.0,
        EYE[2] - (H as f64 / 2.0 - y) * scale,
    ]
}

fn angle(a: V, b: V) -> f64 {
    dot(unit(a), unit(b)).clamp(-1.0, 1.0).acos()
}

/// From floor point `p`: the angle between the light's and the ball's centres, the angular
/// radius of the light's disc (a disc of the light's radius across the line of sight) and of
/// the ball. The light is all visible when the first is at least the sum of the others, and
/// all hidden when it is at most their difference.
fn cones(p: V) -> (f64, f64, f64) {
    let (to_light, to_ball) = (sub(LIGHT, p), sub(BALL, p));
    let a = (LIGHT_RADIUS / dot(to_light, to_light).sqrt()).atan();
    let b = (BALL_RADIUS / dot(to_ball, to_ball).sqrt()).asin();
    (angle(to_light, to_ball), a, b)
}

/// Whether the camera's rays through pixel (x, y) may meet the ball (its corners' rays come
/// within a pixel's reach of it).
fn sees_ball(x: usize, y: usize) -> bool {
    let d = plane_distance();
    let centre = sub(BALL, EYE);
    let dir = unit([
        x as f64 + 0.5 - W as f64 / 2.0,
        -d,
        y as f64 + 0.5 - H as f64 / 2.0,
    ]);
    let along = dot(centre, dir);
    let miss = (dot(centre, centre) - along * along).max(0.0).sqrt();
    miss < BALL_RADIUS + 2.0 * along / d
}

/// The floor's value lit by the whole light (by its centre, as the point light lights it).
fn lit_value(p: V) -> u8 {
    let n_dot_l = unit(sub(LIGHT, p))[1];
    expected_u8(KA * AMBIENT + KD * n_dot_l)
}

#[test]
fn radius_zero_and_aperture_zero_are_the_point_light_and_the_pinhole_to_the_byte() {
    let dir = tempfile::tempdir().unwrap();
    for args in [&[][..], &["--spp", "4"][..]] {
        let mut images = Vec::new();
        for (i, (light, lens)) in [("", ""), ("radius 0", "lens eye 0 20")]
            .into_iter()
            .enumerate()
        {
            let sub_dir = dir.path().join(format!("{}-{i}", args.len()));
            std::fs::create_dir_all(&sub_dir).unwrap();
            let out = render_in(&sub_dir, "scene.sdf", &shadow_scene(light, lens), args);
            images.push(std::fs::read(out.join("image.ppm")).unwrap());
        }
        assert!(images[0] == images[1], "{args:?}: the images differ");
    }
}

#[test]
fn a_soft_shadow_is_the_point_light_s_outside_its_penumbra_and_as_wide_as_the_cones_say() {
    let point = render_ppm(&shadow_scene("", ""), &["--spp", "16"]);
    let soft = render_ppm(
        &shadow_scene(&format!("radius {LIGHT_RADIUS}"), ""),
        &["--spp", "1024"],
    );
    // Over the image: where all four corners of a pixel see all of the light, or none of it,
    // the soft shadow is the point light's image within one level.
    let (mut lit, mut umbra) = (0, 0);
    for y in 0..H {
        for x in 0..W {
            if sees_ball(x, y) {
                continue;
            }
            let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]
                .map(|(dx, dy)| cones(floor_point(x as f64 + dx, y as f64 + dy)));
            let all_lit = corners.iter().all(|&(t, a, b)| t >= a + b);
            let hidden = corners.iter().all(|&(t, a, b)| t <= b - a);
            if !(all_lit || hidden) {
                continue;
            }
            let (p, s) = (point.at(x, y), soft.at(x, y));
            let d = p.iter().zip(s).map(|(a, b)| a.abs_diff(b)).max().unwrap();
            assert!(
                d <= 1,
                "pixel ({x}, {y}): point light {p:?}, spherical {s:?}"
            );
            lit += usize::from(all_lit);
            umbra += usize::from(hidden);
        }
    }
    assert!(
        lit > 10_000 && umbra > 200,
        "{lit} lit, {umbra} in the umbra"
    );

    // Along the middle row beyond the shadow's centre (on the floor below the ball, away
    // from the light): the penumbra, where a pixel is neither the umbra's value nor the
    // whole light's, against the span the cones give.
    let row = H / 2;
    let umbra_value = expected_u8(KA * AMBIENT);
    let centre_x = LIGHT[0] + (BALL[0] - LIGHT[0]) * LIGHT[1] / (LIGHT[1] - BALL[1]);
    let x_of = |col: f64| floor_point(col, row as f64 + 0.5)[0];
    let mut measured = 0;
    for col in 0..W {
        let p = floor_point(col as f64 + 0.5, row as f64 + 0.5);
        if p[0] <= centre_x || sees_ball(col, row) {
            continue;
        }
        let v = soft.at(col, row)[0];
        if v > umbra_value + 1 && v + 1 < lit_value(p) {
            measured += 1;
        }
    }
    let measured = measured as f64 * (x_of(1.0) - x_of(0.0));
    // Where the angle between the centres passes b − a (the umbra ends) and a + b (the light
    // shows whole), found by bisection along the floor: the angle grows outwards there.
    let crossing = |edge: &dyn Fn(f64, f64) -> f64| {
        let (mut lo, mut hi) = (centre_x, centre_x + 20.0);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            let (t, a, b) = cones([mid, 0.0, BALL[2]]);
            if t < edge(a, b) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    };
    let predicted = crossing(&|a, b| a + b) - crossing(&|a, b| b - a);
    eprintln!("penumbra: {measured:.3} wide, the cones say {predicted:.3}; {lit} lit, {umbra} umbra pixels checked");
    assert!(
        (measured / predicted - 1.0).abs() <= 0.15,
        "penumbra {measured:.3} wide, the cones say {predicted:.3}"
    );
}

/// A spot straight above the floor, looking down, seen from overhead.
fn spot_scene(spot: &str) -> String {
    format!(
        "define material matte {KA} {KA} {KA} {KD} {KD} {KD} 0 0 0 1
define shape box ground -60 -1 -60 60 0 60 matte
define light key 0 10 -10 1 1 1 1 {spot}
ambient {AMBIENT} {AMBIENT} {AMBIENT}
background 0 0 0
define camera eye 90 0 12 -10 0 -1 0 0 0 -1
render eye image.ppm 121 121
"
    )
}

#[test]
fn a_spot_is_the_point_light_inside_its_inner_cone_and_dark_outside_its_outer_one() {
    let (inner, outer) = (20.0f64, 35.0f64);
    let point = render_ppm(&spot_scene(""), &["--spp", "4"]);
    let spot = render_ppm(
        &spot_scene(&format!("spot 0 0 -10 {inner} {outer}")),
        &["--spp", "4"],
    );
    let d = 60.5 / 45f64.to_radians().tan();
    let ambient_only = expected_u8(KA * AMBIENT);
    let (mut inside, mut outside) = (0, 0);
    for y in 0..121 {
        for x in 0..121 {
            // The pixel's floor points lie within half a pixel's diagonal of its centre's.
            let off = |v: usize| (v as f64 + 0.5 - 60.5) * 12.0 / d;
            let r = off(x).hypot(off(y));
            let reach = 0.75 * 12.0 / d;
            let deg = |r: f64| (r / 10.0).atan().to_degrees();
            if deg(r + reach) < inner {
                assert_eq!(spot.at(x, y), point.at(x, y), "({x}, {y}) inside");
                inside += 1;
            } else if deg((r - reach).max(0.0)) > outer {
                assert_eq!(spot.at(x, y), [ambient_only; 3], "({x}, {y}) outside");
                outside += 1;
            }
        }
    }
    assert!(
        inside > 500 && outside > 2000,
        "{inside} inside, {outside} outside"
    );
}

/// A lit card in the plane in focus (z = −10, the image's upper half) and one twice as far
/// (the lower half), each with its right edge on the view axis; unlit black behind.
fn lens_scene(lens: &str) -> String {
    "define material card 1 1 1 0 0 0 0 0 0 1
define shape box near -10 0 -10.001 0 10 -10 card
define shape box far -20 -10 -20.001 0 0 -20 card
ambient 1 1 1
background 0 0 0
define camera eye 40
"
    .to_string()
        + lens
        + "\nrender eye image.ppm 201 101\n"
}

/// The radiance a pixel shows: the tone map undone.
fn share(v: u8) -> f64 {
    let t = v as f64 / 255.0;
    t / (1.0 - t)
}

/// Where along row `y` of `img` (pixel centres, from the left) the card's radiance falls
/// through `level` of what the row's first pixel shows, interpolated between pixels.
fn falls_through(img: &Rgb8, y: usize, level: f64) -> f64 {
    let full = share(img.at(0, y)[0]);
    for x in 1..img.width {
        let (a, b) = (
            share(img.at(x - 1, y)[0]) / full,
            share(img.at(x, y)[0]) / full,
        );
        if a >= level && b < level {
            return x as f64 - 0.5 + (a - level) / (a - b);
        }
    }
    panic!("row {y} never falls through {level}");
}

#[test]
fn a_lens_keeps_the_plane_in_focus_sharp_and_blurs_another_over_its_circle_of_confusion() {
    let aperture = 1.0;
    let pinhole = render_ppm(&lens_scene(""), &["--spp", "16"]);
    let lens = render_ppm(
        &lens_scene(&format!("lens eye {aperture} 10")),
        &["--spp", "1024"],
    );
    // The card in focus: every pixel of its rows beyond the far card's blur as the pinhole
    // shows it, within a level.
    for y in 5..35 {
        for x in 0..201 {
            let (p, l) = (pinhole.at(x, y)[0], lens.at(x, y)[0]);
            assert!(p.abs_diff(l) <= 1, "({x}, {y}): pinhole {p}, lens {l}");
        }
    }
    // The far card: a point of it spreads over a disc of radius aperture·d·(1/10 − 1/20)
    // pixels, so its edge over a straight line falls as the share of a disc beyond a chord,
    // (acos u − u·√(1−u²))/π at u = distance/radius; its 90 % and 10 % points lie ±u₁₀·ρ
    // from the edge.
    let d = 100.5 / 20f64.to_radians().tan();
    let rho = aperture * d * (1.0 / 10.0 - 1.0 / 20.0);
    let beyond = |u: f64| (u.acos() - u * (1.0 - u * u).sqrt()) / std::f64::consts::PI;
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if beyond(mid) > 0.1 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let predicted = 2.0 * lo * rho;
    for y in [70, 80, 90] {
        let measured = falls_through(&lens, y, 0.1) - falls_through(&lens, y, 0.9);
        eprintln!("row {y}: the edge falls over {measured:.2} pixels, the circle of confusion says {predicted:.2}");
        assert!(
            (measured / predicted - 1.0).abs() <= 0.15,
            "row {y}: the edge falls over {measured:.2} pixels, the circle of confusion says {predicted:.2}"
        );
        // The pinhole's edge is a step under the one-pixel box of anti-aliasing: read between
        // pixel centres it falls within two.
        let sharp = falls_through(&pinhole, y, 0.1) - falls_through(&pinhole, y, 0.9);
        assert!(sharp <= 2.0, "row {y}: pinhole edge {sharp:.2}");
    }
}

/// A blurred pixel's samples meet points across its circle of confusion, beyond the nine
/// centres around it: taking the light as seen wherever those centres' shadow rays saw it
/// would light the samples that reach into a shadow, and brighten the blurred rim of every
/// shadow. Adaptive sampling's mean is unbiased: over the pixels where the lens changes the
/// image, its difference from the converged render is within three standard errors of zero.
#[test]
fn adaptive_sampling_through_a_lens_does_not_brighten_the_rim_of_a_blurred_shadow() {
    // Focused far beyond the floor, which the lens blurs over several pixels.
    let lens = "lens eye 1 40";
    let pinhole = render_ppm(&shadow_scene("", ""), &["--spp", "16"]);
    let converged = render_ppm(&shadow_scene("", lens), &["--spp", "1024"]);
    let adaptive = render_ppm(&shadow_scene("", lens), &[]);
    let mut diffs = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let (p, c, a) = (
                pinhole.at(x, y)[0],
                converged.at(x, y)[0],
                adaptive.at(x, y)[0],
            );
            if p.abs_diff(c) > 2 {
                diffs.push(f64::from(a) - f64::from(c));
            }
        }
    }
    let n = diffs.len() as f64;
    assert!(
        n > 500.0,
        "only {n} pixels where the lens changes the image"
    );
    let mean = diffs.iter().sum::<f64>() / n;
    let var = diffs.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let standard_error = (var / n).sqrt();
    assert!(
        mean.abs() <= 3.0 * standard_error,
        "over {n} blurred pixels the adaptive render is {mean:+.3} levels off the converged one \
         (standard error {standard_error:.3})"
    );
}
