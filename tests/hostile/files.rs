//! Hostile and unlucky input files, through the real binary: old Mac line endings, escape
//! and NUL bytes, composite trees that multiply out, huge lines, endless devices and
//! thousands of bad lines each end quickly with a clear message (or the right image), and
//! nothing raw reaches the terminal.

use crate::common;

use common::{anim, compare, read_ppm};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

const SCENE_LF: &str = "define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20\n\
    define shape sphere ball 0 0 -5 1 red\n\
    define light sun 5 5 5 1 1 1 1\n\
    ambient 0.1 0.1 0.1\n\
    define camera cam 60\n\
    render cam image.ppm 24 18\n";

/// Inputs here are refused in milliseconds; before the fixes some took minutes. The bound is
/// generous (debug builds, a loaded machine) yet far below any quadratic or exponential walk.
const QUICK: Duration = Duration::from_secs(20);

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// Runs `anim` with `args`; returns (success, stdout, stderr as bytes, wall time).
fn run(args: &[&std::ffi::OsStr]) -> (bool, String, Vec<u8>, Duration) {
    let start = Instant::now();
    let out = anim().args(args).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        out.stderr,
        start.elapsed(),
    )
}

fn check(path: &Path) -> (bool, String, Duration) {
    let (ok, _, stderr, took) = run(&["check".as_ref(), path.as_os_str()]);
    (ok, String::from_utf8_lossy(&stderr).into_owned(), took)
}

fn render(dir: &Path, name: &str, text: &str) -> common::Rgb8 {
    let scene = write(dir, name, text.as_bytes());
    let out = dir.join(format!("out-{name}"));
    let (ok, _, stderr, _) = run(&[
        "render".as_ref(),
        scene.as_os_str(),
        "--quiet".as_ref(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(ok, "{}", String::from_utf8_lossy(&stderr));
    read_ppm(&out.join("image.ppm"))
}

#[test]
fn cr_only_files_render_like_their_lf_version() {
    let dir = tempfile::tempdir().unwrap();
    let lf = render(dir.path(), "lf.sdf", SCENE_LF);
    let cr = render(dir.path(), "cr.sdf", &SCENE_LF.replace('\n', "\r"));
    assert_eq!(compare(&lf, &cr), (0, 0));
    // Before, a CR-only file whose first line is a comment was one comment: an empty image.
    let commented = format!("// made on an old Mac\n{SCENE_LF}").replace('\n', "\r");
    let cr = render(dir.path(), "commented.sdf", &commented);
    assert_eq!(compare(&lf, &cr), (0, 0));
    let background = lf.at(0, 0);
    assert_ne!(lf.at(12, 9), background, "the sphere is drawn");
}

#[test]
fn a_cr_only_file_with_an_error_quotes_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let text = SCENE_LF
        .replace("0 0 -5 1", "0 0 -5 1O")
        .replace('\n', "\r");
    let path = write(dir.path(), "cr.sdf", text.as_bytes());
    let (ok, stderr, _) = check(&path);
    assert!(!ok);
    assert!(stderr.contains("cr.sdf:2:"), "{stderr}");
    assert!(!stderr.contains("define light"), "{stderr}");
}

#[test]
fn control_bytes_never_reach_the_terminal() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        "{SCENE_LF}\u{1b}[2J\u{1b}]0;pwned\u{7} 1 2\ndefine shape sphere \u{1b}[31mx 0 0 0 1 red\u{9b}1m\n"
    );
    let path = write(dir.path(), "esc.sdf", text.as_bytes());
    let (_, _, stderr, _) = run(&["check".as_ref(), path.as_os_str()]);
    assert!(
        !stderr.contains(&0x1b),
        "{}",
        String::from_utf8_lossy(&stderr)
    );
    assert!(!stderr.contains(&0x07));
    let stderr = String::from_utf8_lossy(&stderr);
    assert!(stderr.contains("\\u{1b}[2J"), "{stderr}");
    assert!(!stderr.contains('\u{9b}'), "{stderr}");
}

#[test]
fn a_file_with_nul_bytes_is_not_a_text_file() {
    let dir = tempfile::tempdir().unwrap();
    let mut bytes = SCENE_LF.as_bytes().to_vec();
    bytes.extend([0, 0, 1, 2, 0xff, 0]);
    let path = write(dir.path(), "binary.sdf", &bytes);
    let (ok, stderr, _) = check(&path);
    assert!(!ok);
    assert!(
        stderr.contains("binary.sdf: error: not a text file"),
        "{stderr}"
    );
    assert_eq!(stderr.matches("error").count(), 1, "{stderr}");
}

