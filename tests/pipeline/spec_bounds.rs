//! Issue 45 (10e): a spec's extreme finite numbers (a 1e308 quaternion, `cycles` of 2^64−1, a
//! period of 1e-300 s, and the other fields that take a number) are refused by `anim generate`
//! at the number, saying the range allowed and showing numbers readably, before any frame is
//! written.

use crate::common::anim;

const BASE: &str = "define material m 0.1 0.1 0.1 0.5 0.5 0.5 0 0 0 1\n\
                    define light l 0 5 0 1 1 1 1\n\
                    define shape sphere ball 0 0 -5 1 m\n\
                    define camera cam 60 0 0 0 0 0 -1 0 1 0\n";

/// A spec with `extra` as its fields after the camera.
fn spec(extra: &str) -> String {
    format!(
        "(scene: File(\"base.sdf\"), camera: \"cam\", length: Frames(3), resolution: (8, 8),\n{extra})\n"
    )
}

fn track(fields: &str) -> String {
    spec(&format!(" tracks: [(target: \"ball\", {fields})]"))
}

/// Generates `text` and returns its error output, checking that it failed, wrote no frame,
/// and shows no number in its messages of more than a dozen digits.
fn refused(text: &str) -> String {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("base.sdf"), BASE).unwrap();
    let spec = tmp.path().join("spec.ron");
    std::fs::write(&spec, text).unwrap();
    let out_dir = tmp.path().join("frames");
    let out = anim()
        .arg("generate")
        .arg(&spec)
        .arg("-o")
        .arg(&out_dir)
        .output()
        .expect("anim runs");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let frames = std::fs::read_dir(&out_dir).map_or(0, |d| d.count());
    assert_eq!(frames, 0, "{stderr}");
    // The messages, not the quoted spec lines under them; significant digits only.
    let longest_number = stderr
        .lines()
        .filter(|l| l.contains(": error: "))
        .flat_map(|l| l.split(|c: char| !c.is_ascii_digit()))
        .map(|digits| digits.trim_start_matches('0').len())
        .max()
        .unwrap_or(0);
    assert!(longest_number <= 12, "{stderr}");
    stderr
}

/// The 1-based line and column of the first `marker` in `text`.
fn position(text: &str, marker: &str) -> (usize, usize) {
    let at = text.find(marker).expect(marker);
    let line = text[..at].matches('\n').count() + 1;
    let col = at - text[..at].rfind('\n').map_or(0, |n| n + 1) + 1;
    (line, col)
}

#[test]
fn extreme_numbers_are_refused_at_the_number_with_the_range() {
    let range = "must lie between -1e12 and 1e12, not 1e308";
    // (spec, the text the error points at, what it says)
    let cases = [
        (
            track("orient: [(at: 0, value: Quat(x: 1e308, y: 1e308, z: 0, w: 1)), (at: 0.1, value: Quat(x: 0, y: 0, z: 0, w: 1))]"),
            "Quat(x: 1e308",
            "each part of a quaternion must lie between -1e12 and 1e12, not 1e308",
        ),
        (
            track("cycle: Repeat, cycles: 18446744073709551615, translate: [(at: 0, value: (0, 0, 0)), (at: 0.1, value: (1, 0, 0))]"),
            "18446744073709551615",
            "cycles must be a whole number from 1 to 4294967295, not 1.84467440737e19",
        ),
        (
            track("translate: [(at: 0, value: (1e308, 0, 0)), (at: 0.1, value: (0, 0, 0))]"),
            "(1e308",
            range,
        ),
        (
            track("rotate: [(at: 0, value: 0), (at: 0.1, value: -1e308)]"),
            "-1e308",
            "must lie between -1e12 and 1e12, not -1e308",
        ),
        (
            track("orient: [(at: 0, value: Euler(0, 1e308, 0)), (at: 0.1, value: Euler(0, 0, 0))]"),
            "Euler(0, 1e308",
            range,
        ),
        (
            track("orient: [(at: 0, value: AxisAngle((0, 1, 0), 1e308)), (at: 0.1, value: Euler(0, 0, 0))]"),
            "AxisAngle",
            range,
        ),
        (
            track("offset: 1e308, translate: [(at: 0, value: (0, 0, 0)), (at: 0.1, value: (1, 0, 0))]"),
            "1e308",
            range,
        ),
        (
            track("translate: [(at: 0, value: (0, 0, 0)), (at: 1e308, value: (1, 0, 0))]"),
            "1e308",
            range,
        ),
        (
            track("look_at: Point((0, 0, 1e308))"),
            "Point",
            range,
        ),
        (
            track("look_at: Point((0, 0, 0)), up: (0, 1e308, 0)"),
            "(0, 1e308",
            range,
        ),
        (
            track("axis: (0, 1e308, 0), rotate: [(at: 0, value: 0), (at: 0.1, value: 90)]"),
            "(0, 1e308",
            range,
        ),
        (
            track("path: (points: [(0, 0, 0), (1e308, 0, 0)])"),
            "(1e308",
            range,
        ),
        (
            spec(" orbit: (center: (0, 0, 0), radius: 1, height: 1e308)"),
            "1e308",
            range,
        ),
    ];
    for (text, marker, says) in cases {
        let stderr = refused(&text);
        let (line, col) = position(&text, marker);
        let located = format!("spec.ron:{line}:{col}: error: ");
        assert!(
            stderr
                .lines()
                .any(|l| l.contains(&located) && l.contains(says)),
            "expected {located}… {says}\nfor {text}\ngot {stderr}"
        );
    }
}

