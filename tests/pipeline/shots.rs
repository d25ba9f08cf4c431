//! The example shots that show expressions, parents and paths (animations/candle.ron, rig.ron
//! and flythrough.ron) do what their comments say, read back from their frames.

use crate::animator::{frames, generate, line_with, numbers, place, repo};
use glam::DVec3;

/// The whole frames of `animations/NAME`, generated without a word on stderr.
fn shot(name: &str) -> Vec<(String, String)> {
    let out = tempfile::tempdir().unwrap();
    let (ok, stderr) = generate(&repo().join("animations").join(name), out.path());
    assert!(ok && stderr.is_empty(), "{name}: {stderr}");
    frames(out.path())
}

#[test]
fn the_candle_flickers_the_same_way_every_time() {
    let first = shot("candle.ron");
    assert_eq!(first, shot("candle.ron"));
    let glow: Vec<f64> = first
        .iter()
        .map(|(_, text)| numbers(&line_with(text, "define light glow")[9..10])[0])
        .collect();
    assert_eq!(glow.len(), 96);
    // Lit from almost nothing over the first second…
    assert!(glow[0] < 0.1 && glow[24] > 0.8, "{glow:?}");
    // …then it flickers: the ramp is flat after 1 s, and the brightness still moves, within
    // the ±30 % the multiplier allows and never by a jump (noise is smooth).
    let after = &glow[24..];
    let (lo, hi) = after
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &g| (a.min(g), b.max(g)));
    assert!(hi - lo > 0.1, "{lo}..{hi}");
    assert!(
        lo >= 0.7 * 1.2 - 1e-6 && hi <= 1.3 * 1.2 + 1e-6,
        "{lo}..{hi}"
    );
    for w in after.windows(2) {
        assert!((w[1] - w[0]).abs() < 0.2, "{w:?}");
    }
}

#[test]
fn the_rig_carries_its_camera_and_its_lamp() {
    let frames = shot("rig.ron");
    assert_eq!(frames.len(), 97);
    let eye = DVec3::new(-4.0, 1.2, 0.0);
    let lamp = DVec3::new(0.0, 2.0, 0.0);
    for (name, text) in &frames {
        assert!(text.starts_with("# Frame ") && text.contains(" at 24000/1001 fps)"));
        // The camera is carried as a point of the cart would be, turn and all.
        let (cam, cart) = (place(text, "cam", eye), place(text, "cart", eye));
        assert!((cam - cart).length() < 1e-8, "{name}: {cam} vs {cart}");
        // The lamp only follows where the cart's centre goes.
        // The centre of the cart's box, from the body's foot (−0.7) to the knob's top (0.67).
        let centre = DVec3::new(0.0, -0.015, 0.0);
        let moved = place(text, "cart", centre) - centre;
        let at = place(text, "lamp", lamp);
        assert!((at - (lamp + moved)).length() < 1e-8, "{name}: {at}");
    }
    // It does drive: 12 along by the last frame.
    let last = &frames[96].1;
    assert!((place(last, "cam", eye) - eye).length() > 11.0);
}

#[test]
fn the_flythrough_flies_its_loop_at_constant_speed_facing_ahead() {
    let frames = shot("flythrough.ron");
    let eye0 = DVec3::new(0.0, 0.6, 6.0);
    let view0 = DVec3::new(-1.0, 0.0, 0.0);
    let eyes: Vec<DVec3> = frames.iter().map(|(_, t)| place(t, "cam", eye0)).collect();
    let n = eyes.len();
    assert_eq!(n, 144);
    // A closed loop: the step from the last frame back to the first is one more step.
    let steps: Vec<f64> = (0..n)
        .map(|i| (eyes[(i + 1) % n] - eyes[i]).length())
        .collect();
    let mean = steps.iter().sum::<f64>() / n as f64;
    for (i, s) in steps.iter().enumerate() {
        assert!((s - mean).abs() < 0.01 * mean, "step {i}: {s} vs {mean}");
    }
    for (i, (_, text)) in frames.iter().enumerate() {
        let view = (place(text, "cam", eye0 + view0) - eyes[i]).normalize();
        let heading = (eyes[(i + 1) % n] - eyes[(i + n - 1) % n]).normalize();
        assert!(view.dot(heading) > 0.99, "frame {i}: {view} vs {heading}");
    }
}
