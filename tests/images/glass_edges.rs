//! Glass where surfaces meet: a glass sphere inside a glass sphere, two glass boxes sharing a
//! face, and rays grazing along box faces and edges. Expectations follow docs/shading.md §3:
//! at a surface of a material with opacity α the colour is
//! `α·((1 − ρ)·c_local + ρ·c_r) + (1 − α)·(F·c_r + (1 − F)·c_t)`, with F the exact Fresnel
//! reflectance (at normal incidence ((η − 1)/(η + 1))², and 0 for η = 1 at every angle), the
//! medium outside every object air, recursion to `--max-depth`, and rays whose weight cannot
//! change the 8-bit result not traced.

use crate::common;

use common::{render_ppm, Rgb8};

/// 8-bit value of radiance `c` (docs/shading.md §4).
fn to_u8(c: f64) -> u8 {
    (255.0 * c / (c + 1.0)).round() as u8
}

/// What the renderer never traces: a ray whose weight in the pixel times the largest radiance
/// of the scene is below half an 8-bit step (docs/shading.md §3, "too small to change the
/// 8-bit result").
const NEGLIGIBLE: f64 = 0.5 / 255.0;

/// A straight line through planar interfaces met at normal incidence, each of which
/// reflects a ray straight back or lets it through undeflected (so every path stays on the
/// line): `interfaces[i]` is the opacity of the surface met at position i (positions
/// ascending along the line), each with reflectance `f0`; past either end a ray sees the
/// background `bg`. Rays are cut as the renderer cuts them: at `max_depth` bounces, and where
/// their weight times `max_radiance` cannot change the 8-bit result.
struct Line<'a> {
    interfaces: &'a [f64],
    f0: f64,
    bg: f64,
    max_radiance: f64,
    max_depth: u32,
}

impl Line<'_> {
    /// Radiance along a ray on the line with black local colour: the formula of
    /// docs/shading.md §3, evaluated over all paths exactly as the recursion does. The ray
    /// starts before position `at` going forwards (`dir = 1`) or after position `at` going
    /// backwards (`dir = -1`), after `depth` bounces, with share `weight` of the pixel.
    fn radiance(&self, at: isize, dir: isize, depth: u32, weight: f64) -> f64 {
        if at < 0 || at >= self.interfaces.len() as isize {
            return self.bg;
        }
        let alpha = self.interfaces[at as usize];
        let f0 = self.f0;
        let (w_reflect, w_refract) = ((1.0 - alpha) * f0, (1.0 - alpha) * (1.0 - f0));
        let worth = |w: f64| {
            depth < self.max_depth && w > 0.0 && weight * w * self.max_radiance >= NEGLIGIBLE
        };
        let mut c = 0.0;
        if worth(w_reflect) {
            c += w_reflect * self.radiance(at - dir, -dir, depth + 1, weight * w_reflect);
        }
        if worth(w_refract) {
            c += w_refract * self.radiance(at + dir, dir, depth + 1, weight * w_refract);
        }
        c
    }
}

fn fresnel_normal(ior: f64) -> f64 {
    ((ior - 1.0) / (ior + 1.0)).powi(2)
}

/// Black local colour (no ambient, diffuse or specular), opacity `alpha`, index `ior`.
fn glass(name: &str, alpha: f64, ior: f64) -> String {
    format!("define material {name} 0 0 0  0 0 0  0 0 0  1  0 {alpha} {ior}\n")
}

const MATERIAL_FIELDS: [&str; 2] = ["--material-fields", "reflectivity,opacity,ior"];

fn render(sdf: &str) -> Rgb8 {
    render_ppm(sdf, &["--spp", "1", MATERIAL_FIELDS[0], MATERIAL_FIELDS[1]])
}

fn assert_close(got: [u8; 3], want: u8, what: &str) {
    for c in got {
        assert!(
            c.abs_diff(want) <= 1,
            "{what}: pixel {got:?}, expected {want} in every channel (±1)"
        );
    }
}

/// Concentric glass spheres of the same η, seen through their centre: the centre pixel's ray
/// meets four surfaces at normal incidence (enter outer, enter inner, leave inner, leave
/// outer; each is a boundary with air in the docs' model, so each has F = F₀), is never
/// deflected, and every reflection goes straight back along the same line.
#[test]
fn nested_glass_spheres_along_the_axis() {
    for (alpha_outer, alpha_inner, ior) in [(0.3, 0.6, 1.5), (0.0, 0.0, 1.5), (0.5, 0.2, 2.4)] {
        let bg = 0.8;
        let sdf = format!(
            "{}{}define shape sphere outer 0 0 -10 3 outer\n\
             define shape sphere inner 0 0 -10 1.5 inner\n\
             background {bg} {bg} {bg}\n\
             define camera c 20\n\
             render c image.ppm 33 33\n",
            glass("outer", alpha_outer, ior),
            glass("inner", alpha_inner, ior)
        );
        let img = render(&sdf);
        let line = Line {
            interfaces: &[alpha_outer, alpha_inner, alpha_inner, alpha_outer],
            f0: fresnel_normal(ior),
            bg,
            max_radiance: bg,
            max_depth: 8,
        };
        let c = line.radiance(0, 1, 0, 1.0);
        assert_close(
            img.at(16, 16),
            to_u8(c),
            &format!("α {alpha_outer}/{alpha_inner}, η {ior}: c = {c}"),
        );
        // A glass sphere in glass takes light away (Fresnel reflections lost to the sides,
        // opacity), so the check above is not the background's value by accident.
        if alpha_outer > 0.0 {
            assert!(to_u8(c) + 2 < to_u8(bg));
        }
    }
}

