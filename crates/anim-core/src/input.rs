//! Reading a scene's input files (scene files, included files, meshes, keyframe specs): whole,
//! with a size limit known before memory grows, refusing what is not text, and never waiting
//! on a named pipe that nothing writes to.
//!
//! A file the user names (the scene, the spec) is read as given, a pipe with a writer
//! included. A file a scene names (an `include`, a mesh) is opened first and then judged by
//! what was opened: a regular file whose real path lies inside the scene's folder or the
//! current directory ([`open_named`]). Nothing is read by a path that was checked before, so
//! a file swapped for a link between the check and the reading cannot slip in.

use crate::diag::Diagnostic;
use std::fs::File;
use std::io::Read;
use std::os::unix::fs::{FileTypeExt, MetadataExt, OpenOptionsExt};
use std::path::{Component, Path, PathBuf};

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
    let file = open_without_waiting(path).map_err(cannot)?;
    read_file(file, path, limit, what)
}

/// Reads the open `file` (named `path` in messages) whole, within `limit` bytes, as
/// [`read_input`] does.
fn read_file(file: File, path: &Path, limit: u64, what: &str) -> Result<Vec<u8>, Box<Diagnostic>> {
    let cannot =
        |e: std::io::Error| Diagnostic::file_error(path, format!("cannot read {what}: {e}"));
    let too_big = |size: String| Box::new(Diagnostic::too_large(path, &size, limit));
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
/// pipe has its writer already. Only files the user names come here; a file a scene names
/// is opened by [`open_named`], which never waits.
fn open_without_waiting(path: &Path) -> std::io::Result<File> {
    if !std::fs::metadata(path)?.file_type().is_fifo() {
        return File::open(path);
    }
    let (sender, opened) = std::sync::mpsc::channel();
    let pipe = path.to_path_buf();
    std::thread::spawn(move || {
        let _ = sender.send(File::open(pipe));
    });
    opened.recv_timeout(PIPE_WAIT).unwrap_or_else(|_| {
        Err(std::io::Error::other(
            "it is a named pipe that nothing writes to",
        ))
    })
}

/// A regular file a scene names, open, with the real path it was found at.
#[derive(Debug)]
pub struct Opened {
    file: File,
    real: PathBuf,
}

/// Why a file a scene names is not read.
#[derive(Debug)]
pub enum Refusal {
    /// It is (or would be, if it existed) outside the folders a scene may read from; nothing
    /// more is said of it, not even whether it exists.
    Outside,
    /// A folder.
    Folder,
    /// A named pipe, a device or a socket.
    NotRegular,
    /// It was replaced while it was being opened.
    Changed,
    /// It cannot be opened (it does not exist, or may not be read).
    Io(std::io::Error),
}

impl Refusal {
    /// What a message about the file written `written` says.
    pub fn message(&self, written: &str) -> String {
        match self {
            Refusal::Outside => format!("`{written}` {OUTSIDE_ROOTS}"),
            Refusal::Folder => format!("`{written}` is a folder, not a file"),
            Refusal::NotRegular => {
                format!("`{written}` is not a regular file (a pipe or a device)")
            }
            Refusal::Changed => format!("`{written}` was replaced while it was being opened"),
            Refusal::Io(e) => format!("cannot read `{written}`: {e}"),
        }
    }
}

impl Opened {
    /// The file's real path: absolute, every link followed.
    pub fn real(&self) -> &Path {
        &self.real
    }

    /// The open file, to read from (the caller rewinds it to read it again).
    pub fn file(&self) -> &File {
        &self.file
    }

    /// Its whole text, as [`read_input`] reads a file, named `path` in messages.
    pub fn read(self, path: &Path, limit: u64, what: &str) -> Result<Vec<u8>, Box<Diagnostic>> {
        read_file(self.file, path, limit, what)
    }
}

/// Opens the file at `path`, named by the scene file `scene`, for reading, when a scene may
/// make anim read it: a regular file (a pipe or a device is never opened for reading: it is
/// opened without waiting and refused by what it is) whose real path lies inside one of
/// [`roots`] (`any`: anywhere, `--allow-any-input`). The confinement is judged on the file
/// that was opened: its real path must name that very file, so a link swapped in after the
/// check reads nothing. A path outside the roots is refused alike whether it exists or not.
pub fn open_named(path: &Path, scene: &Path, any: bool) -> Result<Opened, Refusal> {
    let allowed = |real: &Path| any || may_read(real, scene);
    let file = match std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY)
        .open(path)
    {
        Ok(file) => file,
        Err(e) => {
            return Err(if allowed(&would_be(path)) {
                Refusal::Io(e)
            } else {
                Refusal::Outside
            })
        }
    };
    let opened = file.metadata().map_err(Refusal::Io)?;
    // The real path of the file opened, as the system names its descriptor (else the path
    // resolved now), and proof that it names that very file: the same device and inode, read
    // without following a link, so a link swapped in at that path since proves nothing.
    let real = real_path_of(&file)
        .or_else(|| path.canonicalize().ok())
        .filter(|real| {
            std::fs::symlink_metadata(real)
                .is_ok_and(|m| m.dev() == opened.dev() && m.ino() == opened.ino())
        });
    let Some(real) = real else {
        return Err(if !allowed(&would_be(path)) {
            Refusal::Outside
        } else if !opened.is_file() && !opened.is_dir() {
            // A pipe or socket no path names (`/dev/stdin` on a pipe): what it is is the
            // reason, not a swap.
            Refusal::NotRegular
        } else {
            Refusal::Changed
        });
    };
    if !allowed(&real) {
        return Err(Refusal::Outside);
    }
    if opened.is_dir() {
        return Err(Refusal::Folder);
    }
    if !opened.is_file() {
        return Err(Refusal::NotRegular);
    }
    Ok(Opened { file, real })
}

