//! Reading a scene's input files (scene files, included files, keyframe specs): whole, with a
//! size limit known before memory grows, refusing what is not text, and never waiting on a
//! named pipe that nothing writes to.

use crate::diag::Diagnostic;
use std::io::Read;
use std::path::Path;

/// How much of the start of a file is looked at for NUL bytes, which text never holds.
const TEXT_SNIFF_BYTES: usize = 8 << 10;

/// Reads a whole text file of at most `limit` bytes. Larger files are refused from their
/// size when the file system knows it, else after reading `limit + 1` bytes (pipes, devices),
/// so memory never grows past the limit. A file with a NUL byte in its first
/// `TEXT_SNIFF_BYTES` is "not a text file", found before the rest is read (`/dev/zero`
/// fails at once). `what` names the file in messages ("file", "the spec").
pub fn read_input(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>, Vec<Diagnostic>> {
    read_bounded(path, limit, what).map_err(|d| vec![*d])
}

pub(crate) fn read_bounded(
    path: &Path,
    limit: u64,
    what: &str,
) -> Result<Vec<u8>, Box<Diagnostic>> {
    let cannot =
        |e: std::io::Error| Diagnostic::file_error(path, format!("cannot read {what}: {e}"));
    let too_big = |size: String| Box::new(Diagnostic::too_large(path, &size, limit));
    let file = open_without_waiting(path).map_err(cannot)?;
    let meta = file.metadata().map_err(cannot)?;
    // Regular files tell their length; devices and pipes say 0 and are bounded by `take`.
    if meta.is_file() && meta.len() > limit {
        return Err(too_big(format!("{} bytes", meta.len())));
    }
    let expected = if meta.is_file() { meta.len() } else { 0 };
    let mut bytes = Vec::with_capacity(usize::try_from(expected.min(limit)).unwrap_or(0));
    let mut input = file.take(limit.saturating_add(1));
    (&mut input)
        .take(TEXT_SNIFF_BYTES as u64)
        .read_to_end(&mut bytes)
        .map_err(cannot)?;
    if bytes.contains(&0) {
        return Err(Box::new(Diagnostic::file_error(
            path,
            "not a text file (it holds NUL bytes)",
        )));
    }
    input.read_to_end(&mut bytes).map_err(cannot)?;
    if bytes.len() as u64 > limit {
        return Err(too_big("it goes on past the limit".to_string()));
    }
    Ok(bytes)
}

/// How long opening a named pipe may wait for a program to write to it.
const PIPE_WAIT: std::time::Duration = std::time::Duration::from_millis(500);

/// Opens `path` for reading. Opening a named pipe waits until something opens it for
/// writing, which may be never: a pipe is opened on a thread of its own, and given up (the
/// thread left waiting) when no writer comes within `PIPE_WAIT`. `/dev/stdin` fed by a
/// pipe has its writer already.
fn open_without_waiting(path: &Path) -> std::io::Result<std::fs::File> {
    use std::os::unix::fs::FileTypeExt;
    if !std::fs::metadata(path)?.file_type().is_fifo() {
        return std::fs::File::open(path);
    }
    let (sender, opened) = std::sync::mpsc::channel();
    let pipe = path.to_path_buf();
    std::thread::spawn(move || {
        let _ = sender.send(std::fs::File::open(pipe));
    });
    opened.recv_timeout(PIPE_WAIT).unwrap_or_else(|_| {
        Err(std::io::Error::other(
            "it is a named pipe that nothing writes to",
        ))
    })
}

/// Whether a scene may make anim read the file at `path` (resolved: `canonicalize`d), a mesh or
/// an included file, when the file given to anim is `scene`: only inside the scene's folder or
/// the current working directory, each with everything below it, as POV-Ray's read
/// restrictions confine a scene (docs/scene-language.md §11). `--allow-any-input` lifts the
/// rule. A scene cannot make anim read, and quote in its messages, a file from elsewhere.
pub fn may_read(path: &Path, scene: &Path) -> bool {
    let folder = match scene.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.canonicalize().ok(),
        _ => std::env::current_dir().ok(),
    };
    let cwd = std::env::current_dir()
        .ok()
        .and_then(|d| d.canonicalize().ok());
    [folder, cwd]
        .iter()
        .flatten()
        .any(|root| path.starts_with(root))
}

/// What an error about a file that [`may_read`] refuses says after its name.
pub const OUTSIDE_ROOTS: &str = "is outside the scene's folder and the current directory: a scene may read only files inside either (--allow-any-input lifts this)";
