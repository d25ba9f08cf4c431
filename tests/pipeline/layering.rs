//! Tracks on one value combine by a stated rule (`blend: Replace | Add | Multiply`); without
//! one, a second track keying the same value is an error naming both.

use crate::animator::{frames, generate, line_with, numbers, project, BALL};

fn spec(tracks: &str) -> String {
    format!(
        "(scene: File(\"base.sdf\"), fps: 8, length: Seconds(1), end: Inclusive, resolution: (16, 9),
  tracks: [
{tracks}
  ])"
    )
}

/// Brightness and colour of the `sun` line of a frame.
fn sun(text: &str) -> (f64, [f64; 3]) {
    let v = numbers(&line_with(text, "define light sun")[3..]);
    (v[6], [v[3], v[4], v[5]])
}

const RAMP: &str = "    (target: \"sun\", brightness: [(at: 0, value: 0.5), (at: 1, value: 1.5)]),";

#[test]
fn two_tracks_keying_one_brightness_without_blend_is_an_error_naming_both() {
    let text = spec(&format!(
        "{RAMP}\n    (target: \"sun\", brightness: [(at: 0, value: 0.2)]),"
    ));
    let dir = project(&[("base.sdf", BALL), ("shot.ron", &text)]);
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
    assert!(!ok);
    assert!(
        stderr.contains("shot.ron:4:33: error: tracks[0] and tracks[1] both key the brightness of 'sun': give tracks[1] a `blend`"),
        "{stderr}"
    );
    assert!(!dir.path().join("f").exists());
}

#[test]
fn with_blend_add_the_frames_carry_the_sum() {
    let text = spec(&format!(
        "{RAMP}\n    (target: \"sun\", blend: Add, brightness: [(at: 0, value: 0.25), (at: 1, value: -0.25)]),"
    ));
    let dir = project(&[("base.sdf", BALL), ("shot.ron", &text)]);
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
    assert!(ok && stderr.is_empty(), "{stderr}");
    let frames = frames(&dir.path().join("f"));
    assert_eq!(frames.len(), 9);
    for (i, (_, text)) in frames.iter().enumerate() {
        let t = i as f64 / 8.0;
        let (ramp, added) = (0.5 + t, 0.25 - 0.5 * t);
        let (b, _) = sun(text);
        assert!((b - (ramp + added)).abs() < 1e-6, "frame {i}: {b}");
    }
}

#[test]
fn multiply_scales_the_base_scene_s_value_and_replace_takes_over() {
    // BALL's sun has brightness 1 and colour (1, 1, 1).
    let text = spec(
        "    (target: \"sun\", blend: Multiply, brightness: Expr(\"0.5 + t\"), color: [(at: 0, value: (1, 0.5, 0.25))]),
    (target: \"sun\", blend: Replace, color: [(at: 0.5, value: (0, 1, 0))]),",
    );
    let dir = project(&[("base.sdf", BALL), ("shot.ron", &text)]);
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
    assert!(ok && stderr.is_empty(), "{stderr}");
    for (i, (_, text)) in frames(&dir.path().join("f")).iter().enumerate() {
        let t = i as f64 / 8.0;
        let (b, colour) = sun(text);
        assert!((b - (0.5 + t)).abs() < 1e-6, "frame {i}: {b}");
        // The later track's key holds from its time on, and before it as its first value.
        assert_eq!(colour, [0.0, 1.0, 0.0], "frame {i}");
    }
}

#[test]
fn a_blend_needs_a_value_and_a_combination_must_stay_in_range() {
    let text = spec("    (target: \"ball\", blend: Add, translate: [(at: 0, value: (1, 0, 0))]),");
    let dir = project(&[("base.sdf", BALL), ("shot.ron", &text)]);
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
    assert!(!ok);
    assert!(
        stderr.contains("`blend` combines the values a track sets"),
        "{stderr}"
    );
    let text = spec(&format!(
        "{RAMP}\n    (target: \"sun\", blend: Add, brightness: [(at: 0, value: -1)]),"
    ));
    let dir = project(&[("base.sdf", BALL), ("shot.ron", &text)]);
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
    assert!(!ok);
    assert!(
        stderr.contains("at frame 0 (t = 0 s) the brightness of 'sun' is -0.5, below 0"),
        "{stderr}"
    );
}
