//! Keyed lights and lenses (issue 42, "Keyable"): a light's radius and a spot's cone, a
//! camera's aperture and focus, `focus: Object(…)` (a rack focus) read back from the frame
//! files against formulas; their errors located; and the two example shots (animations/
//! rack.ron, penumbra.ron) generated, rendered and encoded.

use crate::animator::{frames, generate, line_with, numbers, project, repo, BALL};
use glam::DVec3;

/// The words after `keyword` on the first line starting with `prefix` (empty if none).
fn after(text: &str, prefix: &str, keyword: &str) -> Vec<f64> {
    let words = line_with(text, prefix);
    match words.iter().position(|w| *w == keyword) {
        Some(i) => numbers(&words[i + 1..]),
        None => Vec::new(),
    }
}

/// A camera line's eye and unit view direction.
fn view(text: &str, camera: &str) -> (DVec3, DVec3) {
    let v = numbers(&line_with(text, &format!("define camera {camera} "))[3..]);
    let eye = DVec3::new(v[1], v[2], v[3]);
    (eye, DVec3::new(v[4], v[5], v[6]).normalize())
}

#[test]
fn the_light_s_radius_grows_as_keyed() {
    let out = tempfile::tempdir().unwrap();
    let (ok, stderr) = generate(&repo().join("animations/penumbra.ron"), out.path());
    assert!(ok && stderr.is_empty(), "{stderr}");
    let frames = frames(out.path());
    assert_eq!(frames.len(), 25);
    for (i, (name, text)) in frames.iter().enumerate() {
        // EaseIn from 0 to 1.2 over 2 s: 1.2·s², s = t/2.
        let s = i as f64 / 12.0 / 2.0;
        let want = 1.2 * s * s;
        // Radius 0 is the point light, whose line has no radius clause.
        let got = after(text, "define light lamp", "radius")
            .first()
            .copied()
            .unwrap_or(0.0);
        assert!((got - want).abs() < 1e-6, "{name}: {got} vs {want}");
    }
}

#[test]
fn a_rack_focus_keeps_the_moving_ball_s_centre_in_focus_at_every_frame() {
    let out = tempfile::tempdir().unwrap();
    let (ok, stderr) = generate(&repo().join("animations/rack.ron"), out.path());
    assert!(ok && stderr.is_empty(), "{stderr}");
    let frames = frames(out.path());
    assert_eq!(frames.len(), 25);
    for (i, (name, text)) in frames.iter().enumerate() {
        let t = i as f64 / 12.0;
        // The ball's centre: (0, −0.55, −8) moved 7 towards the camera by EaseInOut.
        let s = t / 2.0;
        let centre = DVec3::new(0.0, -0.55, -8.0 + 7.0 * (3.0 * s * s - 2.0 * s * s * s));
        let (eye, dir) = view(text, "cam");
        let lens = after(text, "lens cam", "cam");
        let want = (centre - eye).dot(dir);
        assert!(
            (lens[1] - want).abs() < 1e-6,
            "{name}: {} vs {want}",
            lens[1]
        );
        // The aperture opens from 0.1 to 0.2 (two keys: a straight line).
        assert!(
            (lens[0] - (0.1 + 0.05 * t)).abs() < 1e-6,
            "{name}: {lens:?}"
        );
    }
}

