//! Building: canonical statements → render jobs, each with its scene description.
//!
//! Definitions are global to a file (statement order is free in most real files); transforms
//! apply in the order written, composed by the rule of `TransformOrder`; each `render` line
//! sees the transforms DIALECT.md gives it (all of them when the file has one render line,
//! those written before it when it has several). The composite tree is flattened into
//! instances, so a shape listed in two composites is drawn twice.

mod definitions;
mod jobs;
mod references;
mod transforms;

use crate::diag::{suggest, Diagnostic, Loc, Severity};
use crate::scene::RenderJob;
use crate::sdf::ast::{NameRef, Statement};
use crate::sdf::lexer;
use crate::sdf::{LoadOptions, SourceContext};
use std::collections::HashSet;
use std::path::Path;

/// More instances than this means a composite tree that multiplies out of all proportion
/// (each level listing the one below twice, ...): refused before it exhausts memory.
const MAX_INSTANCES: usize = 250_000;
/// The same over all the jobs of a file (each job holds its own scene).
const MAX_TOTAL_INSTANCES: usize = 2_000_000;
/// Name comparisons allowed for "did you mean" suggestions in one file (about a second's
/// work at worst).
const SUGGESTION_BUDGET: usize = 1_000_000;

/// Builds the render jobs of a statement list. `source` is present when the statements come
/// from `sdf::parse_source`, which has already checked (and reported) the values of every
/// statement; without it (statements made by a program) those checks are made here.
pub(super) fn build_jobs(
    statements: &[Statement],
    path: &Path,
    opts: &LoadOptions,
    source: Option<&SourceContext>,
) -> (Vec<RenderJob>, Vec<Diagnostic>) {
    let empty = SourceContext::default();
    let mut b = Builder {
        path,
        opts,
        check_values: source.is_none(),
        source: source.unwrap_or(&empty),
        diagnostics: Vec::new(),
        reported_composites: HashSet::new(),
        too_many_reported: false,

        suggestion_budget: SUGGESTION_BUDGET,
        total_instances: 0,
    };
    let defs = b.definitions(statements);
    b.check_cycles(&defs);
    let jobs = b.jobs(statements, &defs);
    (jobs, b.diagnostics)
}

struct Builder<'a> {
    path: &'a Path,
    opts: &'a LoadOptions,
    /// Whether to check values (radii, scale factors, cameras): only for statements that did
    /// not come through the parser, which checks them with exact columns.
    check_values: bool,
    source: &'a SourceContext,
    diagnostics: Vec<Diagnostic>,
    /// Composites whose cycle or depth problem has been reported (once, not once per job).
    reported_composites: HashSet<String>,
    too_many_reported: bool,

    /// Name comparisons left for "did you mean" suggestions.
    suggestion_budget: usize,
    /// Instances made so far, over all jobs.
    total_instances: usize,
}

impl<'a> Builder<'a> {
    // ----- diagnostics -------------------------------------------------------------------

    /// A diagnostic at `loc`, moved onto the token `name` when the line is known and `loc`
    /// is the start of a statement rather than the name itself.
    fn report(
        &mut self,
        severity: Severity,
        loc: &Loc,
        name: Option<&str>,
        message: String,
        help: Option<String>,
    ) {
        let mut loc = loc.clone();
        let mut d = match self.source.line(loc.line) {
            Some(text) => {
                let tokens = lexer::tokenize(text);
                let width = match name {
                    Some(name) => {
                        match tokens
                            .iter()
                            .skip(1)
                            .find(|t| t.text == name && t.col >= loc.col)
                        {
                            Some(t) => {
                                loc.col = t.col;
                                t.width
                            }
                            None => name.chars().count() as u32,
                        }
                    }
                    None => tokens
                        .iter()
                        .find(|t| t.col == loc.col)
                        .map_or(1, |t| t.width),
                };
                Diagnostic::new(severity, loc, message).with_source(text, width)
            }
            None => Diagnostic::new(severity, loc, message),
        };
        if let Some(h) = help {
            d = d.with_help(h);
        }
        self.diagnostics.push(d);
    }

    fn warn(&mut self, loc: &Loc, name: Option<&str>, message: String, help: Option<String>) {
        self.report(Severity::Warning, loc, name, message, help);
    }

    fn error(&mut self, loc: &Loc, name: Option<&str>, message: String, help: Option<String>) {
        self.report(Severity::Error, loc, name, message, help);
    }

    /// An error or warning about a name reference (the location is the name itself).
    fn at_ref(&mut self, severity: Severity, r: &NameRef, message: String, help: Option<String>) {
        self.report(severity, &r.loc, Some(&r.name), message, help);
    }

    fn skipped(&self, name: &str) -> bool {
        self.source.skipped.contains(name)
    }

    /// The line of a commented-out definition of `name` (`# define shape box b ...`), for
    /// the common case of a definition disabled while its uses were left in.
    fn commented_definition(&self, name: &str) -> Option<u32> {
        self.source.commented.get(name).copied()
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
