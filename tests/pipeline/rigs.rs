//! Rigs: a target travelling a path at constant speed and turning along it, and cameras,
//! lights and objects following a parent.

use crate::animator::{frames, generate, line_with, numbers, place, project, BALL};
use glam::DVec3;

const SQUARE: &str = "[(0, 0, 0), (10, 0, 0), (10, 0, -10), (0, 0, -10)]";

fn shot(tracks: &str) -> String {
    format!(
        "(scene: File(\"base.sdf\"), fps: 24, length: Seconds(4), resolution: (16, 9),
  tracks: [{tracks}])"
    )
}

fn run(tracks: &str) -> Vec<(String, String)> {
    let dir = project(&[("base.sdf", BALL), ("shot.ron", &shot(tracks))]);
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
    assert!(ok && stderr.is_empty(), "{stderr}");
    frames(&dir.path().join("f"))
}

#[test]
fn a_path_is_travelled_at_constant_speed() {
    let frames = run(&format!("(target: \"ball\", path: (points: {SQUARE}))"));
    assert_eq!(frames.len(), 96);
    let at: Vec<DVec3> = frames
        .iter()
        .map(|(_, text)| place(text, "ball", DVec3::ZERO))
        .collect();
    assert_eq!(at[0], DVec3::ZERO);
    let steps: Vec<f64> = at.windows(2).map(|w| (w[1] - w[0]).length()).collect();
    let mean = steps.iter().sum::<f64>() / steps.len() as f64;
    for (i, s) in steps.iter().enumerate() {
        assert!((s - mean).abs() < 0.01 * mean, "step {i}: {s} vs {mean}");
    }
    // It passes its corners: the nearest frame to each is within a step of it.
    for corner in [DVec3::new(10.0, 0.0, 0.0), DVec3::new(10.0, 0.0, -10.0)] {
        let nearest = at
            .iter()
            .map(|p| (*p - corner).length())
            .fold(f64::MAX, f64::min);
        assert!(nearest <= mean, "{corner}: {nearest}");
    }
}

#[test]
fn progress_keys_ease_the_distance_not_the_curve() {
    let frames = run(&format!(
        "(target: \"ball\", path: (points: {SQUARE}, spline: Linear,
           progress: [(at: 0, value: 0, interp: EaseInOut), (at: 2, value: 0.5), (at: 4, value: 1)]))"
    ));
    let at: Vec<DVec3> = frames
        .iter()
        .map(|(_, text)| place(text, "ball", DVec3::ZERO))
        .collect();
    // Straight sides, 30 long: at 1 s the ease is at its middle, a quarter of the way.
    assert!(
        (at[24] - DVec3::new(7.5, 0.0, 0.0)).length() < 1e-9,
        "{}",
        at[24]
    );
    // At 2 s, half way: 15 along, the middle of the second side.
    assert!(
        (at[48] - DVec3::new(10.0, 0.0, -5.0)).length() < 1e-9,
        "{}",
        at[48]
    );
    // Slow at the start: the first step is far shorter than the one at 1 s.
    assert!((at[1] - at[0]).length() < 0.2 * (at[25] - at[24]).length());
}

#[test]
fn along_path_turns_the_object_to_the_path_s_direction() {
    let frames = run(&format!(
        "(target: \"ball\", path: (points: {SQUARE}, closed: true), orient: AlongPath)"
    ));
    let centre = |text: &str| place(text, "ball", DVec3::ZERO);
    let n = frames.len();
    for i in 0..n {
        let text = &frames[i].1;
        // The ball's forward (−z) in the frame, against the way it goes there.
        let facing = (place(text, "ball", DVec3::NEG_Z) - centre(text)).normalize();
        let (prev, next) = (&frames[(i + n - 1) % n].1, &frames[(i + 1) % n].1);
        let heading = (centre(next) - centre(prev)).normalize();
        assert!(
            facing.dot(heading) > 0.99,
            "frame {i}: {facing} vs {heading}"
        );
        // No bank asked: the ball's up stays up.
        let up = place(text, "ball", DVec3::Y) - centre(text);
        assert!(up.abs_diff_eq(DVec3::Y, 1e-9), "frame {i}: {up}");
    }
}

