//! The golden image manifest: every scene we ship (the files git tracks in scenes/ and
//! animations/: a new scene counts once it is added, frames a run left there never do; and
//! frames generated here from every tracked spec) and every file of the shared corpus,
//! rendered small by the real binary, with a fingerprint of each image's decoded pixels.
//! Refactoring must not change a single pixel: the manifest is compared line by line, and it
//! is rewritten only on purpose, with `ANIM_UPDATE_GOLDEN=1 cargo test --test images golden`
//! after a deliberate change of output. That run also renders each scene whose lines changed
//! converged and prints each changed image's RMSE against it.

use crate::common;

use anim_bench::metrics::compare_rgb8;
use anim_core::util::Fnv64;
use common::{anim, shared_dir};
use image::RgbImage;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

const MANIFEST: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/images/golden/manifest.tsv"
);

/// Small enough to keep the suite fast, big enough that every object covers pixels.
const SIZE: [&str; 4] = ["--width", "48", "--height", "36"];

fn image_files(dir: &Path) -> Vec<PathBuf> {
    let mut all = Vec::new();
    common::files_below(dir, &mut all);
    let mut images: Vec<PathBuf> = all
        .into_iter()
        .filter(|p| {
            p.extension().and_then(|e| e.to_str()).is_some_and(|e| {
                ["png", "ppm", "pgm", "pnm", "bmp", "jpg", "jpeg", "tga"]
                    .contains(&e.to_ascii_lowercase().as_str())
            })
        })
        .collect();
    images.sort();
    images
}

/// The files a scene reads that sit beside it: meshes (`define shape obj`) and the static part a
/// generated frame includes. A scene of the repository takes only tracked ones, so that a
/// scene which needs a file the repository lacks fails here, as on a fresh clone.
fn companions(scene: &Path) -> Vec<PathBuf> {
    // Canonical paths: the corpus is reached as `../shared` from the repository's root.
    let canonical = |p: &Path| p.canonicalize().unwrap();
    let folder = canonical(scene.parent().unwrap());
    let root = canonical(Path::new(env!("CARGO_MANIFEST_DIR")));
    let beside: Vec<PathBuf> = match folder.strip_prefix(&root) {
        Ok(dir) => common::tracked_files(&root, &dir.to_string_lossy())
            .into_iter()
            .filter(|f| f.parent() == Some(folder.as_path()))
            .collect(),
        Err(_) => std::fs::read_dir(&folder)
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .collect(),
    };
    beside
        .into_iter()
        .filter(|f| f.extension().is_some_and(|e| e == "obj" || e == "sdfi"))
        .collect()
}

/// Renders one scene file in a sandbox of its own (deep enough that render lines with `../..`
/// stay inside it) with `args` added; the images it wrote, by file name, or `None` if it was
/// rejected.
fn render_images(label: &str, scene: &Path, args: &[&str]) -> Rendered {
    let sandbox = tempfile::tempdir().unwrap();
    let dir = sandbox.path().join("a/b/c/d");
    std::fs::create_dir_all(&dir).unwrap();
    let name = scene.file_name().unwrap();
    let copy = dir.join(name);
    std::fs::copy(scene, &copy).unwrap();
    for companion in companions(scene) {
        std::fs::copy(&companion, dir.join(companion.file_name().unwrap())).unwrap();
    }
    let output = anim()
        .arg("render")
        .arg(&copy)
        .arg("--out")
        .arg(dir.join("out"))
        .args(SIZE)
        .args(args)
        .arg("--quiet")
        .output()
        .unwrap();
    if !output.status.success() {
        return None;
    }
    let images = image_files(sandbox.path()).into_iter().map(|image| {
        let decoded = image::open(&image)
            .unwrap_or_else(|e| panic!("{label}: {}: {e}", image.display()))
            .to_rgb8();
        (
            image.file_name().unwrap().to_string_lossy().into_owned(),
            decoded,
        )
    });
    Some(images.collect())
}

/// The images one scene file rendered as the manifest renders it (`None`: it was rejected).
type Rendered = Option<Vec<(String, RgbImage)>>;

