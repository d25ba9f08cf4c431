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

mod reading;
mod refs;

pub(in crate::sdf) use reading::Chain;
pub use reading::{FileRead, IncludeCache};
pub use refs::{references, Reference};

use super::{At, Line, Parser};
use crate::input::Opened;
use crate::limits::{MAX_INCLUDE_DEPTH, MAX_INCLUDE_REPEATS};
use crate::sdf::ast::StatementKind;
use reading::{Files, Included, Unusable};
use std::path::{Path, PathBuf};
use std::sync::Arc;

impl Parser<'_> {
    /// `include <file>`: the file's statements, in place of the line.
    pub(super) fn include(&mut self, line: &Line) {
        const FORM: &str = "include <file>";
        if self.chain.reading.over.get() {
            // The scene repeats too much already (reported once).
            self.chain.cut.set(true);
            return;
        }
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
        let (path, included) =
            match self
                .chain
                .known(written, &self.opts.includes, &self.opts.material_fields)
            {
                Some(known) => known,
                None => {
                    let opened = match self.chain.open(written) {
                        Ok(opened) => opened,
                        Err(why) => return self.unusable(line, written, why),
                    };
                    let path = opened.real().to_path_buf();
                    let included =
                        match self
                            .opts
                            .includes
                            .get(&path, &self.chain, &self.opts.material_fields)
                        {
                            Some(included) => included,
                            None => {
                                let display =
                                    self.path.parent().unwrap_or(Path::new("")).join(written);
                                match self.read_included(line, opened, &display) {
                                    Some(included) => included,
                                    None => return,
                                }
                            }
                        };
                    (path, included)
                }
            };
        let (read, limit) = self.chain.reading.bytes();
        if read > limit {
            self.error(
                line,
                At::Tok(1),
                format!(
                    "this file and what it includes hold {read} bytes, more than the {limit} that --max-input allows"
                ),
                Some("raise --max-input if the scene is meant to be this large".into()),
            );
            return;
        }
        if let Err(cost) = self.chain.reading.splice(&path, &included) {
            self.chain.cut.set(true);
            self.error(
                line,
                At::Tok(1),
                format!(
                    "`{written}` is in this scene already: splicing its {cost} statements in again would repeat more than the {MAX_INCLUDE_REPEATS} that includes may repeat in one scene"
                ),
                Some(
                    "files that include a file many times, themselves included many times, multiply; repeat shapes with a composite (`define shape composite`)"
                        .into(),
                ),
            );
            return;
        }
        {
            let mut deps = self.chain.deps.borrow_mut();
            for file in included.files.iter() {
                deps.add(file);
            }
        }
        if included.cut {
            self.chain.cut.set(true);
        }
        self.splice(included);
    }

    /// Reports why an `include` line naming `written` reads nothing.
    fn unusable(&mut self, line: &Line, written: &str, why: Unusable) {
        let (message, help) = match why {
            Unusable::Unnamed => ("`include` names no file".to_string(), None),
            Unusable::Refused(refusal) => {
                let help = matches!(refusal, crate::input::Refusal::Outside)
                    .then(|| "copy the file beside the scene".to_string());
                (refusal.message(written), help)
            }
            Unusable::Cycle(round) => (
                format!(
                    "`{written}` is already being read: including it here would never end ({})",
                    round.join(" → ")
                ),
                None,
            ),
            Unusable::TooDeep => {
                self.chain.cut.set(true);
                (
                    format!("includes nest more than {MAX_INCLUDE_DEPTH} files deep"),
                    Some("an included file that includes another, and so on: flatten some".into()),
                )
            }
        };
        self.error(line, At::Tok(1), message, help);
    }

    /// Reads and parses the included file `opened` and keeps it in the cache. Its locations
    /// name it `display`: the path as written, from the including file's.
    fn read_included(
        &mut self,
        line: &Line,
        opened: Opened,
        display: &Path,
    ) -> Option<Arc<Included>> {
        let path = opened.real().to_path_buf();
        let room = self.chain.reading.room();
        let bytes = match opened.read(display, room, "the included file") {
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
        let read = FileRead::of(&path, display, &bytes);
        // The files this one includes are limited by what is left after it.
        self.chain.reading.note(&read);
        let text = String::from_utf8_lossy(&bytes);
        let chain = self.chain.deeper(path.clone());
        let (deps, cut) = (chain.deps.clone(), chain.cut.clone());
        let parsed = super::parse(&text, display, self.opts, true, chain);
        let mut files = Files::default();
        files.add(&read);
        for file in deps.borrow().iter() {
            files.add(file);
        }
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
            cut: cut.get(),
        });
        if !included.cut {
            self.opts.includes.put(path, &included);
        }
        Some(included)
    }

    /// Puts an included file's statements and problems where its `include` line stands.
    fn splice(&mut self, included: Arc<Included>) {
        // Taken whole when nothing else holds it (the cache did not keep it); else what the
        // scene takes of it is copied, once, and the rest (the files it read) left.
        let included = Arc::try_unwrap(included).unwrap_or_else(|shared| Included {
            files: Files::default(),
            statements: shared.statements.clone(),
            shapes: shared.shapes.clone(),
            diagnostics: shared.diagnostics.clone(),
            skipped: shared.skipped.clone(),
            render_lines: shared.render_lines,
            cameras_rejected: shared.cameras_rejected,
            cut: shared.cut,
            layout: shared.layout.clone(),
            generated: shared.generated,
        });
        for s in &included.statements {
            if let StatementKind::Camera(c) = &s.kind {
                self.camera_names.push(c.name.clone());
            }
        }
        let breaks = included.statements.iter().any(|s| breaks_flat(&s.kind));
        let mut rest = Some((included.shapes, included.statements));
        if let Some((shapes, statements)) = rest.take_if(|_| self.flat && !breaks) {
            // Both files keep their shapes apart: the included shapes stay compact, each
            // with its place in its own file, after the statements read so far.
            match self.shapes.append(shapes, self.statements.len()) {
                Ok(()) => self.statements.extend(statements),
                Err(back) => rest = Some((*back, statements)),
            }
        }
        if let Some((shapes, statements)) = rest {
            // Every shape is a statement from here on, in the order read.
            if self.flat {
                self.merge_shapes();
            }
            self.flat = false;
            let (all, _) = shapes.merge_into(statements);
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

/// The files the `include` lines of `text` name, as written, in order.
fn included_names(text: &str) -> Vec<String> {
    named(text, "include", |words| match words {
        ["include", file] => Some(file.trim_matches('"')),
        _ => None,
    })
}

/// The OBJ files that the mesh statements of `text` (read from `path`) name, as the loader
/// finds them (relative to `path`'s folder): `define shape obj <name> <file> <material>`,
/// the one form it reads. A frame's record notes them (`anim-pipeline`'s `frames::cache`), so
/// that an edited mesh renders the frame again.
pub fn mesh_files(text: &str, path: &Path) -> Vec<PathBuf> {
    let folder = path.parent().unwrap_or(Path::new(""));
    let names = named(text, "obj", |words| {
        let k = words.windows(2).position(|w| w == ["shape", "obj"])?;
        (words.len() == k + 5).then(|| words[k + 3])
    });
    names.iter().map(|name| folder.join(name)).collect()
}

/// What the lines of `text` holding `word` name, by `file_of` each line's words, in order.
fn named(
    text: &str,
    word: &str,
    file_of: impl for<'w> Fn(&[&'w str]) -> Option<&'w str>,
) -> Vec<String> {
    let mut tokens = Vec::new();
    let mut names = Vec::new();
    for raw in super::lines_containing(text, word) {
        crate::sdf::lexer::tokenize_into(raw, &mut tokens);
        let words: Vec<&str> = tokens.iter().map(|t| t.text).collect();
        if let Some(file) = file_of(&words) {
            names.push(file.to_string());
        }
    }
    names
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
        assert_eq!(opts.includes.kept(), [false]);
        assert_eq!(shapes(&dir.join("f1.sdf"), &opts), 2);
        assert_eq!(opts.includes.kept(), [true]);
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
