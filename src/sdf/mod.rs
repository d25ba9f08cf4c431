//! The SDF reader: text → statements with source locations → scene description.
//!
//! [`parse`] reads the text line by line into canonical [`ast::Statement`]s, normalising
//! every dialect variant of DIALECT.md; [`build`] resolves names, composes transforms,
//! flattens the composite tree and makes one [`RenderJob`] per `render` statement.
//! [`load_str`] does both. Every problem is a [`Diagnostic`] with file, line and column;
//! warnings let loading go on, errors stop it (`--strict` makes every warning an error).

pub mod ast;
mod build;
mod check;
mod lexer;
mod parser;
#[cfg(test)]
mod tests;

pub use check::check_paths;

use crate::diag::{Diagnostic, Severity};
use crate::scene::RenderJob;
use std::path::Path;

/// Meaning of the numbers after `m` in a material line (`--material-fields`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MaterialField {
    Reflectivity,
    Opacity,
    /// 1 − opacity.
    Transparency,
    Ior,
    /// Accepted and ignored.
    Roughness,
}

/// How a new transform statement composes with the ones before it (`--transform-order`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum TransformOrder {
    /// `M ← T_new · M`: each statement applies after the earlier ones, in the parent's frame.
    #[default]
    World,
    /// `M ← M · T_new`.
    Local,
}

#[derive(Clone, Debug, PartialEq)]
pub struct LoadOptions {
    pub strict: bool,
    pub material_fields: Vec<MaterialField>,
    pub transform_order: TransformOrder,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            strict: false,
            material_fields: vec![
                MaterialField::Reflectivity,
                MaterialField::Opacity,
                MaterialField::Ior,
            ],
            transform_order: TransformOrder::World,
        }
    }
}

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

/// Reads a file's text into canonical statements (every dialect variant normalised), with
/// the problems met. Statements with errors are left out; with `opts.strict`, warnings are
/// reported as errors.
pub fn parse(
    text: &str,
    path: &Path,
    opts: &LoadOptions,
) -> (Vec<ast::Statement>, Vec<Diagnostic>) {
    let parsed = parser::parse(text, path, opts);
    (parsed.statements, finish(parsed.diagnostics, opts))
}

/// Builds the render jobs of a statement list (from [`parse`], or made by a program, whose
/// values are then checked here). `Err` holds every diagnostic when at least one is an error.
pub fn build(
    statements: &[ast::Statement],
    path: &Path,
    opts: &LoadOptions,
) -> Result<Loaded, Vec<Diagnostic>> {
    let (jobs, diagnostics) = build::build(statements, path, opts, None);
    conclude(jobs, finish(diagnostics, opts))
}

/// Parses and builds a file's text. `Err` holds every diagnostic (warnings too) when at least
/// one is an error.
pub fn load_str(text: &str, path: &Path, opts: &LoadOptions) -> Result<Loaded, Vec<Diagnostic>> {
    let parsed = parser::parse(text, path, opts);
    let (jobs, built) = build::build(&parsed.statements, path, opts, Some(&parsed.source));
    let mut diagnostics = parsed.diagnostics;
    diagnostics.extend(built);
    conclude(jobs, finish(diagnostics, opts))
}

fn conclude(jobs: Vec<RenderJob>, diagnostics: Vec<Diagnostic>) -> Result<Loaded, Vec<Diagnostic>> {
    if diagnostics.iter().any(Diagnostic::is_error) {
        Err(diagnostics)
    } else {
        Ok(Loaded { jobs, diagnostics })
    }
}

/// Orders diagnostics by position (file-wide ones last) and applies `--strict`.
fn finish(mut diagnostics: Vec<Diagnostic>, opts: &LoadOptions) -> Vec<Diagnostic> {
    diagnostics.sort_by_key(|d| {
        d.loc
            .as_ref()
            .map_or((u32::MAX, u32::MAX), |l| (l.line, l.col))
    });
    if opts.strict {
        for d in &mut diagnostics {
            if d.severity == Severity::Warning {
                d.severity = Severity::Error;
                if d.help.is_none() {
                    d.help = Some("reported as an error because of --strict".to_string());
                }
            }
        }
    }
    diagnostics
}