#[test]
fn a_doubling_composite_chain_is_refused_from_its_counts() {
    // 300 chained composites, the top 40 listing their child twice: 2^40 copies of a chain of
    // 260, in a 10 kB file. Walking it took minutes; counting takes microseconds.
    let chain = |doubled: usize| {
        let mut text = String::from(
            "define material m 1 0 0 1 0 0 1 0 0 1\ndefine shape sphere s0 0 0 0 1 m\n",
        );
        for k in 1..=300 {
            let child = if k == 1 {
                "s0".to_string()
            } else {
                format!("c{}", k - 1)
            };
            let twice = if k > 300 - doubled {
                format!(" {child}")
            } else {
                String::new()
            };
            text.push_str(&format!("define shape composite c{k} {child}{twice}\n"));
        }
        text.push_str("define camera cam 60\nrender cam image.png 10 10\n");
        text
    };
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "chain.sdf", chain(40).as_bytes());
    let (ok, stderr, took) = check(&path);
    assert!(!ok);
    assert!(took < QUICK, "{took:?}");
    assert!(
        stderr.contains(
            "error: the composite tree expands to 1099511627776 shapes, which need about 393216.0 GiB of memory"
        ),
        "{stderr}"
    );
    assert!(stderr.contains("--max-memory raises the limit"), "{stderr}");

    // 2^20 shapes fit the machine's memory but not a budget of 64 MiB.
    let path = write(dir.path(), "chain20.sdf", chain(20).as_bytes());
    let out = anim()
        .args(["check", "--max-memory", "64M"])
        .arg(&path)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("expands to 1048576 shapes, which need about 384.0 MiB of memory, more than the 64.0 MiB allowed (`c300` is the largest part)"),
        "{stderr}"
    );

    // Composites holding nothing expand to no shapes but would still be walked forever.
    let mut text = String::from("define shape composite e0\n");
    for k in 1..=200 {
        text.push_str(&format!(
            "define shape composite e{k} e{p} e{p}\n",
            p = k - 1
        ));
    }
    let path = write(dir.path(), "empty.sdf", text.as_bytes());
    let (ok, stderr, took) = check(&path);
    assert!(!ok);
    assert!(took < QUICK, "{took:?}");
    assert!(stderr.contains("composites and shapes"), "{stderr}");
}

#[test]
fn a_very_long_chain_of_composites_is_refused_without_overflowing_the_stack() {
    let mut text =
        String::from("define material m 1 0 0 1 0 0 1 0 0 1\ndefine shape sphere c0 0 0 0 1 m\n");
    for k in 1..=100_000 {
        text.push_str(&format!("define shape composite c{k} c{}\n", k - 1));
    }
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "deep.sdf", text.as_bytes());
    let (ok, stderr, took) = check(&path);
    assert!(!ok);
    assert!(took < QUICK, "{took:?}");
    assert!(stderr.contains("nested more than 256 deep"), "{stderr}");
}

