//! Per-key tangents: a key's `in` and `out` shape the segments that arrive at and leave it,
//! as Bézier handles or named eases per side.

use crate::animator::{frames, generate, place, project, BALL};
use glam::DVec3;

fn spec(keys: &str) -> String {
    format!(
        "(scene: File(\"base.sdf\"), fps: 10, length: Seconds(2), end: Inclusive, resolution: (16, 9),
  tracks: [(target: \"ball\", translate: [{keys}])])"
    )
}

/// The ball's x in every frame of `keys`; panics with stderr if `anim generate` fails.
fn xs(keys: &str) -> Vec<f64> {
    let dir = project(&[("base.sdf", BALL), ("shot.ron", &spec(keys))]);
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
    assert!(ok && stderr.is_empty(), "{stderr}");
    frames(&dir.path().join("f"))
        .iter()
        .map(|(_, t)| place(t, "ball", DVec3::ZERO).x)
        .collect()
}

/// The CSS timing curve through (0, 0), (x1, y1), (x2, y2), (1, 1) at time fraction `s`,
/// solved by bisection on its x (which rises with the parameter for x1, x2 in 0..1).
fn css(x1: f64, y1: f64, x2: f64, y2: f64, s: f64) -> f64 {
    let b = |p1: f64, p2: f64, u: f64| {
        3.0 * (1.0 - u) * (1.0 - u) * u * p1 + 3.0 * (1.0 - u) * u * u * p2 + u * u * u
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if b(x1, x2, mid) < s {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    b(y1, y2, 0.5 * (lo + hi))
}

#[test]
fn handles_on_both_sides_make_the_css_curve_of_the_segment() {
    // Out of the first key by (0.3, 0.1), into the second by (0.2, 0): the control points
    // (0.3, 0.1) and (1 − 0.2, 1 − 0) of a segment from x = 0 to x = 4 over 2 s.
    let x = xs("(at: 0, value: (0, 0, 0), out: Handle(0.3, 0.1)), (at: 2, value: (4, 0, 0), in: Handle(0.2, 0))");
    assert_eq!(x.len(), 21);
    for (i, got) in x.iter().enumerate() {
        let want = 4.0 * css(0.3, 0.1, 0.8, 1.0, i as f64 / 20.0);
        assert!((got - want).abs() < 1e-9, "frame {i}: {got} vs {want}");
    }
}

#[test]
fn one_side_given_keeps_the_other_straight() {
    // Only the arrival eases: the start leaves along the straight line (handle (1/3, 1/3)).
    let x = xs("(at: 0, value: (0, 0, 0)), (at: 2, value: (4, 0, 0), in: Quad)");
    for (i, got) in x.iter().enumerate() {
        let want = 4.0 * css(1.0 / 3.0, 1.0 / 3.0, 1.0 - 0.45, 1.0, i as f64 / 20.0);
        assert!((got - want).abs() < 1e-9, "frame {i}: {got} vs {want}");
    }
    // Straight on both sides is the straight line.
    let x = xs("(at: 0, value: (0, 0, 0), out: Linear), (at: 2, value: (4, 0, 0), in: Linear)");
    for (i, got) in x.iter().enumerate() {
        assert!((got - 0.2 * i as f64).abs() < 1e-9, "frame {i}: {got}");
    }
}

#[test]
fn a_key_can_ease_in_and_out_differently() {
    // The middle key arrives gently (Cubic) and leaves sharply (Expo): both sides are flat at
    // the key, so the ball all but stops there, and the slow part after it is longer.
    let x = xs("(at: 0, value: (0, 0, 0)), (at: 1, value: (2, 0, 0), in: Cubic, out: Expo), (at: 2, value: (4, 0, 0))");
    assert!((x[10] - 2.0).abs() < 1e-9);
    let (before, after) = (x[10] - x[9], x[11] - x[10]);
    assert!(before < 0.02 && after < 0.02, "{before} {after}");
    assert!(after < before, "{before} {after}");
    // Named sides are the Bézier handles of their InOut curves.
    let named = xs("(at: 0, value: (0, 0, 0), out: Cubic), (at: 2, value: (4, 0, 0), in: Cubic)");
    let explicit = xs("(at: 0, value: (0, 0, 0), interp: CubicBezier(0.65, 0, 0.35, 1)), (at: 2, value: (4, 0, 0))");
    assert_eq!(named, explicit);
}

#[test]
fn sides_that_cannot_be_are_located_errors() {
    let cases = [
        (
            "(at: 0, value: (0, 0, 0), in: Cubic), (at: 2, value: (4, 0, 0))",
            "the first key has no segment arriving at it",
        ),
        (
            "(at: 0, value: (0, 0, 0)), (at: 2, value: (4, 0, 0), out: Cubic)",
            "the last key has no segment leaving it",
        ),
        (
            "(at: 0, value: (0, 0, 0), out: Handle(1.5, 0)), (at: 2, value: (4, 0, 0))",
            "a handle's x is a fraction of the segment's time, in 0..1, not 1.5",
        ),
        (
            "(at: 0, value: (0, 0, 0), interp: Smooth, out: Cubic), (at: 2, value: (4, 0, 0))",
            "which `Smooth` is not",
        ),
    ];
    for (keys, needle) in cases {
        let dir = project(&[("base.sdf", BALL), ("shot.ron", &spec(keys))]);
        let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
        assert!(!ok, "{keys}");
        assert!(
            stderr.contains("shot.ron:2:") && stderr.contains(needle),
            "{needle}: {stderr}"
        );
    }
}

#[test]
fn auto_starts_and_stops_at_rest_and_is_flat_at_its_peaks() {
    // 0 → 3 → 1 → 4 (keys at 0, 0.6, 1.4 and 2 s): every key is an end, a peak or a dip, so
    // every tangent is flat and each segment is a + (b − a)·(3s² − 2s³).
    let keys = "(at: 0, value: (0, 0, 0), interp: Auto), (at: 0.6, value: (3, 0, 0), interp: Auto),
                (at: 1.4, value: (1, 0, 0), interp: Auto), (at: 2, value: (4, 0, 0))";
    let x = xs(keys);
    let smoothstep = |s: f64| 3.0 * s * s - 2.0 * s * s * s;
    for (i, got) in x.iter().enumerate() {
        let t = i as f64 / 10.0;
        let (a, b, t0, t1) = match t {
            t if t <= 0.6 => (0.0, 3.0, 0.0, 0.6),
            t if t <= 1.4 => (3.0, 1.0, 0.6, 1.4),
            _ => (1.0, 4.0, 1.4, 2.0),
        };
        let want = a + (b - a) * smoothstep((t - t0) / (t1 - t0));
        assert!((got - want).abs() < 1e-9, "frame {i}: {got} vs {want}");
    }
    // Smooth, by contrast, leaves the first key at full speed.
    let smooth = xs(&keys.replace("Auto", "Smooth"));
    assert!(smooth[1] - smooth[0] > 2.0 * (x[1] - x[0]), "{smooth:?}");
}

#[test]
fn auto_keeps_the_catmull_rom_slope_where_the_keys_go_on_rising() {
    // 0 → 2 → 4 at 0, 1 and 2 s: the middle key's tangent is (4 − 0)/(2 − 0) = 2 a second,
    // the ends' 0, so the first segment is the Hermite curve 2·(3s² − 2s³) + 2·(s³ − s²).
    let x = xs("(at: 0, value: (0, 0, 0), interp: Auto), (at: 1, value: (2, 0, 0), interp: Auto), (at: 2, value: (4, 0, 0))");
    for (i, got) in x.iter().enumerate().take(11) {
        let s = i as f64 / 10.0;
        let want = 2.0 * (3.0 * s * s - 2.0 * s * s * s) + 2.0 * (s * s * s - s * s);
        assert!((got - want).abs() < 1e-9, "frame {i}: {got} vs {want}");
    }
    // And it is symmetric about the middle key.
    for i in 0..=10 {
        assert!((x[10 + i] - (4.0 - x[10 - i])).abs() < 1e-9, "frame {i}");
    }
}
