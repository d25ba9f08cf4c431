//! The spec's text with the position of every value in it, and ron's errors turned into
//! located diagnostics in the user's terms.

use crate::keyframe::locate::{Locations, Pos};
use anim_core::diag::{suggest, Diagnostic, Loc, Severity};
use std::path::Path;
use std::sync::Arc;

/// A spec's text and where each value stands in it.
pub struct Source {
    pub path: Arc<Path>,
    pub text: String,
    pub locations: Locations,
}

impl Source {
    /// The largest spec read: as for scene files (`--max-input`'s default).
    pub const MAX_BYTES: u64 = anim_core::limits::DEFAULT_MAX_INPUT;

    /// Reads a spec file: refused unread when larger than `limit` bytes (a device or pipe
    /// after `limit + 1` bytes), when it holds NUL bytes, or when it is not UTF-8. A leading
    /// byte order mark is dropped.
    pub fn read(path: &Path, limit: u64) -> Result<Source, Vec<Diagnostic>> {
        let bytes = anim_core::load::read_input(path, limit, "the spec")?;
        let text = String::from_utf8(bytes)
            .map_err(|_| vec![Diagnostic::file_error(path, "the spec is not UTF-8 text")])?;
        // A byte order mark, as some editors write, is no part of the spec (nor a column).
        let text = match text.strip_prefix('\u{feff}') {
            Some(rest) => rest.to_string(),
            None => text,
        };
        Ok(Source::new(path, text))
    }

    pub fn new(path: &Path, text: String) -> Source {
        let locations = Locations::scan(&text);
        Source {
            path: Arc::from(path),
            text,
            locations,
        }
    }

    fn line_text(&self, line: u32) -> Option<&str> {
        self.text.lines().nth(line.checked_sub(1)? as usize)
    }

    /// A diagnostic at `pos`, quoting the line.
    pub fn at_pos(
        &self,
        severity: Severity,
        pos: Pos,
        width: u32,
        message: impl Into<String>,
    ) -> Diagnostic {
        let loc = Loc {
            file: self.path.clone(),
            line: pos.line,
            col: pos.col,
        };
        let d = Diagnostic::new(severity, loc, message);
        match self.line_text(pos.line) {
            Some(src) => d.with_source(src, width),
            None => d,
        }
    }

    /// An error at the value found at the first existing path of `paths` (more specific
    /// first); at the whole file if none exists.
    pub fn error(&self, paths: &[&str], message: impl Into<String>) -> Diagnostic {
        match self.locations.first(paths) {
            Some((pos, width)) => self.at_pos(Severity::Error, pos, width, message),
            None => Diagnostic::file_error(&self.path, message),
        }
    }

    /// A warning at the value found at the first existing path of `paths`.
    pub fn warning(&self, paths: &[&str], message: impl Into<String>) -> Diagnostic {
        match self.locations.first(paths) {
            Some((pos, width)) => self.at_pos(Severity::Warning, pos, width, message),
            None => Diagnostic::new(
                Severity::Warning,
                Loc {
                    file: self.path.clone(),
                    line: 1,
                    col: 1,
                },
                message,
            ),
        }
    }

    /// Where character `k` of the string value at `path` stands in the spec, and how many of
    /// the spec's characters the `width` characters from it take: escapes (`\"`) take more
    /// than one, and a raw string `r#"…"#` may run over several lines. `None` if no string
    /// stands at `path`.
    pub fn in_string(&self, path: &str, k: usize, width: usize) -> Option<(Pos, u32)> {
        let (start, _) = self.locations.get(path)?;
        let line = self.line_text(start.line)?;
        let from = byte_index(line, start.col);
        let offset: usize = self
            .text
            .split_inclusive('\n')
            .take(start.line as usize - 1)
            .map(str::len)
            .sum();
        let rest: Vec<char> = self.text[offset + from..].chars().collect();
        // Past the opening delimiter; `raw` strings have no escapes.
        let (mut i, raw) = match rest.first() {
            Some('"') => (1, false),
            Some('r') => (rest.iter().position(|&c| c == '"')? + 1, true),
            _ => return None,
        };
        let (mut line_no, mut col) = (start.line, start.col + i as u32);
        // Steps over one character of the string's value, as written.
        let step = |i: &mut usize, line_no: &mut u32, col: &mut u32| {
            let len = match (raw, rest.get(*i)) {
                (false, Some('\\')) => match rest.get(*i + 1) {
                    Some('u') => rest[*i..]
                        .iter()
                        .position(|&c| c == '}')
                        .map_or(2, |p| p + 1),
                    _ => 2,
                },
                _ => 1,
            };
            for _ in 0..len {
                if rest.get(*i) == Some(&'\n') {
                    *line_no += 1;
                    *col = 1;
                } else {
                    *col += 1;
                }
                *i += 1;
            }
        };
        for _ in 0..k {
            if i >= rest.len() {
                break;
            }
            step(&mut i, &mut line_no, &mut col);
        }
        let pos = Pos { line: line_no, col };
        let (mut end_line, mut end_col, mut j) = (line_no, col, i);
        for _ in 0..width {
            if j >= rest.len() || end_line != line_no {
                break;
            }
            step(&mut j, &mut end_line, &mut end_col);
        }
        let taken = if end_line == line_no {
            end_col - col
        } else {
            1
        };
        Some((pos, taken.max(1)))
    }