#[test]
fn endless_and_oversized_inputs_are_refused_unread() {
    // A device that never ends: refused from its first bytes.
    let (ok, _, stderr, took) = run(&["check".as_ref(), "/dev/zero".as_ref()]);
    let stderr = String::from_utf8_lossy(&stderr);
    assert!(!ok);
    assert!(took < QUICK, "{took:?}");
    assert!(stderr.contains("not a text file"), "{stderr}");

    // A file the file system says is too large: refused from its size (sparse: no disk).
    let dir = tempfile::tempdir().unwrap();
    let big = dir.path().join("big.sdf");
    std::fs::File::create(&big)
        .unwrap()
        .set_len(2 << 30)
        .unwrap();
    let (ok, stderr, took) = check(&big);
    assert!(!ok);
    assert!(took < QUICK, "{took:?}");
    assert!(
        stderr.contains(
            "too large to read: 2147483648 bytes, more than the limit of 1073741824 bytes"
        ),
        "{stderr}"
    );

    // A stream of text: refused after the limit, however long it would go on.
    let out = anim()
        .args(["check", "--max-input", "1000", "/dev/stdin"])
        .write_stdin("ambient 0.1 0.1 0.1\n".repeat(1000))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains(
            "too large to read: it goes on past the limit, more than the limit of 1000 bytes"
        ),
        "{stderr}"
    );

    // At the limit exactly, a file is read.
    let small = write(dir.path(), "small.sdf", SCENE_LF.as_bytes());
    let limit = SCENE_LF.len().to_string();
    let (ok, _, stderr, _) = run(&[
        "check".as_ref(),
        "--max-input".as_ref(),
        limit.as_ref(),
        small.as_os_str(),
    ]);
    assert!(ok, "{}", String::from_utf8_lossy(&stderr));

    // The limit takes a unit, as --max-memory does: 1K is 1024 bytes.
    let padded = format!("{SCENE_LF}{}", "# padding\n".repeat(300));
    let padded = write(dir.path(), "padded.sdf", padded.as_bytes());
    let (ok, _, stderr, _) = run(&[
        "check".as_ref(),
        "--max-input".as_ref(),
        "1K".as_ref(),
        padded.as_os_str(),
    ]);
    let stderr = String::from_utf8_lossy(&stderr);
    assert!(
        !ok && stderr.contains("more than the limit of 1024 bytes"),
        "{stderr}"
    );
    let (ok, _, stderr, _) = run(&[
        "check".as_ref(),
        "--max-input".as_ref(),
        "1M".as_ref(),
        padded.as_os_str(),
    ]);
    assert!(ok, "{}", String::from_utf8_lossy(&stderr));
}

#[test]
fn ten_thousand_bad_lines_print_at_most_the_cap() {
    let text: String = (0..10_000).map(|i| format!("bogus{i} 1 2 3\n")).collect();
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "bad.sdf", text.as_bytes());
    for command in ["check", "render"] {
        let (_, _, stderr, took) = run(&[command.as_ref(), path.as_os_str()]);
        let stderr = String::from_utf8_lossy(&stderr);
        assert!(took < QUICK, "{took:?}");
        let shown = stderr.matches("unknown statement").count();
        assert_eq!(shown, 50, "{command}: {stderr}");
        assert!(
            // 9 950 bad lines and the missing render line.
            stderr.contains("and 9951 more (9951 warnings) not shown"),
            "{command}: {stderr}"
        );
    }
}

#[test]
fn a_huge_line_is_quoted_in_part_and_read_in_linear_time() {
    let dir = tempfile::tempdir().unwrap();
    // 20 MB: one word, then many small tokens.
    let word = format!("{}\n", "x".repeat(20 << 20));
    let tokens = format!("define shape composite c {}\n", "a ".repeat(10 << 20));
    for (name, text) in [("word.sdf", word), ("tokens.sdf", tokens)] {
        let path = write(dir.path(), name, text.as_bytes());
        let (ok, stderr, took) = check(&path);
        assert!(!ok || name == "word.sdf");
        assert!(took < QUICK, "{name}: {took:?}");
        assert!(
            stderr.len() < 20_000,
            "{name}: {} bytes of messages",
            stderr.len()
        );
        assert!(stderr.contains('…'), "{name}: {stderr}");
    }
}

/// Control characters in the names of images, scene files and frame directories reach the
/// terminal escaped (`\u{1b}`), in the `wrote` line, the progress lines and the summaries,
/// never raw.
#[test]
fn control_characters_in_names_are_printed_escaped() {
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("frames\u{7}dir");
    std::fs::create_dir(&frames).unwrap();
    let scene = |image: &str| {
        format!(
            "define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20\n\
             define shape sphere ball 0 0 -5 1 red\n\
             define light sun 5 5 5 1 1 1 1\n\
             define camera cam 60\n\
             render cam {image} 8 6\n"
        )
    };
    let file = frames.join("f\u{1b}[2J\r1.sdf");
    std::fs::write(&file, scene("a\u{1b}]0;title\u{7}b.png")).unwrap();
    let raw = |bytes: &[u8]| bytes.iter().any(|&b| b == 0x1b || b == 0x07 || b == b'\r');
    let alone = anim().arg("render").arg(&file).output().unwrap();
    let stderr = String::from_utf8_lossy(&alone.stderr);
    assert!(alone.status.success(), "{stderr}");
    assert!(
        stderr.contains("wrote ") && stderr.contains("\\u{1b}"),
        "{stderr}"
    );
    assert!(!raw(&alone.stderr) && !raw(&alone.stdout), "{stderr:?}");
    std::fs::write(&file, scene("c\u{1b}[31m.png")).unwrap();
    let all = anim().arg("render").arg(&frames).output().unwrap();
    let stderr = String::from_utf8_lossy(&all.stderr);
    assert!(all.status.success(), "{stderr}");
    assert!(
        stderr.contains("rendered f\\u{1b}[2J\\u{d}1.sdf"),
        "{stderr}"
    );
    assert!(!raw(&all.stderr) && !raw(&all.stdout), "{stderr:?}");
}