#[test]
fn path_mistakes_are_located() {
    let cases = [
        (
            "(target: \"ball\", path: (points: [(1, 2, 3)]))".to_string(),
            "a path needs at least two points, not 1",
        ),
        (
            format!("(target: \"ball\", path: (points: {SQUARE}), translate: [(at: 0, value: (1, 0, 0))])"),
            "by `translate` keys or by a `path`, not both",
        ),
        (
            "(target: \"ball\", orient: AlongPath)".to_string(),
            "this track has no path",
        ),
        (
            format!("(target: \"ball\", path: (points: {SQUARE}), bank: 1)"),
            "give it `orient: AlongPath`",
        ),
    ];
    for (tracks, needle) in cases {
        let dir = project(&[("base.sdf", BALL), ("shot.ron", &shot(&tracks))]);
        let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
        assert!(!ok, "{tracks}");
        assert!(
            stderr.contains("shot.ron:2:") && stderr.contains(needle),
            "{stderr}"
        );
    }
}

/// The camera's eye in a frame: its `define camera` line's, carried by its transforms.
fn eye(text: &str) -> DVec3 {
    let cam = numbers(&line_with(text, "define camera cam")[3..]);
    place(text, "cam", DVec3::new(cam[1], cam[2], cam[3]))
}

#[test]
fn a_camera_parented_to_a_moving_object_keeps_its_offset() {
    let frames = run(
        "(target: \"ball\", translate: [(at: 0, value: (0, 0, 0), interp: EaseInOut), (at: 3, value: (6, 1, -3))]),
         (target: \"cam\", parent: \"ball\")",
    );
    // BALL's camera sits at (0, 0, 10); the ball starts at the origin.
    for (i, (_, text)) in frames.iter().enumerate() {
        let moved = place(text, "ball", DVec3::ZERO);
        let e = eye(text);
        assert!(
            (e - (DVec3::new(0.0, 0.0, 10.0) + moved)).length() < 1e-9,
            "frame {i}: {e} vs {moved}"
        );
    }
}

/// Where the `motion NAME AT ops…` line of `name` at `at` carries `p`.
fn moved(text: &str, name: &str, at: &str, p: DVec3) -> DVec3 {
    let line = text
        .lines()
        .find(|l| l.starts_with(&format!("motion {name} {at}")))
        .unwrap_or_else(|| panic!("no motion of {name} at {at} in\n{text}"));
    let w: Vec<&str> = line.split_whitespace().skip(3).collect();
    // The operations one after another, in the words of `transform` lines.
    let mut ops = String::new();
    let mut k = 0;
    while k < w.len() {
        let n = if w[k] == "rotate" { 4 } else { 3 };
        let n = if w[k] == "scale" && w.get(k + 2).is_none_or(|x| x.parse::<f64>().is_err()) {
            1
        } else {
            n
        };
        ops.push_str(&format!("transform {name} {}\n", w[k..=k + n].join(" ")));
        k += n + 1;
    }
    place(&ops, name, p)
}

/// A ball that moves, turns about a tilted axis and grows, and a light following it.
const LEADS: &str =
    "(target: \"ball\", translate: [(at: 0, value: (0, 0, 0)), (at: 3, value: (4, 1, -2))],
    rotate: [(at: 0, value: 0), (at: 3, value: 120)], axis: (0.3, 1, 0.2),
    scale: [(at: 0, value: (1, 1, 1)), (at: 3, value: (2, 2, 2))])";

#[test]
fn a_follower_is_carried_as_a_point_of_its_parent_would_be() {
    let frames = run(&format!("{LEADS}, (target: \"sun\", parent: \"ball\")"));
    let points = [DVec3::new(5.0, 5.0, 5.0), DVec3::new(-1.0, 2.0, 0.5)];
    for (i, (_, text)) in frames.iter().enumerate() {
        for p in points {
            let (sun, ball) = (place(text, "sun", p), place(text, "ball", p));
            assert!((sun - ball).length() < 1e-8, "frame {i}: {sun} vs {ball}");
        }
    }
    // It does move: the light is far from where it started by the end.
    let last = &frames[frames.len() - 1].1;
    assert!((place(last, "sun", DVec3::splat(5.0)) - DVec3::splat(5.0)).length() > 3.0);
}

#[test]
fn follow_translate_takes_where_the_parent_s_centre_goes_and_nothing_else() {
    let frames = run(&format!(
        "{LEADS}, (target: \"sun\", parent: \"ball\", follow: [Translate])"
    ));
    for (i, (_, text)) in frames.iter().enumerate() {
        let shift = place(text, "ball", DVec3::ZERO);
        let sun = place(text, "sun", DVec3::splat(5.0));
        assert!(
            (sun - (DVec3::splat(5.0) + shift)).length() < 1e-9,
            "frame {i}: {sun} vs {shift}"
        );
    }
}

