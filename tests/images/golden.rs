//! The golden image manifest: every scene we ship (scenes/, animations/ and frames generated
//! from every spec in animations/) and every file of the shared corpus, rendered small by the
//! real binary, with a fingerprint of each image's decoded pixels. Refactoring must not change
//! a single pixel: the manifest is compared line by line, and it is rewritten only on purpose,
//! with `ANIM_UPDATE_GOLDEN=1 cargo test --test images golden` after a deliberate change of output.
//! That run also renders each scene whose lines changed converged and prints each changed
//! image's RMSE against it.

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
    // Meshes a scene reads (`define shape obj`) and the static part a generated frame
    // includes sit beside it.
    for entry in std::fs::read_dir(scene.parent().unwrap())
        .unwrap()
        .flatten()
    {
        if entry
            .path()
            .extension()
            .is_some_and(|e| e == "obj" || e == "sdfi")
        {
            std::fs::copy(entry.path(), dir.join(entry.file_name())).unwrap();
        }
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

/// Frames 0, a third and two thirds of the way through each spec's animation.
fn generated_frames(root: &Path, frames_root: &Path) -> Vec<(String, PathBuf)> {
    let mut specs: Vec<PathBuf> = std::fs::read_dir(root.join("animations"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    specs.sort();
    let mut frames = Vec::new();
    for spec in specs {
        let stem = spec.file_stem().unwrap().to_string_lossy().into_owned();
        let out = frames_root.join(&stem);
        let status = anim()
            .arg("generate")
            .arg(&spec)
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
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut scenes: Vec<(String, PathBuf)> = Vec::new();
    for folder in ["scenes", "animations"] {
        let mut files = Vec::new();
        common::files_below(&root.join(folder), &mut files);
        for f in files
            .into_iter()
            .filter(|f| f.extension().is_some_and(|e| e == "sdf"))
        {
            let label = f.strip_prefix(root).unwrap().display().to_string();
            scenes.push((label, f));
        }
    }
    let frames_root = tempfile::tempdir().unwrap();
    scenes.extend(generated_frames(root, frames_root.path()));
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
