//! `include <file>`: the statements of another scene file, read in place of the line
//! (docs/scene-language.md §11). The frames that `anim generate` writes include the part of
//! the scene that no track touches, so the cache here lets every frame of one process share
//! one reading of it.
//!
//! An included file is read as a file of its own (its lines located in it, its material
//! layout its own) and its statements are spliced in where the `include` line stands, so
//! statement order and meaning are those of the file written out whole. Where the file may be
//! is limited like everything else a scene makes anim read: inside the folder of the file
//! given on the command line, within `--max-input` bytes for a file and everything it
//! includes, at most `limits::MAX_INCLUDE_DEPTH` deep, and never round a cycle.

use super::{At, Line, Parser};
use crate::diag::Diagnostic;
use crate::limits::MAX_INCLUDE_DEPTH;
use crate::sdf::ast::{FlatShapes, Statement, StatementKind};
use crate::sdf::MaterialLayout;
use crate::util::Fnv64;
use std::cell::{Cell, RefCell};
use std::collections::{HashMap, HashSet};
use std::fmt;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::{Arc, Mutex};

/// One file read for a scene: where it is, its length and the fingerprint of its bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
struct FileRead {
    path: PathBuf,
    len: u64,
    fingerprint: u64,
}

impl FileRead {
    fn of(path: &Path, bytes: &[u8]) -> FileRead {
        FileRead {
            path: path.to_path_buf(),
            len: bytes.len() as u64,
            fingerprint: Fnv64::of(bytes),
        }
    }

    /// Whether the file still holds what was read (read again, within `limit` bytes).
    fn unchanged(&self, limit: u64) -> bool {
        crate::input::read_bounded(&self.path, limit, "file")
            .is_ok_and(|bytes| FileRead::of(&self.path, &bytes) == *self)
    }
}

/// What reading an included file gave, kept whole so that later scenes splice it in without
/// reading or parsing it again.
#[derive(Clone)]
struct Included {
    /// Every file read for it, itself first, then the files it includes.
    files: Vec<FileRead>,
    /// Its statements, but for `shapes`.
    statements: Vec<Statement>,
    /// Its primitive shapes, kept apart when nothing in it refers to a shape by name.
    shapes: FlatShapes,
    diagnostics: Vec<Diagnostic>,
    skipped: HashSet<String>,
    render_lines: usize,
    cameras_rejected: bool,
    /// How it was read: a generated frame reads what it includes as it is read itself, with
    /// the standard material layout whatever `--material-fields auto` would infer and without
    /// the warnings that hint at another layout (`sdf::is_generated_frame`); a reading is used
    /// again only for the same layout and kind of includer.
    layout: MaterialLayout,
    generated: bool,
}

impl Included {
    fn bytes(&self) -> u64 {
        self.files.iter().map(|f| f.len).sum()
    }
}

/// Included files already read, shared by every clone of one `LoadOptions` (the frames of one
/// `anim render DIR`). An entry is used again only while every file it read still holds the
/// same bytes, and never where that would hide a cycle. A file is kept from its second
/// reading on: a scene rendered alone holds no second copy of what it includes.
#[derive(Clone, Default)]
pub struct IncludeCache {
    /// `None`: read once, not kept.
    entries: Arc<Mutex<HashMap<PathBuf, Option<Arc<Included>>>>>,
}

impl IncludeCache {
    /// How many files the cache holds.
    pub fn len(&self) -> usize {
        self.entries.lock().map_or(0, |e| e.len())
    }

    /// Whether the cache holds no file.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn get(
        &self,
        path: &Path,
        chain: &Chain,
        limit: u64,
        layout: &MaterialLayout,
    ) -> Option<Arc<Included>> {
        let entry = self
            .entries
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .get(path)
            .cloned()??;
        let cycle = entry.files.iter().any(|f| chain.files.contains(&f.path));
        let same = entry.layout == *layout
            && entry.generated == chain.generated
            && entry.files.iter().all(|f| f.unchanged(limit));
        (!cycle && same).then_some(entry)
    }

    /// Keeps `included` if its file was read before.
    fn put(&self, path: PathBuf, included: &Arc<Included>) {
        let mut entries = self.entries.lock().unwrap_or_else(|e| e.into_inner());
        let kept = entries.contains_key(&path).then(|| included.clone());
        entries.insert(path, kept);
    }
}

/// A cache changes how often a file is read, never what a scene means: any two compare
/// equal, and all print alike (the frame pipeline's settings fingerprint prints the options).
impl PartialEq for IncludeCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl fmt::Debug for IncludeCache {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("IncludeCache")
    }
}

