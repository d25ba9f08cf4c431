//! Motion blur in the renderer (docs/scene-language.md §10): a sliding ball's streak against
//! the fraction of the exposure it covers each pixel (derived here), determinism across
//! thread counts, and `motion` lines that move nothing leaving the frame as it was.

use anim::render::{render_job, RenderSettings};
use anim::scene::{load_str, RenderJob};
use anim::sdf::LoadOptions;
use std::path::Path;

const W: u32 = 48;
const H: u32 = 8;
const FOV: f64 = 40.0;
/// The ball: radius, distance, and its slide over the exposure (x from -SLIDE/2 to +SLIDE/2).
const R: f64 = 0.5;
const Z: f64 = -10.0;
const SLIDE: f64 = 4.0;

/// An ambient-only white ball (radiance exactly 1 where seen) on black.
fn scene(motion: &str) -> String {
    format!(
        "define material white 1 1 1 0 0 0 0 0 0 1\n\
         define shape sphere ball 0 0 {Z} {R} white\n\
         ambient 1 1 1\n\
         background 0 0 0\n\
         define camera eye {FOV}\n\
         {motion}\
         render eye streak.ppm {W} {H}\n"
    )
}

const SLIDING: &str =
    "motion ball 0 translate -2 0 0\nmotion ball 0.5\nmotion ball 1 translate 2 0 0\n";

fn job(text: &str) -> RenderJob {
    let loaded = load_str(text, Path::new("streak.sdf"), &LoadOptions::default())
        .unwrap_or_else(|d| panic!("{d:?}"));
    loaded.jobs.into_iter().next().expect("one job")
}

fn render(job: &RenderJob, spp: u32) -> Vec<[f32; 3]> {
    let settings = RenderSettings {
        spp: Some(spp),
        ..RenderSettings::default()
    };
    let out = render_job(job, &settings, &|_| {}).expect("renders");
    out.image.pixels.iter().map(|p| p.to_array()).collect()
}

/// The fraction of the exposure during which the ray from the eye (at the origin) along `d`
/// meets the ball, whose centre slides along x: the distance² from the ray's line to the
/// centre is a quadratic in u, below R² on one interval.
fn covered(d: [f64; 3]) -> f64 {
    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let d = [d[0] / len, d[1] / len, d[2] / len];
    // Centre c(u) = c0 + u·v; |c − (c·d)d|² = |c|² − (c·d)².
    let c0 = [-SLIDE / 2.0, 0.0, Z];
    let v = [SLIDE, 0.0, 0.0];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    // dist²(u) = A u² + B u + C
    let (cd, vd) = (dot(c0, d), dot(v, d));
    let a = dot(v, v) - vd * vd;
    let b = 2.0 * (dot(c0, v) - cd * vd);
    let c = dot(c0, c0) - cd * cd - R * R;
    let disc = b * b - 4.0 * a * c;
    if disc <= 0.0 {
        return 0.0;
    }
    let (u0, u1) = (
        (-b - disc.sqrt()) / (2.0 * a),
        (-b + disc.sqrt()) / (2.0 * a),
    );
    (u1.min(1.0) - u0.max(0.0)).max(0.0)
}

/// The expected value of pixel (x, y): `covered` averaged over the pixel (a 32×32 grid).
fn expected(x: u32, y: u32) -> f64 {
    let dist = (W as f64 / 2.0) / (FOV.to_radians() / 2.0).tan();
    let n = 32;
    let mut sum = 0.0;
    for j in 0..n {
        for i in 0..n {
            let px = x as f64 + (i as f64 + 0.5) / n as f64;
            let py = y as f64 + (j as f64 + 0.5) / n as f64;
            sum += covered([px - W as f64 / 2.0, H as f64 / 2.0 - py, -dist]);
        }
    }
    sum / (n * n) as f64
}

#[test]
fn a_sliding_ball_streaks_as_long_as_it_covers_each_pixel() {
    let pixels = render(&job(&scene(SLIDING)), 256);
    let mut worst = 0.0f64;
    let mut streak = 0;
    for y in [3, 4] {
        for x in 0..W {
            let want = expected(x, y);
            let got = pixels[(y * W + x) as usize][0] as f64;
            worst = worst.max((got - want).abs());
            if want > 0.05 {
                streak += 1;
            }
        }
    }
    // 256 stratified instants: the error of one pixel's mean is far below 0.04.
    assert!(worst < 0.04, "largest difference {worst}");
    // The streak is most of the row, not the ball's own width (about 4 pixels).
    assert!(
        streak > 2 * 20,
        "{streak} pixels of the two rows in the streak"
    );
}

#[test]
fn the_streak_does_not_depend_on_the_thread_count() {
    let job = job(&scene(SLIDING));
    let with = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        let uniform = pool.install(|| render(&job, 16));
        let adaptive = pool.install(|| {
            render_job(&job, &RenderSettings::default(), &|_| {})
                .expect("renders")
                .image
                .pixels
        });
        (uniform, adaptive)
    };
    assert_eq!(with(1), with(2));
}

#[test]
fn motion_lines_that_move_nothing_leave_the_frame_as_it_was() {
    let plain = job(&scene(""));
    let still = job(&scene(
        "motion ball 0 translate 0 0 0\nmotion ball 0.5\nmotion ball 1 rotate 0 0 1 0\n",
    ));
    let moving = job(&scene(SLIDING));
    assert!(plain.scene.motion.is_none());
    assert!(still.scene.motion.is_none(), "nothing moves: no motion");
    assert!(moving.scene.motion.is_some());
    assert_eq!(render(&plain, 4), render(&still, 4));
    assert_ne!(render(&plain, 4), render(&moving, 4));
}

/// The rows of the streak against `expected`, as in the sliding-ball test.
fn worst_difference(pixels: &[[f32; 3]]) -> f64 {
    let mut worst = 0.0f64;
    for y in [3, 4] {
        for x in 0..W {
            let got = pixels[(y * W + x) as usize][0] as f64;
            worst = worst.max((got - expected(x, y)).abs());
        }
    }
    worst
}

#[test]
fn a_camera_sliding_the_other_way_draws_the_same_streak() {
    let camera = "motion eye 0 translate 2 0 0\nmotion eye 0.5\nmotion eye 1 translate -2 0 0\n";
    let job = job(&scene(camera));
    assert!(job
        .scene
        .motion
        .as_ref()
        .is_some_and(|m| m.camera.is_some()));
    let worst = worst_difference(&render(&job, 256));
    assert!(worst < 0.04, "largest difference {worst}");
}

#[test]
fn a_moving_composite_carries_its_shape() {
    let text = scene(
        "define shape composite group ball\n\
         motion group 0 translate -2 0 0\nmotion group 0.5\nmotion group 1 translate 2 0 0\n",
    );
    let worst = worst_difference(&render(&job(&text), 256));
    assert!(worst < 0.04, "largest difference {worst}");
}
