//! Frames are what they say: a frame `anim generate` wrote (and the static part it includes)
//! is read canonically, with no guess of any kind, by `anim render DIR`, `anim check` and the
//! generator's own first-frame check.

use crate::animator::{frames, generate, project};
use crate::common;

/// A grey floor and, in front of it, a red ball whose material the spec fades.
const STAGE: &str = "define material floor 0.3 0.3 0.3 0.6 0.6 0.6 0 0 0 1
define material ghost 0.2 0 0 0.9 0 0 0 0 0 10 0 1 1
define shape plane ground 0 -1 0 0 1 0 floor
define shape sphere ball 0 0 0 1 ghost
define light sun 4 6 8 1 1 1 1
define camera cam 50 0 0.5 6 0 -0.1 -1 0 1 0
";

/// Opacity from 0 to 1 over one second, 9 frames with the last at 1 s.
const FADE: &str = "(scene: File(\"stage.sdf\"), fps: 8, length: Seconds(1), end: Inclusive,
  resolution: (24, 18), output: \"frame_{frame}.ppm\",
  tracks: [(target: \"ghost\", opacity: [(at: 0, value: 0), (at: 1, value: 1)])])";

/// How red the image is: the red channel's excess over green, summed over the pixels.
fn redness(img: &common::Rgb8) -> i64 {
    let mut sum = 0i64;
    for y in 0..img.height {
        for x in 0..img.width {
            let [r, g, _] = img.at(x, y);
            sum += i64::from(r) - i64::from(g);
        }
    }
    sum
}

#[test]
fn a_fade_from_opacity_0_shows_nothing_first_all_last_and_grows_in_between() {
    let dir = project(&[("stage.sdf", STAGE), ("fade.ron", FADE)]);
    let out = dir.path().join("frames");
    // Split frames: the floor's material lives in static.sdfi, the keyed one in the frames.
    let run = common::anim()
        .arg("generate")
        .arg(dir.path().join("fade.ron"))
        .arg("-o")
        .arg(&out)
        .output()
        .expect("run anim");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success() && stderr.is_empty(), "{stderr}");
    let first = &frames(&out)[0].1;
    assert!(
        first.contains("define material ghost 0.2 0 0 0.9 0 0 0 0 0 10 0 0 1"),
        "{first}"
    );
    let render = common::anim()
        .args(["render", "--spp", "4"])
        .arg(&out)
        .output()
        .expect("render");
    let stderr = String::from_utf8_lossy(&render.stderr);
    assert!(render.status.success(), "{stderr}");
    assert!(!stderr.contains("warning"), "{stderr}");
    let check = common::anim()
        .arg("check")
        .arg(&out)
        .output()
        .expect("check");
    assert!(
        check.status.success() && check.stderr.is_empty(),
        "{check:?}"
    );

    // Without the ball: the stage alone, as frame 0 must look.
    let empty = STAGE.replace("define shape sphere ball 0 0 0 1 ghost\n", "");
    let bare = common::render_ppm(
        &format!("{empty}render cam image.ppm 24 18\n"),
        &["--spp", "4"],
    );
    let bare_redness = redness(&bare);
    let reds: Vec<i64> = (0..9)
        .map(|i| redness(&common::read_ppm(&out.join(format!("frame_{i:04}.ppm")))))
        .collect();
    assert_eq!(reds[0], bare_redness, "frame 0 shows the ball: {reds:?}");
    for pair in reds.windows(2) {
        assert!(pair[1] > pair[0], "opacity must grow every frame: {reds:?}");
    }
    // The last frame is the opaque ball: as red as the same scene rendered opaque by hand.
    let opaque = common::render_ppm(
        &format!("{STAGE}render cam image.ppm 24 18\n"),
        &["--spp", "4"],
    );
    assert_eq!(reds[8], redness(&opaque), "{reds:?}");
}

#[test]
fn the_first_frame_check_says_what_anim_check_says_of_the_first_frame() {
    // A material with a negative colour: the reader warns of it in the frame file, and
    // `anim generate` says so up front, at the base scene's line.
    let base = "define material odd -0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20
define shape sphere ball 0 0 0 1 odd
define light sun 5 5 5 1 1 1 1
define camera cam 60 0 0 10 0 0 -1 0 1 0
";
    let spec = "(scene: File(\"base.sdf\"), length: Frames(2), resolution: (16, 9),
  tracks: [(target: \"ball\", translate: [(at: 0, value: (0, 0, 0))])])";
    let dir = project(&[("base.sdf", base), ("odd.ron", spec)]);
    let (ok, stderr) = generate(&dir.path().join("odd.ron"), &dir.path().join("f"));
    assert!(ok, "{stderr}");
    let check = common::anim()
        .arg("check")
        .arg(dir.path().join("f/frame_0000.sdf"))
        .output()
        .expect("check");
    let checked = String::from_utf8_lossy(&check.stderr);
    let said: Vec<&str> = checked
        .lines()
        .filter_map(|l| l.split_once(": warning: ").map(|(_, m)| m))
        .collect();
    assert!(!said.is_empty(), "{checked}");
    for message in said {
        let at_base = stderr
            .lines()
            .any(|l| l.contains("base.sdf:1:") && l.ends_with(&format!("warning: {message}")));
        assert!(
            at_base,
            "`anim check` says `{message}` of frame 0; `anim generate` said:\n{stderr}"
        );
    }
}
