//! The pass over the whole file once every line is read: render lines settled, references
//! to skipped definitions pruned.

use super::render::RenderCamera;
use super::{Anchor, Parser};
use crate::diag::{Diagnostic, Loc, Severity};
use crate::limits;
use crate::sdf::ast::{CameraDef, NameRef, RenderDef, Statement, StatementKind};
use crate::sdf::lexer;
use std::collections::{HashMap, HashSet};
use std::path::Path;

impl Parser<'_> {
    /// Removes references to names whose definition was skipped (a mesh, an ambient light's
    /// name, a line with an error): their transforms and composite entries mean nothing, and
    /// the statement list must stand on its own when written back out as canonical text.
    pub(super) fn prune_skipped_references(&mut self) {
        if self.skipped.is_empty() {
            return;
        }
        let defined: HashSet<String> = self
            .statements
            .iter()
            .filter_map(|s| match &s.kind {
                StatementKind::Shape { name, .. } | StatementKind::Composite { name, .. } => {
                    Some(name.clone())
                }
                StatementKind::Light(l) => Some(l.name.clone()),
                StatementKind::Camera(c) => Some(c.name.clone()),
                _ => None,
            })
            .collect();
        let gone = |name: &str| self.skipped.contains(name) && !defined.contains(name);
        self.statements.retain_mut(|s| match &mut s.kind {
            StatementKind::Transform { target, .. } => !gone(&target.name),
            StatementKind::Composite { children, .. } => {
                children.retain(|c| !gone(&c.name));
                true
            }
            _ => true,
        });
    }

    /// Names of the shapes, composites, lights and cameras the statements define.
    pub(super) fn defined_names(&self) -> HashSet<&str> {
        self.statements
            .iter()
            .filter_map(|s| match &s.kind {
                StatementKind::Shape { name, .. } | StatementKind::Composite { name, .. } => {
                    Some(name.as_str())
                }
                StatementKind::Light(l) => Some(l.name.as_str()),
                StatementKind::Camera(c) => Some(c.name.as_str()),
                _ => None,
            })
            .collect()
    }

    /// Drops (with one warning per name) the transforms of names that are defined only in a
    /// commented-out line: a definition disabled while its transforms were left in, which
    /// leaves them nothing to move (as for a composite's commented-out child).
    pub(super) fn drop_transforms_of_commented_definitions(
        &mut self,
        text: &str,
        commented: &HashMap<&str, u32>,
    ) {
        if commented.is_empty() {
            return;
        }
        let defined = self.defined_names();
        let mut dropped: Vec<(usize, &NameRef, u32)> = Vec::new();
        for (i, s) in self.statements.iter().enumerate() {
            if let StatementKind::Transform { target, .. } = &s.kind {
                if let Some(&line) = commented.get(target.name.as_str()) {
                    if !defined.contains(target.name.as_str()) {
                        dropped.push((i, target, line));
                    }
                }
            }
        }
        if dropped.is_empty() {
            return;
        }
        // The lines, to quote: only when there is something to report.
        let lines: Vec<&str> = lexer::raw_lines(text).collect();
        let mut warned = HashSet::new();
        let mut notes = Vec::new();
        for &(_, target, comment_line) in &dropped {
            if warned.insert(target.name.as_str()) {
                let text = lines
                    .get((target.loc.line as usize).saturating_sub(1))
                    .copied()
                    .unwrap_or("");
                let d = Diagnostic::new(
                    Severity::Warning,
                    target.loc.clone(),
                    format!(
                        "`{}` is only defined in a comment (line {comment_line}); its transforms are skipped",
                        target.name
                    ),
                )
                .with_source(text, target.name.chars().count() as u32);
                notes.push(d);
            }
        }
        let gone: HashSet<usize> = dropped.iter().map(|&(i, _, _)| i).collect();
        self.diagnostics.extend(notes);
        let mut index = 0;
        self.statements.retain(|_| {
            index += 1;
            !gone.contains(&(index - 1))
        });
    }

    /// Settles the camera and output of render lines that left them open, now that every
    /// camera of the file is known, and explains every variant read.
    pub(super) fn resolve_renders(&mut self) {
        let default_output = default_output(self.path);
        let first_camera = self.camera_names.first().cloned();
        let mut need_default_camera = false;
        let mut rejected = Vec::new();
        let mut outputs: HashMap<String, u32> = HashMap::new();
        let rejected_cameras = self.rejected_cameras();
        let mut skipped_renders: HashMap<String, Vec<u32>> = HashMap::new();
        for pending in std::mem::take(&mut self.pending) {
            let mut notes = pending.notes;
            let Some(Statement {
                kind: StatementKind::Render(def),
                ..
            }) = self.statements.get_mut(pending.index)
            else {
                continue;
            };
            let mut camera_missing = false;
            match pending.camera {
                RenderCamera::Named if self.camera_names.contains(&def.camera.name) => {}
                RenderCamera::Named => {
                    let d = unknown_camera(def, &self.camera_names, &pending.anchor);
                    if d.is_error() {
                        self.render_errors.push(d);
                        rejected.push(pending.index);
                        continue;
                    }
                    self.diagnostics.push(d);
                }
                RenderCamera::Ambiguous(word) => {
                    if self.camera_names.contains(&word) {
                        def.camera.name = word;
                    } else {
                        def.output = word;
                        camera_missing = true;
                    }
                }
                RenderCamera::Missing => camera_missing = true,
            }
            if camera_missing && !take_first_camera(def, first_camera.as_deref(), &mut notes) {
                need_default_camera = true;
            }
            if rejected_cameras.contains(&def.camera.name) {
                // Its camera's problem is reported once, on the camera's line.
                skipped_renders
                    .entry(def.camera.name.clone())
                    .or_default()
                    .push(pending.anchor.loc.line);
                rejected.push(pending.index);
                continue;
            }
            if !pending.size_given {
                settle_size(def, &self.camera_sizes, &mut notes);
            }
            settle_output(def, pending.output_given, &default_output, &mut notes);
            let output = def.output.clone();
            let canonical = StatementKind::Render(def.clone()).to_string();
            if is_scene_file(self.path, &output) {
                rejected.push(pending.index);
                self.render_errors
                    .push(output_is_scene_file(&output, pending.output_anchor));
                continue;
            }
            let line = pending.anchor.loc.line;
            self.warn_repeated_output(&mut outputs, output, &pending.output_anchor, line);
            if !notes.is_empty() {
                self.report(
                    Severity::Warning,
                    pending.anchor,
                    notes.join("; "),
                    Some(format!("read as `{canonical}`")),
                );
            }
        }
        // Indices were taken in increasing order; remove from the back so they stay valid.
        for index in rejected.into_iter().rev() {
            self.statements.remove(index);
        }
        self.settle_render_errors(&skipped_renders);
        if need_default_camera {
            self.insert_default_camera();
        }
    }

    /// Cameras whose lines were all rejected: no statement defines them.
    fn rejected_cameras(&self) -> HashSet<String> {
        let defined_cameras: HashSet<&str> = self
            .statements
            .iter()
            .filter_map(|s| match &s.kind {
                StatementKind::Camera(c) => Some(c.name.as_str()),
                _ => None,
            })
            .collect();
        self.camera_errors
            .iter()
            .map(|(name, _)| name.clone())
            .filter(|name| !defined_cameras.contains(name.as_str()))
            .collect()
    }

    /// Warns when the render line on `line` writes `output` (named at `output_anchor`), which
    /// an earlier one writes too (`outputs`: output → the first line writing it).
    fn warn_repeated_output(
        &mut self,
        outputs: &mut HashMap<String, u32>,
        output: String,
        output_anchor: &Anchor,
        line: u32,
    ) {
        match outputs.get(&output) {
            Some(&first) => {
                self.report(
                    Severity::Warning,
                    output_anchor.clone(),
                    format!("render line {first} also writes `{output}`: this image replaces it"),
                    Some(
                        "give each render line its own file name, e.g. frame001.png, frame002.png"
                            .to_string(),
                    ),
                );
            }
            None => {
                outputs.insert(output, line);
            }
        }
    }

    /// Puts the default camera, which a render line takes when the file defines none, first.
    fn insert_default_camera(&mut self) {
        let loc = Loc {
            file: self.file.clone(),
            line: 1,
            col: 1,
        };
        self.statements.insert(
            0,
            Statement::new(
                StatementKind::Camera(CameraDef::at_origin("default", limits::DEFAULT_FOV_DEG)),
                loc,
            ),
        );
    }
}