/// The path the system gives the open `file` (`/proc/self/fd`), where it gives one: where the
/// file was when it was opened, whatever its name has been changed to since.
fn real_path_of(file: &File) -> Option<PathBuf> {
    use std::os::fd::AsRawFd;
    let real = std::fs::read_link(format!("/proc/self/fd/{}", file.as_raw_fd())).ok()?;
    real.is_absolute().then_some(real)
}

/// Where `path` would be if it existed: each component that exists resolved as the system
/// resolves it (links followed), the rest taken as written (`..` going up a level).
fn would_be(path: &Path) -> PathBuf {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut out = PathBuf::from("/");
    let mut exists = true;
    for component in absolute.components() {
        match component {
            Component::ParentDir => {
                out.pop();
            }
            Component::Normal(name) => {
                out.push(name);
                if exists {
                    match out.canonicalize() {
                        Ok(real) => out = real,
                        Err(_) => exists = false,
                    }
                }
            }
            Component::RootDir | Component::CurDir | Component::Prefix(_) => {}
        }
    }
    out
}

/// The folders a scene file at `scene` may make anim read files from, each with everything
/// below it: the scene's folder and the current working directory, as POV-Ray's read
/// restrictions confine a scene (docs/scene-language.md §11). Neither is ever `/` or the
/// home folder, below which every file of the machine or the user lies.
pub fn roots(scene: &Path) -> Vec<PathBuf> {
    let folder = match scene.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.canonicalize().ok(),
        _ => std::env::current_dir().ok(),
    };
    let cwd = std::env::current_dir()
        .ok()
        .and_then(|d| d.canonicalize().ok());
    let home = std::env::var_os("HOME")
        .filter(|h| !h.is_empty())
        .and_then(|h| Path::new(&h).canonicalize().ok());
    [folder, cwd]
        .into_iter()
        .flatten()
        .filter(|root| root.parent().is_some() && Some(root) != home.as_ref())
        .collect()
}

/// Whether a scene file at `scene` may make anim read the file whose real path (absolute,
/// links followed) is `real`: only inside one of its [`roots`]. `--allow-any-input` lifts the
/// rule. A scene cannot make anim read, and quote in its messages, a file from elsewhere.
pub fn may_read(real: &Path, scene: &Path) -> bool {
    roots(scene).iter().any(|root| real.starts_with(root))
}

/// What an error about a file that [`may_read`] refuses says after its name.
pub const OUTSIDE_ROOTS: &str = "is outside the scene's folder and the current directory (never `/` or the home folder): a scene may read only files inside either (--allow-any-input lifts this)";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_file_is_placed_where_it_would_be() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().canonicalize().unwrap();
        std::fs::create_dir(dir.join("a")).unwrap();
        assert_eq!(would_be(&dir.join("a/x/y")), dir.join("a/x/y"));
        assert_eq!(would_be(&dir.join("a/x/../../z")), dir.join("z"));
        assert_eq!(
            would_be(&dir.join("nothing/../../etc")),
            dir.parent().unwrap().join("etc")
        );
    }

    #[test]
    fn outside_files_are_refused_alike_whether_they_exist_or_not() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().canonicalize().unwrap();
        let scene = dir.join("in/scene.sdf");
        std::fs::create_dir(dir.join("in")).unwrap();
        std::fs::write(dir.join("secret"), "x").unwrap();
        std::fs::write(dir.join("in/part"), "y").unwrap();
        std::os::unix::fs::symlink(dir.join("secret"), dir.join("in/link")).unwrap();
        for outside in ["../secret", "../missing", "link", "../in/../secret"] {
            let refusal = open_named(&dir.join("in").join(outside), &scene, false).unwrap_err();
            assert!(
                matches!(refusal, Refusal::Outside),
                "{outside}: {refusal:?}"
            );
        }
        let opened = open_named(&dir.join("in/part"), &scene, false).unwrap();
        assert_eq!(opened.real(), dir.join("in/part"));
        let missing = open_named(&dir.join("in/missing"), &scene, false).unwrap_err();
        assert!(matches!(missing, Refusal::Io(_)), "{missing:?}");
        assert!(open_named(&dir.join("secret"), &scene, true).is_ok());
    }

    #[test]
    fn pipes_and_devices_are_refused_without_waiting() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().canonicalize().unwrap();
        let pipe = dir.join("pipe");
        let made = std::process::Command::new("mkfifo").arg(&pipe).status();
        assert!(made.is_ok_and(|s| s.success()));
        let refusal = open_named(&pipe, &dir.join("scene.sdf"), false).unwrap_err();
        assert!(matches!(refusal, Refusal::NotRegular), "{refusal:?}");
        let refusal = open_named(Path::new("/dev/zero"), &dir.join("s.sdf"), true).unwrap_err();
        assert!(matches!(refusal, Refusal::NotRegular), "{refusal:?}");
        let refusal = open_named(&dir, &dir.join("s.sdf"), false).unwrap_err();
        assert!(matches!(refusal, Refusal::Folder), "{refusal:?}");
    }

    #[test]
    fn neither_the_root_folder_nor_the_home_folder_is_ever_a_root() {
        let home = std::env::var_os("HOME").map(PathBuf::from);
        for root in roots(Path::new("/scene.sdf")) {
            assert_ne!(root, Path::new("/"));
            assert_ne!(Some(&root), home.as_ref());
        }
    }
}