/// The manifest lines of one scene file, from what it rendered.
fn manifest_lines(label: &str, rendered: &Rendered) -> String {
    let mut lines = String::new();
    let Some(images) = rendered else {
        writeln!(lines, "{label}\trejected").unwrap();
        return lines;
    };
    if images.is_empty() {
        writeln!(lines, "{label}\tno image").unwrap();
    }
    for (name, decoded) in images {
        writeln!(
            lines,
            "{label}\t{name}\t{}x{}\t{:016x}",
            decoded.width(),
            decoded.height(),
            Fnv64::of(decoded.as_raw())
        )
        .unwrap();
    }
    lines
}

/// Samples per pixel of the converged render a changed image is compared with.
const CONVERGED_SPP: &str = "1024";

/// Prints, for each scene whose manifest lines changed, the RMSE (8-bit levels) of each of
/// its images (`rendered`, in the order of `scenes`) against the same scene converged
/// (`CONVERGED_SPP` uniform samples), for the commit that rewrites the manifest to list: at
/// this size adaptive images sit 0.3 to 4 levels from converged, so what a change of the
/// sampler must show is that it moves them no farther.
fn changed_against_converged(scenes: &[(String, PathBuf)], rendered: &[Rendered], expected: &str) {
    let old: Vec<&str> = expected.lines().collect();
    for ((label, path), now) in scenes.iter().zip(rendered) {
        let lines = manifest_lines(label, now);
        if lines.lines().all(|l| old.contains(&l)) {
            continue;
        }
        let (Some(now), Some(converged)) =
            (now, render_images(label, path, &["--spp", CONVERGED_SPP]))
        else {
            continue;
        };
        for ((name, a), (_, b)) in now.iter().zip(&converged) {
            let rmse = compare_rgb8(a.as_raw(), b.as_raw()).rmse;
            eprintln!("changed: {label} {name}: RMSE {rmse:.3} against {CONVERGED_SPP} spp");
        }
    }
}

/// The scene files the repository ships (`scenes/`, `animations/`), labelled by their path in
/// it, and its keyframe specs: what git tracks at `root`, not what a run left beside them.
fn shipped(root: &Path) -> (Vec<(String, PathBuf)>, Vec<PathBuf>) {
    let has = |f: &PathBuf, ext: &str| f.extension().is_some_and(|e| e == ext);
    let mut scenes = Vec::new();
    for folder in ["scenes", "animations"] {
        for f in common::tracked_files(root, folder) {
            if has(&f, "sdf") {
                let label = f.strip_prefix(root).unwrap().display().to_string();
                scenes.push((label, f));
            }
        }
    }
    let mut specs = common::tracked_files(root, "animations");
    specs.retain(|f| has(f, "ron"));
    (scenes, specs)
}

/// Frames 0, a third and two thirds of the way through each spec's animation.
fn generated_frames(specs: &[PathBuf], frames_root: &Path) -> Vec<(String, PathBuf)> {
    let mut frames = Vec::new();
    for spec in specs {
        let stem = spec.file_stem().unwrap().to_string_lossy().into_owned();
        let out = frames_root.join(&stem);
        let status = anim()
            .arg("generate")
            .arg(spec)
            .arg("-o")
            .arg(&out)
            .arg("--quiet")
            .output()
            .unwrap();
        assert!(
            status.status.success(),
            "anim generate {} failed: {}",
            spec.display(),
            String::from_utf8_lossy(&status.stderr)
        );
        let mut sdf: Vec<PathBuf> = std::fs::read_dir(&out)
            .unwrap()
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|e| e == "sdf"))
            .collect();
        sdf.sort();
        let n = sdf.len();
        for i in [0, n / 3, 2 * n / 3] {
            let name = sdf[i].file_name().unwrap().to_string_lossy().into_owned();
            frames.push((format!("generated/{stem}/{name}"), sdf[i].clone()));
        }
    }
    frames
}

