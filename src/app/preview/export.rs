//! Export: the frames on screen (full where done, else small, scaled up) encoded with ffmpeg
//! into one MP4 in the preview's temporary folder, as `scripts/encode.sh` encodes: H.264,
//! yuv420p, at the spec's frame rate.

use super::state::{json_string, Shared};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

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

/// Encodes what is on screen; the answer for the page, as JSON.
pub fn run(shared: &Shared, export: &Export) -> String {
    match encode(shared, export) {
        Ok(()) => "{\"ok\":true,\"url\":\"/export/preview.mp4\"}".to_string(),
        Err(e) => format!("{{\"ok\":false,\"error\":{}}}", json_string(&e)),
    }
}

/// Encodes what is on screen into [`Export::video`].
pub fn encode(shared: &Shared, export: &Export) -> Result<(), String> {
    let _one = export.busy.lock().unwrap_or_else(|e| e.into_inner());
    if Command::new("ffmpeg").arg("-version").output().is_err() {
        return Err(INSTALL_HINT.to_string());
    }
    let (frames, fps) = {
        let state = shared.lock();
        let frames: Vec<_> = state
            .frames
            .iter()
            .map(|f| f.best().map(|(img, _)| img.png.clone()))
            .collect();
        (frames, state.fps)
    };
    if frames.is_empty() || frames.iter().any(Option::is_none) {
        return Err("some frames are not drawn yet; export again in a moment".to_string());
    }
    let pngs = export.dir.join("frames");
    let _ = std::fs::remove_dir_all(&pngs);
    std::fs::create_dir_all(&pngs).map_err(|e| format!("{}: {e}", pngs.display()))?;
    let mut size = (0, 0);
    for (i, png) in frames.iter().flatten().enumerate() {
        let (w, h) = image::load_from_memory(png)
            .map(|img| (img.width(), img.height()))
            .map_err(|e| format!("frame {i}: {e}"))?;
        size = (size.0.max(w), size.1.max(h));
        let path = pngs.join(format!("frame_{i:06}.png"));
        std::fs::write(&path, png.as_slice()).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    ffmpeg(&pngs, fps, size, &export.video())
}

/// Runs ffmpeg on `dir`'s numbered PNGs; every frame is scaled to `size` (even sides, as
/// yuv420p needs), so small frames stand in for those not drawn in full yet.
fn ffmpeg(dir: &Path, fps: f64, size: (u32, u32), out: &Path) -> Result<(), String> {
    let (w, h) = (size.0.div_ceil(2) * 2, size.1.div_ceil(2) * 2);
    let status = Command::new("ffmpeg")
        .args(["-y", "-loglevel", "error", "-framerate"])
        .arg(format!("{}", fps.max(1.0)))
        .arg("-i")
        .arg(dir.join("frame_%06d.png"))
        .args(["-vf"])
        .arg(format!("scale={w}:{h}:flags=neighbor"))
        .args([
            "-c:v",
            "libx264",
            "-pix_fmt",
            "yuv420p",
            "-movflags",
            "+faststart",
        ])
        .arg(out)
        .output()
        .map_err(|e| format!("cannot run ffmpeg: {e}"))?;
    if status.status.success() {
        Ok(())
    } else {
        Err(format!(
            "ffmpeg failed: {}",
            String::from_utf8_lossy(&status.stderr).trim()
        ))
    }
}
