//! `include` lines built to multiply or to hang: files that include a file many times, each
//! included many times in turn; a frame directory whose shared part includes itself, a pipe
//! or `/dev/stdin`; a million include lines.

use crate::budgets::limited;
use std::path::Path;
use std::process::Stdio;
use std::time::{Duration, Instant};

const HEAD: &str = "define material m 0.2 0.2 0.2 0.8 0.8 0.8 0 0 0 1\n\
    define light l 0 5 5 1 1 1 1\n\
    define camera c 60\n";

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

/// Eight files, each including the next ten times, the last holding a sphere: 10^7 spheres
/// from 1.3 KB of text. `anim check` refuses it at the line where the repeats pass the limit,
/// in seconds and under 500 MB, with exit code 1 (no abort).
#[test]
fn includes_that_multiply_are_refused_within_time_and_memory() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    for i in 0..8 {
        let text = if i == 7 {
            "define shape sphere s 0 0 -5 1 m\n".to_string()
        } else {
            format!("include f{}.sdfi\n", i + 1).repeat(10)
        };
        write(&dir.join(format!("f{i}.sdfi")), &text);
    }
    write(
        &dir.join("scene.sdf"),
        &format!("{HEAD}include f0.sdfi\nrender c out.png 8 6\n"),
    );
    let (code, stderr, took) = limited(dir, 500_000, "check scene.sdf");
    assert_eq!(code, Some(1), "{stderr}");
    let limit = anim_core::limits::MAX_INCLUDE_REPEATS;
    assert!(
        stderr.contains("is in this scene already")
            && stderr.contains(&format!("more than the {limit} that includes may repeat")),
        "{stderr}"
    );
    assert!(took < Duration::from_secs(5), "{took:?}");
}

/// A million `include` lines of one small file end within seconds (each line once cost a
/// reading and a fingerprint of the file): refused past the repeat limit, read below it.
#[test]
fn a_million_include_lines_end_quickly() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    write(&dir.join("empty.sdfi"), "# nothing\n");
    let limit = anim_core::limits::MAX_INCLUDE_REPEATS as usize;
    for (lines, code) in [(1_000_000, 1), (limit - 10, 0)] {
        write(
            &dir.join("scene.sdf"),
            &format!(
                "{HEAD}define shape sphere s 0 0 -5 1 m\n{}render c out.png 8 6\n",
                "include empty.sdfi\n".repeat(lines)
            ),
        );
        let (got, stderr, took) = limited(dir, 2_000_000, "check scene.sdf");
        assert_eq!(got, Some(code), "{lines}: {stderr}");
        assert!(took < Duration::from_secs(10), "{lines}: {took:?}");
    }
}

/// A frame directory whose shared part includes itself ten times: `anim render DIR` (which
/// fingerprints what each frame includes before loading it) reports the cycle at once.
#[test]
fn a_frame_directory_whose_static_part_includes_itself_gives_the_cycle_error() {
    let tmp = tempfile::tempdir().unwrap();
    let frames = tmp.path().join("frames");
    write(
        &frames.join("static.sdfi"),
        &format!("{HEAD}{}", "include static.sdfi\n".repeat(10)),
    );
    for n in 0..2 {
        write(
            &frames.join(format!("frame_{n:04}.sdf")),
            &format!("include static.sdfi\nrender c f{n}.png 8 6\n"),
        );
    }
    let (code, stderr, took) = limited(tmp.path(), 4_000_000, "render frames --quiet");
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("`static.sdfi` is already being read"),
        "{stderr}"
    );
    assert!(took < Duration::from_secs(5), "{took:?}");
}

/// `include /dev/stdin` in a frame, with stdin a pipe that stays open, and twenty includes of
/// a named pipe nothing writes to: refused at their lines, neither read nor waited for.
#[test]
fn pipes_and_stdin_included_by_a_frame_are_refused_without_waiting() {
    let tmp = tempfile::tempdir().unwrap();
    let frames = tmp.path().join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    let made = std::process::Command::new("mkfifo")
        .arg(frames.join("pipe.sdfi"))
        .status();
    assert!(made.is_ok_and(|s| s.success()));
    write(
        &frames.join("frame_0000.sdf"),
        &format!("{HEAD}include /dev/stdin\nrender c f0.png 8 6\n"),
    );
    write(
        &frames.join("frame_0001.sdf"),
        &format!(
            "{HEAD}{}render c f1.png 8 6\n",
            "include pipe.sdfi\n".repeat(20)
        ),
    );
    let start = Instant::now();
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_anim"))
        .args(["render", "--quiet"])
        .arg(&frames)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The pipe on stdin stays open (never written to, never closed) until anim ends; anim
    // is stopped if it waits on it.
    let stdin = child.stdin.take();
    while child.try_wait().unwrap().is_none() && start.elapsed() < Duration::from_secs(30) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let _ = child.kill();
    let out = child.wait_with_output().unwrap();
    drop(stdin);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    for expected in [
        "frame_0000.sdf:4:9: error: `/dev/stdin`",
        "frame_0001.sdf:4:9: error: `pipe.sdfi` is not a regular file",
    ] {
        assert!(stderr.contains(expected), "{expected}: {stderr}");
    }
    // Allowed anywhere, `/dev/stdin` on a pipe is refused for what it is.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_anim"))
        .args(["check", "--allow-any-input"])
        .arg(frames.join("frame_0000.sdf"))
        .stdin(Stdio::piped())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let expected = "frame_0000.sdf:4:9: error: `/dev/stdin` is not a regular file";
    assert!(stderr.contains(expected), "{stderr}");
    assert!(
        start.elapsed() < Duration::from_secs(5),
        "{:?}",
        start.elapsed()
    );
}
