//! Parsing: the tokens of each line → canonical statements (the scene language).
//!
//! Every accepted variant is normalised here, so the statement list that comes out only uses
//! the canonical forms of `ast.rs`. Problems are reported with the line, the column of the
//! offending token and, where it helps, the canonical form of the statement. A statement with
//! an error is dropped (parsing goes on, to report every problem in one run); the names it
//! would have defined are remembered so that later references to them do not pile up
//! follow-on errors.

mod camera;
mod dialect;
mod include;
mod layout;
mod light;
mod material;
mod motion;
mod render;
mod resolve;
mod shape;
mod transform;

pub(super) use include::Chain;
pub use include::{mesh_files, references, FileRead, IncludeCache, Reference};
pub use resolve::default_output;

use super::ast::{FlatShapes, NameRef, Span, Statement, StatementKind, StatementSpans};
use super::lexer::{self, looks_numeric, Line, NumberError};
use super::LoadOptions;
use crate::diag::{suggest, Diagnostic, Loc, Severity};
use render::PendingRender;
use resolve::commented_definitions;
use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::sync::Arc;

const STATEMENT_KEYWORDS: [&str; 7] = [
    "define",
    "include",
    "transform",
    "render",
    "camera",
    "ambient",
    "background",
];
const DEFINE_KINDS: [&str; 8] = [
    "material",
    "shape",
    "light",
    "camera",
    "ambient",
    "background",
    "transform",
    "render",
];
/// The statements of a file, the problems met, and what the reader left out.
pub struct Parsed {
    /// The statements, but for those in `shapes`.
    pub statements: Vec<Statement>,
    /// The primitive shapes of a file in which nothing refers to a shape by name, when the
    /// reader was asked to keep them apart (`parse_source`); else empty.
    pub shapes: FlatShapes,
    /// The problems met while reading, warnings and errors alike.
    pub diagnostics: Vec<Diagnostic>,
    /// What the reader left out that the scene builder must account for.
    pub omissions: Omissions,
    /// Whether the file is a frame `anim generate` wrote (`sdf::is_generated_frame`): it was
    /// read, and is built, with every guess turned off.
    pub generated: bool,
    /// The files the scene includes, to any depth, each once: where their lines are quoted
    /// from, when still the same.
    pub included: Vec<FileRead>,
}

/// What the reader left out of the statements that building must still account for: its
/// problems are reported already, and must neither be reported again as follow-on errors nor
/// be covered up by a stand-in.
#[derive(Debug, Default)]
pub struct Omissions {
    /// Names whose definition was rejected or skipped (already reported): references to them
    /// are ignored instead of being reported again as undefined.
    pub skipped: HashSet<String>,
    /// Render-like lines met, including rejected ones: a file whose only render line was
    /// rejected has not "no render statement".
    pub render_lines: usize,
    /// Whether a camera definition was rejected (so the default camera is no stand-in).
    pub cameras_rejected: bool,
    /// Names defined only in commented-out lines → the line (see `commented_definitions`).
    pub commented: HashMap<String, u32>,
    /// Whether a limit of the reading as a whole stopped it (its includes repeat too much):
    /// the statements are dropped, and nothing is built from them.
    pub abandoned: bool,
}

/// An error has been reported; the statement is dropped.
struct Fail;
type PResult<T> = Result<T, Fail>;

/// Where on a line a diagnostic points.
#[derive(Clone, Copy, Debug)]
enum At {
    /// One token.
    Tok(usize),
    /// Tokens `a..=b`.
    Span(usize, usize),
    /// Just after the last token (something is missing).
    End,
}

/// A place in the source, kept after the line itself is gone (for checks done at the end).
#[derive(Clone, Debug)]
struct Anchor {
    loc: Loc,
    width: u32,
    text: String,
}

