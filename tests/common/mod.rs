//! Helpers shared by the integration tests: run the real `anim` binary on SDF text and read
//! back the image it wrote.
//!
//! Each test binary (a folder of tests/ with its `main.rs`) compiles this module with
//! `#[path = "../common/mod.rs"] mod common;` and uses only some of its helpers; the others
//! would be dead code in that binary, hence the `allow` (here, so that it covers `hdr` too and
//! no declaration has to repeat it).
#![allow(dead_code)]

use assert_cmd::Command;
use std::path::{Path, PathBuf};

pub struct Rgb8 {
    pub width: usize,
    pub height: usize,
    pub data: Vec<u8>,
}

impl Rgb8 {
    pub fn at(&self, x: usize, y: usize) -> [u8; 3] {
        let i = (y * self.width + x) * 3;
        [self.data[i], self.data[i + 1], self.data[i + 2]]
    }
}

/// Reads a binary PPM (P6) as written by anim.
pub fn read_ppm(path: &Path) -> Rgb8 {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut fields = Vec::new();
    let mut pos = 0;
    while fields.len() < 4 {
        while bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while !bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        fields.push(String::from_utf8_lossy(&bytes[start..pos]).into_owned());
    }
    assert_eq!(fields[0], "P6");
    let width: usize = fields[1].parse().unwrap();
    let height: usize = fields[2].parse().unwrap();
    let data = bytes[pos + 1..].to_vec();
    assert_eq!(data.len(), width * height * 3);
    Rgb8 {
        width,
        height,
        data,
    }
}

pub fn anim() -> Command {
    Command::cargo_bin("anim").expect("the anim binary is built")
}

/// `anim ARGS...` run in `dir`: (exit code, stderr).
pub fn run_in(dir: &Path, args: &[&str]) -> (i32, String) {
    let out = anim()
        .current_dir(dir)
        .args(args)
        .output()
        .expect("anim runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Writes `sdf` to `dir/name` and renders it with `args`, images into `dir/out`.
/// Returns the path of the output directory.
pub fn render_in(dir: &Path, name: &str, sdf: &str, args: &[&str]) -> PathBuf {
    let scene = dir.join(name);
    std::fs::write(&scene, sdf).unwrap();
    let out = dir.join("out");
    let assert = anim()
        .arg("render")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .args(args)
        .assert();
    let output = assert.get_output();
    assert!(
        output.status.success(),
        "anim render failed:\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    out
}

/// Renders `sdf` (which must write `image.ppm`) and reads the image.
pub fn render_ppm(sdf: &str, args: &[&str]) -> Rgb8 {
    let dir = tempfile::tempdir().unwrap();
    let out = render_in(dir.path(), "scene.sdf", sdf, args);
    read_ppm(&out.join("image.ppm"))
}

/// `round(255·c/(c+1))`, written out independently of the renderer's own code.
pub fn expected_u8(c: f64) -> u8 {
    (255.0 * c / (c + 1.0)).round() as u8
}

/// Largest per-channel difference and how many pixels differ at all.
pub fn compare(a: &Rgb8, b: &Rgb8) -> (u8, usize) {
    assert_eq!((a.width, a.height), (b.width, b.height));
    let mut max = 0u8;
    let mut differing = 0;
    for (pa, pb) in a.data.chunks(3).zip(b.data.chunks(3)) {
        let d = pa
            .iter()
            .zip(pb)
            .map(|(x, y)| x.abs_diff(*y))
            .max()
            .unwrap_or(0);
        max = max.max(d);
        differing += usize::from(d > 0);
    }
    (max, differing)
}

/// The project's shared documents and corpus beside the checkout (`../shared`), if there.
/// Tests that need it call this: a missing folder is reported as a visible skip, and is a
/// failure under CI (where the environment variable `CI` is set), so a broken checkout cannot
/// pass by testing nothing.
pub fn shared_dir(test: &str) -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared");
    if dir.is_dir() {
        return Some(dir);
    }
    if std::env::var_os("CI").is_some() {
        panic!(
            "{test}: {} is missing, and CI is set: this test must not be skipped there",
            dir.display()
        );
    }
    eprintln!("{test}: skipped: {} is missing", dir.display());
    None
}

/// The repository's own files below `dir` (a folder of the repository, e.g. `"scenes"`), in
/// order: what git tracks there (`git ls-files`), never what a run of anim left in the tree
/// (the frames, video and caches of the README's main job). Every test that judges "the files
/// we ship" takes them from here; folders outside the repository (the shared corpus, a test's
/// own temporary folder) are read with [`files_below`].
pub fn repository_files(dir: &str) -> Vec<PathBuf> {
    tracked_files(Path::new(env!("CARGO_MANIFEST_DIR")), dir)
}

/// The files git tracks below `dir` of the checkout at `root`, that exist, in order.
///
/// Panics, saying why, when `root` is not the top of a git checkout (git missing, a copy
/// without `.git`, a checkout git refuses to read) or git tracks nothing there: the tests
/// cannot tell the repository's files from the rest without it, and an empty list would
/// pass by testing nothing.
pub fn tracked_files(root: &Path, dir: &str) -> Vec<PathBuf> {
    let run = std::process::Command::new("git")
        .arg("-C")
        .arg(root)
        .args(["ls-files", "-z", "--", dir])
        // Only `root` itself may be the checkout: a repository around a copy without `.git`
        // would list nothing of it.
        .env("GIT_CEILING_DIRECTORIES", root.parent().unwrap_or(root))
        .output();
    let why = match &run {
        Err(e) => format!("git cannot be run ({e})"),
        Ok(out) if !out.status.success() => String::from_utf8_lossy(&out.stderr).trim().into(),
        Ok(_) => String::new(),
    };
    assert!(
        why.is_empty(),
        "the repository's files under {dir}/ are what `git ls-files` lists, and it failed in {}: \
         {why}\nrun the tests in a git checkout of anim",
        root.display()
    );
    let listed = run.map(|out| out.stdout).unwrap_or_default();
    let mut files: Vec<PathBuf> = listed
        .split(|&b| b == 0)
        .filter(|name| !name.is_empty())
        .map(|name| root.join(String::from_utf8_lossy(name).as_ref()))
        // Deleted but not yet committed: no longer part of the tree being tested.
        .filter(|path| path.is_file())
        .collect();
    assert!(
        !files.is_empty(),
        "git tracks no file under {dir}/ in {}: is this a checkout of anim?",
        root.display()
    );
    files.sort();
    files
}

/// Every file below `dir`, recursively (nothing when it cannot be read).
pub fn files_below(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            files_below(&path, out);
        } else {
            out.push(path);
        }
    }
}

/// A vector in f64, for expected values worked out from the formulas of docs/shading.md.
pub type V = [f64; 3];

pub fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn unit(a: V) -> V {
    let l = dot(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}

pub mod hdr;
pub mod media;
