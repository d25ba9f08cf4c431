//! What one scene's reading knows of the files it includes (the [`Chain`] of files being
//! read, the bytes and repeated work spent, each file read once), and what the frames of one
//! run share (the [`IncludeCache`]).

use crate::diag::Diagnostic;
use crate::input::{open_named, Opened};
use crate::limits::MAX_INCLUDE_REPEATS;
use crate::sdf::ast::{FlatShapes, Statement};
use crate::sdf::MaterialLayout;
use crate::util::Fnv64;
use std::cell::{Cell, RefCell};
use std::collections::{HashMap, HashSet};
use std::fmt;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::{Arc, Mutex};

/// One file included by a scene: its real path, the path its lines are located at, its
/// length and the fingerprint of its bytes.
#[derive(Clone, Debug)]
pub struct FileRead {
    path: PathBuf,
    shown: PathBuf,
    len: u64,
    fingerprint: u64,
}

impl FileRead {
    pub(super) fn of(path: &Path, shown: &Path, bytes: &[u8]) -> FileRead {
        FileRead {
            path: path.to_path_buf(),
            shown: shown.to_path_buf(),
            len: bytes.len() as u64,
            fingerprint: Fnv64::of(bytes),
        }
    }

    /// Whether the two readings hold the same bytes.
    fn same(&self, other: &FileRead) -> bool {
        (self.len, self.fingerprint) == (other.len, other.fingerprint)
    }

    /// The path the file's lines are located at in diagnostics.
    pub fn shown(&self) -> &Path {
        &self.shown
    }

    /// The file's bytes, read again (confined as when it was included, for the scene file
    /// `scene`), when they are still those that were read: what a diagnostic may quote.
    pub fn read_again(&self, scene: &Path, opts: &crate::sdf::LoadOptions) -> Option<Vec<u8>> {
        let opened = open_named(&self.path, scene, opts.allow_any_input).ok()?;
        let bytes = opened.read(&self.shown, self.len, "file").ok()?;
        FileRead::of(&self.path, &self.shown, &bytes)
            .same(self)
            .then_some(bytes)
    }
}

/// Files read, each once, in the order first read.
#[derive(Clone, Debug, Default)]
pub(super) struct Files {
    list: Vec<FileRead>,
    paths: HashSet<PathBuf>,
}

impl Files {
    pub(super) fn add(&mut self, file: &FileRead) {
        if !self.paths.contains(&file.path) {
            self.paths.insert(file.path.clone());
            self.list.push(file.clone());
        }
    }

    pub(super) fn iter(&self) -> impl Iterator<Item = &FileRead> {
        self.list.iter()
    }

    pub(super) fn into_vec(self) -> Vec<FileRead> {
        self.list
    }
}

/// What reading an included file gave, kept whole so that later scenes splice it in without
/// reading or parsing it again.
#[derive(Clone)]
pub(super) struct Included {
    /// Every file read for it, each once: itself first, then the files it includes.
    pub(super) files: Files,
    /// Its statements, but for `shapes`.
    pub(super) statements: Vec<Statement>,
    /// Its primitive shapes, kept apart when nothing in it refers to a shape by name.
    pub(super) shapes: FlatShapes,
    pub(super) diagnostics: Vec<Diagnostic>,
    pub(super) skipped: HashSet<String>,
    pub(super) render_lines: usize,
    pub(super) cameras_rejected: bool,
    /// How it was read: a generated frame reads what it includes as it is read itself, with
    /// the standard material layout whatever `--material-fields auto` would infer and without
    /// the warnings that hint at another layout (`sdf::is_generated_frame`); a reading is used
    /// again only for the same layout and kind of includer.
    pub(super) layout: MaterialLayout,
    pub(super) generated: bool,
    /// Whether a limit of the reading that read it (how deep, how much repeated) left
    /// something of it out: such a reading is not kept for another scene.
    pub(super) cut: bool,
}

