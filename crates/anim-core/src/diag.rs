//! Diagnostics in the form users know from compilers:
//! `scene.sdf:12:31: error: expected a number, found '1O'`, the line, and a caret.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// How serious a diagnostic is. A warning orders below an error.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Severity {
    /// Worth the author's attention, but the file still loads.
    Warning,
    /// The file cannot be loaded as it is.
    Error,
}

/// A position in a source file; `line` and `col` count from 1, `col` in characters.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Loc {
    /// The file, as its path was given.
    pub file: Arc<Path>,
    /// The line, counted from 1.
    pub line: u32,
    /// The column, counted from 1 in characters (not bytes).
    pub col: u32,
}

/// One problem met while reading a file: how serious it is, where it is, what is wrong, and
/// perhaps the line it is on and a hint to fix it. `Display` writes it as compilers do.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    /// Whether the problem stops the file from loading.
    pub severity: Severity,
    /// `None` for problems with the file as a whole (cannot be read, ...).
    pub loc: Option<Loc>,
    /// Used when `loc` is `None`.
    pub file: PathBuf,
    /// What is wrong, in words for the author; shown after the place and the severity.
    pub message: String,
    /// The source line, shown with a caret under `loc.col` spanning `width` characters.
    pub source_line: Option<String>,
    /// The column (in characters, from 1) of the line at which `source_line` starts: a
    /// quote of a very long line keeps only the part around `loc.col`.
    pub source_start: u32,
    /// How many characters, from `loc.col`, the carets under the quoted line span.
    pub width: u32,
    /// "did you mean `glass`?", the canonical form of a statement, ...
    pub help: Option<String>,
    /// For the one diagnostic that says how many problems were left out (a file with a
    /// million bad lines keeps only its first ones in memory): how many. `None` for others.
    pub left_out: Option<LeftOut>,
}

/// How many problems were found but not kept, by severity.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LeftOut {
    /// Errors left out.
    pub errors: usize,
    /// Warnings left out.
    pub warnings: usize,
}

impl LeftOut {
    /// Counts `d` as left out: itself, or what it stands for when it is a count already.
    pub fn add(&mut self, d: &Diagnostic) {
        match d.left_out {
            Some(l) => {
                self.errors += l.errors;
                self.warnings += l.warnings;
            }
            None if d.is_error() => self.errors += 1,
            None => self.warnings += 1,
        }
    }

    /// Whether nothing was left out.
    pub fn is_empty(&self) -> bool {
        self.errors + self.warnings == 0
    }
}

impl Diagnostic {
    /// A problem at `loc`, with no line quoted and no help yet.
    pub fn new(severity: Severity, loc: Loc, message: impl Into<String>) -> Self {
        Diagnostic {
            severity,
            file: loc.file.to_path_buf(),
            loc: Some(loc),
            message: message.into(),
            source_line: None,
            source_start: 1,
            width: 1,
            help: None,
            left_out: None,
        }
    }

    /// A file refused unread for its size (`size` says how large, as known), over the
    /// `--max-input` limit of `limit` bytes: one message for every reader.
    pub fn too_large(file: &Path, size: &str, limit: u64) -> Self {
        Diagnostic::file_error(
            file,
            format!("too large to read: {size}, more than the limit of {limit} bytes"),
        )
        .with_help("raise the limit with --max-input BYTES if the file is meant")
    }

    /// A problem with a whole file, e.g. it cannot be read.
    pub fn file_error(file: &Path, message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Error,
            loc: None,
            file: file.to_path_buf(),
            message: message.into(),
            source_line: None,
            source_start: 1,
            width: 1,
            help: None,
            left_out: None,
        }
    }

    /// The same diagnostic quoting `line`, the whole source line at `loc`, with carets
    /// spanning `width` characters (at least one).
    pub fn with_source(mut self, line: impl AsRef<str>, width: u32) -> Self {
        self.width = width.max(1);
        self.quote(line.as_ref());
        self
    }

    /// Sets the quoted source line from the whole `line`, keeping only the part shown (so
    /// that diagnostics about a line of megabytes do not each hold a copy of it).
    pub fn quote(&mut self, line: &str) {
        let col = self.loc.as_ref().map_or(1, |l| l.col);
        let (start, end) = quote_range(line, col);
        let skipped = line[..start].chars().count();
        // The `…` marks are kept in the quote; the opening one stands in the column of the
        // last character left out, so columns still line up.
        let mut quoted = String::with_capacity(end - start + 6);
        if start > 0 {
            quoted.push('…');
        }
        quoted.push_str(&line[start..end]);
        if end < line.len() {
            quoted.push('…');
        }
        let first = if start > 0 { skipped } else { 1 };
        self.source_start = u32::try_from(first).unwrap_or(u32::MAX);
        self.source_line = Some(quoted);
    }

    /// The same diagnostic with a hint, shown under it after `= help:`.
    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    /// The same problem, reported as `severity` instead.
    pub fn with_severity(mut self, severity: Severity) -> Self {
        self.severity = severity;
        self
    }

    /// Whether the problem is an error, one that stops the file from loading.
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }
}

