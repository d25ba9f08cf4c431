//! The OBJ files a generated frame names, where the frames can read them. `anim render DIR`
//! may read only inside the frame folder and the current directory, and nothing in a frame
//! folder may widen that (whoever wrote the folder could forge it); so a mesh that lies
//! outside the frame folder is copied into its [`COPY_DIR`], and the frames name the copy.
//! A mesh inside the folder is named by its path from there.
//!
//! The copies are listed in the frame folder's list of generated files (`keyframe/mod.rs`),
//! so that a later run may replace or remove them, and nothing else: a file of the user's
//! where a copy would go is never written over (the copy takes another name). A copy whose
//! bytes are the mesh's already is left alone, so that its modification time (which a
//! frame's fingerprint notes) stays and no frame renders again for nothing.

use super::spec_file::Source;
use anim_core::diag::Diagnostic;
use anim_core::scene::Geometry;
use anim_core::sdf::ast::{Statement, StatementKind};
use anim_core::util::{path_from, write_atomically};
use std::collections::{HashMap, HashSet};
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// The folder of a frame folder that holds the copies of meshes from outside it.
pub const COPY_DIR: &str = "meshes";

/// What placing the meshes did to the frame folder.
#[derive(Debug, Default)]
pub struct Placed {
    /// Every copy the frames name, as the list of generated files writes it
    /// (`meshes/NAME`).
    pub listed: Vec<String>,
    /// The copies this run made where no file was, which a run that fails takes away.
    pub created: Vec<PathBuf>,
    /// [`COPY_DIR`], when this run made it.
    pub created_dir: Option<PathBuf>,
}

impl Placed {
    /// Takes away what this run added (after a failure): its new copies, and the folder it
    /// made when nothing else is in it.
    pub fn undo(&self) {
        for path in &self.created {
            let _ = std::fs::remove_file(path);
        }
        if let Some(dir) = &self.created_dir {
            let _ = std::fs::remove_dir(dir);
        }
    }
}

/// Whether `name`, a line of the list of generated files, is a copy of a mesh: `meshes/NAME`
/// with a plain file name.
pub fn is_copy(name: &str) -> bool {
    name.strip_prefix(COPY_DIR)
        .and_then(|rest| rest.strip_prefix('/'))
        .is_some_and(|file| Path::new(file).file_name() == Some(file.as_ref()))
}

/// Points every `define shape obj` of `statements` at a file the frames in `frame_dir` can
/// read: the mesh itself when it lies inside `frame_dir`, else its copy in [`COPY_DIR`]. A
/// mesh is found as the reader found it, beside the file whose line names it (the base scene
/// `scene`, or a file it includes). `previous` is the list of generated files of the run
/// before (the copies it may replace). Errors are said at the spec's scene.
pub fn place_meshes(
    statements: &mut [Statement],
    scene: &Path,
    frame_dir: &Path,
    previous: &[String],
    src: &Source,
) -> Result<Placed, Vec<Diagnostic>> {
    let mut copier = Copier {
        frame_dir: frame_dir.canonicalize().map_err(|e| {
            vec![Diagnostic::file_error(
                frame_dir,
                format!("cannot read the frame directory: {e}"),
            )]
        })?,
        scene,
        previous: previous.iter().map(String::as_str).collect(),
        names: HashMap::new(),
        taken: HashSet::new(),
        placed: Placed::default(),
    };
    let base_dir = scene.parent().unwrap_or(Path::new(""));
    let result = statements.iter_mut().try_for_each(|s| {
        let StatementKind::Shape {
            geometry: Geometry::Mesh(m),
            ..
        } = &mut s.kind
        else {
            return Ok(());
        };
        let written_in = match s.loc.file.parent() {
            Some(dir) if !s.loc.file.as_os_str().is_empty() => dir,
            _ => base_dir,
        };
        let named = copier
            .name_for(&written_in.join(&m.file))
            .map_err(|why| mesh_error(&m.file, frame_dir, &why, src))?;
        match named.to_str() {
            // A file name the SDF reader would split into two words cannot be written.
            Some(p) if !p.contains(char::is_whitespace) => m.file = p.to_string(),
            _ => {
                let why = format!(
                    "its path from there, `{}`, is not one word",
                    named.display()
                );
                return Err(mesh_error(&m.file, frame_dir, &why, src));
            }
        }
        Ok(())
    });
    match result {
        Ok(()) => Ok(copier.placed),
        Err(e) => {
            copier.placed.undo();
            Err(e)
        }
    }
}

