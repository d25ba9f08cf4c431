//! `anim bench` end to end: the real binary at its hidden `--tiny` size on bench scenes,
//! checking the files it writes, the settings, turns and clock a run names. POV-Ray rows are
//! checked when POV-Ray and the shared converter scripts are there, and the skip note
//! otherwise.

use assert_cmd::Command;
use std::path::Path;

const HEADER: &str = "scene,renderer,mode,setting,width,height,cpu_s,wall_s,rays,mean_spp,rmse,pct_over_1lsb,max_error,psnr_db";

fn pov_available() -> bool {
    Path::new("../shared/tools/sdf2pov.py").is_file()
        && std::process::Command::new("povray")
            .arg("--version")
            .output()
            .is_ok()
}

/// The RMSE column of the anim row of `scene` at `setting`.
fn rmse(csv: &str, scene: &str, setting: &str) -> f64 {
    let line = csv
        .lines()
        .find(|l| l.starts_with(&format!("{scene},anim,uniform,{setting},")))
        .unwrap_or_else(|| panic!("no row for {scene} {setting} in\n{csv}"));
    line.split(',').nth(10).unwrap().parse().unwrap()
}

#[test]
fn quick_bench_writes_csv_markdown_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let output = Command::cargo_bin("anim")
        .unwrap()
        .args(["bench", "--quick", "--tiny", "--scene", "assignment"])
        .args(["--scene", "showcase", "--out"])
        .arg(&out)
        .arg("--cache")
        .arg(dir.path().join("cache"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "bench failed:\n{stderr}");

    let csv = std::fs::read_to_string(out.join("bench.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some(HEADER));
    for line in lines {
        assert_eq!(line.split(',').count(), 14, "{line}");
    }
    for scene in ["assignment", "showcase"] {
        let one = rmse(&csv, scene, "1 spp");
        let many = rmse(&csv, scene, "64 spp");
        assert!(many < one, "{scene}: 64 spp RMSE {many} ≥ 1 spp RMSE {one}");
        for plot in ["time-vs-error", "estimate-vs-error"] {
            let png = out.join(format!("{plot}-{scene}.png"));
            let img = image::open(&png).unwrap_or_else(|e| panic!("{}: {e}", png.display()));
            assert!(img.width() > 100 && img.height() > 100);
        }
    }
    let md = std::fs::read_to_string(out.join("bench.md")).unwrap();
    assert!(md.contains("## assignment") && md.contains("## showcase"));
    // Adaptive rows are measured alongside the uniform ones.
    assert!(csv.contains("assignment,anim,adaptive,error 2,"), "{csv}");
    if pov_available() {
        assert!(csv.contains("showcase,povray,AM2,+A0.1 +AM2 +R3,"), "{csv}");
    } else {
        assert!(md.contains("POV-Ray: skipped"), "{md}");
    }
    // The references were cached: a second run renders none.
    let again = Command::cargo_bin("anim")
        .unwrap()
        .args(["bench", "--tiny", "--no-pov", "--scene", "assignment"])
        .arg("--cache")
        .arg(dir.path().join("cache"))
        .output()
        .unwrap();
    assert!(again.status.success());
    assert!(String::from_utf8_lossy(&again.stderr).contains("anim reference from cache"));
}

/// `anim bench ARGS --tiny --scene assignment`, files in `dir`: (success, stderr).
fn bench_in(dir: &Path, args: &[&str]) -> (bool, String) {
    let output = Command::cargo_bin("anim")
        .unwrap()
        .args(["bench", "--tiny", "--scene", "assignment", "--out"])
        .arg(dir.join("out"))
        .arg("--cache")
        .arg(dir.join("cache"))
        .args(args)
        .output()
        .unwrap();
    (
        output.status.success(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

/// The settings a run names are the ones measured, each timed in every turn, and a timed
/// `anim render` process must draw the image measured in the bench's own process (the bench
/// fails otherwise), so its flags ask for what the setting asks.
#[test]
fn named_settings_are_timed_in_turns_as_whole_processes() {
    let dir = tempfile::tempdir().unwrap();
    let (ok, stderr) = bench_in(
        dir.path(),
        &[
            "--spp",
            "1,16",
            "--error",
            "2",
            "--pov-setting",
            "+A0.1 +AM2 +R3",
            "--turns",
            "3",
            "--whole-process",
        ],
    );
    assert!(ok, "bench failed:\n{stderr}");
    let csv = std::fs::read_to_string(dir.path().join("out/bench.csv")).unwrap();
    let rows: Vec<(&str, &str)> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let cols: Vec<&str> = l.split(',').collect();
            (cols[1], cols[3])
        })
        .collect();
    let mut expected = vec![("anim", "1 spp"), ("anim", "16 spp"), ("anim", "error 2")];
    if pov_available() {
        expected.push(("povray", "+A0.1 +AM2 +R3"));
    }
    assert_eq!(rows, expected, "{csv}");
    assert!(rmse(&csv, "assignment", "16 spp") < rmse(&csv, "assignment", "1 spp"));
    for turn in 1..=3 {
        assert!(
            stderr.contains(&format!("assignment: turn {turn} of 3")),
            "{stderr}"
        );
    }
    let md = std::fs::read_to_string(dir.path().join("out/bench.md")).unwrap();
    assert!(
        md.contains("whole process") && md.contains("median of 3 turns"),
        "{md}"
    );
    // The timed processes' images went to a work folder, gone afterwards.
    let left: Vec<_> = std::fs::read_dir(dir.path().join("cache"))
        .unwrap()
        .flatten()
        .filter(|e| e.path().is_dir())
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// A process renders every render line of its file, so it cannot be timed for one of them.
#[test]
fn whole_process_timing_refuses_a_scene_of_two_render_lines() {
    let dir = tempfile::tempdir().unwrap();
    let scenes = dir.path().join("scenes");
    std::fs::create_dir(&scenes).unwrap();
    let scene = std::fs::read_to_string("scenes/bench/assignment.sdf").unwrap();
    std::fs::write(
        scenes.join("assignment.sdf"),
        format!("{scene}\nrender eye second.ppm 48 27\n"),
    )
    .unwrap();
    let scenes_dir = scenes.to_str().unwrap();
    let args = ["--no-pov", "--spp", "1", "--scenes", scenes_dir];
    let (ok, stderr) = bench_in(dir.path(), &[&args[..], &["--whole-process"]].concat());
    assert!(!ok);
    assert!(stderr.contains("has 2 render lines"), "{stderr}");
    let (ok, stderr) = bench_in(dir.path(), &args);
    assert!(
        ok,
        "around the render call, the first render line is measured:\n{stderr}"
    );
}

#[test]
fn stress_writes_its_table() {
    let dir = tempfile::tempdir().unwrap();
    let output = Command::cargo_bin("anim")
        .unwrap()
        .args([
            "bench",
            "--stress",
            "--tiny",
            "--scene",
            "assignment",
            "--scene",
            "anisotropic",
            "--out",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let csv = std::fs::read_to_string(dir.path().join("stress.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().collect();
    assert_eq!(
        rows[0],
        "scene,change,pct_within_1lsb,nonfinite_pixels,dropped_shapes,cpu_s,spawned_rays,rehits"
    );
    // Per scene (the file's and the built-in one of every primitive scaled non-uniformly),
    // the unchanged render and eight changes.
    assert_eq!(rows.len(), 1 + 2 * 9);
    assert!(rows[1].starts_with("assignment,none,100.0000,0,"));
    assert!(rows[10].starts_with("anisotropic,none,100.0000,0,"));
    for row in &rows[1..] {
        // The change's label has commas of its own ("translate 1e3 (x, y, z)"): count from
        // the end.
        let cols: Vec<&str> = row.rsplit(',').collect();
        let spawned: u64 = cols[1].parse().unwrap();
        // Every row spawns rays, and none of them meets the surface it left.
        assert!(spawned > 0 && cols[0] == "0", "{row}");
    }
    // A change to centimetres loses nothing in f32.
    let cm = rows.iter().find(|r| r.contains("scale 1e-2")).unwrap();
    let pct: f64 = cm.split(',').nth(2).unwrap().parse().unwrap();
    assert!(pct > 99.0, "{cm}");
    assert!(dir.path().join("stress.md").is_file());
}