/// Reads `text`. With `flat`, the primitive shapes are kept apart in compact form when nothing
/// in the file refers to a shape by name.
pub(super) fn parse(
    text: &str,
    path: &Path,
    opts: &LoadOptions,
    flat: bool,
    chain: include::Chain,
) -> Parsed {
    let generated = chain.generated;
    let mut p = Parser {
        chain,
        file: Arc::from(path),
        path,
        opts,
        statements: Vec::new(),
        diagnostics: Vec::new(),
        skipped: HashSet::new(),
        camera_names: Vec::new(),
        pending: Vec::new(),
        nine_number_noted: [false; 2],
        variants_noted: HashSet::new(),
        render_lines: 0,
        cameras_rejected: false,
        layout: material_layout(text, opts),
        render_errors: Vec::new(),
        camera_sizes: HashMap::new(),
        shapes: FlatShapes::default(),
        flat,
        camera_errors: Vec::new(),
    };
    // Line by line, one line's tokens at a time: the file is never held as a list of lines.
    // The same pass finds the lines too long to read whole and the definitions in comments.
    let mut overlong = Vec::new();
    let mut commented: HashMap<&str, u32> = HashMap::new();
    lexer::each_line(text, |line| {
        if let Some(count) = lexer::overlong(line.text) {
            overlong.push((line.number, count));
        }
        if line.tokens.is_empty() && line.text.trim_start().starts_with(['#', '/']) {
            for (name, _) in commented_definitions(line.text) {
                commented.entry(name).or_insert(line.number);
            }
        }
        p.line(line);
    });
    if !p.flat {
        p.merge_shapes();
    }
    p.resolve_renders();
    p.resolve_camera_role(text);
    p.prune_skipped_references();
    p.drop_transforms_of_commented_definitions(text, &commented);
    p.resolve_motion(text);
    // The lexer keeps only the first tokens of an overlong line; the line is refused here so
    // that a truncated statement is never taken for what was written.
    for (line, count) in overlong {
        p.diagnostics.push(Diagnostic::new(
            Severity::Error,
            Loc {
                file: p.file.clone(),
                line,
                col: 1,
            },
            format!(
                "line holds {count} tokens, more than the {} a line may hold",
                crate::limits::MAX_TOKENS_PER_LINE
            ),
        ));
    }
    crate::sdf::keep_shown(&mut p.diagnostics, path);
    let included = p.chain.take_included();
    let abandoned = p.chain.abandoned();
    if abandoned {
        p.statements = Vec::new();
        p.shapes = FlatShapes::default();
    }
    Parsed {
        included,
        statements: p.statements,
        shapes: p.shapes,
        diagnostics: p.diagnostics,
        omissions: Omissions {
            skipped: p.skipped,
            render_lines: p.render_lines,
            cameras_rejected: p.cameras_rejected,
            commented: commented
                .into_iter()
                .map(|(name, line)| (name.to_string(), line))
                .collect(),
            abandoned,
        },
        generated,
    }
}

struct Parser<'a> {
    /// The files being read, this one last (for `include`).
    chain: include::Chain,
    file: Arc<Path>,
    path: &'a Path,
    opts: &'a LoadOptions,
    statements: Vec<Statement>,
    diagnostics: Vec<Diagnostic>,
    skipped: HashSet<String>,
    /// Every camera name defined in the file (also by lines that failed), in order.
    camera_names: Vec<String>,
    pending: Vec<PendingRender>,
    /// Whether the 9-number light reading was already explained: [rgb-brightness, lecture].
    nine_number_noted: [bool; 2],
    /// Variant spellings already explained: each is warned about once per file, as the same
    /// reading applies to every later line written that way.
    variants_noted: HashSet<&'static str>,
    render_lines: usize,
    cameras_rejected: bool,
    /// How the numbers after a material's colours are read: `--material-fields`, or the
    /// layout inferred from the file's materials when it is `auto` (an empty list).
    layout: layout::Layout,
    /// Problems of render lines, each of which rejects only its own line when another render
    /// line of the file stands (settled in `resolve_renders`).
    render_errors: Vec<Diagnostic>,
    /// Image sizes written on camera lines (`camera eye 45 500 500`), for the render lines
    /// of that camera that give none.
    camera_sizes: HashMap<String, (u32, u32)>,
    /// Primitive shapes read while `flat` holds.
    shapes: FlatShapes,
    /// Whether shapes are kept apart: asked for, and nothing read so far refers to a shape
    /// by name (a composite, a transform) or is a shape kept as a statement (a mesh).
    flat: bool,
    /// Problems of rejected camera lines, by camera: each rejects only its own camera and
    /// the render lines using it when another render line stands (settled in `resolve`).
    camera_errors: Vec<(String, Vec<Diagnostic>)>,
}