/// The diagnostic of a render line naming `def.camera`, which the file (with `cameras`)
/// does not define: with one camera, a warning and the line takes it (a renamed or misspelt
/// camera); otherwise an error. The line is quoted from `anchor`.
fn unknown_camera(def: &mut RenderDef, cameras: &[String], anchor: &Anchor) -> Diagnostic {
    match cameras {
        [only] => {
            let help = match crate::diag::suggest(&def.camera.name, [only.as_str()]) {
                Some(s) => format!("did you mean `{s}`?"),
                None => format!("write `render {only} ...`"),
            };
            let d = Diagnostic::new(
                Severity::Warning,
                def.camera.loc.clone(),
                format!(
                    "unknown camera `{}`: the file's only camera `{only}` is used",
                    def.camera.name
                ),
            )
            .with_source(anchor.text.clone(), def.camera.name.chars().count() as u32)
            .with_help(help);
            def.camera.name = only.clone();
            d
        }
        cameras => {
            let help =
                match crate::diag::suggest(&def.camera.name, cameras.iter().map(String::as_str)) {
                    Some(s) => format!("did you mean `{s}`?"),
                    None if cameras.is_empty() => {
                        "the file defines no camera: add `define camera <name> <fov-x>`".to_string()
                    }
                    None => format!("cameras of this file: {}", cameras.join(", ")),
                };
            Diagnostic::new(
                Severity::Error,
                def.camera.loc.clone(),
                format!("unknown camera `{}`", def.camera.name),
            )
            .with_source(anchor.text.clone(), def.camera.name.chars().count() as u32)
            .with_help(help)
        }
    }
}

