//! Hostile and unlucky inputs end quickly with a clear message or a correct result: deep mirror
//! recursion, huge images, render lines that point outside the scene's folder, corrupted or
//! half-written images, two runs on one frame directory, and frames that are links or empty.

use crate::common;

use common::anim;
use std::path::Path;
use std::time::{Duration, Instant};

/// A closed box of perfect mirrors around the camera: every ray bounces to the depth limit.
const MIRROR_BOX: &str = "define material mirror 0 0 0 0 0 0 0 0 0 1 1 1 1\n\
    define shape box room -1 -1 -1 1 1 1 mirror\n\
    define light l 0 0.5 0 1 1 1 1\n\
    ambient 0.1 0.1 0.1\n\
    define camera c 60 0 0 0.5 0 0 -1 0 1 0\n\
    render c mirror.png 4 3\n";

const SPHERE: &str = "define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20\n\
    define shape sphere ball 0 0 -5 1 red\n\
    define light sun 5 5 5 1 1 1 1\n\
    define camera cam 60\n";

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn deep_mirror_recursion_renders_and_the_depth_has_a_stated_cap() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write(dir.path(), "mirror.sdf", MIRROR_BOX);
    let out = anim()
        .args(["render", "--quiet", "--max-depth", "10000"])
        .arg(&scene)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.path().join("mirror.png").is_file());

    let out = anim()
        .args(["render", "--max-depth", "10001"])
        .arg(&scene)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("--max-depth") && stderr.contains("10000"),
        "{stderr}"
    );
}

#[test]
fn an_image_too_big_for_memory_is_refused_before_anything_is_allocated() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write(
        dir.path(),
        "huge.sdf",
        &format!("{SPHERE}render cam huge.png 65536 65536\n"),
    );
    let start = Instant::now();
    let out = anim()
        .args(["render", "--max-memory", "1G"])
        .arg(&scene)
        .output()
        .unwrap();
    assert!(start.elapsed() < Duration::from_secs(10));
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("huge.sdf:5:") && stderr.contains("65536×65536") && stderr.contains("GiB"),
        "{stderr}"
    );
    assert!(!dir.path().join("huge.png").exists());
}

#[test]
fn render_lines_cannot_write_outside_the_scene_folder() {
    let root = tempfile::tempdir().unwrap();
    let scenes = root.path().join("a/b");
    std::fs::create_dir_all(&scenes).unwrap();
    let absolute = root.path().join("elsewhere/abs.png");
    let scene = write(
        &scenes,
        "escape.sdf",
        &format!(
            "{SPHERE}render cam ../../up.png 8 6\nrender cam {} 8 6\n",
            absolute.display()
        ),
    );

    let out = anim().arg("render").arg(&scene).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("escape.sdf:5:") && stderr.contains("outside"),
        "{stderr}"
    );
    assert!(stderr.contains("escape.sdf:6:"), "{stderr}");
    assert!(!root.path().join("up.png").exists());
    assert!(!absolute.exists());
    assert!(scenes.join("up.png").is_file() && scenes.join("abs.png").is_file());

    // Under --strict the escape is an error and nothing is written.
    std::fs::remove_file(scenes.join("up.png")).unwrap();
    let out = anim()
        .args(["render", "--strict"])
        .arg(&scene)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(!scenes.join("up.png").exists());

    // --out with an absolute path confines to that folder just the same.
    let out_dir = root.path().join("out");
    let out = anim()
        .arg("render")
        .arg(&scene)
        .arg("--out")
        .arg(&out_dir)
        .output()
        .unwrap();
    assert!(out.status.success());
    assert!(out_dir.join("up.png").is_file() && out_dir.join("abs.png").is_file());
    assert!(!absolute.exists());

    // --allow-any-output honours the paths as written.
    let out = anim()
        .args(["render", "--allow-any-output"])
        .arg(&scene)
        .output()
        .unwrap();
    assert!(out.status.success());
    assert!(root.path().join("up.png").is_file() && absolute.is_file());
}

