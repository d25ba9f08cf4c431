//! Frames that share a static part: every example spec's frames, generated split (each frame
//! includes `static.sdfi`) and whole (`--standalone`), render to the same bytes; a split frame
//! renders on its own; and the split takes the static part out of every frame.

use crate::common::{self, anim};
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn run(args: &[&std::ffi::OsStr]) {
    let out = anim().args(args).output().expect("anim runs");
    assert!(
        out.status.success(),
        "anim {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn generate(spec: &Path, out: &Path, standalone: bool) {
    let mut args = vec![
        "generate".as_ref(),
        spec.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--quiet".as_ref(),
    ];
    if standalone {
        args.push("--standalone".as_ref());
    }
    run(&args);
}

/// Small images: the claim is about what the frames mean, not about their detail.
const SIZE: [&str; 4] = ["--width", "32", "--height", "18"];

fn render(target: &Path, out: &Path) {
    let mut args = vec![
        "render".as_ref(),
        target.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
        "--quiet".as_ref(),
    ];
    args.extend(SIZE.iter().map(std::ffi::OsStr::new));
    run(&args);
}

fn files(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    out.sort();
    out
}

fn size(paths: &[PathBuf]) -> u64 {
    paths
        .iter()
        .map(|p| std::fs::metadata(p).unwrap().len())
        .sum()
}

#[test]
fn split_frames_render_to_the_bytes_of_whole_frames() {
    let specs: Vec<PathBuf> = common::repository_files("animations")
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    assert!(specs.len() >= 8, "{specs:?}");
    for spec in &specs {
        let name = spec.file_stem().unwrap().to_string_lossy().into_owned();
        let tmp = tempfile::tempdir().unwrap();
        let (split, whole) = (tmp.path().join("split"), tmp.path().join("whole"));
        generate(spec, &split, false);
        generate(spec, &whole, true);
        let (split_frames, whole_frames) = (files(&split, "sdf"), files(&whole, "sdf"));
        assert_eq!(split_frames.len(), whole_frames.len(), "{name}");
        assert!(
            split.join("static.sdfi").is_file(),
            "{name}: no static part"
        );
        // The static part is written once instead of in every frame.
        let split_size = size(&split_frames) + size(&[split.join("static.sdfi")]);
        assert!(
            split_size < size(&whole_frames),
            "{name}: {split_size} bytes split, {} whole",
            size(&whole_frames)
        );
        let (split_images, whole_images) = (tmp.path().join("si"), tmp.path().join("wi"));
        render(&split, &split_images);
        render(&whole, &whole_images);
        let (a, b) = (files(&split_images, "png"), files(&whole_images, "png"));
        assert_eq!(a.len(), split_frames.len(), "{name}");
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x.file_name(), y.file_name());
            assert!(
                std::fs::read(x).unwrap() == std::fs::read(y).unwrap(),
                "{name}: {} differs between split and whole frames",
                x.display()
            );
        }
        // A split frame renders on its own, as the same image.
        let middle = &split_frames[split_frames.len() / 2];
        let alone = tmp.path().join("alone");
        render(middle, &alone);
        let image = files(&alone, "png");
        assert_eq!(image.len(), 1, "{name}");
        let from_dir = split_images.join(image[0].file_name().unwrap());
        assert!(
            std::fs::read(&image[0]).unwrap() == std::fs::read(from_dir).unwrap(),
            "{name}: {} alone differs",
            middle.display()
        );
    }
}

#[test]
fn a_still_scene_keeps_only_the_camera_and_render_line_in_its_frames() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(
        dir.join("base.sdf"),
        "define material m 0.1 0.1 0.1 0.5 0.5 0.5 0 0 0 1\n\
         define light l 0 5 0 1 1 1 1\n\
         define shape sphere ball 0 0 -5 1 m\n\
         define shape sphere mover 2 0 -5 0.5 m\n\
         define camera cam 60 0 0 0 0 0 -1 0 1 0\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("spec.ron"),
        "(scene: File(\"base.sdf\"), camera: \"cam\", length: Frames(3), resolution: (8, 8),\n\
          tracks: [(target: \"mover\", translate: [(at: 0, value: (0, 0, 0)), (at: 0.1, value: (1, 0, 0))])])\n",
    )
    .unwrap();
    let out = dir.join("frames");
    generate(&dir.join("spec.ron"), &out, false);
    let statics = std::fs::read_to_string(out.join("static.sdfi")).unwrap();
    let frame = std::fs::read_to_string(out.join("frame_0001.sdf")).unwrap();
    let lines = |t: &str| -> Vec<String> {
        t.lines()
            .filter(|l| !l.starts_with('#'))
            .map(str::to_string)
            .collect()
    };
    for kept in [
        "define material m",
        "define light l",
        "define shape sphere ball",
        "define camera cam",
    ] {
        assert!(statics.contains(kept), "{kept} not static:\n{statics}");
        assert!(!frame.contains(kept), "{kept} in the frame:\n{frame}");
    }
    let keyed = lines(&frame);
    assert_eq!(keyed[0], "include static.sdfi", "{frame}");
    assert!(
        keyed
            .iter()
            .any(|l| l.starts_with("define shape sphere mover")),
        "{frame}"
    );
    assert!(
        keyed.iter().any(|l| l.starts_with("transform mover")),
        "{frame}"
    );
    assert!(keyed.last().unwrap().starts_with("render cam"), "{frame}");
    // `--standalone` takes the static part away again.
    generate(&dir.join("spec.ron"), &out, true);
    assert!(!out.join("static.sdfi").exists());
    let whole = std::fs::read_to_string(out.join("frame_0001.sdf")).unwrap();
    assert!(whole.contains("define shape sphere ball"), "{whole}");
}