/// Gives a render line that names no camera the file's first, `first_camera`; false when
/// the file defines none, and the line takes the default camera.
fn take_first_camera(
    def: &mut RenderDef,
    first_camera: Option<&str>,
    notes: &mut Vec<String>,
) -> bool {
    match first_camera {
        Some(c) => {
            def.camera.name = c.to_string();
            notes.push(format!(
                "no camera named: the file's first camera `{c}` is used"
            ));
            true
        }
        None => {
            def.camera.name = "default".to_string();
            notes.push(format!(
                "no camera named and none defined: a default camera (fov {}) is used",
                limits::DEFAULT_FOV_DEG
            ));
            false
        }
    }
}

/// The image size of a render line that gives none: the one its camera's line gives
/// (`camera_sizes`), else the default size `def` holds.
fn settle_size(
    def: &mut RenderDef,
    camera_sizes: &HashMap<String, (u32, u32)>,
    notes: &mut Vec<String>,
) {
    match camera_sizes.get(&def.camera.name) {
        Some(&(w, h)) => {
            (def.width, def.height) = (w, h);
            notes.push(format!(
                "no image size given: {w}×{h} from the camera's line is used"
            ));
        }
        None => notes.push(format!("no image size given: {}×{}", def.width, def.height)),
    }
}

