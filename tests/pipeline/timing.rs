//! Time as animators count it: keys at `Frames(n)`, fractional frame rates carried exactly to
//! the frame headers and the encoder, and `--frames A..B` for `anim generate` and
//! `anim render DIR`.

use crate::animator::{frames, generate, project, BALL};
use crate::common;
use std::path::Path;

fn hop(at: &str, fps: &str, length: &str) -> String {
    format!(
        "(scene: File(\"base.sdf\"), fps: {fps}, length: {length}, resolution: (16, 9),
  tracks: [(target: \"ball\", translate: [
      (at: 0, value: (0, 0, 0), interp: EaseInOut), (at: {at}, value: (0, 2, 0))])])"
    )
}

#[test]
fn a_key_at_frames_12_at_24_fps_is_the_key_at_half_a_second() {
    let seconds = project(&[
        ("base.sdf", BALL),
        ("shot.ron", &hop("0.5", "24", "Seconds(1)")),
    ]);
    let counted = project(&[
        ("base.sdf", BALL),
        ("shot.ron", &hop("Frames(12)", "24", "Seconds(1)")),
    ]);
    for dir in [&seconds, &counted] {
        let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
        assert!(ok && stderr.is_empty(), "{stderr}");
    }
    let (a, b) = (
        frames(&seconds.path().join("f")),
        frames(&counted.path().join("f")),
    );
    assert_eq!(a.len(), 24);
    assert_eq!(a, b);
    // `Seconds(s)` is accepted too, and a misspelt unit is located.
    let spelled = project(&[
        ("base.sdf", BALL),
        ("shot.ron", &hop("Seconds(0.5)", "24", "Seconds(1)")),
    ]);
    let (ok, _) = generate(&spelled.path().join("shot.ron"), &spelled.path().join("f"));
    assert!(ok);
    assert_eq!(frames(&spelled.path().join("f")), a);
    let wrong = project(&[
        ("base.sdf", BALL),
        ("shot.ron", &hop("Fraems(12)", "24", "Seconds(1)")),
    ]);
    let (ok, stderr) = generate(&wrong.path().join("shot.ron"), &wrong.path().join("f"));
    assert!(!ok);
    assert!(
        stderr.contains("shot.ron:3:")
            && stderr.contains("expected a number of seconds, or `Frames(n)`"),
        "{stderr}"
    );
}

#[test]
fn ntsc_rates_are_exact_ratios_in_every_frame_header() {
    for (fps, ratio) in [
        ("23.976", "24000/1001"),
        ("\"24000/1001\"", "24000/1001"),
        ("29.97", "30000/1001"),
        ("\"60000/1001\"", "60000/1001"),
    ] {
        let dir = project(&[
            ("base.sdf", BALL),
            ("shot.ron", &hop("1", fps, "Seconds(2)")),
        ]);
        let (ok, stderr) = generate(&dir.path().join("shot.ron"), &dir.path().join("f"));
        assert!(ok && stderr.is_empty(), "{fps}: {stderr}");
        let frames = frames(&dir.path().join("f"));
        // Two seconds of timecode: 48, 60 or 120 frames, whatever the exact rate.
        let whole: usize = ratio.split('/').next().unwrap().parse::<usize>().unwrap() / 1000;
        assert_eq!(frames.len(), 2 * whole, "{fps}");
        for (i, (_, text)) in frames.iter().enumerate() {
            let t = i as f64 * 1001.0 / (whole as f64 * 1000.0);
            let header = text.lines().next().unwrap();
            let written: f64 = header
                .split("(t = ")
                .nth(1)
                .and_then(|r| r.split(' ').next())
                .and_then(|n| n.parse().ok())
                .unwrap_or_else(|| panic!("{header}"));
            assert!((written - t).abs() < 1e-9, "{header}: t = {t}");
            assert!(
                header.contains(&format!(
                    " s at {ratio} fps), generated from shot.ron by anim "
                )),
                "{header}"
            );
        }
    }
}