#[test]
fn a_changed_static_part_renders_its_frames_again() {
    let tmp = tempfile::tempdir().unwrap();
    let frames = tmp.path().join("frames");
    generate(&repo().join("animations/orbit.ron"), &frames, false);
    let summary = |frames: &Path| {
        let mut args = vec!["render".as_ref(), frames.as_os_str()];
        args.extend(SIZE.iter().map(std::ffi::OsStr::new));
        let out = anim().args(&args).output().expect("anim runs");
        assert!(out.status.success());
        let text = String::from_utf8_lossy(&out.stdout).into_owned()
            + &String::from_utf8_lossy(&out.stderr);
        text.lines().last().unwrap_or_default().to_string()
    };
    assert!(summary(&frames).contains(": 120 rendered, 0 skipped"));
    assert!(summary(&frames).contains(": 0 rendered, 120 skipped"));
    let statics = frames.join("static.sdfi");
    let text = std::fs::read_to_string(&statics).unwrap();
    assert!(text.contains("define material floor 0.12"), "{text}");
    std::fs::write(
        &statics,
        text.replacen("define material floor 0.12", "define material floor 0.5", 1),
    )
    .unwrap();
    assert!(summary(&frames).contains(": 120 rendered, 0 skipped"));
}

/// Issue 45 (10b): a keyed shape written before many still shapes of its material left them
/// all in every frame. Shapes that only share a material trade places freely, so they are
/// static whatever the order; statements that refer to the keyed shape (a composite listing
/// it, then a transform of that composite) stay in the frames, and the frames render as the
/// whole files do.
#[test]
fn still_shapes_after_a_keyed_one_stay_in_the_static_part() {
    const STILL: usize = 100_000;
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mut base = String::from(
        "define material m 0.1 0.1 0.1 0.5 0.5 0.5 0 0 0 1\n\
         define light l 0 5 0 1 1 1 1\n\
         define shape sphere mover 0 0 -5 0.5 m\n\
         define shape composite group mover\n\
         transform group translate 0 0.5 0\n",
    );
    for i in 0..STILL {
        let (x, y) = ((i % 400) as f64 * 0.01 - 2.0, (i / 400) as f64 * 0.01 - 1.5);
        base += &format!("define shape sphere s{i} {x} {y} -8 0.004 m\n");
    }
    base += "define camera cam 60 0 0 0 0 0 -1 0 1 0\n";
    std::fs::write(dir.join("base.sdf"), &base).unwrap();
    std::fs::write(
        dir.join("spec.ron"),
        "(scene: File(\"base.sdf\"), camera: \"cam\", length: Frames(4), resolution: (8, 8),\n\
          tracks: [(target: \"mover\", translate: [(at: 0, value: (0, 0, 0)), (at: 0.1, value: (1, 0, 0))])])\n",
    )
    .unwrap();
    let (split, whole) = (dir.join("split"), dir.join("whole"));
    generate(&dir.join("spec.ron"), &split, false);
    let statics = std::fs::read_to_string(split.join("static.sdfi")).unwrap();
    let still = |t: &str| t.lines().filter(|l| l.contains("sphere s")).count();
    assert_eq!(still(&statics), STILL);
    let frames = files(&split, "sdf");
    assert_eq!(frames.len(), 4);
    for f in &frames {
        let text = std::fs::read_to_string(f).unwrap();
        assert_eq!(still(&text), 0, "{}", f.display());
        // What refers to the keyed shape keeps its place after it.
        let kept = [
            "define shape sphere mover",
            "define shape composite group",
            "transform group",
        ];
        let at: Vec<usize> = kept.iter().map(|k| text.find(k).expect(k)).collect();
        assert!(at.windows(2).all(|w| w[0] < w[1]), "{text}");
        assert!(!statics.contains("composite group"), "{statics}");
        assert!(text.len() < 1000, "{} bytes", text.len());
    }
    generate(&dir.join("spec.ron"), &whole, true);
    let (split_images, whole_images) = (dir.join("si"), dir.join("wi"));
    render(&split, &split_images);
    render(&whole, &whole_images);
    let (a, b) = (files(&split_images, "png"), files(&whole_images, "png"));
    assert_eq!(a.len(), 4);
    for (x, y) in a.iter().zip(&b) {
        assert!(
            std::fs::read(x).unwrap() == std::fs::read(y).unwrap(),
            "{} differs between split and whole frames",
            x.display()
        );
    }
}