/// The layout of the numbers after the colours of the file's materials: the one named by
/// `--material-fields`, or with `auto` the most plausible one for every
/// material line of the file (`docs/scene-language.md §3.1`).
fn material_layout(text: &str, opts: &LoadOptions) -> layout::Layout {
    if let Some(fields) = opts.material_fields.explicit() {
        return layout::Layout::explicit(fields);
    }
    let mut extras: Vec<Vec<f64>> = Vec::new();
    let mut tokens = Vec::new();
    for raw in lines_containing(text, "material") {
        // Only lines naming a material can be material lines; the rest are not tokenized.
        lexer::tokenize_into(raw, &mut tokens);
        let is_material = tokens.first().is_some_and(|t| t.text == "define")
            && tokens.get(1).is_some_and(|t| t.text == "material");
        if !is_material {
            continue;
        }
        // Lines with a malformed number are reported when read; they do not vote.
        let nums: Option<Vec<f64>> = tokens
            .iter()
            .skip(3)
            .map(|t| lenient_number(t.text))
            .collect();
        extras.extend(nums.filter(|n| n.len() >= 10).map(|n| n[9..].to_vec()));
    }
    layout::infer(&extras).unwrap_or_else(layout::default_layout)
}

/// The lines of `text` (as `lexer::raw_lines` splits them) that contain `word`, found by
/// searching the whole text for it rather than line by line.
fn lines_containing<'t>(text: &'t str, word: &'t str) -> impl Iterator<Item = &'t str> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut from = 0;
    std::iter::from_fn(move || {
        let at = find_from(text, from, word)?;
        let start = text[..at].rfind(['\n', '\r']).map_or(0, |i| i + 1);
        let end = text[at..].find(['\n', '\r']).map_or(text.len(), |i| at + i);
        from = end;
        Some(&text[start..end])
    })
}

/// The first place at or after byte `from` (a character boundary) where `word` (non-empty,
/// ending in an ASCII character) is written. The text is scanned for the word's last byte,
/// which the standard library finds a machine word at a time, far faster than a general
/// substring search; the whole word is compared only where that byte is.
fn find_from(text: &str, from: usize, word: &str) -> Option<usize> {
    let w = word.as_bytes();
    let last = char::from(*w.last().filter(|b| b.is_ascii())?);
    let bytes = text.as_bytes();
    let mut i = from;
    loop {
        let end = i + text.get(i..)?.find(last)? + 1;
        if let Some(start) = end.checked_sub(w.len()).filter(|&s| s >= from) {
            if &bytes[start..end] == w {
                return Some(start);
            }
        }
        // Just past an ASCII byte: a character boundary.
        i = end;
    }
}

/// A number as the reader takes it, a C-style suffix (`1.0f`) included.
fn lenient_number(text: &str) -> Option<f64> {
    match lexer::parse_number(text) {
        Ok(v) => Some(v),
        Err(NumberError::Suffix(plain)) => lexer::parse_number(&plain).ok(),
        Err(_) => None,
    }
}