#[test]
fn an_aimed_camera_focused_on_what_it_looks_at_focuses_at_its_distance() {
    let spec = "(scene: File(\"base.sdf\"), fps: 4, length: Seconds(1), end: Inclusive, resolution: (16, 9),
  tracks: [
    (target: \"ball\", translate: [(at: 0, value: (0, 0, 0)), (at: 1, value: (3, 1, -4))]),
    (target: \"cam\", translate: [(at: 0, value: (0, 0, 0)), (at: 1, value: (-2, 0, 0))],
     look_at: Object(\"ball\"), focus: Object(\"ball\"), aperture: [(at: 0, value: 0.3)]),
  ])";
    let dir = project(&[("base.sdf", BALL), ("shot.ron", spec)]);
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
    assert!(ok && stderr.is_empty(), "{stderr}");
    let frames = frames(&dir.path().join("f"));
    assert_eq!(frames.len(), 5);
    for (i, (name, text)) in frames.iter().enumerate() {
        let t = i as f64 / 4.0;
        let centre = DVec3::new(3.0, 1.0, -4.0) * t;
        let eye = DVec3::new(0.0, 0.0, 10.0) + DVec3::new(-2.0, 0.0, 0.0) * t;
        let lens = after(text, "lens cam", "cam");
        // The camera looks straight at the centre: it lies its whole distance along the view.
        let want = (centre - eye).length();
        assert!((lens[1] - want).abs() < 1e-6, "{name}: {lens:?} vs {want}");
        assert_eq!(lens[0], 0.3, "{name}");
    }
}

/// `anim generate`'s stderr for `tracks` over a base scene with a spot light `lamp`.
fn refused(tracks: &str) -> String {
    let base = format!("{BALL}define light lamp 0 5 0 1 1 1 1 spot 0 0 0 20 30\n");
    let spec = format!(
        "(scene: File(\"base.sdf\"), fps: 4, length: Seconds(1), resolution: (16, 9),\n  tracks: [\n{tracks}\n  ])"
    );
    let dir = project(&[("base.sdf", &base), ("shot.ron", &spec)]);
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
    assert!(!ok, "{stderr}");
    assert!(!dir.path().join("f").exists());
    stderr
}

#[test]
fn bad_radii_cones_apertures_and_focus_targets_are_located() {
    let e = refused("(target: \"lamp\", radius: [(at: 0, value: 1), (at: 1, value: -0.5)]),");
    assert!(
        e.contains("shot.ron:3:61: error: radius must not be negative"),
        "{e}"
    );
    let e =
        refused("(target: \"cam\", aperture: [(at: 0, value: -0.1)], focus: [(at: 0, value: 5)]),");
    assert!(
        e.contains("shot.ron:3:43: error: aperture must not be negative"),
        "{e}"
    );
    let e = refused("(target: \"cam\", focus: Object(\"bal\")),");
    assert!(
        e.contains("shot.ron:3:31: error: the base scene has no shape or composite named 'bal' to focus on"),
        "{e}"
    );
    assert!(e.contains("did you mean 'ball'?"), "{e}");
    let e = refused("(target: \"cam\", aperture: [(at: 0, value: 0.2)]),");
    assert!(
        e.contains("shot.ron:3:27: error: camera 'cam' has no lens line to focus it"),
        "{e}"
    );
    let e = refused("(target: \"sun\", inner: [(at: 0, value: 10)]),");
    assert!(
        e.contains("shot.ron:3:24: error: 'sun' is no spot light"),
        "{e}"
    );
    // A spot points at its line's target: `look_at` is refused, saying where the aim lives.
    let e = refused("(target: \"lamp\", look_at: Point((1, 0, 0))),");
    assert!(
        e.contains("shot.ron:3:27: error: 'lamp' is a light: `look_at` aims shapes, composites and cameras; a point light shines every way, and a spot points at the target of its `define light` line"),
        "{e}"
    );
    // Each half-angle in range, but the inner passes the outer (30°) after half a second.
    let e = refused("(target: \"lamp\", inner: [(at: 0, value: 10), (at: 1, value: 50)]),");
    assert!(
        e.contains("shot.ron:3:26: error: at frame 3 (t = 0.75 s) the spot 'lamp' has an inner half-angle of 40° and an outer one of 30°"),
        "{e}"
    );
    // The ball passes behind the camera (at z = 10).
    let e = refused("(target: \"ball\", translate: [(at: 0, value: (0, 0, 0)), (at: 1, value: (0, 0, 16))]),\n    (target: \"cam\", focus: Object(\"ball\")),");
    assert!(
        e.contains("error: at frame 3 (t = 0.75 s) 'ball' is not in front of camera 'cam'"),
        "{e}"
    );
}

#[test]
fn the_rack_focus_and_the_widening_shadow_render_and_encode() {
    let have_ffmpeg = std::process::Command::new("ffmpeg")
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !have_ffmpeg {
        use std::io::Write as _;
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED the_rack_focus_and_the_widening_shadow_render_and_encode: ffmpeg is not installed (apt-get install ffmpeg); CI installs it"
        );
        return;
    }
    for spec in ["rack.ron", "penumbra.ron"] {
        let out = tempfile::tempdir().unwrap();
        let video = out.path().join("shot.mp4");
        let run = std::process::Command::new(repo().join("scripts/animate.sh"))
            .arg(repo().join("animations").join(spec))
            .arg(&video)
            .env("ANIM", env!("CARGO_BIN_EXE_anim"))
            .env("FRAMES_DIR", out.path().join("frames"))
            .output()
            .expect("run animate.sh");
        assert!(
            run.status.success(),
            "{spec}: {}{}",
            String::from_utf8_lossy(&run.stdout),
            String::from_utf8_lossy(&run.stderr)
        );
        let images = std::fs::read_dir(out.path().join("frames"))
            .unwrap()
            .filter_map(Result::ok)
            .filter(|e| e.file_name().to_string_lossy().ends_with(".png"))
            .count();
        assert_eq!(images, 25, "{spec}");
        let probe = std::process::Command::new("ffprobe")
            .args(["-v", "error", "-count_frames", "-select_streams", "v:0"])
            .args(["-show_entries", "stream=nb_read_frames", "-of", "csv=p=0"])
            .arg(&video)
            .output()
            .expect("ffprobe");
        let counted = String::from_utf8_lossy(&probe.stdout).trim().to_string();
        assert_eq!(counted, "25", "{spec}");
    }
}