fn frame_dir() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for i in 0..3 {
        write(
            dir.path(),
            &format!("frame_{i:04}.sdf"),
            &format!("{SPHERE}render cam frame_{i:04}.png 8 6\n"),
        );
    }
    dir
}

fn render_dir(dir: &Path) -> String {
    let out = anim().arg("render").arg(dir).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{stderr}");
    stderr
}

#[test]
fn a_corrupted_image_of_the_right_size_is_rendered_again() {
    let dir = frame_dir();
    render_dir(dir.path());
    let image = dir.path().join("frame_0001.png");
    let good = std::fs::read(&image).unwrap();
    let mut bad = good.clone();
    let middle = bad.len() / 2;
    bad[middle] ^= 0xff;
    std::fs::write(&image, &bad).unwrap();
    let stderr = render_dir(dir.path());
    assert!(stderr.contains("1 rendered, 2 skipped"), "{stderr}");
    assert_eq!(std::fs::read(&image).unwrap(), good);
}

#[test]
fn temporary_files_of_killed_runs_are_cleared_and_foreign_files_kept() {
    let dir = frame_dir();
    // Process ids stay below 2^22 on Linux: this writer cannot be running.
    let stale = write(dir.path(), ".frame_0000.png.4194999.tmp", "half an image");
    let foreign = write(dir.path(), "notes.4194999.tmp", "mine");
    render_dir(dir.path());
    if Path::new("/proc/self").exists() {
        assert!(!stale.exists());
    }
    assert!(foreign.exists());
}

#[test]
fn a_second_run_on_the_same_directory_waits_for_the_first() {
    let dir = frame_dir();
    let cache = dir.path().join(".anim-cache");
    std::fs::create_dir_all(&cache).unwrap();
    let lock = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(cache.join("lock"))
        .unwrap();
    lock.lock().unwrap();
    std::fs::write(cache.join("lock"), "4242").unwrap();
    let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("anim"))
        .arg("render")
        .arg(dir.path())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(500));
    assert!(
        child.try_wait().unwrap().is_none(),
        "the second run went ahead while the directory was locked"
    );
    assert!(!dir.path().join("frame_0000.png").exists());
    lock.unlock().unwrap();
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("waiting for another anim render") && stderr.contains("4242"),
        "{stderr}"
    );
    assert!(dir.path().join("frame_0002.png").is_file());
}

/// A scene with its camera and lights, moved as a whole.
fn far_scene(offset: f64) -> String {
    format!(
        "define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20\n\
         define material blue 0 0 0.2 0.1 0.1 0.8 0.3 0.3 0.3 10\n\
         define shape sphere ball 0 0.5 -5 1 red\n\
         define shape box floor -4 -1 -9 4 -0.5 -1 blue\n\
         define shape cylinder post 2 -0.5 -6 2 2 -6 0.3 red\n\
         define shape composite root ball floor post\n\
         define light sun 5 5 5 1 1 1 1\n\
         define camera cam 60 0 1 2 0 -0.2 -1 0 1 0\n\
         transform root translate {offset} {offset} {offset}\n\
         transform sun translate {offset} {offset} {offset}\n\
         transform cam translate {offset} {offset} {offset}\n\
         render cam image.ppm 160 120\n"
    )
}

/// Rendering is camera-relative: the scene is moved (in f64) so the eye sits at the origin
/// before anything goes to f32, so a scene far from the world origin keeps its detail.
#[test]
fn a_scene_far_from_the_origin_renders_as_it_does_at_the_origin() {
    let near = common::render_ppm(&far_scene(0.0), &["--spp", "1"]);
    for offset in [1e3, 1e5, 1e6] {
        let far = common::render_ppm(&far_scene(offset), &["--spp", "1"]);
        let (max, differing) = common::compare(&near, &far);
        let pixels = near.width * near.height;
        assert!(
            max <= 1 || differing * 1000 <= pixels,
            "offset {offset}: {differing} of {pixels} pixels differ, by up to {max}"
        );
    }
}

