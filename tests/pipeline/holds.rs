//! Frames that show the same scene (a hold: nothing moves, the camera stands still) are
//! rendered once: the others get copies of its images, byte for byte what rendering them
//! alone writes, and their records say which frame they were copied from.

use assert_cmd::Command;
use std::path::Path;

/// A tiny frame of a sphere at `x`, 16×12 pixels, written to `image`. The comment differs
/// from frame to frame, as in generated frames.
fn frame_text(x: f64, image: &str, number: usize) -> String {
    format!(
        "# frame {number}\n\
         define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20\n\
         define shape sphere ball {x} 0 -5 1 red\n\
         define light sun 5 5 5 1 1 1 1\n\
         define camera cam 60\n\
         render cam {image} 16 12\n"
    )
}

fn render_dir(dir: &Path, extra: &[&str]) -> String {
    let out = Command::cargo_bin("anim")
        .expect("binary")
        .arg("render")
        .arg(dir)
        .args(extra)
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{stderr}");
    stderr
}

/// The image `sdf` writes when rendered alone, in a folder of its own.
fn rendered_alone(sdf: &Path, image: &str) -> Vec<u8> {
    let alone = tempfile::tempdir().expect("tempdir");
    let copy = alone.path().join(sdf.file_name().expect("a file"));
    std::fs::copy(sdf, &copy).expect("copy");
    Command::cargo_bin("anim")
        .expect("binary")
        .args(["render", "--quiet"])
        .arg(&copy)
        .assert()
        .success();
    std::fs::read(alone.path().join(image)).expect("the image")
}

#[test]
fn a_hold_renders_one_frame_and_copies_the_others_byte_for_byte() {
    let dir = tempfile::tempdir().expect("tempdir");
    for i in 0..24 {
        let text = frame_text(0.25, &format!("frame_{i:04}.png"), i);
        std::fs::write(dir.path().join(format!("frame_{i:04}.sdf")), text).expect("write");
    }
    let log = render_dir(dir.path(), &[]);
    assert!(
        log.contains("1 rendered, 23 copied (same scene as an earlier frame)"),
        "{log}"
    );
    let first = std::fs::read(dir.path().join("frame_0000.png")).expect("frame 0");
    for i in [1, 12, 23] {
        let image = format!("frame_{i:04}.png");
        let copied = std::fs::read(dir.path().join(&image)).expect("a copy");
        assert_eq!(copied, first, "{image}");
        let alone = rendered_alone(&dir.path().join(format!("frame_{i:04}.sdf")), &image);
        assert_eq!(copied, alone, "{image} against its frame rendered alone");
        let record = std::fs::read_to_string(anim_pipeline::frames::record_path(
            dir.path(),
            &format!("frame_{i:04}.sdf"),
        ))
        .expect("a record");
        assert!(record.contains("\nfrom frame_0000.sdf\n"), "{record}");
    }
    let again = render_dir(dir.path(), &[]);
    assert!(
        again.contains("0 rendered, 24 skipped (unchanged)"),
        "{again}"
    );
}

#[test]
fn only_frames_of_the_same_scene_and_image_format_are_copied() {
    let dir = tempfile::tempdir().expect("tempdir");
    let frames = [
        (0.0, "a_0.png"),
        (0.0, "a_1.png"),
        (0.5, "a_2.png"),
        (0.0, "a_3.png"),
        (0.0, "a_4.ppm"),
    ];
    for (i, (x, image)) in frames.iter().enumerate() {
        std::fs::write(
            dir.path().join(format!("a_{i}.sdf")),
            frame_text(*x, image, i),
        )
        .expect("write");
    }
    let log = render_dir(dir.path(), &[]);
    assert!(log.contains("3 rendered, 2 copied"), "{log}");
    for (i, (_, image)) in frames.iter().enumerate() {
        let written = std::fs::read(dir.path().join(image)).expect("an image");
        let alone = rendered_alone(&dir.path().join(format!("a_{i}.sdf")), image);
        assert_eq!(written, alone, "{image}");
    }
    let moved = std::fs::read(dir.path().join("a_2.png")).expect("a_2");
    assert_ne!(
        moved,
        std::fs::read(dir.path().join("a_0.png")).expect("a_0")
    );
    // A damaged copy is rendered again on the next run (its original is up to date, so
    // there is nothing rendered to copy from).
    std::fs::write(dir.path().join("a_3.png"), b"damaged").expect("damage");
    let again = render_dir(dir.path(), &[]);
    assert!(again.contains("1 rendered, 4 skipped"), "{again}");
}
