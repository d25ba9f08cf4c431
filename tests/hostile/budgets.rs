//! Reading and parsing within the memory the process may have: inputs whose reading once cost
//! many times their size end with a result or a located message under `ulimit -v`, exit code
//! 1 and no signal.

use std::path::Path;
use std::time::{Duration, Instant};

/// `anim ARGS` in `dir` under `ulimit -v` of `kib` KiB, stopped after 60 s: (exit code,
/// stderr, time taken). A signal leaves no exit code; being stopped, code 124.
pub fn limited(dir: &Path, kib: u64, args: &str) -> (Option<i32>, String, Duration) {
    let start = Instant::now();
    let out = std::process::Command::new("sh")
        .current_dir(dir)
        .arg("-c")
        .arg(format!("ulimit -v {kib} && exec timeout 60 \"$0\" {args}"))
        .arg(env!("CARGO_BIN_EXE_anim"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    (out.status.code(), stderr, start.elapsed())
}

/// A 150 MB line of numbers glued by signs (`1+1+1…`, which would be read as 75 million
/// numbers) and of signs alone (`1+-+-…`): each a located error within 1.5 GB, where splitting
/// them once took 24 bytes per byte of the line.
#[test]
fn a_glued_number_line_of_150_mb_ends_within_its_memory() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let len = 150 << 20;
    for (name, unit) in [("ones.sdf", "1+"), ("signs.sdf", "+-")] {
        let mut text = String::with_capacity(len + 100);
        text.push_str("define material m 1 0 0 1 0 0 1 0 0 10\ndefine shape sphere s 0 0 -5 1");
        while text.len() < len {
            text.push_str(unit);
        }
        text.push_str("1 m\n");
        std::fs::write(dir.join(name), &text).unwrap();
        drop(text);
        let (code, stderr, _) = limited(dir, 1_500_000, &format!("check {name}"));
        assert_eq!(code, Some(1), "{name}: {stderr}");
        assert!(
            stderr.contains(&format!("{name}:2:30: error: ")),
            "{name}: {stderr}"
        );
        std::fs::remove_file(dir.join(name)).unwrap();
    }
}

const HEAD: &str = "define camera c 60 0 0 0 0 0 -1 0 1 0\n\
                    define material m 0.1 0.1 0.1 0.5 0.5 0.5 0 0 0 1\n\
                    define light l 0 10 0 1 1 1\n";

/// `n` spheres on a grid, one line each, named `name` followed by the index when `numbered`.
fn spheres(n: usize, name: &str, numbered: bool) -> String {
    let mut text = String::with_capacity(n * 48);
    for i in 0..n {
        let suffix = if numbered {
            i.to_string()
        } else {
            String::new()
        };
        let (x, y) = (i % 1000, i / 1000);
        text.push_str(&format!(
            "define shape sphere {name}{suffix} {x} {y} -50 0.4 m\n"
        ));
    }
    text
}

/// A million spheres through one include: the same located "needs about ... MiB" message as
/// the flat file gets, where reading them through the include once cost nearly three times
/// the memory and aborted.
#[test]
fn a_million_spheres_through_an_include_end_with_the_memory_message() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("part.sdfi"), spheres(1_000_000, "s", true)).unwrap();
    let scene = format!("{HEAD}include part.sdfi\nrender c out.png 8 6\n");
    std::fs::write(dir.join("scene.sdf"), scene).unwrap();
    for command in ["check", "render"] {
        let (code, stderr, _) = limited(dir, 500_000, &format!("{command} scene.sdf"));
        assert_eq!(code, Some(1), "{command}: {stderr}");
        let message = "part.sdfi:1:21: error: the scene's 1000000 shapes need about ";
        assert!(stderr.contains(message), "{command}: {stderr}");
    }
}

