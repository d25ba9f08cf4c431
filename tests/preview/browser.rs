//! The page in a real browser: headless Chromium driven by `scripts/preview-browser.py`
//! (Playwright). It waits for the frames, reads the pixels on screen, scrubs, edits the spec,
//! breaks and fixes it, edits the materials file the base scene includes; this test checks
//! what it saw. Where Chromium or Playwright is
//! missing the test says so and passes, unless `CI` is set: CI installs both (`.ci/run`).

use crate::common::media::psnr_per_frame;
use crate::common::read_ppm;
use crate::common::Rgb8;
use crate::session::{
    materials, red_floor, rendered_by_anim_render, spec, Preview, EDITED_KEY, FIRST_KEY, FRAMES,
    MATERIALS,
};
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

/// The floor, grey before, is red on screen once the materials file the base scene includes
/// says so (the script waits at most 5 s for the change to show): frame 0 as `anim render`
/// draws it then (`expected`).
fn the_included_edit_shows(dir: &Path, expected: &image::RgbImage) {
    assert!(
        same_pixels(&dir.join("included.ppm"), expected),
        "frame 0 after the edit of {MATERIALS}"
    );
    let (grey, reddened) = (
        read_ppm(&dir.join("edited.ppm")),
        read_ppm(&dir.join("included.ppm")),
    );
    let pixels = reddened.width * reddened.height;
    assert!(
        red_pixels(&reddened) > red_pixels(&grey) + pixels / 10,
        "{} red pixels before the edit of {MATERIALS}, {} after, of {pixels}",
        red_pixels(&grey),
        red_pixels(&reddened)
    );
}

/// The pixels of `image` whose red is over twice their green and their blue.
fn red_pixels(image: &Rgb8) -> usize {
    image
        .data
        .chunks_exact(3)
        .filter(|p| u32::from(p[0]) > 2 * u32::from(p[1]).max(u32::from(p[2])))
        .count()
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
    let before = rendered_by_anim_render(&spec(FIRST_KEY), &materials());
    let after = rendered_by_anim_render(&spec(EDITED_KEY), &materials());
    let red = red_floor(&materials());
    let red_after = rendered_by_anim_render(&spec(EDITED_KEY), &red);
    let out = tempfile::tempdir().unwrap();
    let edited = out.path().join("edited.ron");
    let broken = out.path().join("broken.ron");
    let red_materials = out.path().join("red.sdf");
    std::fs::write(&edited, spec(EDITED_KEY)).unwrap();
    std::fs::write(&broken, spec("(0, 1.5,, 0)")).unwrap();
    std::fs::write(&red_materials, &red).unwrap();
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
        .arg("--included")
        .arg(preview.dir.path().join(MATERIALS))
        .arg("--included-edited")
        .arg(&red_materials)
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
    the_included_edit_shows(dir, &red_after[0]);
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
    assert!(result.contains("\"included_edit_to_screen_s\""), "{result}");
    // Every climbing URL the browser sent was refused with a 4xx.
    assert!(result.contains("\"all_refused\": true"), "{result}");
    // Each arrow key steps one frame, whatever has the focus.
    let steps = key_steps(&result);
    assert_eq!(steps.len(), 5, "{result}");
    for (focus, before, after, key) in steps {
        let by = if key == "ArrowRight" { 1 } else { FRAMES - 1 };
        assert_eq!(after, (before + by) % FRAMES, "{key} on {focus}: {result}");
    }
    // Export encodes with ffmpeg where it is installed, and says how to install it where not.
    let ffmpeg = Command::new("ffmpeg").arg("-version").output().is_ok();
    if ffmpeg {
        assert!(result.contains("\"mp4\": true"), "{result}");
        the_export_is_at_full_quality(dir, &result, &after);
    } else {
        assert!(result.contains("apt-get install -y ffmpeg"), "{result}");
    }
    eprintln!("{said}");
}

/// `result.json`'s key steps: (focus, frame before, frame after, key).
fn key_steps(result: &str) -> Vec<(String, usize, usize, String)> {
    let steps = result.split("\"key_steps\": [").nth(1).expect("key_steps");
    let steps = &steps[..steps.find("]\n  ]").expect("the list's end") + 1];
    steps
        .split('[')
        .skip(1)
        .map(|step| {
            let fields: Vec<&str> = step
                .split(['"', ',', ']', '\n', ' '])
                .filter(|f| !f.is_empty())
                .collect();
            let number = |f: &str| f.parse().expect("a frame number");
            (
                fields[0].to_string(),
                number(fields[1]),
                number(fields[2]),
                fields[3].to_string(),
            )
        })
        .collect()
}

/// Export, pressed while the frames were drafts again, said so, waited, and encoded every
/// frame as `anim render` draws it (`expected`): at least 40 dB each, where an up-scaled
/// draft scores about 26.
fn the_export_is_at_full_quality(dir: &Path, result: &str, expected: &[image::RgbImage]) {
    assert!(
        result.contains("export: waiting for full quality"),
        "{result}"
    );
    assert!(
        result.contains(&format!("exported {FRAMES} frames at full quality")),
        "{result}"
    );
    for (i, image) in expected.iter().enumerate() {
        image.save(dir.join(format!("ref_{i:04}.png"))).unwrap();
    }
    let db = psnr_per_frame(&dir.join("export.mp4"), &dir.join("ref_%04d.png"));
    assert_eq!(db.len(), FRAMES, "{result}");
    for (i, db) in db.iter().enumerate() {
        assert!(*db >= 40.0, "exported frame {i}: {db:.1} dB");
    }
}