fn mesh_error(file: &str, frame_dir: &Path, why: &str, src: &Source) -> Vec<Diagnostic> {
    vec![src.error(
        &["scene[0]", "scene"],
        format!(
            "the mesh file `{file}` cannot be named from the frame directory `{}`: {why}",
            frame_dir.display()
        ),
    )]
}

/// The copies of one run: which mesh (by its real path) went to which name.
struct Copier<'a> {
    /// The frame folder's real path.
    frame_dir: PathBuf,
    scene: &'a Path,
    previous: HashSet<&'a str>,
    names: HashMap<PathBuf, PathBuf>,
    /// The copies' names given out so far (`meshes/NAME`).
    taken: HashSet<String>,
    placed: Placed,
}

impl Copier<'_> {
    /// How the frames name the mesh at `path`: its path from the frame folder when it lies
    /// inside, else its copy's (made or refreshed now).
    fn name_for(&mut self, path: &Path) -> Result<PathBuf, String> {
        let real = path.canonicalize().map_err(|e| e.to_string())?;
        if real.starts_with(&self.frame_dir) {
            return path_from(&self.frame_dir, &real).map_err(|e| e.to_string());
        }
        if let Some(name) = self.names.get(&real) {
            return Ok(name.clone());
        }
        let name = self.free_name(&real)?;
        self.copy(path, &name)?;
        let name = PathBuf::from(name);
        self.names.insert(real, name.clone());
        Ok(name)
    }

    /// The first of `NAME`, `STEM-2.EXT`, `STEM-3.EXT`, … in [`COPY_DIR`] that no other mesh
    /// of this run took and that holds no file but one an earlier run copied there.
    fn free_name(&mut self, real: &Path) -> Result<String, String> {
        let file = Path::new(real.file_name().ok_or("it has no file name")?);
        let stem = file.file_stem().unwrap_or_default().to_string_lossy();
        let ext = file
            .extension()
            .map(|e| format!(".{}", e.to_string_lossy()))
            .unwrap_or_default();
        for n in 1.. {
            let candidate = match n {
                1 => format!("{COPY_DIR}/{stem}{ext}"),
                _ => format!("{COPY_DIR}/{stem}-{n}{ext}"),
            };
            if self.taken.contains(&candidate) {
                continue;
            }
            let ours = self.previous.contains(candidate.as_str());
            match std::fs::symlink_metadata(self.frame_dir.join(&candidate)) {
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Ok(_) if ours => {}
                Ok(_) => continue,
                Err(e) => return Err(format!("cannot look at `{candidate}`: {e}")),
            }
            self.taken.insert(candidate.clone());
            return Ok(candidate);
        }
        unreachable!("the names are endless")
    }

    /// Copies the mesh at `path` (read as the base scene read it: confined to its roots,
    /// bounded) to `name` in the frame folder, unless `name` holds its bytes already.
    fn copy(&mut self, path: &Path, name: &str) -> Result<(), String> {
        let dir = self.frame_dir.join(COPY_DIR);
        match std::fs::symlink_metadata(&dir) {
            Ok(m) if m.is_dir() => {}
            Ok(_) => {
                return Err(format!(
                    "`{COPY_DIR}` in the frame directory is not a folder"
                ))
            }
            Err(_) => {
                std::fs::create_dir(&dir)
                    .map_err(|e| format!("cannot create `{COPY_DIR}`: {e}"))?;
                self.placed.created_dir = Some(dir);
            }
        }
        let opened = anim_core::input::open_named(path, self.scene, false)
            .map_err(|refusal| refusal.message(&path.display().to_string()))?;
        let target = self.frame_dir.join(name);
        let limit = anim_core::limits::DEFAULT_MAX_INPUT;
        let bytes = opened
            .read(path, limit, "the mesh file")
            .map_err(|d| d.message)?;
        // The size first: only a copy of the same length is read to compare.
        let same = std::fs::symlink_metadata(&target)
            .is_ok_and(|m| m.is_file() && m.len() == bytes.len() as u64)
            && std::fs::read(&target).is_ok_and(|old| old == bytes);
        if !same {
            let existed = std::fs::symlink_metadata(&target).is_ok();
            write_atomically(&target, |w| w.write_all(&bytes))
                .map_err(|e| format!("cannot copy it to `{name}`: {e}"))?;
            if !existed {
                self.placed.created.push(target);
            }
        }
        self.placed.listed.push(name.to_string());
        Ok(())
    }
}