/// Under an address-space limit (`ulimit -v`), the default memory budget is half of it: an
/// image too large for it and a 2 GB sparse OBJ file each end at once with a located message
/// and exit code 1, never an abort.
#[test]
fn an_address_space_limit_is_the_budget_and_nothing_aborts() {
    let dir = tempfile::tempdir().unwrap();
    let head = "define material m 0.2 0.2 0.2 0.8 0.8 0.8 0 0 0 1\n\
        define light l 0 0 5 1 1 1 1\n\
        define camera c 60 0.3 0.3 3 0 0 -1 0 1 0\n";
    std::fs::write(
        dir.path().join("huge.sdf"),
        format!("{head}define shape sphere s 0 0 0 1 m\nrender c huge.png 16384 16384\n"),
    )
    .unwrap();
    let obj = dir.path().join("big.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    std::fs::OpenOptions::new()
        .write(true)
        .open(&obj)
        .unwrap()
        .set_len(2 << 30)
        .unwrap();
    std::fs::write(
        dir.path().join("mesh.sdf"),
        format!("{head}define shape obj t big.obj m\nrender c mesh.png 8 6\n"),
    )
    .unwrap();
    let anim_bin = assert_cmd::cargo::cargo_bin("anim");
    for (scene, expected) in [
        ("huge.sdf", "huge.sdf:5:"),
        ("mesh.sdf", "mesh.sdf:4:1: error: mesh file `big.obj`"),
    ] {
        let start = std::time::Instant::now();
        let out = std::process::Command::new("sh")
            .arg("-c")
            .arg("ulimit -v 4000000 && exec \"$0\" render \"$1\"")
            .arg(&anim_bin)
            .arg(dir.path().join(scene))
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{scene}: {stderr}");
        assert!(stderr.contains(expected), "{scene}: {stderr}");
        assert!(start.elapsed().as_secs() < 10, "{scene}: {stderr}");
    }
}

/// A named pipe given as the scene file, which nothing writes to, is an error within a
/// second, for `check` and `render` alike (opening it would wait for a writer forever).
#[test]
fn a_named_pipe_nothing_writes_to_is_an_error_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let pipe = dir.path().join("scene.sdf");
    let made = std::process::Command::new("mkfifo")
        .arg(&pipe)
        .status()
        .unwrap();
    assert!(made.success());
    for command in ["check", "render"] {
        let start = std::time::Instant::now();
        let out = anim()
            .arg(command)
            .arg(&pipe)
            .timeout(std::time::Duration::from_secs(20))
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{command}: {stderr}");
        assert!(
            stderr.contains("a named pipe that nothing writes to"),
            "{command}: {stderr}"
        );
        assert!(
            start.elapsed().as_millis() < 1500,
            "{command}: {:?}",
            start.elapsed()
        );
    }
}

/// Time linear in a shape's `motion` lines: 200,000 of them for one sphere check and render
/// in seconds (placing the shape at each key's instant walked the keys from the first, which
/// took minutes at this count).
#[test]
fn many_motion_lines_for_one_shape_take_linear_time() {
    let dir = tempfile::tempdir().unwrap();
    let n = 200_000;
    let mut text = String::from(
        "define material m 0.2 0.2 0.2 0.8 0.8 0.8 0 0 0 1\n\
         define light l 0 0 5 1 1 1 1\n\
         define shape sphere s 0 0 -5 1 m\n\
         define camera c 60\n\
         render c motion.ppm 16 12\n",
    );
    for i in 0..=n {
        let u = i as f64 / n as f64;
        text.push_str(&format!("motion s {u} translate {} 0 0\n", u * 0.5));
    }
    let scene = write(dir.path(), "motion.sdf", text.as_bytes());
    for command in ["check", "render"] {
        let start = std::time::Instant::now();
        let out = anim()
            .args([command, "--quiet"])
            .arg(&scene)
            .timeout(std::time::Duration::from_secs(120))
            .output()
            .unwrap();
        let took = start.elapsed();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(took.as_secs() < 20, "{command}: {took:?}");
    }
}

