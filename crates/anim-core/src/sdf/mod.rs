//! The SDF reader: text → canonical statements with source locations.
//!
//! [`parse`] reads the text line by line into canonical [`ast::Statement`]s, normalising
//! every dialect variant of the scene language; `crate::scene` builds them into render jobs.
//! Every problem is a [`Diagnostic`] with file, line and column; warnings let loading go on,
//! errors stop it (`--strict` makes every warning an error).

pub mod ast;
mod lexer;
mod parse;
pub mod repair;

pub use lexer::{image_names, raw_lines, scene_key, ImageName, MAX_MAGNITUDE};
pub use parse::{
    default_output, mesh_files, references, FileRead, IncludeCache, Omissions, Parsed, Reference,
};

use crate::diag::{Diagnostic, LeftOut, Severity};
use crate::limits::MAX_DIAGNOSTICS;
use crate::shape::MeshCache;
use std::path::Path;

/// Meaning of the numbers after `m` in a material line (`--material-fields`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MaterialField {
    /// ρ, the share of light reflected as by a mirror.
    Reflectivity,
    /// α, the share of light the surface stops; 1 is opaque.
    Opacity,
    /// 1 − opacity.
    Transparency,
    /// η, the index of refraction.
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

/// What `anim generate` writes after the frame header's first words: a frame file states
/// exactly what it means, so nothing about it is inferred.
pub const GENERATED_FRAME_SIGNATURE: &str = "by anim";

/// Whether `text` is a frame written by `anim generate`: its first line is the generator's
/// header comment, `# Frame ... generated from SPEC by anim VERSION.` Such a frame, and every
/// file it includes, is read with every guess turned off
/// ([`LoadOptions::without_inference`]): anim wrote it in the canonical language, so a
/// reading that makes it "more plausible" could only misread it (an invisible material read
/// in another layout, a camera turned round). The header turns guesses off and nothing else:
/// a file that forges it is read as written, which is what its text says anyway.
pub fn is_generated_frame(text: &str) -> bool {
    let first = text.lines().next().unwrap_or("");
    first.starts_with("# Frame ")
        && first.contains("generated from")
        && first.contains(GENERATED_FRAME_SIGNATURE)
}

/// How the numbers after `m` in material lines are read (`--material-fields`).
#[derive(Clone, Debug, PartialEq)]
pub enum MaterialLayout {
    /// The layout that makes every material of the file most plausible, the standard one when
    /// it ties (docs/scene-language.md §3.1).
    Auto,
    /// These fields, in this order.
    Fields(Vec<MaterialField>),
}

impl MaterialLayout {
    /// `reflectivity,opacity,ior`: the most common layout, and the one inference prefers on a
    /// tie.
    pub fn standard() -> MaterialLayout {
        MaterialLayout::Fields(vec![
            MaterialField::Reflectivity,
            MaterialField::Opacity,
            MaterialField::Ior,
        ])
    }

    /// The fields asked for, or `None` for inference.
    pub fn explicit(&self) -> Option<&[MaterialField]> {
        match self {
            MaterialLayout::Auto => None,
            MaterialLayout::Fields(fields) => Some(fields),
        }
    }
}

/// How files are read: the reading options of the command line.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadOptions {
    /// Whether every warning is reported as an error (`--strict`).
    pub strict: bool,
    /// How the numbers after `m` in material lines are read (`--material-fields`).
    pub material_fields: MaterialLayout,
    /// How a transform statement composes with the ones before it (`--transform-order`).
    pub transform_order: TransformOrder,
    /// Whether a file whose images would be blank in `transform_order` but not in the other
    /// order is read in the other one (`--transform-order auto`, docs/scene-language.md §7).
    /// Never for generated frames (see [`is_generated_frame`]) or under `strict`.
    pub infer_transform_order: bool,
    /// Largest input file read, in bytes (`--max-input`); larger files are refused unread.
    pub max_input: u64,
    /// Whether meshes and included files may be read from anywhere (`--allow-any-input`), not
    /// only from inside the scene's folder and the current directory (`input::may_read`).
    pub allow_any_input: bool,
    /// Memory the scene may take, in bytes (`--max-memory`): a scene whose shapes would need
    /// more (`limits::scene_memory`) is refused before it is built.
    pub max_memory: u64,
    /// Meshes already read, shared by every clone of these options: the frames of one
    /// `anim render DIR` read each OBJ file once (`MeshCache`).
    pub meshes: MeshCache,
    /// Included files already read, shared like `meshes`: the frames of one
    /// `anim render DIR` read and parse the part of the scene they share once.
    pub includes: IncludeCache,
}