/// The output of a render line: `default_output` when it names none (`output_given` false,
/// or its only name was taken as the file), and an image file name when its name is none.
fn settle_output(
    def: &mut RenderDef,
    output_given: bool,
    default_output: &str,
    notes: &mut Vec<String>,
) {
    if def.output.is_empty() {
        def.output = default_output.to_string();
        if !output_given {
            notes.push(format!(
                "no output file named: `{default_output}` is written"
            ));
        }
    }
    if let Some(image) = image_name(&def.output) {
        // The renderers these files were written for save PPM whatever the name says; a name
        // without an image extension (or the scene's own) means that.
        notes.push(format!(
            "`{}` is no image file name: `{image}` is written",
            def.output
        ));
        def.output = image;
    }
}

/// The error of a render line whose output, written at `anchor`, is the scene file itself.
fn output_is_scene_file(output: &str, anchor: Anchor) -> Diagnostic {
    Diagnostic::new(
        Severity::Error,
        anchor.loc,
        format!("the render output `{output}` is this scene file itself"),
    )
    .with_source(anchor.text, anchor.width)
    .with_help("name an image file such as image.png")
}

impl Parser<'_> {
    /// A rejected render line stops the file only when no other render line stands: each
    /// render line is its own image, and the others can still be made (warnings then).
    fn settle_render_errors(&mut self, skipped_renders: &HashMap<String, Vec<u32>>) {
        let standing = self
            .statements
            .iter()
            .any(|s| matches!(s.kind, StatementKind::Render(_)));
        for (camera, problems) in std::mem::take(&mut self.camera_errors) {
            for mut d in problems {
                if standing && d.severity == Severity::Error {
                    d.severity = Severity::Warning;
                    d.message
                        .push_str(&format!("; camera `{camera}` is skipped"));
                    if let Some(lines) = skipped_renders.get(&camera) {
                        let lines: Vec<String> = lines.iter().map(u32::to_string).collect();
                        d.message.push_str(&format!(
                            " with the render line{s} that use{v} it (line{s} {}), the other render lines are rendered",
                            lines.join(", "),
                            s = if lines.len() == 1 { "" } else { "s" },
                            v = if lines.len() == 1 { "s" } else { "" },
                        ));
                    }
                }
                self.diagnostics.push(d);
            }
        }
        for mut d in std::mem::take(&mut self.render_errors) {
            if standing && d.severity == Severity::Error {
                d.severity = Severity::Warning;
                d.message
                    .push_str("; this render line is skipped, the other render lines are rendered");
            }
            self.diagnostics.push(d);
        }
    }

    /// `transform camera ...` in a file with exactly one camera, none of whose objects is
    /// named `camera`: the word names the camera's role, and there is only one to mean.
    pub(super) fn resolve_camera_role(&mut self, text: &str) {
        let [only] = self.camera_names.as_slice() else {
            return;
        };
        if only == "camera" {
            return;
        }
        let only = only.clone();
        let named_camera = self.statements.iter().any(|s| match &s.kind {
            StatementKind::Shape { name, .. } | StatementKind::Composite { name, .. } => {
                name == "camera"
            }
            StatementKind::Light(l) => l.name == "camera",
            _ => false,
        });
        if named_camera {
            return;
        }
        let mut first = None;
        for s in &mut self.statements {
            if let StatementKind::Transform { target, .. } = &mut s.kind {
                if target.name == "camera" {
                    first.get_or_insert_with(|| target.loc.clone());
                    target.name = only.clone();
                }
            }
        }
        if let Some(loc) = first {
            let text = lexer::line_text(text, loc.line).unwrap_or("");
            let d = Diagnostic::new(
                Severity::Warning,
                loc,
                format!("`transform camera` read as a transform of the file's only camera `{only}`"),
            )
            .with_source(text, 6)
            .with_help(format!(
                "write `transform {only} ...` (later lines written this way are read the same, without a warning)"
            ));
            self.diagnostics.push(d);
        }
    }
}

