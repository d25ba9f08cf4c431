//! Diagnostics in the form users know from compilers:
//! `scene.sdf:12:31: error: expected a number, found '1O'`, the line, and a caret.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Severity {
    Warning,
    Error,
}

/// A position in a source file; `line` and `col` count from 1, `col` in characters.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Loc {
    pub file: Arc<Path>,
    pub line: u32,
    pub col: u32,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    pub severity: Severity,
    /// `None` for problems with the file as a whole (cannot be read, ...).
    pub loc: Option<Loc>,
    /// Used when `loc` is `None`.
    pub file: PathBuf,
    pub message: String,
    /// The source line, shown with a caret under `loc.col` spanning `width` characters.
    pub source_line: Option<String>,
    pub width: u32,
    /// "did you mean `glass`?", the canonical form of a statement, ...
    pub help: Option<String>,
}

impl Diagnostic {
    pub fn new(severity: Severity, loc: Loc, message: impl Into<String>) -> Self {
        Diagnostic {
            severity,
            file: loc.file.to_path_buf(),
            loc: Some(loc),
            message: message.into(),
            source_line: None,
            width: 1,
            help: None,
        }
    }

    /// A problem with a whole file, e.g. it cannot be read.
    pub fn file_error(file: &Path, message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Error,
            loc: None,
            file: file.to_path_buf(),
            message: message.into(),
            source_line: None,
            width: 1,
            help: None,
        }
    }

    pub fn with_source(mut self, line: impl Into<String>, width: u32) -> Self {
        self.source_line = Some(line.into());
        self.width = width.max(1);
        self
    }

    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    pub fn with_severity(mut self, severity: Severity) -> Self {
        self.severity = severity;
        self
    }

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
        match &self.loc {
            Some(loc) => write!(
                f,
                "{}:{}:{}: {kind}: {}",
                loc.file.display(),
                loc.line,
                loc.col,
                self.message
            )?,
            None => write!(f, "{}: {kind}: {}", self.file.display(), self.message)?,
        }
        if let (Some(src), Some(loc)) = (&self.source_line, &self.loc) {
            let gutter = loc.line.to_string().len();
            write!(
                f,
                "\n{:gutter$} |\n{} | {}\n{:gutter$} | ",
                "",
                loc.line,
                src.replace('\t', " "),
                ""
            )?;
            let pad = loc.col.saturating_sub(1) as usize;
            write!(f, "{:pad$}{}", "", "^".repeat(self.width as usize))?;
        }
        if let Some(help) = &self.help {
            write!(f, "\n  = help: {help}")?;
        }
        Ok(())
    }
}

/// The closest name to `wanted` among `candidates`, if it is close enough to be a likely typo.
pub fn suggest<'a>(wanted: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    candidates
        .into_iter()
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

    #[test]
    fn suggestions_only_for_near_misses() {
        let names = ["glass", "red", "blue"];
        assert_eq!(suggest("glas", names), Some("glass"));
        assert_eq!(suggest("blu", names), Some("blue"));
        assert_eq!(suggest("zzzzzz", names), None);
    }
}
