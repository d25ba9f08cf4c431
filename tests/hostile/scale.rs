//! Scale, through the real binary: a flat file of more shapes than the old fixed cap of
//! 250 000 loads and renders, and a scene is refused only beyond the memory budget
//! (`--max-memory`), with the memory it would need.

use crate::common;

use anim_core::limits::scene_memory;
use anim_core::util::{human_bytes, SplitMix64};
use common::{anim, read_ppm};
use std::fmt::Write;
use std::path::{Path, PathBuf};

const HEAD: &str = "define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20\n\
    define light sun 0 50 50 1 1 1 1\n\
    ambient 0.2 0.2 0.2\n\
    define camera eye 60 0 0 0 0 0 -1 0 1 0\n";

/// A file of `n` small spheres on a grid in front of the camera, rendered at `w`×`h`.
fn spheres(dir: &Path, n: usize, render: &str) -> PathBuf {
    let mut text = String::with_capacity(n * 48 + 512);
    text.push_str(HEAD);
    text.push_str(render);
    let side = (n as f64).sqrt().ceil() as usize;
    for i in 0..n {
        let (x, y) = ((i % side) as f64, (i / side) as f64);
        let s = side as f64;
        writeln!(
            text,
            "define shape sphere s{i} {:.3} {:.3} {:.3} {:.4} red",
            x - s / 2.0,
            y - s / 2.0,
            -1.2 * s,
            0.45
        )
        .unwrap();
    }
    let path = dir.join(format!("spheres-{n}.sdf"));
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_flat_file_above_the_old_cap_renders() {
    let dir = tempfile::tempdir().unwrap();
    let path = spheres(dir.path(), 300_000, "render eye out.ppm 32 18\n");
    let out = anim()
        .args(["render", "--spp", "1", "-q"])
        .arg(&path)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let image = read_ppm(&dir.path().join("out.ppm"));
    // The grid fills the middle of the view: its centre pixel is a lit red sphere or the
    // darker gap between spheres, never the black background.
    let centre = image.at(16, 9);
    assert!(centre[0] > centre[2] && centre[0] > 0, "{centre:?}");
}

#[test]
fn a_scene_over_the_budget_is_refused_with_what_it_needs() {
    let dir = tempfile::tempdir().unwrap();
    let path = spheres(dir.path(), 3000, "render eye out.ppm 32 18\n");
    for command in ["check", "render"] {
        let out = anim()
            .args([command, "--max-memory", "1M"])
            .arg(&path)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{stderr}");
        let want = format!(
            "spheres-3000.sdf:6:21: error: the scene's 3000 shapes need about {} of memory, more than the 1.0 MiB allowed",
            human_bytes(scene_memory(3000))
        );
        assert!(stderr.contains(&want), "{command}: {stderr}");
        assert!(stderr.contains("--max-memory raises the limit"), "{stderr}");
    }
    // The same scene under a budget that holds it.
    let out = anim()
        .args(["check", "--max-memory", "64M"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The text of a flat file of `n` random spheres in two materials (about 64 bytes a line).
fn random_spheres(n: usize) -> String {
    let mut text = String::with_capacity(n * 64 + 512);
    text.push_str(HEAD);
    text.push_str("define material blue 0 0 0.2 0.1 0.1 0.8 0.5 0.5 0.5 20\n");
    text.push_str("render eye out.png 640 360\n");
    let mut rng = SplitMix64::new(0x9E37_79B9_7F4A_7C15);
    let mut next = move || rng.unit_f64();
    for i in 0..n {
        let (x, y, z) = (
            next() * 200.0 - 100.0,
            next() * 200.0 - 100.0,
            next() * 200.0 - 100.0,
        );
        writeln!(
            text,
            "define shape sphere s{i} {x:.4} {y:.4} {z:.4} {:.4} {}",
            0.2 + next() * 0.4,
            if i % 2 == 0 { "red" } else { "blue" }
        )
        .unwrap();
    }
    text
}

/// The whole front end of `anim render` before the hierarchy is built: reading the file
/// from disk, tokenizing, parsing and building the scene (`anim_core::load::load_file`, with the
/// command line's default options), on a flat file of a million random spheres, in lines per
/// CPU-second of the loading thread; it fails below 1.5 M lines/s (BENCHMARKS.md §10: about
/// 2 M measured, 1 M before the reader took flat lines directly). A measurement, run by
/// scripts/bench-scale.sh with `READER=1`:
/// `cargo test --release --test hostile -- --ignored --nocapture scale::the_loader_loads`.
#[test]
#[ignore]
fn the_loader_loads_one_and_a_half_million_lines_a_second() {
    let n = 1_000_000;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("spheres.sdf");
    let text = random_spheres(n);
    let lines = text.lines().count();
    std::fs::write(&path, text).unwrap();
    let opts = anim_core::sdf::LoadOptions {
        material_fields: anim_core::sdf::MaterialLayout::Auto,
        infer_transform_order: true,
        ..anim_core::sdf::LoadOptions::default()
    };
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let start = cpu_time::ThreadTime::now();
        let loaded = anim_core::load::load_file(&path, &opts).expect("loads");
        let seconds = start.elapsed().as_secs_f64();
        assert_eq!(loaded.jobs[0].scene.instances.len(), n);
        drop(loaded);
        best = best.min(seconds);
    }
    let rate = lines as f64 / best;
    println!(
        "loader: {lines} lines in {best:.3} CPU-s (best of 5): {:.2} M lines/s",
        rate / 1e6
    );
    assert!(rate >= 1.5e6, "{:.2} M lines/s", rate / 1e6);
}

/// The reader alone (`anim_core::sdf::parse_source`, no scene building) on a flat file of a million
/// random spheres, in lines per CPU-second of the reading thread, against issue 8's target of
/// 2 M lines/s. A measurement, run by scripts/bench-scale.sh:
/// `cargo test --release --test hostile -- --ignored --nocapture scale::the_reader_reads`.
#[test]
#[ignore]
fn the_reader_reads_two_million_lines_a_second() {
    let n = 1_000_000;
    let text = random_spheres(n);
    let lines = text.lines().count();
    let opts = anim_core::sdf::LoadOptions::default();
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let start = cpu_time::ThreadTime::now();
        let parsed = anim_core::sdf::parse_source(&text, Path::new("spheres.sdf"), &opts);
        let seconds = start.elapsed().as_secs_f64();
        assert_eq!(parsed.shapes.len(), n);
        assert!(parsed.diagnostics.iter().all(|d| !d.is_error()));
        drop(parsed);
        best = best.min(seconds);
    }
    let rate = lines as f64 / best;
    println!(
        "reader: {lines} lines in {best:.3} CPU-s (best of 5): {:.2} M lines/s",
        rate / 1e6
    );
    assert!(rate >= 2e6, "{:.2} M lines/s", rate / 1e6);
}

/// `n` statements of one kind (`kind`), numbered `i`, after a header that makes them valid.
fn statements_of_kind(kind: &str, n: usize) -> String {
    let mut text = String::from(HEAD);
    for i in 0..n {
        let (x, y, z) = (
            (i % 100) as f64,
            (i / 100 % 100) as f64,
            -5.0 - (i / 10_000) as f64,
        );
        let line = match kind {
            "material" => format!("define material m{i} 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20"),
            "sphere" => format!("define shape sphere s{i} {x} {y} {z} 0.3 red"),
            "box" => format!(
                "define shape box s{i} {x} {y} {z} {} {} {} red",
                x + 0.5,
                y + 0.5,
                z + 0.5
            ),
            "triangle" => format!(
                "define shape triangle s{i} {x} {y} {z} {} {y} {z} {x} {} {z} red",
                x + 0.5,
                y + 0.5
            ),
            "light" => format!("define light l{i} {x} 5 5 0.001 0.001 0.001 1"),
            "camera" => format!("define camera c{i} 60 0 0 {x} 0 0 -1 0 1 0"),
            "transform" => format!(
                "define shape sphere s{i} {x} {y} {z} 0.3 red\ntransform s{i} translate 0 0 -1"
            ),
            "composite" => {
                format!("define shape sphere s{i} {x} {y} {z} 0.3 red\ndefine shape composite c{i} s{i}")
            }
            "render" => format!("render eye img{i}.png 8 6"),
            "ambient" => "ambient 0.1 0.1 0.1".to_string(),
            "motion" => format!(
                "motion s0 {} translate {} 0 0",
                i as f64 / n as f64,
                i as f64 / n as f64
            ),
            other => panic!("no statement kind {other}"),
        };
        if i == 0 && kind == "motion" {
            text.push_str("define shape sphere s0 0 0 -5 1 red\n");
        }
        text.push_str(&line);
        text.push('\n');
    }
    text
}

/// Loading is linear in the number of statements of every kind: ten times as many statements
/// take at most 30 times the CPU time of the loading thread (a quadratic step would take about
/// 100 times). A measurement, as timing belongs to benchmarks:
/// `cargo test --release --test hostile -- --ignored --nocapture scale::every_statement_kind`.
#[test]
#[ignore]
fn every_statement_kind_loads_in_linear_time() {
    let kinds = [
        "material",
        "sphere",
        "box",
        "triangle",
        "light",
        "camera",
        "transform",
        "composite",
        "render",
        "ambient",
        "motion",
    ];
    let dir = tempfile::tempdir().unwrap();
    let opts = anim_core::sdf::LoadOptions::default();
    let mut slow = Vec::new();
    for kind in kinds {
        let mut seconds = [0.0; 2];
        for (slot, n) in [100_000, 1_000_000].into_iter().enumerate() {
            let path = dir.path().join(format!("{kind}-{n}.sdf"));
            std::fs::write(&path, statements_of_kind(kind, n)).unwrap();
            let start = cpu_time::ThreadTime::now();
            let loaded = anim_core::load::load_file(&path, &opts);
            seconds[slot] = start.elapsed().as_secs_f64();
            assert!(loaded.is_ok(), "{kind} × {n} does not load");
        }
        let ratio = seconds[1] / seconds[0].max(1e-6);
        println!(
            "{kind:>10}: 10^5 in {:.3} CPU-s, 10^6 in {:.3} CPU-s: ×{ratio:.1}",
            seconds[0], seconds[1]
        );
        if ratio > 30.0 {
            slow.push(format!("{kind}: ×{ratio:.1}"));
        }
    }
    assert!(slow.is_empty(), "not linear: {slow:?}");
}