/// Keys in range that repeat with `RepeatOffset` every 1e-300 s add up past the range within
/// the first frame: refused at the last key's time, which sets the period.
#[test]
fn a_period_too_short_for_its_repeats_is_refused_at_the_key_time() {
    let text = track(
        "cycle: RepeatOffset, translate: [(at: 0, value: (0, 0, 0)), (at: 1e-300, value: (1, 0, 0))]",
    );
    let stderr = refused(&text);
    let (line, col) = position(&text, "1e-300");
    let located = format!("spec.ron:{line}:{col}: error: at frame 0 ");
    assert!(
        stderr.lines().any(|l| l.contains(&located)
            && l.contains("every 1e-300 s")
            && l.contains("values must lie between -1e12 and 1e12")),
        "{stderr}"
    );
    // The same keys repeating plainly stay in range.
    let plain = text.replace("RepeatOffset", "Repeat");
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("base.sdf"), BASE).unwrap();
    std::fs::write(tmp.path().join("spec.ron"), plain).unwrap();
    let out = anim()
        .arg("generate")
        .arg(tmp.path().join("spec.ron"))
        .arg("-o")
        .arg(tmp.path().join("frames"))
        .arg("--quiet")
        .output()
        .expect("anim runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The spec's own fields (shutter, rate, length) at the ends of the floats are refused with
/// their numbers written short, at the field.
#[test]
fn extreme_shutters_rates_and_lengths_are_refused_with_short_numbers() {
    let with = |fields: &str| {
        format!("(scene: File(\"base.sdf\"), camera: \"cam\", resolution: (8, 8),\n{fields})\n")
    };
    for (fields, marker, says) in [
        (
            "length: Frames(3), shutter: 1e300",
            "1e300",
            "shutter must be 0 (no motion blur) or a fraction of the frame interval greater than 0 and at most 1, not 1e300",
        ),
        (
            "length: Frames(3), shutter: -1e300",
            "-1e300",
            "not -1e300",
        ),
        ("length: Frames(3), fps: 1e300", "1e300", "or a ratio \"A/B\", not 1e300"),
        ("length: Frames(3), fps: 1e-300", "1e-300", "or a ratio \"A/B\", not 1e-300"),
        (
            "length: Seconds(1e300)",
            "Seconds",
            "2.4e301 frames is more than the 1000000 allowed",
        ),
        (
            "length: Seconds(1e-300)",
            "Seconds",
            "1e-300 s at 24 fps is less than one frame",
        ),
        (
            "length: Frames(18446744073709551615)",
            "Frames",
            "1.84467440737e19 frames is more than the 1000000 allowed",
        ),
        (
            "length: Frames(1e-300)",
            "Frames",
            "the number of frames must be a whole number, at least 1, not 1e-300",
        ),
    ] {
        let text = with(fields);
        let stderr = refused(&text);
        let (line, _) = position(&text, marker);
        let located = format!("spec.ron:{line}:");
        assert!(
            stderr
                .lines()
                .any(|l| l.contains(&located) && l.contains(": error: ") && l.contains(says)),
            "expected {located}… {says}\nfor {text}\ngot {stderr}"
        );
    }
}