/// The files being read, from the one the reader was given to the one being read now.
#[derive(Clone)]
pub(in crate::sdf) struct Chain {
    /// The files being read (resolved), outermost first.
    files: Vec<PathBuf>,
    /// Bytes read for the outermost file so far, itself and every file it includes.
    read: Rc<Cell<u64>>,
    /// The files read for the file being read now and those it includes.
    deps: Rc<RefCell<Vec<FileRead>>>,
    /// Whether the outermost file is a frame `anim generate` wrote
    /// (`sdf::is_generated_frame`): it and everything it includes are read with no guess.
    pub(in crate::sdf) generated: bool,
}

impl Chain {
    /// The chain of a file read on its own: `text` is its whole text.
    pub(in crate::sdf) fn outermost(path: &Path, text: &str) -> Chain {
        let resolved = path.canonicalize().unwrap_or_else(|_| {
            // A text held in memory (a frame being checked) has no file yet: its folder does.
            let folder = match path.parent() {
                Some(p) if !p.as_os_str().is_empty() => p.canonicalize().ok(),
                _ => std::env::current_dir().ok(),
            };
            match (folder, path.file_name()) {
                (Some(folder), Some(name)) => folder.join(name),
                _ => path.to_path_buf(),
            }
        });
        Chain {
            files: vec![resolved],
            read: Rc::new(Cell::new(text.len() as u64)),
            deps: Rc::default(),
            generated: crate::sdf::is_generated_frame(text),
        }
    }

    /// The chain one file deeper.
    fn deeper(&self, path: PathBuf) -> Chain {
        let mut files = self.files.clone();
        files.push(path);
        Chain {
            files,
            read: self.read.clone(),
            deps: Rc::default(),
            generated: self.generated,
        }
    }
}