    /// Turns ron's error into a located diagnostic in the user's terms.
    pub fn ron_error(&self, e: &ron::error::SpannedError) -> Diagnostic {
        use ron::error::Error as E;
        let (pos, width) = self.span_of(&e.span);
        let line_text = self.line_text(pos.line).unwrap_or("");
        let names_a_name = matches!(
            e.code,
            E::NoSuchStructField { .. } | E::NoSuchEnumVariant { .. }
        );
        let (message, help) = describe_ron_error(&e.code);
        // ron reads `64.5` where a whole number belongs as `64` followed by a stray `.5`, and
        // complains about what follows; the real problem is the number.
        let (pos, message, width) = match decimal_before(line_text, byte_index(line_text, pos.col))
        {
            Some((start, text)) => (
                Pos {
                    line: pos.line,
                    col: line_text[..start].chars().count() as u32 + 1,
                },
                format!("expected a whole number, found `{text}`"),
                text.chars().count() as u32,
            ),
            None => (pos, message, width),
        };
        if let Some(open) = unclosed_bracket(&self.text, pos) {
            let close = match open.bracket {
                '(' => ')',
                '[' => ']',
                _ => '}',
            };
            return self
                .at_pos(
                    Severity::Error,
                    open.pos,
                    1,
                    format!("this `{}` is never closed", open.bracket),
                )
                .with_help(format!(
                    "the spec could not be read past {}:{} ({message}): add `{close}` where this `{}` should end",
                    pos.line, pos.col, open.bracket
                ));
        }
        let message = match self.locations_at(pos) {
            Some((path, _)) if !names_a_name && !path.is_empty() => {
                format!("{message} (in `{path}`)")
            }
            _ => message,
        };
        let d = self.at_pos(Severity::Error, pos, width, message);
        match help {
            Some(h) => d.with_help(h),
            None => d,
        }
    }

    /// Where ron's error span starts and how many characters of its first line it covers.
    /// ron starts some spans at the whitespace before the offending value, which is skipped;
    /// an empty span (a missing comma, a missing field) takes the width of the value there.
    fn span_of(&self, span: &ron::error::Span) -> (Pos, u32) {
        let line = span.start.line.max(1) as u32;
        let chars: Vec<char> = self.line_text(line).unwrap_or("").chars().collect();
        let mut start = (span.start.col.max(1) - 1).min(chars.len());
        let end = if span.end.line == span.start.line {
            (span.end.col.max(1) - 1).clamp(start, chars.len())
        } else {
            chars.len()
        };
        while start < end && chars[start].is_whitespace() {
            start += 1;
        }
        let pos = if start == chars.len() && span.end.line > span.start.line {
            Pos {
                line: span.end.line as u32,
                col: span.end.col.max(1) as u32,
            }
        } else {
            Pos {
                line,
                col: start as u32 + 1,
            }
        };
        let width = if pos.line == line && end > start {
            (end - start) as u32
        } else {
            self.locations_at(pos).map_or(1, |(_, w)| w)
        };
        (pos, width)
    }

    /// The deepest value starting exactly at `pos`.
    fn locations_at(&self, pos: Pos) -> Option<(String, u32)> {
        self.locations.starting_at(pos)
    }
}

/// An opening bracket and where it stands.
struct Open {
    bracket: char,
    pos: Pos,
}

