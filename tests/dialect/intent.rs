//! Author intent: material layouts inferred per file, forms other renderers accepted, and no
//! silent blank image. The corpus rows drive the real binary; the summary table classifies
//! every public corpus file through the library (`load::probe::classify`).

use crate::common;

use anim_core::load::probe::{classify, Classification};
use anim_core::sdf::LoadOptions;
use common::{anim, shared_dir};
use std::path::{Path, PathBuf};

/// `--material-fields auto`, as the command line's default.
fn auto() -> LoadOptions {
    LoadOptions {
        material_fields: anim_core::sdf::MaterialLayout::Auto,
        ..LoadOptions::default()
    }
}

/// The files of both public sets, `corpus/wild` and `corpus/wild2`.
fn corpus_files(test: &str) -> Option<Vec<PathBuf>> {
    let shared = shared_dir(test)?;
    let mut files = Vec::new();
    for set in ["wild", "wild2"] {
        for entry in std::fs::read_dir(shared.join("corpus").join(set))
            .ok()?
            .flatten()
        {
            for file in std::fs::read_dir(entry.path())
                .into_iter()
                .flatten()
                .flatten()
            {
                files.push(file.path());
            }
        }
    }
    files.sort();
    Some(files)
}

fn corpus_file(test: &str, name: &str) -> Option<PathBuf> {
    let path = shared_dir(test)?.join("corpus/wild").join(name);
    assert!(path.is_file(), "{} is missing", path.display());
    Some(path)
}