#[test]
fn a_23_976_fps_video_is_encoded_at_24000_over_1001() {
    let have = |tool: &str| {
        std::process::Command::new(tool)
            .arg("-version")
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if !have("ffmpeg") || !have("ffprobe") {
        use std::io::Write as _;
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED a_23_976_fps_video_is_encoded_at_24000_over_1001: ffmpeg is not installed (apt-get install ffmpeg); CI installs it"
        );
        return;
    }
    let dir = project(&[
        ("base.sdf", BALL),
        ("shot.ron", &hop("1", "23.976", "Seconds(2)")),
    ]);
    let out = dir.path().join("f");
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &out);
    assert!(ok, "{stderr}");
    let render = common::anim()
        .args(["render", "--spp", "1", "-q"])
        .arg(&out)
        .output()
        .expect("render");
    assert!(render.status.success(), "{render:?}");
    // The header carries the exact ratio, and the encoder reads it from there: no rate given.
    let header = frames(&out)[0].1.lines().next().unwrap().to_string();
    let fps = header
        .split(" fps)")
        .next()
        .and_then(|h| h.rsplit(' ').next())
        .unwrap()
        .to_string();
    assert_eq!(fps, "24000/1001");
    let video = dir.path().join("shot.mp4");
    let encode = std::process::Command::new(crate::animator::repo().join("scripts/encode.sh"))
        .arg(&out)
        .arg(&video)
        .output()
        .expect("encode");
    assert!(
        encode.status.success(),
        "{}",
        String::from_utf8_lossy(&encode.stderr)
    );
    let probe = std::process::Command::new("ffprobe")
        .args(["-v", "error", "-select_streams", "v:0", "-count_frames"])
        .args([
            "-show_entries",
            "stream=r_frame_rate,nb_read_frames",
            "-of",
            "csv=p=0",
        ])
        .arg(&video)
        .output()
        .expect("ffprobe");
    let said = String::from_utf8_lossy(&probe.stdout);
    assert_eq!(said.trim(), "24000/1001,48", "{said}");
}

#[test]
fn render_dir_frames_10_to_19_renders_exactly_those_ten() {
    let dir = project(&[
        ("base.sdf", BALL),
        ("shot.ron", &hop("1", "24", "Seconds(2)")),
    ]);
    let out = dir.path().join("f");
    let (ok, stderr) = generate(&dir.path().join("shot.ron"), &out);
    assert!(ok, "{stderr}");
    let render = common::anim()
        .args(["render", "--spp", "1", "--frames", "10..19"])
        .arg(&out)
        .output()
        .expect("render");
    let stderr = String::from_utf8_lossy(&render.stderr);
    assert!(render.status.success(), "{stderr}");
    assert!(
        stderr.contains("frames 10..19 (10 of 48 frames): 10 rendered"),
        "{stderr}"
    );
    let rendered: Vec<usize> = (0..48)
        .filter(|i| out.join(format!("frame_{i:04}.png")).exists())
        .collect();
    assert_eq!(rendered, (10..=19).collect::<Vec<_>>());
    for bad in ["19..10", "x..3", "1..2..3"] {
        let run = common::anim()
            .args(["render", "--frames", bad])
            .arg(&out)
            .output()
            .expect("render");
        assert!(!run.status.success(), "{bad}");
    }
}

#[test]
fn generate_frames_10_to_19_writes_those_frames_as_a_full_run_does() {
    let dir = project(&[
        ("base.sdf", BALL),
        ("shot.ron", &hop("1", "24", "Seconds(2)")),
    ]);
    let spec = dir.path().join("shot.ron");
    let run = |out: &Path, range: Option<&str>| {
        let mut cmd = common::anim();
        cmd.arg("generate").arg(&spec).arg("-o").arg(out);
        if let Some(r) = range {
            cmd.args(["--frames", r]);
        }
        let o = cmd.output().expect("generate");
        assert!(o.status.success(), "{o:?}");
    };
    let (full, part) = (dir.path().join("full"), dir.path().join("part"));
    run(&full, None);
    run(&part, Some("10..19"));
    let written = frames(&part);
    let names: Vec<&str> = written.iter().map(|(n, _)| n.as_str()).collect();
    let expected: Vec<String> = (10..=19).map(|i| format!("frame_{i:04}.sdf")).collect();
    assert_eq!(names, expected);
    let whole = frames(&full);
    assert_eq!(written[..], whole[10..=19]);
    assert_eq!(
        std::fs::read(part.join("static.sdfi")).unwrap(),
        std::fs::read(full.join("static.sdfi")).unwrap()
    );
    // A range past the animation's end is refused.
    let o = common::anim()
        .arg("generate")
        .arg(&spec)
        .args(["--frames", "48.."])
        .arg("-o")
        .arg(dir.path().join("none"))
        .output()
        .expect("generate");
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("the animation's last frame is 47"));
}
