//! Export: every frame at full quality (as `anim render` draws it; drafts are waited for
//! until the workers have drawn them in full) encoded with ffmpeg into one MP4 in the
//! preview's temporary folder, as `scripts/encode.sh` encodes by default: H.264, yuv420p, at
//! the spec's frame rate. And the checks of `--export OUT` made before anything renders.

use super::state::{json_string, Shared};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// How to get ffmpeg, shown where it is missing.
pub const INSTALL_HINT: &str = "ffmpeg is not installed. Install it with: Debian/Ubuntu `sudo apt-get install -y ffmpeg`, Fedora `sudo dnf install -y ffmpeg` (RPM Fusion), macOS `brew install ffmpeg`, Windows `winget install ffmpeg`";

/// The preview's export folder; one encode at a time.
pub struct Export {
    dir: PathBuf,
    busy: Mutex<()>,
}

impl Export {
    pub fn new(dir: PathBuf) -> Export {
        Export {
            dir,
            busy: Mutex::new(()),
        }
    }

    /// Where the video is written (and served from).
    pub fn video(&self) -> PathBuf {
        self.dir.join("preview.mp4")
    }
}

/// Waits for every frame at full quality, encodes them; the answer for the page, as JSON.
pub fn run(shared: &Shared, export: &Export) -> String {
    match encode(shared, export) {
        Ok(count) => format!(
            "{{\"ok\":true,\"url\":\"/export/preview.mp4\",\"frames\":{count},\"note\":{}}}",
            json_string(&format!("{count} frames at full quality"))
        ),
        Err(e) => format!("{{\"ok\":false,\"error\":{}}}", json_string(&e)),
    }
}

/// Waits until every frame is drawn at full quality, then encodes them into
/// [`Export::video`]; how many frames it holds, or the lines that say why not (each a whole
/// diagnostic, as the terminal prints it).
pub fn encode(shared: &Shared, export: &Export) -> Result<usize, String> {
    let _one = export.busy.lock().unwrap_or_else(|e| e.into_inner());
    if !have_ffmpeg() {
        return Err(format!("error: {INSTALL_HINT}"));
    }
    let (frames, fps) = full_frames(shared)?;
    let pngs = export.dir.join("frames");
    let _ = std::fs::remove_dir_all(&pngs);
    std::fs::create_dir_all(&pngs).map_err(|e| format!("error: {}: {e}", pngs.display()))?;
    for (i, png) in frames.iter().enumerate() {
        let path = pngs.join(format!("frame_{i:06}.png"));
        std::fs::write(&path, png.as_slice())
            .map_err(|e| format!("error: {}: {e}", path.display()))?;
    }
    ffmpeg(&pngs, fps, &export.video())?;
    Ok(frames.len())
}

fn have_ffmpeg() -> bool {
    Command::new("ffmpeg").arg("-version").output().is_ok()
}

/// A frame's PNG file, as the state holds it.
type Png = Arc<Vec<u8>>;

/// Every frame's full-quality PNG of its current content and the frame rate, once all are
/// drawn (taken under one lock, so no edit can mix two builds); an error when a frame failed,
/// the first build failed or the preview stops.
fn full_frames(shared: &Shared) -> Result<(Vec<Png>, f64), String> {
    let mut state = shared.lock();
    loop {
        if state.stop {
            return Err(
                "error: the preview stopped before every frame was drawn in full".to_string(),
            );
        }
        if state.builds == 0 && !state.diagnostics.is_empty() {
            return Err(state.diagnostics.join("\n"));
        }
        let failed: Vec<&str> = state
            .frames
            .iter()
            .filter_map(|f| f.error.as_deref())
            .collect();
        if !failed.is_empty() {
            return Err(failed.join("\n"));
        }
        let full: Option<Vec<_>> = state
            .frames
            .iter()
            .map(|f| f.full.as_ref().filter(|i| i.key == f.key))
            .map(|i| i.map(|i| i.png.clone()))
            .collect();
        match full {
            Some(frames) if state.builds > 0 && !frames.is_empty() => {
                return Ok((frames, state.fps));
            }
            _ => state = shared.wait(&shared.changed, state, Duration::from_millis(200)),
        }
    }
}