/// `anim check FILE args...`: (exit code, stderr).
fn check(file: &Path, args: &[&str]) -> (i32, String) {
    let out = anim()
        .arg("check")
        .arg(file)
        .args(args)
        .output()
        .expect("anim runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Every public corpus file: renders, blank with the reason, or rejected with the reason.
/// No image may be blank without a reason (the probe's warning gives it).
#[test]
fn corpus_summary_has_no_silent_blank_images() {
    let Some(files) = corpus_files("corpus_summary_has_no_silent_blank_images") else {
        return;
    };
    let (mut renders, mut blank, mut rejected) = (0, 0, 0);
    let mut table = String::new();
    for file in files.iter().filter(|f| !f.ends_with("MANIFEST.tsv")) {
        let name = file
            .strip_prefix(
                file.parent()
                    .and_then(Path::parent)
                    .unwrap_or(Path::new("")),
            )
            .unwrap_or(file)
            .display()
            .to_string();
        let (class, detail) = match classify(file, &auto()) {
            Classification::Renders => {
                renders += 1;
                ("renders", String::new())
            }
            Classification::BlankExplained(why) => {
                assert!(!why.is_empty(), "{name}: blank without a reason");
                blank += 1;
                ("blank", why)
            }
            Classification::Rejected(why) => {
                rejected += 1;
                ("rejected", why)
            }
        };
        table.push_str(&format!("{class:9} {name}  {detail}\n"));
    }
    println!("{table}");
    println!(
        "{} files: {renders} render, {blank} blank with a reason, {rejected} rejected",
        renders + blank + rejected
    );
    assert!(renders > 0);
}

/// A file whose 14-number materials carry a glossiness field: read, with one warning that
/// names the layout and the flag; an explicit list still wins.
#[test]
fn fourteen_number_materials_are_read_with_glossiness_ignored() {
    let Some(file) = corpus_file("fourteen", "BSVogler__Raytracer/file141.txt") else {
        return;
    };
    let (code, stderr) = check(&file, &[]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(stderr.matches("are read as").count(), 1, "{stderr}");
    assert!(stderr.contains("glossiness is ignored"), "{stderr}");
    assert!(stderr.contains("--material-fields"), "{stderr}");
    let (code, stderr) = check(&file, &["--material-fields", "reflectivity,opacity,ior"]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("too many numbers for a material"),
        "{stderr}"
    );
}

/// Corpus files whose materials only make sense in another layout.
#[test]
fn corpus_layouts_are_inferred() {
    let cases = [
        (
            "christiandunkel__raytracer/spheresInSkyScene.sdf",
            "transparency",
        ),
        (
            "perlauy__programmiersprachen-raytracer/scene_composite.sdf",
            "m ior opacity",
        ),
        ("tgrochow__scene/animation.sdf", "m opacity ior"),
        (
            "jacoblammert__programmiersprachen-raytracer/start.sdf",
            "glossiness",
        ),
    ];
    for (name, layout) in cases {
        let Some(file) = corpus_file("corpus_layouts_are_inferred", name) else {
            return;
        };
        let (_, stderr) = check(&file, &[]);
        let line = stderr
            .lines()
            .find(|l| l.contains("are read as"))
            .unwrap_or_else(|| panic!("{name}: no layout warning\n{stderr}"));
        assert!(line.contains(layout), "{name}: {line}");
        assert!(!stderr.contains("invisible"), "{name}: {stderr}");
    }
}

/// `define renderer <camera> <file> <w> <h>` renders (it used to fail with a message that
/// contradicted the line).
#[test]
fn define_renderer_with_a_camera_renders() {
    let dir = tempfile::tempdir().expect("temp dir");
    let sdf = "define material red 0.2 0 0 1 0 0 0 0 0 10\n\
               define shape sphere s 0 0 -5 1 red\n\
               define light l 0 5 0 1 1 1 1\n\
               define camera eye 60\n\
               define renderer eye out.ppm 32 24\n";
    let out = common::render_in(dir.path(), "scene.sdf", sdf, &[]);
    let img = common::read_ppm(&out.join("out.ppm"));
    assert_eq!((img.width, img.height), (32, 24));
    assert!(img.data.iter().any(|&b| b > 0), "the sphere shows");
}

/// A bad render line rejects only its own image.
#[test]
fn a_bad_render_line_rejects_only_itself() {
    let dir = tempfile::tempdir().expect("temp dir");
    let sdf = "define material red 0.2 0 0 1 0 0 0 0 0 10\n\
               define shape sphere s 0 0 -5 1 red\n\
               define light l 0 5 0 1 1 1 1\n\
               define camera eye 60\n\
               define camera other 60\n\
               render ghost bad.ppm 16 16\n\
               render eye good.ppm 16 16\n";
    let out = common::render_in(dir.path(), "scene.sdf", sdf, &[]);
    assert!(out.join("good.ppm").is_file());
    assert!(!out.join("bad.ppm").exists());
}

/// Each accepted form is an error with `--strict`.
#[test]
fn accepted_forms_are_errors_when_strict() {
    let forms = [
        "define camera c2 1.5f\n",
        "define shape sphere 0 0 -5 1 red ball\n",
        "define shape sphere b 0 0 -5 1 nothing\n",
        "define light l2 0 5 0 0.1 0.1 0.1 1 1 1 2\n",
        "define camera c3 60 0 0 0 0 0 -1\n",
        "define camera c4 60 800 600 0 0 5 0 0 -1\n",
        "define camera c5 60 0 0 5 0 0 0\n",
        "define camera c6 45 90 0 0 -5 10\n",
        "define camera c7 60 0 0 5 0 0 -1 0 0 1\n",
        "define shape cone k 0 0 -5 1 1 red\n",
        "define shape cylinder z 0 0 -5 1 1 red\n",
    ];
    for form in forms {
        let dir = tempfile::tempdir().expect("temp dir");
        let scene = dir.path().join("scene.sdf");
        let text = format!(
            "define material red 0.2 0 0 1 0 0 0 0 0 10\ndefine light l 0 5 0 1 1 1 1\n\
             {form}define camera eye 60\nrender eye out.ppm 8 8\n"
        );
        std::fs::write(&scene, text).expect("write");
        let (code, stderr) = check(&scene, &[]);
        assert_eq!(code, 0, "{form}: {stderr}");
        assert!(stderr.contains("warning"), "{form}: {stderr}");
        let (code, stderr) = check(&scene, &["--strict"]);
        assert_eq!(code, 1, "{form}: {stderr}");
    }
}

/// `anim check --summary` prints what each file would show, and why not when it shows nothing.
#[test]
fn check_summary_classifies_each_file() {
    let dir = tempfile::tempdir().unwrap();
    let material = "define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20\n";
    let visible = "define shape sphere ball 0 0 -5 1 red\n";
    let camera = "define camera cam 60\nrender cam out.png 8 6\n";
    let lit = format!("{material}{visible}define light sun 5 5 5 1 1 1 1\n{camera}");
    let dark = format!("{material}{visible}{camera}");
    std::fs::write(dir.path().join("lit.sdf"), lit).unwrap();
    std::fs::write(dir.path().join("dark.sdf"), dark).unwrap();
    std::fs::write(dir.path().join("broken.sdf"), "define shape sphere\n").unwrap();
    let out = assert_cmd::Command::cargo_bin("anim")
        .unwrap()
        .args(["check", "--summary", "--quiet"])
        .arg(dir.path())
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let row = |name: &str| {
        stdout
            .lines()
            .find(|l| l.contains(name))
            .unwrap_or_else(|| panic!("no row for {name}:\n{stdout}"))
            .to_string()
    };
    assert!(row("lit.sdf").contains("| renders |"), "{stdout}");
    let dark = row("dark.sdf");
    assert!(
        dark.contains("| blank |") && dark.contains("light"),
        "{dark}"
    );
    assert!(row("broken.sdf").contains("| rejected |"), "{stdout}");
    assert!(
        stdout.contains("renders: 1, blank with a reason: 1, rejected with a reason: 1"),
        "{stdout}"
    );
}