impl std::error::Error for Diagnostic {}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kind = match self.severity {
            Severity::Warning => "warning",
            Severity::Error => "error",
        };
        let message = shorten(&self.message);
        let message = escape(&message);
        match &self.loc {
            Some(loc) => write!(
                f,
                "{}:{}:{}: {kind}: {message}",
                escape(&loc.file.display().to_string()),
                loc.line,
                loc.col,
            )?,
            None => write!(
                f,
                "{}: {kind}: {message}",
                escape(&self.file.display().to_string())
            )?,
        }
        if let (Some(src), Some(loc)) = (&self.source_line, &self.loc) {
            let gutter = loc.line.to_string().len();
            // The column within the quoted part of the line.
            let col = loc
                .col
                .saturating_sub(self.source_start.saturating_sub(1))
                .max(1);
            let (start, end) = quote_range(src, col);
            let before = src[..start].chars().count();
            let open = if start > 0 { "…" } else { "" };
            let close = if end < src.len() { "…" } else { "" };
            let shown = &src[start..end];
            // The caret goes under the escaped text, so its column counts escapes' widths.
            let pad = open.chars().count()
                + shown
                    .chars()
                    .take((col as usize - 1).saturating_sub(before))
                    .map(shown_width)
                    .sum::<usize>();
            let carets: usize = shown
                .chars()
                .skip((col as usize - 1).saturating_sub(before))
                .take(self.width as usize)
                .map(shown_width)
                .sum::<usize>()
                .max(1);
            write!(
                f,
                "\n{:gutter$} |\n{} | {open}{}{close}\n{:gutter$} | ",
                "",
                loc.line,
                escape(&shown.replace('\t', " ")),
                ""
            )?;
            write!(f, "{:pad$}{}", "", "^".repeat(carets))?;
        }
        if let Some(help) = &self.help {
            write!(f, "\n  = help: {}", shorten(&escape(help)))?;
        }
        Ok(())
    }
}

/// Characters of a source line quoted on each side of the column pointed at.
const QUOTE_SIDE: usize = 100;
/// Characters of a message or help shown at most (they quote tokens, which can be huge).
const MAX_MESSAGE_CHARS: usize = 1000;

/// The byte range of `line` quoted for a diagnostic at 1-based character column `col`:
/// the whole line when short, else about [`QUOTE_SIDE`] characters on each side of `col`.
fn quote_range(line: &str, col: u32) -> (usize, usize) {
    // Two more for the `…` marks of a line quoted already.
    if line.len() <= 2 * QUOTE_SIDE || line.chars().nth(2 * QUOTE_SIDE + 2).is_none() {
        return (0, line.len());
    }
    let col = col.saturating_sub(1) as usize;
    let first = col.saturating_sub(QUOTE_SIDE);
    let mut start = line.len();
    let mut end = line.len();
    for (n, (i, _)) in line.char_indices().enumerate() {
        if n == first {
            start = i;
        }
        if n == first + 2 * QUOTE_SIDE {
            end = i;
            break;
        }
    }
    if start == line.len() {
        // The column lies past the end (a missing argument): quote the line's end.
        let from = line
            .char_indices()
            .rev()
            .nth(2 * QUOTE_SIDE - 1)
            .map_or(0, |(i, _)| i);
        return (from, line.len());
    }
    (start, end)
}

/// Whether `c` must not reach a terminal as it is: C0 and C1 controls and DEL (escape
/// sequences could recolour, retitle or clear the user's terminal).
fn is_control(c: char) -> bool {
    c != '\n' && c != '\t' && c.is_control()
}

/// Width of a quoted character once escaped.
fn shown_width(c: char) -> usize {
    if is_control(c) {
        format!("{}", c.escape_unicode()).chars().count()
    } else {
        1
    }
}

/// `text` with control characters written as escapes (`\u{1b}`).
pub fn escape(text: &str) -> std::borrow::Cow<'_, str> {
    if !text.chars().any(is_control) {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if is_control(c) {
            out.extend(c.escape_unicode());
        } else {
            out.push(c);
        }
    }
    std::borrow::Cow::Owned(out)
}