impl Parser<'_> {
    /// `include <file>`: the file's statements, in place of the line.
    pub(super) fn include(&mut self, line: &Line) {
        const FORM: &str = "include <file>";
        let Some(token) = line.tokens.get(1) else {
            self.error(
                line,
                At::End,
                "`include` needs the file to read",
                Some(format!("write `{FORM}`, relative to this file")),
            );
            return;
        };
        if line.tokens.len() > 2 {
            self.error(
                line,
                At::Span(2, line.tokens.len() - 1),
                format!(
                    "`include` takes one file, found {} words after it",
                    line.tokens.len() - 1
                ),
                Some(format!(
                    "write `{FORM}`; a file name with spaces cannot be included"
                )),
            );
            return;
        }
        let written = token.text.trim_matches('"');
        let at = At::Tok(1);
        let here = self.chain.files.last().cloned().unwrap_or_default();
        let folder = here.parent().unwrap_or(Path::new("")).to_path_buf();
        let Some(path) = self.include_target(line, written, &folder) else {
            return;
        };
        if let Some(depth) = self.chain.files.iter().position(|f| *f == path) {
            let round: Vec<String> = self.chain.files[depth..]
                .iter()
                .chain([&path])
                .map(|f| shown(f, &folder))
                .collect();
            self.error(
                line,
                at,
                format!(
                    "`{written}` is already being read: including it here would never end ({})",
                    round.join(" → ")
                ),
                None,
            );
            return;
        }
        if self.chain.files.len() >= MAX_INCLUDE_DEPTH {
            self.error(
                line,
                at,
                format!("includes nest more than {MAX_INCLUDE_DEPTH} files deep"),
                Some("an included file that includes another, and so on: flatten some".into()),
            );
            return;
        }
        let limit = self.opts.max_input;
        let before = self.chain.read.get();
        let display = self.path.parent().unwrap_or(Path::new("")).join(written);
        let cached = self
            .opts
            .includes
            .get(&path, &self.chain, limit, &self.opts.material_fields);
        let included = match cached {
            Some(included) => included,
            None => match self.read_included(line, &path, &display) {
                Some(included) => included,
                None => return,
            },
        };
        let total = before + included.bytes();
        if total > limit {
            self.error(
                line,
                at,
                format!(
                    "this file and what it includes hold {total} bytes, more than the {limit} that --max-input allows"
                ),
                Some("raise --max-input if the scene is meant to be this large".into()),
            );
            return;
        }
        self.chain.read.set(total);
        self.chain
            .deps
            .borrow_mut()
            .extend(included.files.iter().cloned());
        self.splice(included);
    }

    /// The resolved path of the file `written` names, relative to `folder`; `None` (with the
    /// error reported) when it cannot be included.
    fn include_target(&mut self, line: &Line, written: &str, folder: &Path) -> Option<PathBuf> {
        let at = At::Tok(1);
        if written.is_empty() {
            self.error(line, at, "`include` names no file", None);
            return None;
        }
        let path = match folder.join(written).canonicalize() {
            Ok(path) => path,
            Err(e) => {
                self.error(line, at, format!("cannot read `{written}`: {e}"), None);
                return None;
            }
        };
        let outermost = self.chain.files.first().cloned().unwrap_or_default();
        if !self.opts.allow_any_input && !crate::input::may_read(&path, &outermost) {
            self.error(
                line,
                at,
                format!("`{written}` {}", crate::input::OUTSIDE_ROOTS),
                Some("copy the file beside the scene".into()),
            );
            return None;
        }
        match std::fs::metadata(&path) {
            Ok(meta) if meta.is_dir() => {
                self.error(
                    line,
                    at,
                    format!("`{written}` is a folder, not a scene file"),
                    None,
                );
                None
            }
            Ok(meta) if !meta.is_file() => {
                self.error(
                    line,
                    at,
                    format!("`{written}` is not a regular file (a pipe or a device)"),
                    None,
                );
                None
            }
            Ok(_) => Some(path),
            Err(e) => {
                self.error(line, at, format!("cannot read `{written}`: {e}"), None);
                None
            }
        }
    }

    /// Reads and parses the included file at `path` (resolved) and keeps it in the cache.
    /// Its locations name it `display`: the path as written, from the including file's.
    fn read_included(&mut self, line: &Line, path: &Path, display: &Path) -> Option<Arc<Included>> {
        let room = self.opts.max_input.saturating_sub(self.chain.read.get());
        let bytes = match crate::input::read_bounded(path, room, "the included file") {
            Ok(bytes) => bytes,
            Err(d) => {
                let message = match &d.help {
                    Some(help) => format!("{} ({help})", d.message),
                    None => d.message.clone(),
                };
                self.error(line, At::Tok(1), message, None);
                return None;
            }
        };
        let text = String::from_utf8_lossy(&bytes);
        let chain = self.chain.deeper(path.to_path_buf());
        // The files this one includes are limited by what is left after it.
        chain.read.set(chain.read.get() + bytes.len() as u64);
        let deps = chain.deps.clone();
        let parsed = super::parse(&text, display, self.opts, true, chain);
        let mut files = vec![FileRead::of(path, &bytes)];
        files.extend(deps.borrow().iter().cloned());
        let included = Arc::new(Included {
            files,
            statements: parsed.statements,
            shapes: parsed.shapes,
            diagnostics: parsed.diagnostics,
            skipped: parsed.omissions.skipped,
            render_lines: parsed.omissions.render_lines,
            cameras_rejected: parsed.omissions.cameras_rejected,
            layout: self.opts.material_fields.clone(),
            generated: self.chain.generated,
        });
        self.opts.includes.put(path.to_path_buf(), &included);
        Some(included)
    }

    /// Puts an included file's statements and problems where its `include` line stands.
    fn splice(&mut self, included: Arc<Included>) {
        // Taken whole when nothing else holds it (the cache did not keep it), else copied.
        let included = Arc::try_unwrap(included).unwrap_or_else(|shared| Included::clone(&shared));
        for s in &included.statements {
            if let StatementKind::Camera(c) = &s.kind {
                self.camera_names.push(c.name.clone());
            }
        }
        let first = self.statements.is_empty() && self.shapes.is_empty();
        if self.flat && first {
            // The include opens a file that keeps its shapes apart (a generated frame): the
            // included shapes stay compact, their places those of the included file.
            self.flat = !included.statements.iter().any(|s| breaks_flat(&s.kind));
            self.shapes = included.shapes;
            self.statements.extend(included.statements);
        } else {
            // Every shape is a statement from here on, in the order read.
            if self.flat {
                self.merge_shapes();
            }
            self.flat = false;
            let (all, _) = included.shapes.merge_into(included.statements);
            self.statements.extend(all);
        }
        self.diagnostics.extend(included.diagnostics);
        self.skipped.extend(included.skipped);
        self.render_lines += included.render_lines;
        self.cameras_rejected |= included.cameras_rejected;
    }
}

/// Whether a statement means its file refers to shapes by name or holds a shape that is not
/// kept apart, so that no shape of the file is kept apart.
fn breaks_flat(kind: &StatementKind) -> bool {
    matches!(
        kind,
        StatementKind::Shape { .. }
            | StatementKind::Composite { .. }
            | StatementKind::Transform { .. }
            | StatementKind::Motion(_)
    )
}