impl LoadOptions {
    /// These options with every guess turned off: the standard material layout where the
    /// layout would be inferred, and the transform order as given (never the other one, nor
    /// cameras turned round). Explicit choices (`--material-fields LIST`,
    /// `--transform-order local`) stay: they are not guesses.
    pub fn without_inference(&self) -> LoadOptions {
        let material_fields = match &self.material_fields {
            MaterialLayout::Auto => MaterialLayout::standard(),
            fields => fields.clone(),
        };
        LoadOptions {
            material_fields,
            infer_transform_order: false,
            ..self.clone()
        }
    }
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            strict: false,
            // Programs (the animation generator, tests) state what they mean; inference is
            // the command line's default, for files written by hand.
            material_fields: MaterialLayout::standard(),
            transform_order: TransformOrder::World,
            infer_transform_order: false,
            max_input: crate::limits::DEFAULT_MAX_INPUT,
            allow_any_input: false,
            max_memory: crate::limits::default_memory_budget(),
            meshes: MeshCache::default(),
            includes: IncludeCache::default(),
        }
    }
}

/// Reads a file's text into canonical statements (every dialect variant normalised), with
/// the problems met. Statements with errors are left out; with `opts.strict`, warnings are
/// reported as errors.
pub fn parse(
    text: &str,
    path: &Path,
    opts: &LoadOptions,
) -> (Vec<ast::Statement>, Vec<Diagnostic>) {
    let parsed = read(text, path, opts, false);
    (
        parsed.statements,
        finish_diagnostics(parsed.diagnostics, opts),
    )
}

/// A file's text as the reader leaves it: canonical statements (with the spans later problems
/// point at), the problems met, and what it left out. The primitive shapes of a file in which
/// nothing refers to a shape by name are kept apart, compactly, in `Parsed::shapes`.
pub fn parse_source(text: &str, path: &Path, opts: &LoadOptions) -> Parsed {
    read(text, path, opts, true)
}

/// [`parse_source`] with every statement kept as a statement, shapes included.
pub fn parse_source_whole(text: &str, path: &Path, opts: &LoadOptions) -> Parsed {
    read(text, path, opts, false)
}

fn read(text: &str, path: &Path, opts: &LoadOptions, flat: bool) -> Parsed {
    let chain = parse::Chain::outermost(path, text, opts);
    if chain.generated {
        // Its includes are read with these options too (see `is_generated_frame`).
        parse::parse(text, path, &opts.without_inference(), flat, chain)
    } else {
        parse::parse(text, path, opts, flat, chain)
    }
}