impl Included {
    /// What splicing it in costs: its statements, shapes, problems and names left out.
    pub(super) fn weight(&self) -> u64 {
        (self.statements.len() + self.shapes.len() + self.diagnostics.len() + self.skipped.len())
            as u64
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

    /// The reading of the file at `path` (real), when one is kept and every file it read
    /// still holds what it held (each checked at most once per scene, by `chain`'s reading).
    pub(super) fn get(
        &self,
        path: &Path,
        chain: &Chain,
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
            && entry.files.iter().all(|f| chain.reading.holds(f));
        (!cycle && same).then_some(entry)
    }

    /// Keeps `included` if its file was read before.
    pub(super) fn put(&self, path: PathBuf, included: &Arc<Included>) {
        let mut entries = self.entries.lock().unwrap_or_else(|e| e.into_inner());
        let kept = entries.contains_key(&path).then(|| included.clone());
        entries.insert(path, kept);
    }

    #[cfg(test)]
    pub(super) fn kept(&self) -> Vec<bool> {
        let entries = self.entries.lock().unwrap_or_else(|e| e.into_inner());
        entries.values().map(Option::is_some).collect()
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

/// What the files of one scene's reading share: the scene file, the bytes read (each file
/// once), the work repeated, and what each file held when this reading first met it.
pub(super) struct Reading {
    /// The file given to the reader, as given: the folders it may read from are its own.
    pub(super) scene: PathBuf,
    /// `--max-input`, and `--allow-any-input`.
    limit: u64,
    any: bool,
    /// Bytes of the scene's text and of every file read for it, each file once.
    read: Cell<u64>,
    /// Statements spliced in again (see `limits::MAX_INCLUDE_REPEATS`).
    repeated: Cell<u64>,
    /// Whether the repeated work went over its limit (reported once; every later `include`
    /// line of the reading is skipped).
    pub(super) over: Cell<bool>,
    /// Each file read or checked, as it was then.
    seen: RefCell<HashMap<PathBuf, FileRead>>,
    /// The files spliced in so far.
    spliced: RefCell<HashSet<PathBuf>>,
    /// Included files as named (the including file's folder joined to the name written) →
    /// their real paths: an `include` line met again is not resolved again.
    resolved: RefCell<HashMap<PathBuf, PathBuf>>,
}

impl Reading {
    /// Notes that `file` was read; whether the bytes read for the scene stay within the
    /// limit. A file already read for this scene adds nothing.
    pub(super) fn note(&self, file: &FileRead) -> bool {
        let mut seen = self.seen.borrow_mut();
        if !seen.contains_key(&file.path) {
            self.read.set(self.read.get().saturating_add(file.len));
            seen.insert(file.path.clone(), file.clone());
        }
        self.read.get() <= self.limit
    }

    /// Bytes read so far, and the limit.
    pub(super) fn bytes(&self) -> (u64, u64) {
        (self.read.get(), self.limit)
    }

    /// Bytes that a file not read yet may hold.
    pub(super) fn room(&self) -> u64 {
        self.limit.saturating_sub(self.read.get())
    }

    /// Whether `file` still holds what it held: read again (confined, bounded) the first time
    /// this reading asks, remembered after.
    fn holds(&self, file: &FileRead) -> bool {
        if let Some(seen) = self.seen.borrow().get(&file.path) {
            return seen.same(file);
        }
        let now = open_named(&file.path, &self.scene, self.any)
            .ok()
            .and_then(|opened| opened.read(&file.shown, self.room(), "file").ok())
            .map(|bytes| FileRead::of(&file.path, &file.shown, &bytes));
        match now {
            Some(now) => self.note(&now) && now.same(file),
            None => false,
        }
    }

    /// Counts splicing in `included` (read from `path`) by one `include` line: free the first
    /// time the scene splices the file in, its weight after. Whether the work stays within
    /// the limit; the cost when it does not.
    pub(super) fn splice(&self, path: &Path, included: &Included) -> Result<(), u64> {
        if self.spliced.borrow_mut().insert(path.to_path_buf()) {
            return Ok(());
        }
        let cost = included.weight() + 1;
        let total = self.repeated.get().saturating_add(cost);
        if total > MAX_INCLUDE_REPEATS {
            self.over.set(true);
            return Err(cost);
        }
        self.repeated.set(total);
        Ok(())
    }
}

/// The files being read, from the one the reader was given to the one being read now.
#[derive(Clone)]
pub(in crate::sdf) struct Chain {
    /// The files being read (real paths), outermost first.
    pub(super) files: Vec<PathBuf>,
    pub(super) reading: Rc<Reading>,
    /// The files read for the file being read now and those it includes, each once.
    pub(super) deps: Rc<RefCell<Files>>,
    /// Whether a limit left something of the file being read now out.
    pub(super) cut: Rc<Cell<bool>>,
    /// Whether the outermost file is a frame `anim generate` wrote
    /// (`sdf::is_generated_frame`): it and everything it includes are read with no guess.
    pub(in crate::sdf) generated: bool,
}

impl Chain {
    /// The chain of a file read on its own: `text` is its whole text.
    pub(in crate::sdf) fn outermost(
        path: &Path,
        text: &str,
        opts: &crate::sdf::LoadOptions,
    ) -> Chain {
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
            reading: Rc::new(Reading {
                scene: path.to_path_buf(),
                limit: opts.max_input,
                any: opts.allow_any_input,
                read: Cell::new(text.len() as u64),
                repeated: Cell::new(0),
                over: Cell::new(false),
                seen: RefCell::default(),
                spliced: RefCell::default(),
                resolved: RefCell::default(),
            }),
            deps: Rc::default(),
            cut: Rc::default(),
            generated: crate::sdf::is_generated_frame(text),
        }
    }

    /// Whether the file being read now is included by another.
    pub(in crate::sdf) fn is_included(&self) -> bool {
        self.files.len() > 1
    }

    /// The files read for the file being read now, each once, taken.
    pub(in crate::sdf) fn take_included(&self) -> Vec<FileRead> {
        std::mem::take(&mut *self.deps.borrow_mut()).into_vec()
    }

    /// Whether the reading went over a limit that stops it as a whole.
    pub(in crate::sdf) fn abandoned(&self) -> bool {
        self.reading.over.get()
    }

    /// The chain one file deeper.
    pub(super) fn deeper(&self, path: PathBuf) -> Chain {
        let mut files = self.files.clone();
        files.push(path);
        Chain {
            files,
            reading: self.reading.clone(),
            deps: Rc::default(),
            cut: Rc::default(),
            generated: self.generated,
        }
    }

    /// The file `written` names from the file being read now, as named.
    fn named(&self, written: &str) -> PathBuf {
        let here = self.files.last().map_or(Path::new(""), PathBuf::as_path);
        here.parent().unwrap_or(Path::new("")).join(written)
    }

    /// The real path of the file `written` names and the kept reading of it, when this
    /// reading opened that file from the same folder before, the reading `cache` keeps of it
    /// still holds, and nothing stops it here (a cycle, the depth): an `include` line that
    /// repeats costs no opening of its file.
    pub(super) fn known(
        &self,
        written: &str,
        cache: &IncludeCache,
        layout: &MaterialLayout,
    ) -> Option<(PathBuf, Arc<Included>)> {
        if self.files.len() >= crate::limits::MAX_INCLUDE_DEPTH {
            return None;
        }
        let real = self
            .reading
            .resolved
            .borrow()
            .get(&self.named(written))?
            .clone();
        let included = cache.get(&real, self, layout)?;
        Some((real, included))
    }

    /// Opens the file an `include` line names, as written (`written`) in the file being read
    /// now: a file the scene may read ([`open_named`]), not being read already, and not
    /// deeper than files may nest.
    pub(super) fn open(&self, written: &str) -> Result<Opened, Unusable> {
        if written.is_empty() {
            return Err(Unusable::Unnamed);
        }
        let named = self.named(written);
        let folder = named.parent().unwrap_or(Path::new("")).to_path_buf();
        let opened =
            open_named(&named, &self.reading.scene, self.reading.any).map_err(Unusable::Refused)?;
        if let Some(depth) = self.files.iter().position(|f| f == opened.real()) {
            let round = self.files[depth..]
                .iter()
                .chain([&opened.real().to_path_buf()])
                .map(|f| shown(f, &folder))
                .collect();
            return Err(Unusable::Cycle(round));
        }
        if self.files.len() >= crate::limits::MAX_INCLUDE_DEPTH {
            return Err(Unusable::TooDeep);
        }
        let real = opened.real().to_path_buf();
        self.reading.resolved.borrow_mut().insert(named, real);
        Ok(opened)
    }
}

/// Why an `include` line reads nothing.
pub(super) enum Unusable {
    /// It names no file.
    Unnamed,
    /// The file may not be read, or cannot be ([`crate::input::Refusal`]).
    Refused(crate::input::Refusal),
    /// The file is being read already: the files round the loop, as messages show them.
    Cycle(Vec<String>),
    /// Files nest more than `limits::MAX_INCLUDE_DEPTH` deep.
    TooDeep,
}

/// `path` as a message shows it: relative to `folder` when it is inside it.
fn shown(path: &Path, folder: &Path) -> String {
    path.strip_prefix(folder)
        .unwrap_or(path)
        .display()
        .to_string()
}