impl Parser<'_> {
    // ----- diagnostics -------------------------------------------------------------------

    /// Column and caret width of `at`.
    fn place(line: &Line, at: At) -> (u32, u32) {
        match at {
            At::Tok(i) => line
                .tokens
                .get(i)
                .map_or((line.end_col(), 1), |t| (t.col, t.width)),
            At::Span(a, b) => match (line.tokens.get(a), line.tokens.get(b)) {
                (Some(ta), Some(tb)) => (
                    ta.col,
                    tb.col
                        .saturating_add(tb.width)
                        .saturating_sub(ta.col)
                        .max(1),
                ),
                _ => (line.end_col(), 1),
            },
            At::End => (line.end_col(), 1),
        }
    }

    fn anchor(&self, line: &Line, at: At) -> Anchor {
        let (col, width) = Self::place(line, at);
        Anchor {
            loc: Loc {
                file: self.file.clone(),
                line: line.number,
                col,
            },
            width,
            text: line.text.to_string(),
        }
    }

    /// The location of `at` (without copying the line, as `anchor` does: name references
    /// are made for every token of long composite lines).
    fn loc(&self, line: &Line, at: At) -> Loc {
        Loc {
            file: self.file.clone(),
            line: line.number,
            col: Self::place(line, at).0,
        }
    }

    fn report(
        &mut self,
        severity: Severity,
        anchor: Anchor,
        message: String,
        help: Option<String>,
    ) {
        let mut d =
            Diagnostic::new(severity, anchor.loc, message).with_source(anchor.text, anchor.width);
        if let Some(h) = help {
            d = d.with_help(h);
        }
        self.diagnostics.push(d);
    }

    fn error(
        &mut self,
        line: &Line,
        at: At,
        message: impl Into<String>,
        help: Option<String>,
    ) -> Fail {
        let anchor = self.anchor(line, at);
        self.report(Severity::Error, anchor, message.into(), help);
        Fail
    }

    fn warn(&mut self, line: &Line, at: At, message: impl Into<String>, help: Option<String>) {
        let anchor = self.anchor(line, at);
        self.report(Severity::Warning, anchor, message.into(), help);
    }

    /// Explains a variant spelling the first time the file uses it.
    fn variant(&mut self, line: &Line, at: At, key: &'static str, message: String, help: String) {
        let help =
            format!("{help} (later lines written this way are read the same, without a warning)");
        self.warn_once(line, at, key, message, help);
    }

    /// A warning given only the first time its `key` comes up in the file.
    fn warn_once(&mut self, line: &Line, at: At, key: &'static str, message: String, help: String) {
        if self.variants_noted.insert(key) {
            self.warn(line, at, message, Some(help));
        }
    }

    fn emit(&mut self, line: &Line, kind: StatementKind) {
        self.push(line, kind, None);
    }

    /// A statement about a name (the one a definition gives, a transform's target), with
    /// where that name (token `name_at`) is written: problems found once the whole file is
    /// known (a duplicate, a cycle) point at it.
    fn emit_named(&mut self, line: &Line, name_at: usize, kind: StatementKind) {
        let (col, width) = Self::place(line, At::Tok(name_at));
        let name = Span { col, width };
        self.push(line, kind, Some(name));
    }

    fn push(&mut self, line: &Line, kind: StatementKind, name: Option<Span>) {
        let loc = self.loc(line, At::Tok(0));
        let first_width = Self::place(line, At::Tok(0)).1;
        match &kind {
            StatementKind::Material(m) => self.shapes.define_material(&m.name),
            StatementKind::Composite { .. }
            | StatementKind::Transform { .. }
            | StatementKind::Motion(_) => {
                self.flat = false;
            }
            _ => {}
        }
        let stmt = Statement {
            kind,
            loc,
            spans: Some(StatementSpans { first_width, name }),
        };
        if !self.flat {
            self.statements.push(stmt);
            return;
        }
        if let Some(stmt) = self.shapes.push(stmt, self.statements.len()) {
            self.flat &= !matches!(stmt.kind, StatementKind::Shape { .. });
            self.statements.push(stmt);
        }
    }

    /// Puts the shapes kept apart back among the statements, where they were read: the file
    /// turned out to refer to shapes by name, or the caller wants every statement.
    fn merge_shapes(&mut self) {
        if self.shapes.is_empty() {
            return;
        }
        let shapes = std::mem::take(&mut self.shapes);
        let others = std::mem::take(&mut self.statements);
        let (all, moved) = shapes.merge_into(others);
        self.statements = all;
        // Pending render lines point at their statements.
        for pending in &mut self.pending {
            pending.index = moved.get(pending.index).copied().unwrap_or(pending.index);
        }
    }

    fn name_ref(&self, line: &Line, i: usize) -> NameRef {
        NameRef {
            name: line
                .tokens
                .get(i)
                .map_or(String::new(), |t| t.text.to_string()),
            loc: self.loc(line, At::Tok(i)),
        }
    }

    /// Remembers that the definition of the name at token `i` was not taken, so references
    /// to it stay quiet (the problem was reported here).
    fn skip_name(&mut self, line: &Line, i: usize) {
        if let Some(t) = line.tokens.get(i) {
            self.skipped.insert(t.text.to_string());
        }
    }

    // ----- numbers -----------------------------------------------------------------------

    fn bad_number(&mut self, line: &Line, i: usize, e: NumberError) -> Fail {
        let text = crate::diag::shorten(line.tokens.get(i).map_or("", |t| t.text)).into_owned();
        let (message, help) = match e {
            NumberError::Malformed => {
                let help = if text.contains(['O', 'o'])
                    && lexer::parse_number(&text.replace(['O', 'o'], "0")).is_ok()
                {
                    format!(
                        "`{text}` contains the letter O; did you mean `{}`?",
                        text.replace(['O', 'o'], "0")
                    )
                } else {
                    "numbers look like 1, -1.5, .5, +100 or 1e-3".to_string()
                };
                (format!("expected a number, found '{text}'"), help)
            }
            NumberError::NotFinite => (
                format!("expected a number, found '{text}'"),
                "nan and inf are not allowed: every number must be finite".to_string(),
            ),
            NumberError::Suffix(plain) => (
                format!("expected a number, found '{text}'"),
                format!("SDF numbers take no type suffix: write `{plain}`"),
            ),
            NumberError::DecimalComma(dotted) => (
                format!("expected a number, found '{text}'"),
                format!("use a decimal point: `{dotted}`"),
            ),
            NumberError::TooLarge => (
                format!("number '{text}' is out of range"),
                format!(
                    "numbers must lie between -{m:e} and {m:e}",
                    m = lexer::MAX_MAGNITUDE
                ),
            ),
        };
        self.error(line, At::Tok(i), message, Some(help))
    }

    /// Reads tokens `from..to` as numbers, reporting every one that is not.
    fn numbers(&mut self, line: &Line, from: usize, to: usize) -> PResult<Vec<f64>> {
        let mut out = Vec::with_capacity(to.saturating_sub(from));
        let mut failed = false;
        for i in from..to.min(line.tokens.len()) {
            match lexer::parse_number(line.tokens[i].text) {
                Ok(v) => out.push(v),
                Err(NumberError::Suffix(plain)) if lexer::parse_number(&plain).is_ok() => {
                    // `1.0f`: C and Java source pasted into scene files; the meaning is clear.
                    let text = line.tokens[i].text.to_string();
                    self.variant(
                        line,
                        At::Tok(i),
                        "number-suffix",
                        format!("number `{text}` written with a type suffix"),
                        format!("read as `{plain}`; SDF numbers take no suffix"),
                    );
                    out.extend(lexer::parse_number(&plain).ok());
                }
                Err(e) => {
                    self.bad_number(line, i, e);
                    failed = true;
                }
            }
        }
        if failed {
            Err(Fail)
        } else {
            Ok(out)
        }
    }

    /// The index just past the run of number-like tokens starting at `from`.
    fn number_run_end(line: &Line, from: usize) -> usize {
        let mut j = from;
        while j < line.tokens.len() && looks_numeric(line.tokens[j].text) {
            j += 1;
        }
        j
    }

    // ----- dispatch ----------------------------------------------------------------------

    fn line(&mut self, written: &Line) {
        // Between lines, where no line's problems are being gathered.
        crate::sdf::keep_shown(&mut self.diagnostics, self.path);
        match self.split_statements(written) {
            Some(statements) => {
                for statement in &statements {
                    self.statement_line(statement);
                }
            }
            None => self.statement_line(written),
        }
    }

    /// One statement's tokens, as written on a line.
    fn statement_line(&mut self, written: &Line) {
        let normalised;
        let line = if dialect::may_need_normalising(written) {
            match self.normalise(written) {
                Some(l) => {
                    normalised = l;
                    &normalised
                }
                None => return,
            }
        } else {
            written
        };
        let Some(first) = line.tokens.first() else {
            return;
        };
        match first.text {
            "define" => self.define(line),
            "transform" => self.transform(line, 1, None),
            "view" => self.transform(line, 1, Some("`view` read as `transform`")),
            "render" => self.render(line, 1, true, None),
            "renderer" => self.render(line, 1, false, Some("`renderer` read as `render`")),
            "camera" => self.camera(line, 1),
            "ambient" => self.ambient(line, 1),
            "background" => self.background(line, 1),
            "motion" => self.motion(line),
            "include" => self.include(line),
            other => {
                let help = if other.starts_with("<<<<<<<")
                    || other.starts_with("=======")
                    || other.starts_with(">>>>>>>")
                {
                    Some("this looks like a merge-conflict marker".to_string())
                } else {
                    suggest(other, STATEMENT_KEYWORDS).map(|s| format!("did you mean `{s}`?"))
                };
                self.warn(
                    line,
                    At::Tok(0),
                    format!("unknown statement '{other}'; line skipped"),
                    help,
                );
            }
        }
    }

    fn define(&mut self, line: &Line) {
        let Some(kind) = line.tokens.get(1) else {
            self.warn(
                line,
                At::Tok(0),
                "`define` without anything to define; line skipped",
                None,
            );
            return;
        };
        match kind.text {
            "material" => self.material(line),
            "shape" => self.shape(line, 2),
            "light" => self.light(line),
            "camera" => self.camera(line, 2),
            "ambient" => self.ambient(line, 2),
            "background" => self.background(line, 2),
            "backgroundcolor" => self.background(line, 2),
            "amblight" => {
                self.variant(
                    line,
                    At::Tok(1),
                    "amblight",
                    "`define amblight` read as `ambient`".into(),
                    "the ambient light is set by `ambient <r> <g> <b>`".into(),
                );
                self.ambient(line, 2);
            }
            "transform" => self.transform(line, 2, Some("`define transform` read as `transform`")),
            "render" | "renderer" => {
                // `define renderer <camera> <file> <w> <h>`: a camera is named like on a
                // render line (a lone name is settled once every camera is known).
                let note = format!("`define {}` read as `render`", kind.text);
                self.render(line, 2, true, Some(&note))
            }
            k if shape::SHAPE_KINDS.contains(&k) => self.shape(line, 1),
            other => {
                let help = suggest(other, DEFINE_KINDS)
                    .map(|s| format!("did you mean `{s}`?"))
                    .unwrap_or_else(|| format!("known kinds: {}", DEFINE_KINDS.join(", ")));
                self.warn(
                    line,
                    At::Tok(1),
                    format!("unknown definition kind '{other}'; line skipped"),
                    Some(help),
                );
                self.skip_name(line, 2);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_containing_a_word_are_those_a_line_by_line_search_finds() {
        for text in [
            "\u{feff}define material m\r\nx\rmaterial material\n\nno\nmaterialmaterial",
            "material",
            "a\nb material\n",
            "",
            "\u{feff}",
        ] {
            let found: Vec<&str> = lines_containing(text, "material").collect();
            let expected: Vec<&str> = lexer::raw_lines(text)
                .filter(|l| l.contains("material"))
                .collect();
            assert_eq!(found, expected, "{text:?}");
        }
    }

    #[test]
    fn a_word_is_found_where_the_standard_search_finds_it() {
        let text = "l ml material jklö materialmaterial\nmaterial";
        for from in (0..=text.len()).filter(|&i| text.is_char_boundary(i)) {
            for word in ["material", "l", "ial", "jkl", "x"] {
                let expected = text[from..].find(word).map(|i| from + i);
                assert_eq!(find_from(text, from, word), expected, "{from} {word}");
            }
        }
    }
}