/// Names defined in commented-out lines (`# define shape box b ...`, `//define light l ...`)
/// → the line, for explaining references to them.
pub(crate) fn commented_definitions(text: &str) -> HashMap<&str, u32> {
    let mut index = HashMap::new();
    for (i, raw) in lexer::raw_lines(text).enumerate() {
        let body = raw.trim_start();
        let Some(body) = body.strip_prefix("//").or_else(|| body.strip_prefix('#')) else {
            continue;
        };
        let tokens = lexer::tokenize(body.trim_start_matches(['#', '/']));
        if tokens.first().is_some_and(|t| t.text == "define") {
            // `define shape <kind> <name>` or `define <kind> <name>`.
            for t in tokens.iter().skip(2).take(2) {
                index
                    .entry(t.text)
                    .or_insert(u32::try_from(i + 1).unwrap_or(u32::MAX));
            }
        }
    }
    index
}

/// `<file-stem>.png`, the output for files that name none.
pub fn default_output(path: &Path) -> String {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "image".to_string());
    format!("{stem}.png")
}

/// The PPM file meant by an output name without an image extension: its extension replaced
/// when it is a word (`scene.sdf` → `scene.ppm`), `.ppm` added otherwise (`out`, `frame.001`).
/// `None` for a name that already ends in an image extension.
fn image_name(output: &str) -> Option<String> {
    let path = Path::new(output);
    let ext = path.extension().and_then(|e| e.to_str());
    if ext.is_some_and(limits::is_image_extension) || path.file_name().is_none() {
        return None;
    }
    let word = ext.is_some_and(|e| e.chars().all(|c| c.is_ascii_alphabetic()));
    Some(if word {
        path.with_extension("ppm").to_string_lossy().into_owned()
    } else {
        format!("{output}.ppm")
    })
}

/// Whether the output path, resolved (as the renderer does) against the scene file's
/// directory, is the scene file itself.
fn is_scene_file(scene: &Path, output: &str) -> bool {
    let out = Path::new(output);
    if out.is_absolute() {
        return out == scene;
    }
    let in_same_dir = out.parent().is_none_or(|p| {
        p.components()
            .all(|c| matches!(c, std::path::Component::CurDir))
    });
    in_same_dir && out.file_name().is_some() && out.file_name() == scene.file_name()
}

#[cfg(test)]
mod tests {
    use super::image_name;
    use crate::diag::Severity;
    use crate::sdf::ast::StatementKind;
    use crate::sdf::{parse, LoadOptions};
    use std::path::Path;

    #[test]
    fn output_names_without_an_image_extension_write_ppm() {
        assert_eq!(image_name("out.png"), None);
        assert_eq!(image_name("a/b.PPM"), None);
        assert_eq!(image_name("test0.sdf").as_deref(), Some("test0.ppm"));
        assert_eq!(image_name("../sdf/box").as_deref(), Some("../sdf/box.ppm"));
        assert_eq!(image_name("frame.001").as_deref(), Some("frame.001.ppm"));
    }

    #[test]
    fn a_render_line_writing_its_own_scene_file_writes_ppm_beside_it() {
        let text = "define camera c 60\nrender c s.sdf 8 8\n";
        let (statements, ds) = parse(text, Path::new("s.sdf"), &LoadOptions::default());
        let output = statements.iter().find_map(|s| match &s.kind {
            StatementKind::Render(r) => Some(r.output.clone()),
            _ => None,
        });
        assert_eq!(output.as_deref(), Some("s.ppm"));
        assert!(ds.iter().all(|d| d.severity == Severity::Warning), "{ds:?}");
        assert!(ds.iter().any(|d| d.message.contains("no image file name")));
        let strict = LoadOptions {
            strict: true,
            ..LoadOptions::default()
        };
        let (_, ds) = parse(text, Path::new("s.sdf"), &strict);
        assert!(ds.iter().any(|d| d.severity == Severity::Error));
    }
}
