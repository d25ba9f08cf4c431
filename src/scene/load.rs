//! Loading a scene file: the reader's statements built into render jobs.

use super::build::build_jobs;
use super::RenderJob;
use crate::diag::Diagnostic;
use crate::sdf::ast::Statement;
use crate::sdf::{self, finish_diagnostics, LoadOptions};
use std::path::Path;

/// A successfully loaded file: its images to render and the warnings met on the way.
#[derive(Clone, Debug)]
pub struct Loaded {
    pub jobs: Vec<RenderJob>,
    pub diagnostics: Vec<Diagnostic>,
}

/// Reads and loads a file. `Err` holds every diagnostic (at least one error).
pub fn load_file(path: &Path, opts: &LoadOptions) -> Result<Loaded, Vec<Diagnostic>> {
    let text = std::fs::read(path).map_err(|e| {
        vec![Diagnostic::file_error(
            path,
            format!("cannot read file: {e}"),
        )]
    })?;
    load_str(&String::from_utf8_lossy(&text), path, opts)
}

/// Builds the render jobs of a statement list (from [`sdf::parse`], or made by a program, whose
/// values are then checked here). `Err` holds every diagnostic when at least one is an error.
pub fn build(
    statements: &[Statement],
    path: &Path,
    opts: &LoadOptions,
) -> Result<Loaded, Vec<Diagnostic>> {
    let (jobs, diagnostics) = build_jobs(statements, path, opts, None);
    conclude(jobs, finish_diagnostics(diagnostics, opts))
}

/// Parses and builds a file's text. `Err` holds every diagnostic (warnings too) when at least
/// one is an error.
pub fn load_str(text: &str, path: &Path, opts: &LoadOptions) -> Result<Loaded, Vec<Diagnostic>> {
    let parsed = sdf::parse_source(text, path, opts);
    let (jobs, mut built) = build_jobs(&parsed.statements, path, opts, Some(&parsed.omissions));
    parsed.quote_source(&mut built);
    let mut diagnostics = parsed.diagnostics;
    diagnostics.extend(built);
    conclude(jobs, finish_diagnostics(diagnostics, opts))
}

fn conclude(jobs: Vec<RenderJob>, diagnostics: Vec<Diagnostic>) -> Result<Loaded, Vec<Diagnostic>> {
    if diagnostics.iter().any(Diagnostic::is_error) {
        Err(diagnostics)
    } else {
        Ok(Loaded { jobs, diagnostics })
    }
}
