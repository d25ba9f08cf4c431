//! The SDF reader: text → statements with source locations → scene description.
//! PLACEHOLDER API: the SDF helper implements `parse` and `build` (see DIALECT.md).

pub mod ast;

use crate::diag::Diagnostic;
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

pub fn load_str(_text: &str, path: &Path, _opts: &LoadOptions) -> Result<Loaded, Vec<Diagnostic>> {
    Err(vec![Diagnostic::file_error(
        path,
        "SDF reader not implemented yet",
    )])
}