fn generate(spec: &Path) -> String {
    let out = anim().arg("generate").arg(spec).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{stderr}");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// `anim generate` pointed at a folder of the user's own files with frame-like names removes
/// only what it wrote itself, and `anim render DIR` only the images it rendered.
#[test]
fn generate_and_render_remove_only_the_files_they_wrote() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "base.sdf",
        &format!("{SPHERE}render cam x.png 8 6\n"),
    );
    let spec_text = |frames: u32| {
        format!(
            "(scene: File(\"base.sdf\"), fps: 1, length: Frames({frames}), resolution: (8, 6),\n\
             output: \"IMG_{{frame}}.jpg\", frames_dir: \"photos\")\n"
        )
    };
    let photos = dir.path().join("photos");
    std::fs::create_dir_all(&photos).unwrap();
    // The user's photos, named as frames of the spec would be.
    let theirs = [
        "IMG_0002.jpg",
        "IMG_0007.jpg",
        "IMG_0042.jpg",
        "IMG_0007.sdf",
    ];
    for name in theirs {
        write(&photos, name, "a holiday");
    }
    let untouched = || {
        for name in theirs {
            assert_eq!(
                std::fs::read_to_string(photos.join(name)).unwrap(),
                "a holiday",
                "{name}"
            );
        }
    };
    let spec = write(dir.path(), "spec.ron", &spec_text(4));
    generate(&spec);
    assert!(photos.join("IMG_0003.sdf").is_file());
    untouched();

    // Shorter: the frames it wrote past the new end go, the photos stay.
    write(dir.path(), "spec.ron", &spec_text(2));
    let said = generate(&spec);
    assert!(said.contains("removed 2 files"), "{said}");
    assert!(!photos.join("IMG_0002.sdf").exists() && !photos.join("IMG_0003.sdf").exists());
    untouched();

    // Rendered, then shorter again: the renderer removes its own image of the dropped frame.
    render_dir(&photos);
    assert!(photos.join("IMG_0001.jpg").is_file());
    write(dir.path(), "spec.ron", &spec_text(1));
    generate(&spec);
    render_dir(&photos);
    assert!(!photos.join("IMG_0001.jpg").exists());
    assert!(photos.join("IMG_0000.jpg").is_file());
    untouched();
}

/// A frame of a directory that is a symbolic link is rendered (or fails, when it leads
/// nowhere) rather than left out, and an empty frame fails instead of rendering a blank view.
#[test]
fn linked_and_empty_frames_are_not_passed_over() {
    let dir = tempfile::tempdir().unwrap();
    let elsewhere = tempfile::tempdir().unwrap();
    let scene = "define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20\n\
        define shape sphere ball 0 0 -5 1 red\n\
        define light sun 5 5 5 1 1 1 1\n\
        define camera cam 60\n";
    std::fs::write(
        dir.path().join("f_1.sdf"),
        format!("{scene}render cam f_1.png 8 6\n"),
    )
    .unwrap();
    let target = elsewhere.path().join("kept.sdf");
    // Another scene than f_1's, so that it is rendered rather than copied.
    let moved = scene.replace("ball 0 0 -5", "ball 1 0 -5");
    std::fs::write(&target, format!("{moved}render cam f_2.png 8 6\n")).unwrap();
    std::os::unix::fs::symlink(&target, dir.path().join("f_2.sdf")).unwrap();
    std::os::unix::fs::symlink(
        elsewhere.path().join("gone.sdf"),
        dir.path().join("f_3.sdf"),
    )
    .unwrap();
    std::fs::write(dir.path().join("f_4.sdf"), " \n\n").unwrap();
    let out = anim().arg("render").arg(dir.path()).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(
        stderr.contains("2 rendered, 0 skipped (unchanged), 2 failed"),
        "{stderr}"
    );
    assert!(dir.path().join("f_2.png").is_file(), "{stderr}");
    assert!(
        stderr.contains("f_3.sdf") && stderr.contains("cannot read file"),
        "{stderr}"
    );
    assert!(
        stderr.contains("f_4.sdf") && stderr.contains("the frame file is empty"),
        "{stderr}"
    );
    assert!(!dir.path().join("f_4.png").exists() && !dir.path().join("image.ppm").exists());
}

