//! Expressions and noise through `anim generate`: a whole channel as a formula of the frame's
//! time, a formula over keys, named values, located errors inside the string, and noise that
//! is the same every run and smooth.

use crate::animator::{frames, generate, line_with, numbers, project, BALL};
use std::f64::consts::TAU;

/// A spec over [`BALL`] at 24 fps for one second, with `extra` top-level fields and `tracks`.
fn spec(extra: &str, tracks: &str) -> String {
    format!(
        "(scene: File(\"base.sdf\"), fps: 24, length: Seconds(1), resolution: (16, 9),{extra}
  tracks: [{tracks}])"
    )
}

/// The brightness the `sun` line of each frame carries.
fn brightness(text: &str) -> f64 {
    // define light sun x y z r g b brightness
    numbers(&line_with(text, "define light sun")[3..])[6]
}

fn run(files: &[(&str, &str)]) -> (tempfile::TempDir, Vec<(String, String)>) {
    let dir = project(files);
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
    assert!(ok && stderr.is_empty(), "{stderr}");
    let frames = frames(&dir.path().join("f"));
    (dir, frames)
}

#[test]
fn a_brightness_expression_is_the_formula_at_every_frame_s_time() {
    let (_dir, frames) = run(&[
        ("base.sdf", BALL),
        (
            "shot.ron",
            &spec(
                "",
                "(target: \"sun\", brightness: Expr(\"1 + 0.5 * sin(tau * t)\"))",
            ),
        ),
    ]);
    assert_eq!(frames.len(), 24);
    for (i, (_, text)) in frames.iter().enumerate() {
        let t = i as f64 / 24.0;
        let want = 1.0 + 0.5 * (TAU * t).sin();
        let got = brightness(text);
        assert!((got - want).abs() < 1e-6, "frame {i}: {got} vs {want}");
    }
}

#[test]
fn an_expression_reads_keys_as_value_and_the_spec_s_named_values() {
    let (_dir, frames) = run(&[
        ("base.sdf", BALL),
        (
            "shot.ron",
            &spec(
                "\n  values: {\"base\": 2, \"swing\": \"base * 0.25\"},",
                "(target: \"sun\", brightness: Expr(\"value + swing * frame / fps\", [(at: 0, value: 1), (at: 1, value: 5)]))",
            ),
        ),
    ]);
    for (i, (_, text)) in frames.iter().enumerate() {
        let t = i as f64 / 24.0;
        // Linear keys from 1 to 5, plus 0.5·t.
        let want = 1.0 + 4.0 * t + 0.5 * t;
        assert!((brightness(text) - want).abs() < 1e-6, "frame {i}");
    }
    // With no keys, `value` is the base scene's brightness (1).
    let (_dir, frames) = run(&[
        ("base.sdf", BALL),
        (
            "shot.ron",
            &spec("", "(target: \"sun\", brightness: Expr(\"value * 3\"))"),
        ),
    ]);
    assert!(frames.iter().all(|(_, text)| brightness(text) == 3.0));
}

#[test]
fn a_malformed_expression_is_an_error_at_its_column_inside_the_string() {
    let text = spec(
        "",
        "(target: \"sun\", brightness: Expr(\"1 + 0.5 * sn(tau * t)\"))",
    );
    let dir = project(&[("base.sdf", BALL), ("shot.ron", &text)]);
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
    assert!(!ok);
    // Line 2 of the spec; the string opens at column 44, `sn` is its 11th character.
    let line = text.lines().nth(1).unwrap();
    let col = line.find("sn(").unwrap() + 1;
    assert!(
        stderr.contains(&format!("shot.ron:2:{col}: error: unknown function `sn`")),
        "{stderr}"
    );
    assert!(stderr.contains("^^"), "{stderr}");
    assert!(!dir.path().join("f").exists());
    // Inside a raw string over two lines, after an escaped quote in a plain one.
    let text = spec(
        "",
        "(target: \"sun\", brightness: Expr(r#\"1 +\n      0.5 * sin(tau * tt)\"#))",
    );
    let dir = project(&[("base.sdf", BALL), ("shot.ron", &text)]);
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
    assert!(!ok);
    assert!(
        stderr.contains("shot.ron:3:23: error: unknown name `tt`"),
        "{stderr}"
    );
    assert!(stderr.contains("did you mean `t`?"), "{stderr}");
    // A vector where a number belongs, and a name that is not `Expr`.
    let text = spec(
        "",
        "(target: \"sun\", brightness: Expr(\"(1, 2, 3)\"), color: Exp(\"1\"))",
    );
    let dir = project(&[("base.sdf", BALL), ("shot.ron", &text)]);
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
    assert!(!ok);
    assert!(
        stderr.contains("gives a vector (x, y, z), but brightness is a number"),
        "{stderr}"
    );
    assert!(
        stderr.contains("write an expression as `Expr(\"…\")`"),
        "{stderr}"
    );
}

#[test]
fn an_expression_that_gives_no_number_is_an_error_naming_the_frame() {
    let text = spec("", "(target: \"sun\", brightness: Expr(\"sqrt(0.5 - t)\"))");
    let dir = project(&[("base.sdf", BALL), ("shot.ron", &text)]);
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
    assert!(!ok);
    assert!(
        stderr.contains("at frame 12 (between t = 0.5 and 0.541666666667 s)"),
        "{stderr}"
    );
    assert!(
        stderr.contains("the expression gives no number there"),
        "{stderr}"
    );
}

#[test]
fn noise_flickers_the_same_way_every_run_and_smoothly() {
    let text = |fps: u32| {
        spec(
            "",
            "(target: \"sun\", brightness: Expr(\"1 + 0.3 * noise(t * 4)\")),
             (target: \"ball\", translate: Expr(\"wiggle(2, 0.5)\"))",
        )
        .replace("fps: 24", &format!("fps: {fps}"))
    };
    let (_a, first) = run(&[("base.sdf", BALL), ("shot.ron", &text(24))]);
    let (_b, second) = run(&[("base.sdf", BALL), ("shot.ron", &text(24))]);
    assert_eq!(first, second);
    let values = |frames: &[(String, String)]| -> Vec<f64> {
        frames.iter().map(|(_, t)| brightness(t)).collect()
    };
    let at24 = values(&first);
    assert!(at24.iter().any(|v| (v - 1.0).abs() > 0.01), "{at24:?}");
    assert!(at24.iter().all(|v| (v - 1.0).abs() <= 0.3), "{at24:?}");
    // Smooth: halving the step quarters the largest second difference, as it does for a
    // curve with a continuous second derivative (a kink or a jump would not shrink so).
    let (_c, fine) = run(&[("base.sdf", BALL), ("shot.ron", &text(48))]);
    let at48 = values(&fine);
    let bend = |v: &[f64]| {
        v.windows(3)
            .map(|w| (w[0] - 2.0 * w[1] + w[2]).abs())
            .fold(0.0, f64::max)
    };
    let (coarse, fine) = (bend(&at24), bend(&at48));
    assert!(coarse / fine > 3.0, "{coarse} then {fine}");
}