/// Two glass boxes sharing the face z = −6, seen face-on through a narrow field of view: the
/// shared face is one boundary, crossed once, so a ray meets three surfaces (z = −4, −6, −8),
/// not two (the face lost) or four (counted twice); the whole face-on view agrees with the
/// axis within the small angles off normal incidence.
#[test]
fn glass_boxes_sharing_a_face_cross_it_once() {
    let (alpha, ior, bg) = (0.4, 1.5, 0.9);
    let sdf = format!(
        "{}define shape box a -1 -1 -6  1 1 -4 g\n\
         define shape box b -1 -1 -8  1 1 -6 g\n\
         background {bg} {bg} {bg}\n\
         define camera c 6\n\
         render c image.ppm 31 31\n",
        glass("g", alpha, ior)
    );
    let img = render(&sdf);
    let f0 = fresnel_normal(ior);
    let line = |n: usize| {
        let line = Line {
            interfaces: &vec![alpha; n],
            f0,
            bg,
            max_radiance: bg,
            max_depth: 8,
        };
        line.radiance(0, 1, 0, 1.0)
    };
    let (two, three, four) = (to_u8(line(2)), to_u8(line(3)), to_u8(line(4)));
    assert!(two > three + 2 && three > four + 2, "{two} {three} {four}");
    // The 6° view sees only box faces (the boxes span ±9.5° from 6 units away).
    for y in 0..img.height {
        for x in 0..img.width {
            assert_close(img.at(x, y), three, &format!("pixel ({x}, {y})"));
        }
    }
}

/// Glass of η = 1 bends nothing and reflects nothing (F = 0 at every angle), so with black
/// local colour and opacity 0 every pixel is exactly the background, however rays meet the
/// shapes, unless a ray is lost: a self-intersection that runs into the depth limit (black), a
/// ray that slips through an edge into the wrong side (still background here, so the other
/// tests catch those), or a NaN (stored as 0). The eye sits exactly in the planes of the top
/// and right faces of the box, so the middle row and column of pixels travel along those faces
/// and the centre pixel along their common edge; the nested spheres are grazed by the rays
/// through their silhouettes.
#[test]
fn grazing_rays_along_box_faces_and_edges_lose_nothing() {
    let bg = 0.7;
    let sdf = format!(
        "{}define shape box b -1 -1 -8  1 1 -4 g\n\
         define shape box c 1 -1 -8  3 1 -4 g\n\
         define shape sphere s -2 -1.5 -9 1.2 g\n\
         define shape sphere t -2 -1.5 -9 0.6 g\n\
         define shape cylinder p -1 -1 -12 -1 3 -12 0.8 g\n\
         define shape cone k 2.5 2 -10 2.5 4 -10 0.9 g\n\
         background {bg} {bg} {bg}\n\
         define camera cam 70 1 1 0 0 0 -1 0 1 0\n\
         render cam image.ppm 41 41\n",
        glass("g", 0.0, 1.0)
    );
    let img = render(&sdf);
    let want = to_u8(bg);
    for y in 0..img.height {
        for x in 0..img.width {
            assert_eq!(img.at(x, y), [want; 3], "pixel ({x}, {y})");
        }
    }
}

/// The same grazing views in real glass (η = 1.5, partly opaque, a light for shadow rays
/// through glass): every pixel finite (a NaN would be stored as 0) and none black — every
/// path ends in the lit background or a lit surface, so black would mean lost rays.
#[test]
fn grazing_rays_in_real_glass_give_no_black_speckles() {
    let sdf = format!(
        "{}define material wall 0.3 0.3 0.3  0.6 0.6 0.6  0 0 0  1  0 1 1\n\
         define shape box b -1 -1 -8  1 1 -4 g\n\
         define shape box c 1 -1 -8  3 1 -4 g\n\
         define shape sphere s -2 -1.5 -9 1.2 g\n\
         define shape sphere t -2 -1.5 -9 0.6 g\n\
         define shape box back -20 -20 -30  20 20 -29 wall\n\
         define light l 0 8 2 1 1 1\n\
         ambient 0.3 0.3 0.3\n\
         background 0.5 0.5 0.5\n\
         define camera cam 70 1 1 0 0 0 -1 0 1 0\n\
         render cam image.ppm 41 41\n",
        glass("g", 0.2, 1.5)
    );
    let img = render(&sdf);
    for y in 0..img.height {
        for x in 0..img.width {
            let p = img.at(x, y);
            assert!(p.iter().all(|&c| c >= 8), "pixel ({x}, {y}) is {p:?}");
        }
    }
}