/// What lies in a frame directory's records folder is read with care: a pipe where a record
/// should be does not block the run, a record of gigabytes is not read, and a frame file over
/// `--max-input` is refused unread.
#[test]
fn records_and_frames_that_are_pipes_or_huge_do_not_stall_a_run() {
    let dir = tempfile::tempdir().unwrap();
    let frame = |image: &str, x: f64| {
        format!("{SPHERE}render cam {image} 8 6\n")
            .replace("ball 0 0 -5", &format!("ball {x} 0 -5"))
    };
    std::fs::write(dir.path().join("f_1.sdf"), frame("f_1.png", 0.0)).unwrap();
    std::fs::write(dir.path().join("f_2.sdf"), frame("f_2.png", 0.5)).unwrap();
    let records = dir.path().join(".anim-cache");
    std::fs::create_dir_all(&records).unwrap();
    let made = std::process::Command::new("mkfifo")
        .arg(records.join("f_1.sdf.hash"))
        .status()
        .unwrap();
    assert!(made.success());
    std::fs::File::create(records.join("f_2.sdf.hash"))
        .unwrap()
        .set_len(3 << 30)
        .unwrap();
    let big = std::fs::File::create(dir.path().join("f_3.sdf")).unwrap();
    big.set_len(2 << 20).unwrap();
    let start = Instant::now();
    let out = anim()
        .args(["render", "--max-input", "1048576"])
        .arg(dir.path())
        .timeout(Duration::from_secs(20))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(start.elapsed() < Duration::from_secs(10), "{stderr}");
    assert!(
        stderr.contains("2 rendered, 0 skipped (unchanged), 1 failed"),
        "{stderr}"
    );
    assert!(
        stderr.contains("f_3.sdf") && stderr.contains("too large to read"),
        "{stderr}"
    );
    let again = anim()
        .args(["render", "--max-input", "1048576"])
        .arg(dir.path())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&again.stderr);
    assert!(stderr.contains("0 rendered, 2 skipped"), "{stderr}");
}

/// Two frames of a directory that name one image: the later fails, located at its image name,
/// before anything renders, and stays failed on every run instead of overwriting the other.
#[test]
fn two_frames_naming_one_image_is_an_error_at_the_later() {
    let dir = tempfile::tempdir().unwrap();
    for (name, x) in [("f_1", 0.0), ("f_2", 0.5)] {
        let text = format!("{SPHERE}render cam same.png 8 6\n")
            .replace("ball 0 0 -5", &format!("ball {x} 0 -5"));
        std::fs::write(dir.path().join(format!("{name}.sdf")), text).unwrap();
    }
    let line = SPHERE.lines().count() + 1;
    for run in ["first", "second"] {
        let out = anim().arg("render").arg(dir.path()).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{run}: {stderr}");
        let at = format!("f_2.sdf:{line}:12: error: image 'same.png' is also written by f_1.sdf");
        assert!(stderr.contains(&at), "{run}: {stderr}");
        let rendered = if run == "first" {
            "1 rendered, 0 skipped"
        } else {
            "0 rendered, 1 skipped"
        };
        assert!(
            stderr.contains(&format!("{rendered} (unchanged), 1 failed")),
            "{run}: {stderr}"
        );
    }
}

