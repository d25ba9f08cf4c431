//! Building: canonical statements → render jobs, each with its scene description.
//!
//! Definitions are global to a file (statement order is free in most real files); transforms
//! apply in the order written, composed by the rule of `TransformOrder`; each `render` line
//! sees the transforms the scene language gives it (all of them when the file has one render
//! line, those written before it when it has several). The composite tree is flattened into
//! instances, so a shape listed in two composites is drawn twice.

mod definitions;
mod flat;
mod instancing;
mod jobs;
mod motion;
mod references;
mod transforms;

use crate::diag::{suggest, Diagnostic, Loc, Severity};
use crate::scene::RenderJob;
use crate::sdf::ast::{FlatShapes, NameRef, Statement};
use crate::sdf::{LoadOptions, Omissions};
use instancing::{Building, Plan};
use std::collections::HashSet;
use std::path::Path;

/// Name comparisons allowed for "did you mean" suggestions in one file (about a second's
/// work at worst).
const SUGGESTION_BUDGET: usize = 1_000_000;

/// Builds the render jobs of a statement list. `omissions` is present when the statements
/// come from `sdf::parse_source` in this same load, which has already checked (and reported)
/// the values of every statement; without it (statements made by a program) those checks are
/// made here. `shapes` are the file's primitive shapes the reader kept apart (see
/// `sdf::parse_source`), if any: they are built into instances directly.
pub fn build_jobs(
    statements: &[Statement],
    shapes: FlatShapes,
    path: &Path,
    opts: &LoadOptions,
    omissions: Option<&Omissions>,
) -> (Vec<RenderJob>, Vec<Diagnostic>) {
    let empty = Omissions::default();
    let mut b = Builder {
        path,
        opts,
        from_reader: omissions.is_some(),
        omissions: omissions.unwrap_or(&empty),
        diagnostics: Vec::new(),
        reported_composites: HashSet::new(),
        too_many_reported: false,

        suggestion_budget: SUGGESTION_BUDGET,
    };
    if !shapes.is_empty() {
        let jobs = b.flat_jobs(statements, shapes);
        return (jobs, b.diagnostics);
    }
    let defs = b.definitions(statements);
    b.check_cycles(&defs);
    let jobs = b.jobs(statements, &defs);
    (jobs, b.diagnostics)
}

/// What a builder diagnostic points at.
#[derive(Clone, Copy)]
enum At<'s> {
    /// A statement's first token.
    Statement(&'s Statement),
    /// The name a statement is about: the one a definition gives, or a transform's target.
    Name(&'s Statement),
    /// A name used to refer to a definition.
    Ref(&'s NameRef),
    /// A place in the file and the width of its caret.
    Place(&'s Loc, u32),
}

struct Builder<'a> {
    path: &'a Path,
    opts: &'a LoadOptions,
    /// Whether the statements were read from text in this same load: the reader has then
    /// checked their values (radii, scale factors, cameras) and recorded where their names
    /// are written. Other statements (made by a program, or read earlier) have their values
    /// checked here and their problems placed at the start of the statement.
    from_reader: bool,
    omissions: &'a Omissions,
    diagnostics: Vec<Diagnostic>,
    /// Composites whose cycle or depth problem has been reported (once, not once per job).
    reported_composites: HashSet<String>,
    too_many_reported: bool,

    /// Name comparisons left for "did you mean" suggestions.
    suggestion_budget: usize,
}

impl<'a> Builder<'a> {
    // ----- diagnostics -------------------------------------------------------------------

    /// Where `at` lies and how wide its caret is. Statements read in this same load point at
    /// the tokens the reader recorded; the others at where they start (they have no text).
    fn place(&self, at: At) -> (Loc, u32) {
        match at {
            At::Ref(r) => (r.loc.clone(), r.name.chars().count() as u32),
            At::Place(loc, width) => (loc.clone(), width),
            At::Name(stmt) if self.from_reader => match stmt.spans.as_ref().and_then(|s| s.name) {
                Some(name) => (
                    Loc {
                        col: name.col,
                        ..stmt.loc.clone()
                    },
                    name.width,
                ),
                None => self.place(At::Statement(stmt)),
            },
            At::Name(stmt) | At::Statement(stmt) => (
                stmt.loc.clone(),
                stmt.spans.as_ref().map_or(1, |s| s.first_width),
            ),
        }
    }

    fn report(&mut self, severity: Severity, at: At, message: String, help: Option<String>) {
        let (loc, width) = self.place(at);
        let mut d = Diagnostic::new(severity, loc, message);
        // The source line is quoted by the loader, which has the text.
        d.width = width.max(1);
        if let Some(h) = help {
            d = d.with_help(h);
        }
        self.push(d);
    }

    /// Keeps `d`, and of a flood of diagnostics only those a report shows.
    fn push(&mut self, d: Diagnostic) {
        self.diagnostics.push(d);
        crate::sdf::keep_shown(&mut self.diagnostics, self.path);
    }

    fn warn(&mut self, at: At, message: String, help: Option<String>) {
        self.report(Severity::Warning, at, message, help);
    }

    fn error(&mut self, at: At, message: String, help: Option<String>) {
        self.report(Severity::Error, at, message, help);
    }

    /// An error or warning about a name reference (the location is the name itself).
    fn at_ref(&mut self, severity: Severity, r: &NameRef, message: String, help: Option<String>) {
        self.report(severity, At::Ref(r), message, help);
    }

    fn skipped(&self, name: &str) -> bool {
        self.omissions.skipped.contains(name)
    }

    /// The line of a commented-out definition of `name` (`# define shape box b ...`), for
    /// the common case of a definition disabled while its uses were left in.
    fn commented_definition(&self, name: &str) -> Option<u32> {
        self.omissions.commented.get(name).copied()
    }

    /// A pointer to a commented-out definition of `name`, else "did you mean" among
    /// `candidates`.
    fn name_help<'n>(
        &mut self,
        name: &str,
        candidates: impl IntoIterator<Item = &'n str>,
    ) -> Option<String> {
        // A commented-out definition explains the problem better than a similar name.
        if let Some(line) = self.commented_definition(name) {
            return Some(format!(
                "`{name}` is only defined in a comment, on line {line}"
            ));
        }
        // Only names of about the same length can be close enough to be suggested; the edit
        // distance is costly, so a file with very many unknown names among very many defined
        // ones stops getting suggestions once the budget is spent.
        let len = name.chars().count();
        let near: Vec<&str> = candidates
            .into_iter()
            .filter(|c| {
                // The edit distance is at least the difference in length, and `suggest`
                // accepts at most a third of the longer name (at least 1).
                let other = c.chars().count();
                other.abs_diff(len) <= (len.max(other) / 3).max(1)
            })
            .collect();
        if near.len() > self.suggestion_budget {
            return None;
        }
        self.suggestion_budget -= near.len();
        suggest(name, near).map(|s| format!("did you mean `{s}`?"))
    }
}