/// The bracket left open where reading stopped at `stop`: the innermost open bracket, when
/// the text there closes a different kind of bracket or ends. Strings, characters and
/// comments are passed over.
fn unclosed_bracket(text: &str, stop: Pos) -> Option<Open> {
    let chars: Vec<char> = text.chars().collect();
    let (mut line, mut col, mut i) = (1u32, 1u32, 0usize);
    let mut open: Vec<Open> = Vec::new();
    let advance = |i: &mut usize, line: &mut u32, col: &mut u32| {
        if chars[*i] == '\n' {
            *line += 1;
            *col = 1;
        } else {
            *col += 1;
        }
        *i += 1;
    };
    while i < chars.len() && (line, col) < (stop.line, stop.col) {
        let c = chars[i];
        let next = chars.get(i + 1).copied();
        match c {
            '(' | '[' | '{' => open.push(Open {
                bracket: c,
                pos: Pos { line, col },
            }),
            ')' | ']' | '}' => {
                open.pop();
            }
            '/' if next == Some('/') => {
                while i < chars.len() && chars[i] != '\n' {
                    advance(&mut i, &mut line, &mut col);
                }
                continue;
            }
            '/' if next == Some('*') => {
                while i < chars.len() && !(chars[i] == '*' && chars.get(i + 1) == Some(&'/')) {
                    advance(&mut i, &mut line, &mut col);
                }
                advance(&mut i, &mut line, &mut col);
            }
            '"' => {
                advance(&mut i, &mut line, &mut col);
                while i < chars.len() && chars[i] != '"' {
                    if chars[i] == '\\' {
                        advance(&mut i, &mut line, &mut col);
                    }
                    if i < chars.len() {
                        advance(&mut i, &mut line, &mut col);
                    }
                }
            }
            _ => {}
        }
        if i < chars.len() {
            advance(&mut i, &mut line, &mut col);
        }
    }
    let innermost = open.pop()?;
    let closes = |b: char, c: char| matches!((b, c), ('(', ')') | ('[', ']') | ('{', '}'));
    let rest = chars[i.min(chars.len())..]
        .iter()
        .find(|c| !c.is_whitespace());
    match rest {
        None => Some(innermost),
        Some(&c) if matches!(c, ')' | ']' | '}') && !closes(innermost.bracket, c) => {
            Some(innermost)
        }
        _ => None,
    }
}

/// If `line[at]` is the `.` of a decimal number (`64.5`), the number's start and text.
fn decimal_before(line: &str, at: usize) -> Option<(usize, &str)> {
    let bytes = line.as_bytes();
    if bytes.get(at) != Some(&b'.') || !at.checked_sub(1).is_some_and(|p| bytes[p].is_ascii_digit())
    {
        return None;
    }
    let start = line[..at]
        .rfind(|c: char| !(c.is_ascii_digit() || c == '-' || c == '+'))
        .map_or(0, |i| i + 1);
    let end = at
        + 1
        + line[at + 1..]
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '-' || c == '+'))
            .unwrap_or(line.len() - at - 1);
    Some((start, &line[start..end]))
}

/// What the user calls each serde type in messages.
fn user_name(outer: &Option<String>) -> &'static str {
    match outer.as_deref() {
        Some("SpecFile") => "the spec",
        Some("OrbitSpec") => "`orbit`",
        Some("TrackSpec") => "a track",
        Some("KeySpec") => "a key",
        Some("SceneSource") => "`scene`",
        Some("Length") => "`length`",
        Some("Interp") => "`interp`",
        _ => "this value",
    }
}

fn list(names: &[&str]) -> String {
    names
        .iter()
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn describe_ron_error(code: &ron::error::Error) -> (String, Option<String>) {
    use ron::error::Error as E;
    match code {
        E::NoSuchStructField {
            expected,
            found,
            outer,
        } => {
            let help = match suggest(found, expected.iter().copied()) {
                Some(s) => format!("did you mean `{s}`?"),
                None => format!("the fields of {} are {}", user_name(outer), list(expected)),
            };
            (
                format!("unknown field `{found}` in {}", user_name(outer)),
                Some(help),
            )
        }
        E::NoSuchEnumVariant {
            expected,
            found,
            outer,
        } => {
            let help = match suggest(found, expected.iter().copied()) {
                Some(s) => format!("did you mean `{s}`?"),
                None => format!("expected one of {}", list(expected)),
            };
            (
                format!("unknown variant `{found}` for {}", user_name(outer)),
                Some(help),
            )
        }
        E::MissingStructField { field, outer } => (
            format!("{} is missing the field `{field}`", user_name(outer)),
            None,
        ),
        E::DuplicateStructField { field, outer } => (
            format!("the field `{field}` is given twice in {}", user_name(outer)),
            None,
        ),
        E::ExpectedInteger => ("expected a whole number".to_string(), None),
        E::ExpectedFloat => ("expected a number".to_string(), None),
        E::ExpectedString => ("expected a string in double quotes".to_string(), None),
        E::ExpectedBoolean => ("expected `true` or `false`".to_string(), None),
        E::InvalidValueForType { expected, found } => {
            (format!("expected {expected}, found {found}"), None)
        }
        E::Message(m) => (lower_first(m), None),
        // ron's own wording ("Expected closing `)`"), in the lower case of the rest.
        other => (lower_first(&other.to_string()), None),
    }
}

fn lower_first(text: &str) -> String {
    let mut chars = text.chars();
    match chars.next() {
        Some(c) => c.to_lowercase().collect::<String>() + chars.as_str(),
        None => String::new(),
    }
}

/// The byte index of 1-based character column `col` in `line` (its end if past it).
fn byte_index(line: &str, col: u32) -> usize {
    line.char_indices()
        .nth(col.saturating_sub(1) as usize)
        .map_or(line.len(), |(i, _)| i)
}
