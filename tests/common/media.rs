//! ffmpeg and ffprobe as the independent readers of what anim and `scripts/encode.sh` write
//! (OpenEXR, 16-bit PNG, videos): whether they are here, what ffprobe says of a file, and a
//! file decoded to raw pixels.

use std::io::Write as _;
use std::path::Path;
use std::process::Command;

/// Whether `tool -version` runs.
pub fn have(tool: &str) -> bool {
    Command::new(tool)
        .arg("-version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// Whether ffmpeg and ffprobe are here for `test`; when they are not, says so where a normal
/// `cargo test` run shows it (the harness captures `eprintln!` of a passing test), and fails
/// under CI, which installs them.
pub fn ffmpeg_for(test: &str) -> bool {
    if have("ffmpeg") && have("ffprobe") {
        return true;
    }
    assert!(
        std::env::var_os("CI").is_none(),
        "{test}: CI must have ffmpeg and ffprobe"
    );
    let _ = writeln!(
        std::io::stderr(),
        "SKIPPED {test}: ffmpeg/ffprobe are not installed (apt-get install ffmpeg); CI installs them"
    );
    false
}

/// What `ffprobe -v error ARGS FILE` prints, trimmed.
pub fn ffprobe(args: &[&str], file: &Path) -> String {
    let out = Command::new("ffprobe")
        .args(["-v", "error"])
        .args(args)
        .arg(file)
        .output()
        .expect("ffprobe runs");
    assert!(
        out.status.success(),
        "ffprobe {}: {}",
        file.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).trim().to_string()
}

/// One `key=value` of ffprobe's first video stream, e.g. `codec_name`.
pub fn stream_field(file: &Path, key: &str) -> String {
    let entries = format!("stream={key}");
    let args = ["-select_streams", "v:0", "-show_entries", &entries];
    ffprobe(&[&args[..], &["-of", "default=nw=1:nk=1"]].concat(), file)
}

/// The frames of `file` as ffmpeg decodes them, in `pix_fmt` (e.g. `rgb24`,
/// `gbrapf32le`), all frames one after the other.
pub fn decode(file: &Path, pix_fmt: &str) -> Vec<u8> {
    let out = Command::new("ffmpeg")
        .args(["-v", "error", "-nostdin", "-i"])
        .arg(file)
        .args(["-f", "rawvideo", "-pix_fmt", pix_fmt, "-"])
        .output()
        .expect("ffmpeg runs");
    assert!(
        out.status.success(),
        "ffmpeg {}: {}",
        file.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

/// Planar float frames (`gbrpf32le`, `gbrapf32le`) as RGB(A) per pixel, row-major.
pub fn planar_floats(raw: &[u8], pixels: usize, planes: usize) -> Vec<[f32; 4]> {
    let floats: Vec<f32> = raw
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    assert_eq!(
        floats.len(),
        pixels * planes,
        "one frame of {planes} planes"
    );
    let plane = |p: usize, i: usize| floats[p * pixels + i];
    (0..pixels)
        .map(|i| {
            let alpha = if planes == 4 { plane(3, i) } else { 1.0 };
            // ffmpeg's planar order is G, B, R (then A).
            [plane(2, i), plane(0, i), plane(1, i), alpha]
        })
        .collect()
}

/// Each frame's PSNR (dB, the mean over Y, U and V) of `video` against the images
/// `reference` (an ffmpeg pattern such as `dir/ref_%04d.png`), as ffmpeg's `psnr` filter
/// measures it: the reference converted to the video's own pixel format first, the way
/// a codec's fidelity is usually stated.
pub fn psnr_per_frame(video: &Path, reference: &Path) -> Vec<f64> {
    let stats = tempfile::NamedTempFile::new().expect("a stats file");
    let filter = format!(
        // Frame n of each at second n: they pair by their order, whatever their rates.
        "[0:v]setpts=N/TB[v];[1:v]setpts=N/TB[r];[v][r]psnr=stats_file='{}'",
        stats.path().display().to_string().replace('\'', "\\'")
    );
    let out = Command::new("ffmpeg")
        .args(["-v", "error", "-nostdin", "-i"])
        .arg(video)
        .arg("-i")
        .arg(reference)
        .args(["-lavfi", &filter, "-f", "null", "-"])
        .output()
        .expect("ffmpeg runs");
    assert!(
        out.status.success(),
        "ffmpeg psnr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(stats.path()).expect("the stats");
    text.lines()
        .filter_map(|l| {
            l.split_whitespace()
                .find_map(|f| f.strip_prefix("psnr_avg:"))
        })
        .map(|v| {
            if v == "inf" {
                f64::INFINITY
            } else {
                v.parse().expect("a PSNR")
            }
        })
        .collect()
}