/// Orders diagnostics by position (file-wide ones last) and applies `--strict`.
pub fn finish_diagnostics(mut diagnostics: Vec<Diagnostic>, opts: &LoadOptions) -> Vec<Diagnostic> {
    sort_by_place(&mut diagnostics);
    if opts.strict {
        for d in &mut diagnostics {
            if let Some(left) = &mut d.left_out {
                left.errors += std::mem::take(&mut left.warnings);
            }
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

/// Orders diagnostics by position, file-wide ones last; those at one place keep their order.
fn sort_by_place(diagnostics: &mut [Diagnostic]) {
    diagnostics.sort_by_key(|d| {
        d.loc
            .as_ref()
            .map_or((u32::MAX, u32::MAX), |l| (l.line, l.col))
    });
}

/// How many diagnostics a list may hold before [`keep_shown`] drops those no one will see.
const KEEP_AT: usize = 4 * MAX_DIAGNOSTICS;

/// Keeps a list of diagnostics of the file `path` as it grows no longer than what a file's
/// report shows needs: once it holds `KEEP_AT`, only the first [`MAX_DIAGNOSTICS`] by place
/// (as [`finish_diagnostics`] orders them) are kept, and one more says how many were left out
/// ([`not_shown`]). Those shown are the same as if every one had been kept: any dropped has
/// that many before it. A file with a million bad lines, or a million shapes of one name, so
/// holds a few hundred diagnostics, not a million.
pub fn keep_shown(diagnostics: &mut Vec<Diagnostic>, path: &Path) {
    if diagnostics.len() < KEEP_AT {
        return;
    }
    let mut left = LeftOut::default();
    diagnostics.retain(|d| {
        if d.left_out.is_some() {
            left.add(d);
        }
        d.left_out.is_none()
    });
    sort_by_place(diagnostics);
    for d in diagnostics.drain(MAX_DIAGNOSTICS.min(diagnostics.len())..) {
        left.add(&d);
    }
    if !left.is_empty() {
        diagnostics.push(not_shown(path, left.errors, left.warnings));
    }
}

/// The last diagnostic of a file with more problems than are listed: how many `errors` and
/// `warnings` were left out after the first [`MAX_DIAGNOSTICS`].
/// An error if any of those is one, so that the count is never mistaken for harmless.
pub fn not_shown(path: &Path, errors: usize, warnings: usize) -> Diagnostic {
    let plural = |n: usize, what: &str| format!("{n} {what}{}", if n == 1 { "" } else { "s" });
    let kinds: Vec<String> = [(errors, "error"), (warnings, "warning")]
        .into_iter()
        .filter(|(n, _)| *n > 0)
        .map(|(n, what)| plural(n, what))
        .collect();
    let severity = if errors > 0 {
        Severity::Error
    } else {
        Severity::Warning
    };
    let mut d = Diagnostic::file_error(
        path,
        format!(
            "and {} more ({}) not shown: only the first {} problems of a file are listed",
            errors + warnings,
            kinds.join(", "),
            MAX_DIAGNOSTICS
        ),
    )
    .with_severity(severity);
    d.left_out = Some(LeftOut { errors, warnings });
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load::load_str;

    /// A material made invisible by a fade: reflectivity 0, opacity 0, index of refraction 1
    /// in the standard layout, which inference would read another way.
    const FADED: &str = "define material ghost 1 0 0 1 0 0 0 0 0 10 0 0 1
define shape sphere ball 0 0 -5 1 ghost
define light sun 0 5 5 1 1 1 1
define camera eye 60
render eye image.ppm 8 8
";

    fn opacity(text: &str, path: &Path, opts: &LoadOptions) -> f32 {
        let loaded = load_str(text, path, opts).expect("loads");
        let scene = &loaded.jobs[0].scene;
        let ghost = scene.materials.iter().find(|m| m.name == "ghost");
        ghost.expect("ghost").opacity
    }

    fn header() -> String {
        format!(
            "# Frame 0 of 24 (t = 0 s at 24 fps), generated from fade.ron {GENERATED_FRAME_SIGNATURE} 0.1.0.\n"
        )
    }

    #[test]
    fn a_generated_frame_is_read_with_the_standard_layout_whatever_inference_would_say() {
        let auto = LoadOptions {
            material_fields: MaterialLayout::Auto,
            infer_transform_order: true,
            ..LoadOptions::default()
        };
        let path = Path::new("fade.sdf");
        // By hand, the same text is read in the layout that makes it plausible: visible.
        assert_ne!(opacity(FADED, path, &auto), 0.0);
        let frame = format!("{}{FADED}", header());
        assert!(is_generated_frame(&frame));
        assert_eq!(opacity(&frame, path, &auto), 0.0);
        let loaded = load_str(&frame, path, &auto).expect("loads");
        assert!(loaded.diagnostics.is_empty(), "{:?}", loaded.diagnostics);
    }

    #[test]
    fn what_a_generated_frame_includes_is_read_with_the_standard_layout_too() {
        let dir = tempfile::tempdir().expect("tempdir");
        let (materials, rest) = FADED.split_once('\n').expect("two parts");
        std::fs::write(dir.path().join("static.sdfi"), format!("{materials}\n")).expect("write");
        let frame = format!("{}include static.sdfi\n{rest}", header());
        let by_hand = format!("include static.sdfi\n{rest}");
        let auto = LoadOptions {
            material_fields: MaterialLayout::Auto,
            ..LoadOptions::default()
        };
        let path = dir.path().join("frame_0000.sdf");
        // One cache for both readings, as one `anim render DIR` run shares it: each reading
        // keeps its own layout, in either order.
        for _ in 0..2 {
            assert_eq!(opacity(&frame, &path, &auto), 0.0);
            assert_ne!(opacity(&by_hand, &path, &auto), 0.0);
        }
        // An explicit layout is no guess: it stays (its second field, a transparency of 0, is
        // an opacity of 1).
        let explicit = LoadOptions {
            material_fields: MaterialLayout::Fields(vec![
                MaterialField::Reflectivity,
                MaterialField::Transparency,
                MaterialField::Ior,
            ]),
            ..LoadOptions::default()
        };
        assert_eq!(opacity(&frame, &path, &explicit), 1.0);
    }
}