/// `text` cut in the middle (with `…`) when longer than a message shows (a thousand
/// characters): what a message quoting a token of megabytes holds of it.
pub fn shorten(text: &str) -> std::borrow::Cow<'_, str> {
    if text.len() <= MAX_MESSAGE_CHARS {
        return std::borrow::Cow::Borrowed(text);
    }
    let n = text.chars().count();
    if n <= MAX_MESSAGE_CHARS {
        return std::borrow::Cow::Borrowed(text);
    }
    let half = MAX_MESSAGE_CHARS / 2;
    let head: String = text.chars().take(half).collect();
    let tail: String = text.chars().skip(n - half).collect();
    std::borrow::Cow::Owned(format!("{head}…{tail}"))
}

/// The closest name to `wanted` among `candidates`, if it is close enough to be a likely typo.
pub fn suggest<'a>(wanted: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let len = wanted.chars().count();
    candidates
        .into_iter()
        // The distance is at least the difference in length, and at most a third of the
        // longer name is accepted: other names are not compared (the comparison costs the
        // product of the lengths, which a huge token would make minutes).
        .filter(|c| {
            let other = c.chars().count();
            other.abs_diff(len) <= (len.max(other) / 3).max(1)
        })
        .map(|c| (strsim::damerau_levenshtein(wanted, c), c))
        .filter(|&(d, c)| d > 0 && d <= (wanted.chars().count().max(c.chars().count()) / 3).max(1))
        .min_by_key(|&(d, c)| (d, c.to_string()))
        .map(|(_, c)| c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_like_a_compiler() {
        let loc = Loc {
            file: Arc::from(Path::new("scene.sdf")),
            line: 12,
            col: 5,
        };
        let d = Diagnostic::new(Severity::Error, loc, "expected a number, found '1O'")
            .with_source("abc 1O x", 2)
            .with_help("numbers look like 1, -1.5, .5 or 1e-3");
        let text = d.to_string();
        assert!(text.starts_with("scene.sdf:12:5: error: expected a number, found '1O'"));
        assert!(text.contains("12 | abc 1O x\n   |     ^^"), "{text}");
    }

    fn at(col: u32) -> Loc {
        Loc {
            file: Arc::from(Path::new("s.sdf")),
            line: 3,
            col,
        }
    }

    #[test]
    fn long_lines_are_quoted_around_the_column() {
        let line = format!("{}BAD{}", "a ".repeat(5000), " b".repeat(5000));
        let d = Diagnostic::new(Severity::Error, at(10_001), "bad").with_source(line.clone(), 3);
        let text = d.to_string();
        assert!(text.len() < 600, "{text}");
        let quoted = text.lines().nth(2).unwrap();
        let caret = text.lines().nth(3).unwrap();
        assert!(
            quoted.starts_with("3 | …") && quoted.ends_with('…'),
            "{quoted}"
        );
        let col = quoted.chars().position(|c| c == 'B').unwrap();
        assert_eq!(caret.chars().position(|c| c == '^'), Some(col), "{text}");
        assert!(caret.ends_with("^^^"));
        // Quoting from the loader's copy of the line gives the same picture.
        let mut e = Diagnostic::new(Severity::Error, at(10_001), "bad");
        e.width = 3;
        e.quote(&line);
        assert_eq!(e.to_string(), text);
        // A column past the end quotes the end of the line.
        let end = Diagnostic::new(Severity::Error, at(20_002), "missing").with_source(line, 1);
        assert!(end.to_string().contains(" b b\n"), "{end}");
    }

    #[test]
    fn control_characters_are_escaped() {
        let d = Diagnostic::new(Severity::Error, at(4), "unknown '\u{1b}[31m'")
            .with_source("ab \u{1b}[31m\0 \u{85}x", 6)
            .with_help("\u{7}");
        let text = d.to_string();
        assert!(!text.chars().any(|c| c.is_control() && c != '\n'), "{text}");
        assert!(text.contains("unknown '\\u{1b}[31m'"), "{text}");
        assert!(
            // `\u{1b}[31m\u{0}` takes 15 columns once escaped; the caret spans them all.
            text.contains("ab \\u{1b}[31m\\u{0} \\u{85}x\n  |    ^^^^^^^^^^^^^^^\n"),
            "{text}"
        );
    }

    #[test]
    fn suggestions_only_for_near_misses() {
        let names = ["glass", "red", "blue"];
        assert_eq!(suggest("glas", names), Some("glass"));
        assert_eq!(suggest("blu", names), Some("blue"));
        assert_eq!(suggest("zzzzzz", names), None);
        assert_eq!(suggest(&"x".repeat(100_000), names), None);
    }
}