#[test]
fn every_scene_renders_the_pixels_of_the_golden_manifest() {
    let (mut scenes, specs) = shipped(Path::new(env!("CARGO_MANIFEST_DIR")));
    let frames_root = tempfile::tempdir().unwrap();
    scenes.extend(generated_frames(&specs, frames_root.path()));
    let shared = shared_dir("golden manifest (corpus part)");
    if let Some(shared) = &shared {
        // The first public set is labelled `corpus/`, the second `corpus-wild2/`.
        for (set, prefix) in [("wild", "corpus"), ("wild2", "corpus-wild2")] {
            let corpus = shared.join("corpus").join(set);
            let mut files = Vec::new();
            common::files_below(&corpus, &mut files);
            for f in files
                .into_iter()
                .filter(|f| f.file_name().is_some_and(|n| n != "MANIFEST.tsv"))
            {
                let label = format!("{prefix}/{}", f.strip_prefix(&corpus).unwrap().display());
                scenes.push((label, f));
            }
        }
    }
    scenes.sort();
    let rendered: Vec<Rendered> = scenes
        .iter()
        .map(|(label, path)| render_images(label, path, &[]))
        .collect();
    let actual: String = scenes
        .iter()
        .zip(&rendered)
        .map(|((label, _), images)| manifest_lines(label, images))
        .collect();

    if std::env::var_os("ANIM_UPDATE_GOLDEN").is_some() {
        assert!(
            shared.is_some(),
            "the manifest is written only with the corpus present"
        );
        let expected = std::fs::read_to_string(MANIFEST).unwrap_or_default();
        changed_against_converged(&scenes, &rendered, &expected);
        std::fs::write(MANIFEST, &actual).unwrap();
        eprintln!("wrote {MANIFEST}");
        return;
    }
    let expected =
        std::fs::read_to_string(MANIFEST).expect("tests/images/golden/manifest.tsv exists");
    let expected: Vec<&str> = expected
        .lines()
        .filter(|l| shared.is_some() || !l.starts_with("corpus"))
        .collect();
    let actual: Vec<&str> = actual.lines().collect();
    let missing: Vec<&&str> = expected.iter().filter(|l| !actual.contains(l)).collect();
    let extra: Vec<&&str> = actual.iter().filter(|l| !expected.contains(l)).collect();
    assert!(
        missing.is_empty() && extra.is_empty(),
        "the images differ from the golden manifest\nexpected, not found:\n{}\nfound, not expected:\n{}",
        missing.iter().map(|l| format!("  {l}")).collect::<Vec<_>>().join("\n"),
        extra.iter().map(|l| format!("  {l}")).collect::<Vec<_>>().join("\n"),
    );
    eprintln!("{} manifest lines match", actual.len());
}

/// `git` in `dir`, which must succeed.
fn git(dir: &Path, args: &[&str]) {
    let out = std::process::Command::new("git")
        .arg("-C")
        .arg(dir)
        .args(args)
        .output()
        .expect("git runs");
    assert!(
        out.status.success(),
        "git {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The README's main job, then its tests: what `scripts/animate.sh animations/orbit.ron
/// animation.mp4` leaves in the tree (frames, their static part and cache, the video) is no
/// scene of the manifest, nor is a scene nobody added to the repository.
#[test]
fn the_manifest_takes_what_git_tracks_not_what_a_run_left() {
    let checkout = tempfile::tempdir().unwrap();
    let root = checkout.path();
    let write = |name: &str| {
        let path = root.join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, "# a file\n").unwrap();
    };
    for tracked in [
        "scenes/a.sdf",
        "scenes/meshes/m.obj",
        "animations/orbit.ron",
    ] {
        write(tracked);
    }
    write("animations/showcase.sdf");
    git(root, &["init", "-q"]);
    git(root, &["add", "."]);
    for left in [
        "animations/frames/orbit/frame_0000.sdf",
        "animations/frames/orbit/static.sdfi",
        "animations/frames/orbit/.anim-cache/frame_0000.sdf.record",
        "animations/frames/orbit/frame_0000.png",
        "animations/scratch.sdf",
        "animations/scratch.ron",
        "animation.mp4",
    ] {
        write(left);
    }
    let (scenes, specs) = shipped(root);
    let labels: Vec<&str> = scenes.iter().map(|(label, _)| label.as_str()).collect();
    assert_eq!(labels, ["scenes/a.sdf", "animations/showcase.sdf"]);
    assert_eq!(specs, [root.join("animations/orbit.ron")]);
}

#[test]
#[should_panic(expected = "run the tests in a git checkout")]
fn outside_a_git_checkout_the_shipped_files_are_an_error_not_a_guess() {
    let copy = tempfile::tempdir().unwrap();
    std::fs::create_dir(copy.path().join("scenes")).unwrap();
    std::fs::write(copy.path().join("scenes/a.sdf"), "# a file\n").unwrap();
    shipped(copy.path());
}
