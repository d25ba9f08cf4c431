//! The page in a real browser: headless Chromium driven by `scripts/preview-browser.py`
//! (Playwright). It waits for the frames, reads the pixels on screen, scrubs, edits the spec,
//! breaks and fixes it; this test checks what it saw. Where Chromium or Playwright is
//! missing the test says so and passes, unless `CI` is set: CI installs both (`.ci/run`).

use crate::common::read_ppm;
use crate::session::{rendered_by_anim_render, spec, Preview, EDITED_KEY, FIRST_KEY, FRAMES};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

fn chromium() -> PathBuf {
    std::env::var_os("ANIM_CHROMIUM")
        .map_or_else(|| PathBuf::from("/usr/bin/chromium"), PathBuf::from)
}

/// Why the browser test cannot run here, if it cannot.
fn missing() -> Option<String> {
    if !chromium().is_file() {
        return Some(format!("no Chromium at {}", chromium().display()));
    }
    let playwright = Command::new("python3")
        .args(["-c", "import playwright.sync_api"])
        .output();
    match playwright {
        Ok(out) if out.status.success() => None,
        _ => Some("no Playwright for python3 (pip install playwright)".to_string()),
    }
}

fn same_pixels(shown: &Path, expected: &image::RgbImage) -> bool {
    let shown = read_ppm(shown);
    shown.width == expected.width() as usize
        && shown.height == expected.height() as usize
        && shown.data == expected.as_raw().as_slice()
}

#[test]
fn the_page_plays_scrubs_and_follows_edits_in_chromium() {
    if let Some(why) = missing() {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI must run the browser test: {why}"
        );
        // Straight to stderr: the test harness captures `eprintln!` of a passing test.
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED tests/preview/browser.rs: {why} (CI installs both: .ci/run)"
        );
        return;
    }
    let preview = Preview::start();
    let before = rendered_by_anim_render(&spec(FIRST_KEY));
    let after = rendered_by_anim_render(&spec(EDITED_KEY));
    let out = tempfile::tempdir().unwrap();
    let edited = out.path().join("edited.ron");
    let broken = out.path().join("broken.ron");
    std::fs::write(&edited, spec(EDITED_KEY)).unwrap();
    std::fs::write(&broken, spec("(0, 1.5,, 0)")).unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/preview-browser.py");
    let run = Command::new("python3")
        .arg(script)
        .args(["--url", &format!("http://127.0.0.1:{}/", preview.port)])
        .arg("--spec")
        .arg(preview.spec_path())
        .arg("--edited")
        .arg(&edited)
        .arg("--broken")
        .arg(&broken)
        .args(["--frames", &FRAMES.to_string()])
        .arg("--out")
        .arg(out.path())
        .arg("--chromium")
        .arg(chromium())
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&run.stdout).into_owned();
    assert!(
        run.status.success(),
        "the browser driver failed:\n{said}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let dir = out.path();
    assert!(
        same_pixels(&dir.join("first.ppm"), &before[0]),
        "frame 0 on screen"
    );
    assert!(
        same_pixels(&dir.join("last.ppm"), &before[FRAMES - 1]),
        "the last frame on screen"
    );
    assert!(
        same_pixels(&dir.join("edited.ppm"), &after[0]),
        "frame 0 after the edit"
    );
    let result = std::fs::read_to_string(dir.join("result.json")).unwrap();
    assert!(result.contains("frame 2 / 5 · 0.25 s"), "{result}");
    assert!(result.contains("\"key_marks\": 2"), "{result}");
    assert!(result.contains("\"played\": true"), "{result}");
    assert!(result.contains("\"stepped\": true"), "{result}");
    // The diagnostic as the terminal prints it: file:line:col, the quoted line, the caret.
    assert!(result.contains("small.ron:10:"), "{result}");
    assert!(
        result.contains("(0, 1.5,, 0)") && result.contains('^'),
        "{result}"
    );
    assert!(result.contains("\"frame_kept\": true"), "{result}");
    // Every climbing URL the browser sent was refused with a 4xx.
    assert!(result.contains("\"all_refused\": true"), "{result}");
    // Export encodes with ffmpeg where it is installed, and says how to install it where not.
    let ffmpeg = Command::new("ffmpeg").arg("-version").output().is_ok();
    if ffmpeg {
        assert!(result.contains("\"mp4\": true"), "{result}");
    } else {
        assert!(result.contains("apt-get install -y ffmpeg"), "{result}");
    }
    eprintln!("{said}");
}