/// The files a scene's `include` lines name, resolved against the folder of the scene at
/// `path`, in order: what a record of the scene's images vouches for besides its own bytes.
pub fn included_files(text: &str, path: &Path) -> Vec<PathBuf> {
    named_files(text, path, "include", |words| match words {
        ["include", file] => Some(file.trim_matches('"')),
        _ => None,
    })
}

/// The OBJ files that the mesh statements of `text` (read from `path`) name, as the loader
/// finds them (relative to `path`'s folder): `define shape obj <name> <file> <material>`,
/// the one form it reads. A frame's record notes them (`anim-pipeline`'s `frames::cache`), so
/// that an edited mesh renders the frame again.
pub fn mesh_files(text: &str, path: &Path) -> Vec<PathBuf> {
    named_files(text, path, "obj", |words| {
        let k = words.windows(2).position(|w| w == ["shape", "obj"])?;
        (words.len() == k + 5).then(|| words[k + 3])
    })
}

/// The files that the lines of `text` (read from `path`) holding `word` name, by `file_of`
/// each line's words, relative to `path`'s folder, in order.
fn named_files(
    text: &str,
    path: &Path,
    word: &str,
    file_of: impl for<'w> Fn(&[&'w str]) -> Option<&'w str>,
) -> Vec<PathBuf> {
    let folder = path.parent().unwrap_or(Path::new(""));
    let mut tokens = Vec::new();
    let mut files = Vec::new();
    for raw in super::lines_containing(text, word) {
        crate::sdf::lexer::tokenize_into(raw, &mut tokens);
        let words: Vec<&str> = tokens.iter().map(|t| t.text).collect();
        if let Some(file) = file_of(&words) {
            files.push(folder.join(file));
        }
    }
    files
}

/// `path` as a message shows it: relative to `folder` when it is inside it.
fn shown(path: &Path, folder: &Path) -> String {
    path.strip_prefix(folder)
        .unwrap_or(path)
        .display()
        .to_string()
}

#[cfg(test)]
mod tests {
    use crate::load::load_file;
    use crate::sdf::LoadOptions;
    use std::path::Path;

    fn write(dir: &Path, name: &str, text: &str) {
        std::fs::write(dir.join(name), text).unwrap();
    }

    #[test]
    fn mesh_files_are_those_of_the_mesh_statement_beside_the_file_that_names_them() {
        let text = "define shape obj tri meshes/tri.obj red\n\
                    # define shape obj old old.obj red\n\
                    define shape obj short.obj\n\
                    define shape obj big big.obj red extra\n\
                    define shape sphere obj 0 0 0 1 red\n";
        let files = super::mesh_files(text, Path::new("scenes/part.sdfi"));
        assert_eq!(files, [Path::new("scenes/meshes/tri.obj")]);
    }

    const PART: &str = "define material m 0.1 0.1 0.1 0.5 0.5 0.5 0 0 0 1\n\
                        define light l 0 5 0 1 1 1 1\n\
                        define shape sphere a 0 0 -5 1 m\n\
                        define shape sphere b 2 0 -5 1 m\n";

    fn frame(n: u32) -> String {
        format!(
            "include part.sdfi\ndefine camera c 60 0 0 {n} 0 0 -1 0 1 0\nrender c f{n}.png 8 8\n"
        )
    }

    fn shapes(path: &Path, opts: &LoadOptions) -> usize {
        let loaded = load_file(path, opts).unwrap_or_else(|e| panic!("{e:?}"));
        loaded.jobs[0].scene.instances.len()
    }

    #[test]
    fn an_included_file_is_kept_from_its_second_reading_while_its_bytes_stay_the_same() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        write(dir, "part.sdfi", PART);
        for n in 0..3 {
            write(dir, &format!("f{n}.sdf"), &frame(n));
        }
        let opts = LoadOptions::default();
        assert_eq!(shapes(&dir.join("f0.sdf"), &opts), 2);
        // Read once: remembered, not kept.
        assert_eq!(opts.includes.len(), 1);
        assert!(opts
            .includes
            .entries
            .lock()
            .unwrap()
            .values()
            .all(Option::is_none));
        assert_eq!(shapes(&dir.join("f1.sdf"), &opts), 2);
        assert!(opts
            .includes
            .entries
            .lock()
            .unwrap()
            .values()
            .all(Option::is_some));
        // A clone of the options shares the cache; a changed file is read again.
        let clone = opts.clone();
        write(
            dir,
            "part.sdfi",
            &format!("{PART}define shape sphere c 4 0 -5 1 m\n"),
        );
        assert_eq!(shapes(&dir.join("f2.sdf"), &clone), 3);
        assert_eq!(shapes(&dir.join("f0.sdf"), &opts), 3);
    }
}