/// Three hundred thousand shapes of one name: each is a warning, but only the first ones a
/// report shows are kept, so the file reads within a budget that once aborted it.
#[test]
fn same_name_shapes_keep_only_the_warnings_shown() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let n = 300_000;
    let scene = format!("{HEAD}{}render c out.png 8 6\n", spheres(n, "s", false));
    std::fs::write(dir.join("same.sdf"), scene).unwrap();
    let (code, stderr, _) = limited(dir, 300_000, "check same.sdf");
    assert_eq!(code, Some(0), "{stderr}");
    let shown = anim_core::limits::MAX_DIAGNOSTICS;
    // Every shape but the first repeats a name; the first `shown` of those are listed.
    let left_out = n - 1 - shown;
    let note = format!("and {left_out} more ({left_out} warnings) not shown");
    assert!(
        stderr.contains(&note),
        "{}",
        &stderr[stderr.len().saturating_sub(2000)..]
    );
}

/// Under an address-space limit too small for a worker's stack, `check` says why it cannot
/// start (the stack each worker reserves, the memory the process may use), where it once
/// said only "cannot start worker threads".
#[test]
fn worker_threads_that_cannot_start_say_why() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    std::fs::write(dir.join("s.sdf"), format!("{HEAD}render c out.png 8 6\n")).unwrap();
    let (code, stderr, _) = limited(dir, 30_000, "check s.sdf");
    assert_eq!(code, Some(1), "{stderr}");
    let stack = anim_core::util::human_bytes(anim_core::limits::RENDER_STACK_BYTES as u64);
    assert!(
        stderr.contains("error: cannot start worker threads"),
        "{stderr}"
    );
    assert!(
        stderr.contains(&format!(
            "each reserves {stack} of address space for its stack"
        )),
        "{stderr}"
    );
    assert!(
        stderr.contains("this process may use 29.3 MiB in all"),
        "{stderr}"
    );
}

/// An OBJ file of `n` × `n` vertices on a grid, two triangles to each square of it.
fn grid_obj(n: usize) -> String {
    let mut text = String::with_capacity(n * n * 40);
    for j in 0..n {
        for i in 0..n {
            text.push_str(&format!("v {i} {j} 0\n"));
        }
    }
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = j * n + i + 1;
            let (b, c, d) = (a + 1, a + n, a + n + 1);
            text.push_str(&format!("f {a} {b} {d}\nf {a} {d} {c}\n"));
        }
    }
    text
}

/// An OBJ file of `n` triangles, each with its own three vertices.
fn soup_obj(n: usize) -> String {
    let mut text = String::with_capacity(n * 60);
    for t in 0..n {
        let (x, y) = (t % 1000, t / 1000);
        text.push_str(&format!(
            "v {x} {y} 0\nv {x}.5 {y} 0\nv {x} {y}.5 0\nf -3 -2 -1\n"
        ));
    }
    text
}

/// A 300,000-triangle mesh under an address-space limit too small to read it: the located
/// "needs about ... MiB" message at the statement naming it, exit code 1 and no signal, where
/// reading it once aborted (whether its triangles share their vertices or not). The same
/// mesh reads under a limit that holds it.
#[test]
fn a_300k_triangle_mesh_beyond_the_memory_ends_with_the_memory_message() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // 388 × 388 vertices make 2 · 387² = 299,538 triangles.
    let meshes = [
        ("grid.obj", grid_obj(388), 299_538),
        ("soup.obj", soup_obj(300_000), 300_000),
    ];
    for (name, text, triangles) in meshes {
        std::fs::write(dir.join(name), text).unwrap();
        let scene = format!("{HEAD}define shape obj mesh {name} m\nrender c out.png 8 6\n");
        std::fs::write(dir.join("scene.sdf"), scene).unwrap();
        // Not lower: near 150000 KiB the worker threads' stacks may not fit beside the
        // reading, and the run ends with that message instead (also exit 1, no signal).
        for kib in [200_000, 250_000, 300_000] {
            let (code, stderr, _) = limited(dir, kib, "check scene.sdf");
            assert_eq!(code, Some(1), "{name} at {kib} KiB: {stderr}");
            let message = format!("scene.sdf:4:1: error: mesh file `{name}` needs about ");
            assert!(stderr.contains(&message), "{name} at {kib} KiB: {stderr}");
            let count = format!("to read and build its {triangles} triangles, more than the ");
            assert!(stderr.contains(&count), "{name} at {kib} KiB: {stderr}");
        }
        let (code, stderr, _) = limited(dir, 600_000, "check scene.sdf");
        assert_eq!(code, Some(0), "{name} at 600000 KiB: {stderr}");
    }
}