/// Memory sizes read and read back: `--max-memory` takes sizes up to the 16 EiB its help
/// names, and a tiny budget is written in bytes, never as "0.0 MiB".
#[test]
fn memory_budgets_are_read_and_written_at_both_ends() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.sdf");
    std::fs::write(&scene, format!("{SPHERE}render cam s.png 8 6\n")).unwrap();
    let check = |budget: &str| {
        let out = anim()
            .args(["check", "--max-memory", budget])
            .arg(&scene)
            .output()
            .unwrap();
        (
            out.status.success(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    for budget in ["16E", "16EiB", "1P", "8G"] {
        let (ok, stderr) = check(budget);
        assert!(ok, "{budget}: {stderr}");
    }
    let (ok, stderr) = check("17E");
    assert!(
        !ok && stderr.contains("between 1 byte and 16 EiB"),
        "{stderr}"
    );
    let (ok, stderr) = check("1");
    assert!(!ok, "{stderr}");
    assert!(stderr.contains("more than the 1 byte allowed"), "{stderr}");
    assert!(!stderr.contains("0.0"), "{stderr}");
}

/// A generate run that cannot write one of its frames (a full disk, or as here a folder in
/// the way) fails and takes back the frames it had added, so no frame is left that the list
/// of generated frames does not name.
#[test]
fn a_generate_that_fails_midway_takes_back_the_frames_it_added() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("scene.sdf"),
        format!("{SPHERE}render cam s.png 8 6\n"),
    )
    .unwrap();
    std::fs::write(
        dir.path().join("s.ron"),
        "(scene: File(\"scene.sdf\"), camera: \"cam\", fps: 24, length: Frames(5), \
         resolution: (16, 12), output: \"f_{frame}.png\")\n",
    )
    .unwrap();
    let frames = dir.path().join("frames");
    std::fs::create_dir_all(frames.join("f_0002.sdf")).unwrap();
    let out = anim()
        .arg("generate")
        .arg(dir.path().join("s.ron"))
        .arg("-o")
        .arg(&frames)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(stderr.contains("cannot write the frame"), "{stderr}");
    let mut left: Vec<String> = std::fs::read_dir(&frames)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["f_0002.sdf"], "{stderr}");
}

#[test]
fn hdr_never_replaces_a_radiance_file_that_anim_did_not_write() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write(
        dir.path(),
        "s.sdf",
        &format!("{SPHERE}render cam s.png 8 6\n"),
    );
    let users = dir.path().join("s.pfm");
    std::fs::write(&users, b"the user's own radiance file").unwrap();
    let render = || {
        anim()
            .arg("render")
            .arg(&scene)
            .args(["--spp", "1", "--hdr"])
            .output()
            .unwrap()
    };
    let out = render();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(
        stderr.contains("s.sdf:5:1: error: with --hdr, the radiance file")
            && stderr.contains("would replace a file that anim did not write"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read(&users).unwrap(),
        b"the user's own radiance file"
    );
    assert!(
        !dir.path().join("s.png").exists(),
        "nothing is written after an error"
    );

    // Once the user's file is gone, anim writes its own, and may replace it on the next run
    // (its mark vouches for it) but not once someone else has changed it.
    std::fs::remove_file(&users).unwrap();
    assert!(render().status.success());
    let first = std::fs::read(&users).unwrap();
    assert!(first.starts_with(b"PF\n"));
    assert!(render().status.success());
    std::fs::write(&users, b"edited by hand").unwrap();
    assert!(!render().status.success());
    assert_eq!(std::fs::read(&users).unwrap(), b"edited by hand");
}

#[test]
fn an_image_the_process_cannot_get_memory_for_is_refused_even_over_the_budget() {
    // `--max-memory` lets anim take 100 GiB; `ulimit -v` lets the process have about 4 GB.
    // The image is refused with its located message instead of aborting mid-render.
    let dir = tempfile::tempdir().unwrap();
    let scene = write(
        dir.path(),
        "huge.sdf",
        &format!("{SPHERE}render cam huge.png 16384 16384\n"),
    );
    let start = Instant::now();
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 4000000 && exec \"$0\" render \"$1\" --max-memory 100G")
        .arg(env!("CARGO_BIN_EXE_anim"))
        .arg(&scene)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("huge.sdf:5:1: error: a 16384×16384 image needs about")
            && stderr.contains("more than the system will give this process now"),
        "{stderr}"
    );
    assert!(start.elapsed() < Duration::from_secs(10));
}
