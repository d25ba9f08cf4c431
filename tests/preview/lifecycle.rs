//! The preview's edges as a user meets them: `--export` encodes only full-quality frames and
//! refuses a wrong output (a missing folder, any file the preview reads) at once, before it
//! renders; SIGTERM and SIGHUP clean up as Ctrl-C does; the terminal prints each build's
//! diagnostics and says when the animation builds again.

use crate::common::media::{ffmpeg_for, psnr_per_frame, stream_field};
use crate::session::{
    all_full, materials, rendered_by_anim_render, spec, test_animation, Preview, FIRST_KEY, FRAMES,
    MATERIALS,
};
use std::path::Path;
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// `anim preview small.ron --export OUT` in `dir`, with its temporary folders in `dir/tmp`.
fn export(dir: &Path, out: &str) -> Output {
    let tmp = dir.join("tmp");
    let _ = std::fs::create_dir(&tmp);
    Command::new(env!("CARGO_BIN_EXE_anim"))
        .args(["preview", "small.ron", "--export", out])
        .current_dir(dir)
        .env("TMPDIR", &tmp)
        .output()
        .unwrap()
}

#[test]
fn export_encodes_every_frame_as_anim_render_draws_it() {
    if !ffmpeg_for("export_encodes_every_frame_as_anim_render_draws_it") {
        return;
    }
    let dir = test_animation();
    let run = export(dir.path(), "out.mp4");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert!(
        stderr.contains(&format!("({FRAMES} frames at full quality)")),
        "{stderr}"
    );
    let video = dir.path().join("out.mp4");
    assert_eq!(stream_field(&video, "codec_name"), "h264");
    let expected = rendered_by_anim_render(&spec(FIRST_KEY), &materials());
    let (w, h) = expected[0].dimensions();
    assert_eq!(stream_field(&video, "width"), w.to_string());
    assert_eq!(stream_field(&video, "height"), h.to_string());
    for (i, image) in expected.iter().enumerate() {
        image
            .save(dir.path().join(format!("ref_{i:04}.png")))
            .unwrap();
    }
    let db = psnr_per_frame(&video, &dir.path().join("ref_%04d.png"));
    assert_eq!(db.len(), FRAMES, "{FRAMES} frames");
    for (i, db) in db.iter().enumerate() {
        // A draft (a quarter of each side, one sample, scaled up) scores about 26 dB.
        assert!(*db >= 40.0, "frame {i}: {db:.1} dB");
    }
    assert_eq!(
        std::fs::read_dir(dir.path().join("tmp")).unwrap().count(),
        0
    );
}

#[test]
fn a_wrong_export_is_refused_at_once_and_writes_nothing() {
    let dir = test_animation();
    let mesh = "v -1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    std::fs::write(dir.path().join("tri.obj"), mesh).unwrap();
    let scene = dir.path().join("showcase.sdf");
    let base = std::fs::read_to_string(&scene).unwrap();
    std::fs::write(
        &scene,
        format!("{base}define shape obj tri tri.obj floor\n"),
    )
    .unwrap();
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    let inputs = [
        ("small.ron", "small.ron"),
        ("showcase.sdf", "showcase.sdf"),
        ("sub/../small.ron", "small.ron"),
        (MATERIALS, MATERIALS),
        ("tri.obj", "tri.obj"),
    ];
    for (out, input) in inputs {
        let before: Vec<Vec<u8>> = ["small.ron", "showcase.sdf", MATERIALS, "tri.obj"]
            .iter()
            .map(|f| std::fs::read(dir.path().join(f)).unwrap())
            .collect();
        let start = Instant::now();
        let run = export(dir.path(), out);
        let took = start.elapsed();
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{out}: {stderr}");
        assert_eq!(
            stderr.trim(),
            format!("error: --export {out}: that is {input}, which the preview reads; write the video elsewhere")
        );
        assert!(took < Duration::from_secs(1), "{out}: {took:?}");
        let after: Vec<Vec<u8>> = ["small.ron", "showcase.sdf", MATERIALS, "tri.obj"]
            .iter()
            .map(|f| std::fs::read(dir.path().join(f)).unwrap())
            .collect();
        assert!(before == after, "{out} changed an input");
    }
    // A folder that does not exist: said before anything renders, with the option and path.
    let start = Instant::now();
    let run = export(dir.path(), "missing dir/x.mp4");
    let took = start.elapsed();
    assert_eq!(run.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&run.stderr).trim(),
        "error: --export missing dir/x.mp4: the folder missing dir does not exist; make it first"
    );
    assert!(took < Duration::from_secs(1), "{took:?}");
    assert_eq!(
        std::fs::read_dir(dir.path().join("tmp")).unwrap().count(),
        0
    );
}

#[test]
fn sigterm_and_sighup_clean_up_as_ctrl_c_does() {
    for signal in ["TERM", "HUP"] {
        let mut preview = Preview::start();
        preview.wait_for(Duration::from_secs(60), |s| s.contains("\"builds\":1"));
        assert_eq!(preview.temporary_files(), 1);
        assert!(preview.signal(signal), "SIG{signal} did not end it cleanly");
        assert_eq!(
            preview.temporary_files(),
            0,
            "SIG{signal} left /tmp/anim-preview-*"
        );
    }
}

#[test]
fn the_terminal_prints_each_build_s_diagnostics_and_when_it_builds_again() {
    let preview = Preview::start();
    preview.wait_for(Duration::from_secs(60), all_full);
    let said = |what: &str| {
        let start = Instant::now();
        while !preview.terminal().contains(what) {
            let terminal = preview.terminal();
            assert!(
                start.elapsed() < Duration::from_secs(20),
                "no {what:?} in\n{terminal}"
            );
            std::thread::sleep(Duration::from_millis(50));
        }
    };
    std::fs::write(preview.spec_path(), spec("(0, 1.5,, 0)")).unwrap();
    // As `anim check` prints it: located, the line quoted.
    said("small.ron:10:");
    said("(0, 1.5,, 0)");
    std::fs::write(preview.spec_path(), spec(FIRST_KEY)).unwrap();
    said(&format!(
        "note: the animation builds again ({FRAMES} frames)"
    ));
    // Another error: printed too.
    let errors = |t: String| t.matches(": error:").count();
    let printed = errors(preview.terminal());
    std::fs::write(preview.spec_path(), spec("(0, 1.5, 0")).unwrap();
    let start = Instant::now();
    while errors(preview.terminal()) == printed {
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "{}",
            preview.terminal()
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    assert_eq!(
        preview.terminal().matches("builds again").count(),
        1,
        "{}",
        preview.terminal()
    );
}