/// Runs ffmpeg on `dir`'s numbered PNGs (all of one size: the spec's); odd sides are padded
/// by one pixel, as yuv420p needs even ones.
fn ffmpeg(dir: &Path, fps: f64, out: &Path) -> Result<(), String> {
    let status = Command::new("ffmpeg")
        .args(["-y", "-nostdin", "-loglevel", "error", "-framerate"])
        .arg(format!("{}", fps.max(1.0)))
        .arg("-i")
        .arg(dir.join("frame_%06d.png"))
        .args([
            "-vf",
            "pad=ceil(iw/2)*2:ceil(ih/2)*2",
            "-c:v",
            "libx264",
            "-preset",
            "veryfast",
            // Near-transparent quality: a preview export stands for the frames themselves.
            "-crf",
            "12",
            "-pix_fmt",
            "yuv420p",
            "-movflags",
            "+faststart",
            "-f",
            "mp4",
        ])
        .arg(out)
        .output()
        .map_err(|e| format!("error: cannot run ffmpeg: {e}"))?;
    if status.status.success() {
        Ok(())
    } else {
        Err(format!(
            "error: ffmpeg failed: {}",
            String::from_utf8_lossy(&status.stderr).trim()
        ))
    }
}

/// The checks of `--export OUT`, before anything renders: a file name ending .mp4, in a
/// folder that exists, that is none of `inputs` (the files the preview reads:
/// writing the video there would destroy one), and ffmpeg installed. The error names the
/// option and the path.
pub fn check_output(out: &Path, inputs: &[PathBuf]) -> Result<(), String> {
    let shown = out.display();
    let fail = |what: String| Err(format!("error: --export {shown}: {what}"));
    if out.is_dir() || out.file_name().is_none() {
        return fail("that is a folder; give the video's file name, e.g. out.mp4".to_string());
    }
    let parent = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !parent.is_dir() {
        return fail(format!(
            "the folder {} does not exist; make it first",
            parent.display()
        ));
    }
    if let Some(input) = inputs.iter().find(|i| same_file(out, i)) {
        return fail(format!(
            "that is {}, which the preview reads; write the video elsewhere",
            input.display()
        ));
    }
    if !out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mp4"))
    {
        return fail("the video's name must end in .mp4 (an H.264 MP4)".to_string());
    }
    if !have_ffmpeg() {
        return fail(INSTALL_HINT.to_string());
    }
    Ok(())
}

/// Whether writing `out` would write `input`: the same path once the folders' links are
/// resolved, or (for a file that exists) the same file under another name (a hard link or a
/// symbolic one).
fn same_file(out: &Path, input: &Path) -> bool {
    let resolved = |p: &Path| -> Option<PathBuf> {
        let parent = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        Some(parent.canonicalize().ok()?.join(p.file_name()?))
    };
    if resolved(out).is_some_and(|o| resolved(input).is_some_and(|i| i == o)) {
        return true;
    }
    identity(out).is_some_and(|o| identity(input) == Some(o))
}

#[cfg(unix)]
fn identity(path: &Path) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt as _;
    let meta = std::fs::metadata(path).ok()?;
    Some((meta.dev(), meta.ino()))
}

#[cfg(not(unix))]
fn identity(path: &Path) -> Option<PathBuf> {
    path.canonicalize().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_input_under_any_name_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let spec = dir.path().join("shot.ron");
        std::fs::write(&spec, "()").unwrap();
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let inputs = [spec.clone()];
        let by_climbing = dir.path().join("sub/../shot.ron");
        assert!(same_file(&by_climbing, &spec));
        let linked = dir.path().join("link.mp4");
        std::fs::hard_link(&spec, &linked).unwrap();
        assert!(same_file(&linked, &spec));
        // Said as such, whatever the name's extension.
        for out in [&linked, &spec] {
            let err = check_output(out, &inputs).unwrap_err();
            assert!(err.contains("which the preview reads"), "{err}");
        }
        assert!(!same_file(&dir.path().join("new.mp4"), &spec));
    }

    #[test]
    fn a_missing_folder_and_a_name_without_a_video_extension_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("missing dir/x.mp4");
        let err = check_output(&missing, &[]).unwrap_err();
        assert!(
            err.starts_with(&format!(
                "error: --export {}: the folder",
                missing.display()
            )),
            "{err}"
        );
        let err = check_output(&dir.path().join("x.ron"), &[]).unwrap_err();
        assert!(err.contains("must end in .mp4"), "{err}");
        let err = check_output(dir.path(), &[]).unwrap_err();
        assert!(err.contains("that is a folder"), "{err}");
    }
}
