//! The files a scene refers to, found as the loader finds them, without parsing the scene:
//! what a frame's record vouches for besides the frame's own bytes, and what the preview
//! watches. Every `include` line is resolved by the reader's own [`Chain::open`] (confined,
//! never a pipe or a device, never round a cycle, no deeper than the reader goes), within
//! `--max-input` bytes, each file read once however often it is included.

use super::{included_names, mesh_files, Chain};
use crate::sdf::LoadOptions;
use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// A file a scene refers to.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Reference {
    /// An OBJ file a mesh statement names, as the loader finds it (relative to the file
    /// that names it). Never read here: a mesh may be hundreds of megabytes, and editing it
    /// changes its time.
    Mesh(PathBuf),
    /// A file an `include` line names (relative to the file that names it), with its bytes
    /// when the loader would read them; `None` when the loader refuses it (the scene then
    /// fails to load, and no record vouches for it).
    Included(PathBuf, Option<Vec<u8>>),
}

/// What the scene file `path`, whose bytes are `text`, refers to, in the order the loader
/// meets it: the meshes its statements name, then each file it includes followed by what
/// that refers to. A file included again is listed once, where it is first met.
pub fn references(text: &[u8], path: &Path, opts: &LoadOptions) -> Vec<Reference> {
    let text = String::from_utf8_lossy(text);
    let chain = Chain::outermost(path, &text, opts);
    let mut out = Vec::new();
    walk(&text, path, &chain, &mut Met::default(), &mut out);
    out
}

/// The files listed so far: those read (by real path) and those refused (by name).
#[derive(Default)]
struct Met {
    read: HashSet<PathBuf>,
    refused: HashSet<PathBuf>,
}

impl Met {
    fn refuse(&mut self, named: PathBuf, out: &mut Vec<Reference>) {
        if self.refused.insert(named.clone()) {
            out.push(Reference::Included(named, None));
        }
    }
}

/// Lists what `text` (of the file named `path` at the end of `chain`) refers to.
fn walk(text: &str, path: &Path, chain: &Chain, met: &mut Met, out: &mut Vec<Reference>) {
    out.extend(mesh_files(text, path).into_iter().map(Reference::Mesh));
    let folder = path.parent().unwrap_or(Path::new(""));
    for written in included_names(text) {
        let named = folder.join(&written);
        let Ok(opened) = chain.open(&written) else {
            met.refuse(named, out);
            continue;
        };
        let real = opened.real().to_path_buf();
        if !met.read.insert(real.clone()) {
            continue;
        }
        let room = chain.reading.room();
        let Ok(bytes) = opened.read(&named, room, "file") else {
            met.refuse(named, out);
            continue;
        };
        chain
            .reading
            .note(&super::FileRead::of(&real, &named, &bytes));
        let inner = String::from_utf8_lossy(&bytes).into_owned();
        out.push(Reference::Included(named.clone(), Some(bytes)));
        walk(&inner, &named, &chain.deeper(real), met, out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) {
        std::fs::write(dir.join(name), text).unwrap();
    }

    fn included(refs: &[Reference]) -> Vec<(String, bool)> {
        refs.iter()
            .filter_map(|r| match r {
                Reference::Included(p, bytes) => Some((
                    p.file_name()?.to_string_lossy().into_owned(),
                    bytes.is_some(),
                )),
                Reference::Mesh(_) => None,
            })
            .collect()
    }

    #[test]
    fn a_diamond_of_includes_is_walked_once_per_file() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        // Eight files, each including the next ten times: 10^7 inclusions, 8 files.
        for i in 0..8 {
            let text = if i == 7 {
                "define shape obj t t.obj m\n".to_string()
            } else {
                format!("include f{}.sdfi\n", i + 1).repeat(10)
            };
            write(dir, &format!("f{i}.sdfi"), &text);
        }
        write(dir, "scene.sdf", "include f0.sdfi\n");
        let refs = references(
            b"include f0.sdfi\n",
            &dir.join("scene.sdf"),
            &LoadOptions::default(),
        );
        let names: Vec<(String, bool)> = (0..8).map(|i| (format!("f{i}.sdfi"), true)).collect();
        assert_eq!(included(&refs), names);
        assert_eq!(
            refs.iter()
                .filter(|r| matches!(r, Reference::Mesh(_)))
                .count(),
            1
        );
    }

    #[test]
    fn cycles_pipes_and_outside_files_are_listed_unread() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("in");
        std::fs::create_dir(&dir).unwrap();
        write(&dir, "self.sdfi", &"include self.sdfi\n".repeat(10));
        write(tmp.path(), "secret.sdfi", "ambient 1 1 1\n");
        let made = std::process::Command::new("mkfifo")
            .arg(dir.join("pipe.sdfi"))
            .status();
        assert!(made.is_ok_and(|s| s.success()));
        let text =
            b"include self.sdfi\ninclude pipe.sdfi\ninclude ../secret.sdfi\ninclude /dev/stdin\n";
        let refs = references(text, &dir.join("scene.sdf"), &LoadOptions::default());
        assert_eq!(
            included(&refs),
            [
                ("self.sdfi".to_string(), true),
                ("self.sdfi".to_string(), false),
                ("pipe.sdfi".to_string(), false),
                ("secret.sdfi".to_string(), false),
                ("stdin".to_string(), false),
            ]
        );
    }
}
