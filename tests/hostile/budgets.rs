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
