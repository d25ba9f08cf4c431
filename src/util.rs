//! Small helpers below everything else.

use std::fs;
use std::io::{self, BufWriter};
use std::path::Path;

/// Writes `contents` to `path` through a temporary file in the same directory and a rename,
/// so that `path` either keeps its old contents or has the complete new ones.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<fs::File>) -> io::Result<()>,
) -> io::Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    fs::create_dir_all(dir)?;
    let name = path
        .file_name()
        .ok_or_else(|| io::Error::other("output path has no file name"))?;
    let tmp = dir.join(format!(
        ".{}.{}.tmp",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| {
        let mut w = BufWriter::new(fs::File::create(&tmp)?);
        write(&mut w)?;
        // No fsync: the rename already guarantees that an interrupted process never leaves a
        // partial image under the final name, and syncing every frame costs ~0.1 s each.
        w.into_inner().map_err(|e| e.into_error())?;
        fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result
}