/// A spec saved with a byte order mark (as some editors save) generates like the same spec
/// without one, and an error on its first line is at the column an editor shows.
#[test]
fn a_spec_with_a_byte_order_mark_reads_as_without() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("scene.sdf"),
        "define material m 0.2 0.2 0.2 0.8 0.8 0.8 0 0 0 1\n\
         define light l 0 0 5 1 1 1 1\n\
         define shape sphere s 0 0 -5 1 m\n\
         define camera cam 60\n",
    )
    .unwrap();
    let spec = "(scene: File(\"scene.sdf\"), camera: \"cam\", fps: 24, length: Frames(2), \
        resolution: (16, 12), output: \"f_{frame}.png\")\n";
    for (name, text) in [
        ("plain.ron", spec.to_string()),
        ("bom.ron", format!("\u{feff}{spec}")),
    ] {
        std::fs::write(dir.path().join(name), text).unwrap();
        let out = anim()
            .arg("generate")
            .arg(dir.path().join(name))
            .arg("-o")
            .arg(dir.path().join(name.replace(".ron", "")))
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let frame = |d: &str| std::fs::read_to_string(dir.path().join(d).join("f_0001.sdf")).unwrap();
    assert_eq!(
        frame("plain").replace("plain.ron", "X"),
        frame("bom").replace("bom.ron", "X")
    );
    std::fs::write(dir.path().join("bad.ron"), "\u{feff}(scene: 5)\n").unwrap();
    let out = anim()
        .arg("generate")
        .arg(dir.path().join("bad.ron"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("bad.ron:1:9:"),
        "{stderr}"
    );
}

/// Output patterns whose frames `anim render DIR` would pass over (hidden files) or whose
/// names would carry control characters are errors at the spec's `output` field.
#[test]
fn output_patterns_of_hidden_or_control_names_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("scene.sdf"),
        "define material m 0.2 0.2 0.2 0.8 0.8 0.8 0 0 0 1\ndefine camera cam 60\n",
    )
    .unwrap();
    for (output, says) in [
        (".{frame}.png", "starts with a dot"),
        ("a\\u{1b}[2J{frame}.png", "control character"),
    ] {
        let spec = format!(
            "(scene: File(\"scene.sdf\"), camera: \"cam\", fps: 24, length: Frames(2), \
             resolution: (16, 12), output: \"{output}\")\n"
        );
        std::fs::write(dir.path().join("s.ron"), spec).unwrap();
        let out = anim()
            .arg("generate")
            .arg(dir.path().join("s.ron"))
            .arg("-o")
            .arg(dir.path().join("frames"))
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{output}: {stderr}");
        assert!(
            stderr.contains("s.ron:1:") && stderr.contains(says),
            "{output}: {stderr}"
        );
        assert!(!stderr.contains('\u{1b}'), "{stderr:?}");
        assert!(
            !dir.path().join("frames").exists(),
            "{output}: frames were written"
        );
    }
}

/// A spec with 100,000 bad keys lists the first errors and counts the rest, in seconds (each
/// error quoted its line, which took minutes at this count).
#[test]
fn a_spec_with_very_many_bad_keys_lists_the_first_and_counts_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("scene.sdf"),
        "define material m 0.2 0.2 0.2 0.8 0.8 0.8 0 0 0 1\ndefine camera cam 60\n",
    )
    .unwrap();
    let keys: Vec<String> = (0..100_000)
        .map(|i| format!("(at: -1, value: ({i}, 0, 0))"))
        .collect();
    let spec = format!(
        "(scene: File(\"scene.sdf\"), camera: \"cam\", fps: 24, length: Frames(2), \
         resolution: (16, 12), output: \"f_{{frame}}.png\", \
         tracks: [(target: \"cam\", translate: [{}])])\n",
        keys.join(",")
    );
    std::fs::write(dir.path().join("bad.ron"), spec).unwrap();
    let start = std::time::Instant::now();
    let out = anim()
        .arg("generate")
        .arg(dir.path().join("bad.ron"))
        .timeout(std::time::Duration::from_secs(120))
        .output()
        .unwrap();
    let took = start.elapsed();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(took.as_secs() < 20, "{took:?}");
    assert!(
        stderr.contains("more (199949 errors) not shown"),
        "{}",
        &stderr[stderr.len().saturating_sub(500)..]
    );
    assert_eq!(stderr.matches(": error: ").count(), 51);
}