#[test]
fn followers_are_carried_through_the_exposure_too() {
    let spec = format!(
        "(scene: File(\"base.sdf\"), fps: 8, length: Seconds(4), resolution: (16, 9), shutter: 0.5,
  tracks: [{LEADS}, (target: \"sun\", parent: \"ball\")])"
    );
    let dir = project(&[("base.sdf", BALL), ("shot.ron", &spec)]);
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
    assert!(ok && stderr.is_empty(), "{stderr}");
    let p = DVec3::new(5.0, 5.0, 5.0);
    let mut blurred = 0;
    for (name, text) in frames(&dir.path().join("f")) {
        // Once the ball stops (at 3 s), neither moves during an exposure.
        let moving = text.contains("motion ball");
        assert_eq!(moving, text.contains("motion sun"), "{name}");
        if !moving {
            continue;
        }
        blurred += 1;
        for at in ["0 ", "1 "] {
            // Where the light is at the shutter's opening and closing, against the ball.
            let sun = moved(text.as_str(), "sun", at, place(&text, "sun", p));
            let ball = moved(text.as_str(), "ball", at, place(&text, "ball", p));
            assert!(
                (sun - ball).length() < 1e-8,
                "{name} at {at}: {sun} vs {ball}"
            );
        }
    }
    assert_eq!(blurred, 24);
}

#[test]
fn an_aimed_camera_on_a_moving_rig_keeps_looking_at_its_target() {
    let frames = run(
        "(target: \"ball\", translate: [(at: 0, value: (0, 0, 0)), (at: 3, value: (6, 0, 0))]),
         (target: \"cam\", parent: \"ball\", look_at: Point((0, 0, -20)))",
    );
    for (i, (_, text)) in frames.iter().enumerate() {
        let cam = numbers(&line_with(text, "define camera cam")[3..]);
        let eye = DVec3::new(cam[1], cam[2], cam[3]);
        let dir = DVec3::new(cam[4], cam[5], cam[6]);
        let carried = DVec3::new(0.0, 0.0, 10.0) + place(text, "ball", DVec3::ZERO);
        assert!((eye - carried).length() < 1e-9, "frame {i}: {eye}");
        let to = (DVec3::new(0.0, 0.0, -20.0) - eye).normalize();
        assert!(dir.normalize().dot(to) > 1.0 - 1e-9, "frame {i}: {dir}");
    }
}

#[test]
fn a_light_follows_an_aimed_camera() {
    // The camera turns to watch the moving ball; the lamp on it turns with it, about its eye.
    let frames = run(
        "(target: \"ball\", translate: [(at: 0, value: (0, 0, 0)), (at: 3, value: (6, 0, 0))]),
         (target: \"cam\", look_at: Object(\"ball\")),
         (target: \"sun\", parent: \"cam\")",
    );
    for (i, (_, text)) in frames.iter().enumerate() {
        let cam = numbers(&line_with(text, "define camera cam")[3..]);
        let eye = DVec3::new(cam[1], cam[2], cam[3]);
        let dir = DVec3::new(cam[4], cam[5], cam[6]).normalize();
        let sun = place(text, "sun", DVec3::splat(5.0));
        // The lamp keeps its distance from the eye and its angle to the view.
        let before = DVec3::splat(5.0) - DVec3::new(0.0, 0.0, 10.0);
        let now = sun - eye;
        assert!((now.length() - before.length()).abs() < 1e-9, "frame {i}");
        let cos = |a: DVec3, b: DVec3| a.normalize().dot(b);
        assert!(
            (cos(now, dir) - cos(before, DVec3::NEG_Z)).abs() < 1e-9,
            "frame {i}"
        );
    }
}

#[test]
fn parenting_mistakes_are_located() {
    let cases = [
        ("(target: \"cam\", parent: \"cam\")", "'cam' cannot follow itself"),
        (
            "(target: \"cam\", parent: \"bal\")",
            "no shape, composite, light or camera named 'bal'",
        ),
        (
            "(target: \"cam\", parent: \"ball\"), (target: \"ball\", parent: \"sun\"), (target: \"sun\", parent: \"cam\")",
            "parents go round a loop: cam → ball → sun → cam",
        ),
        (
            "(target: \"cam\", parent: \"ball\"), (target: \"cam\", parent: \"sun\")",
            "'cam' follows another parent in tracks[0] already",
        ),
        ("(target: \"red\", parent: \"ball\")", "parent"),
    ];
    for (tracks, needle) in cases {
        let dir = project(&[("base.sdf", BALL), ("shot.ron", &shot(tracks))]);
        let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
        assert!(!ok, "{tracks}");
        assert!(
            stderr.contains("shot.ron:2:") && stderr.contains(needle),
            "{needle}: {stderr}"
        );
    }
}

/// BALL with a composite of two small spheres beside the ball.
const PAIR: &str = "define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20
define shape sphere ball 0 0 0 1 red
define shape sphere left 3 0 0 0.3 red
define shape sphere right 4 0 0 0.3 red
define shape composite pair left right
define light sun 5 5 5 1 1 1 1
define camera cam 60 0 0 10 0 0 -1 0 1 0
";

#[test]
fn a_composite_rides_on_a_turning_parent_and_its_children_cannot_ride_alone() {
    let shot = |tracks: &str| {
        let spec = format!(
            "(scene: File(\"base.sdf\"), fps: 8, length: Seconds(2), end: Inclusive, resolution: (16, 9),
  tracks: [{tracks}])"
        );
        let dir = project(&[("base.sdf", PAIR), ("shot.ron", &spec)]);
        let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
        (
            ok,
            stderr,
            if ok {
                frames(&dir.path().join("f"))
            } else {
                Vec::new()
            },
        )
    };
    let (ok, stderr, frames) = shot(
        "(target: \"ball\", rotate: [(at: 0, value: 0), (at: 2, value: 90)], axis: (0, 0, 1)),
         (target: \"pair\", parent: \"ball\")",
    );
    assert!(ok && stderr.is_empty(), "{stderr}");
    for (i, (_, text)) in frames.iter().enumerate() {
        // The pair swings round the ball's centre as the ball turns: 90° × t / 2 s about z.
        let angle = (90.0 * (i as f64 / 8.0) / 2.0f64).to_radians();
        let want = DVec3::new(3.0 * angle.cos(), 3.0 * angle.sin(), 0.0);
        let got = place(text, "pair", DVec3::new(3.0, 0.0, 0.0));
        assert!((got - want).length() < 1e-9, "frame {i}: {got} vs {want}");
    }
    let (ok, stderr, _) = shot("(target: \"left\", parent: \"ball\")");
    assert!(!ok);
    assert!(
        stderr.contains("'left' is placed by composite 'pair': give the composite the parent"),
        "{stderr}"
    );
}

#[test]
fn an_aim_follows_a_target_carried_by_its_parent() {
    let spec = "(scene: File(\"base.sdf\"), fps: 8, length: Seconds(2), end: Inclusive, resolution: (16, 9),
  tracks: [(target: \"ball\", translate: [(at: 0, value: (0, 0, 0)), (at: 2, value: (0, 4, -2))]),
           (target: \"pair\", parent: \"ball\"),
           (target: \"cam\", look_at: Object(\"pair\"))])";
    let dir = project(&[("base.sdf", PAIR), ("shot.ron", spec)]);
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
    assert!(ok && stderr.is_empty(), "{stderr}");
    for (name, text) in frames(&dir.path().join("f")) {
        let cam = numbers(&line_with(&text, "define camera cam")[3..]);
        let (eye, view) = (
            DVec3::new(cam[1], cam[2], cam[3]),
            DVec3::new(cam[4], cam[5], cam[6]),
        );
        // The pair's centre (3.5, 0, 0), carried as the ball moves.
        let centre = place(&text, "pair", DVec3::new(3.5, 0.0, 0.0));
        let to = (centre - eye).normalize();
        assert!(
            view.normalize().dot(to) > 1.0 - 1e-9,
            "{name}: {view} vs {to}"
        );
    }
}

#[test]
fn follow_rotate_takes_the_parent_s_turn_about_where_it_stood() {
    let spec = "(scene: File(\"base.sdf\"), fps: 8, length: Seconds(2), end: Inclusive, resolution: (16, 9),
  tracks: [(target: \"ball\", translate: [(at: 0, value: (0, 0, 0)), (at: 2, value: (0, 5, 0))],
            rotate: [(at: 0, value: 0), (at: 2, value: 90)], axis: (0, 0, 1)),
           (target: \"pair\", parent: \"ball\", follow: [Rotate])])";
    let dir = project(&[("base.sdf", PAIR), ("shot.ron", spec)]);
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
    assert!(ok && stderr.is_empty(), "{stderr}");
    for (i, (_, text)) in frames(&dir.path().join("f")).iter().enumerate() {
        // Turned about the ball's base centre (the origin), not carried up with it.
        let angle = (45.0 * i as f64 / 8.0).to_radians();
        let want = DVec3::new(3.0 * angle.cos(), 3.0 * angle.sin(), 0.0);
        let got = place(text, "pair", DVec3::new(3.0, 0.0, 0.0));
        assert!((got - want).length() < 1e-9, "frame {i}: {got} vs {want}");
    }
}
