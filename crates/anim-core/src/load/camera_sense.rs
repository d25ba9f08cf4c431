//! `--transform-order auto` for cameras: the course framework's own extended example turns
//! its camera by `rotate -45 0 1 0` and shows its objects only if a camera's rotation turns
//! it the opposite way from a shape's (docs/scene-language.md §7). Over the public corpus,
//! that reading shows the objects of every file whose camera is turned that the other
//! readings show, and more. So where an image would be blank and some camera is turned, the
//! file is also read with every camera rotation reversed, and that reading is taken (with a
//! warning) when it shows more.

use super::another_reading;
use crate::diag::{Diagnostic, Severity};
use crate::scene::RenderJob;
use crate::sdf::ast::{Statement, StatementKind, TransformOp};
use crate::sdf::{self, LoadOptions};
use std::collections::HashSet;
use std::path::Path;

/// The names of the cameras the statements define.
fn cameras(statements: &[Statement]) -> HashSet<&str> {
    statements
        .iter()
        .filter_map(|s| match &s.kind {
            StatementKind::Camera(c) => Some(c.name.as_str()),
            _ => None,
        })
        .collect()
}

/// The first statement that turns a camera.
fn first_turn(statements: &[Statement]) -> Option<&Statement> {
    let cameras = cameras(statements);
    statements.iter().find(|s| match &s.kind {
        StatementKind::Transform { target, ops } => {
            cameras.contains(target.name.as_str())
                && ops
                    .iter()
                    .any(|op| matches!(op, TransformOp::Rotate { .. }))
        }
        _ => false,
    })
}

/// Whether some camera is turned by a transform statement.
pub(super) fn turns_a_camera(statements: &[Statement]) -> bool {
    first_turn(statements).is_some()
}

/// The statements with every rotation of a camera reversed.
fn turned_back(statements: &[Statement]) -> Vec<Statement> {
    let cameras = cameras(statements);
    statements
        .iter()
        .map(|s| {
            let mut s = s.clone();
            if let StatementKind::Transform { target, ops } = &mut s.kind {
                if cameras.contains(target.name.as_str()) {
                    for op in ops {
                        if let TransformOp::Rotate { degrees, .. } = op {
                            *degrees = -*degrees;
                        }
                    }
                }
            }
            s
        })
        .collect()
}

/// The jobs and diagnostics of the file read with its cameras' rotations reversed, with a
/// warning that says so, when that leaves fewer images blank and none blank that was not.
pub(super) fn read_with_cameras_turned_back(
    statements: &[Statement],
    omissions: &sdf::Omissions,
    jobs: &[RenderJob],
    path: &Path,
    opts: &LoadOptions,
) -> Option<(Vec<RenderJob>, Vec<Diagnostic>)> {
    let turn = first_turn(statements)?;
    let reversed = turned_back(statements);
    let (other_jobs, mut built, job, reason) =
        another_reading(&reversed, omissions, jobs, path, opts)?;
    let StatementKind::Transform { target, .. } = &turn.kind else {
        return None;
    };
    built.push(
        Diagnostic::new(
            Severity::Warning,
            turn.loc.clone(),
            format!(
                "camera `{}` turned the opposite way from a shape by the same rotation, as the course framework turns cameras: turned like a shape, the image `{}` shows nothing: {reason}",
                target.name,
                job.output.display()
            ),
        )
        .with_help(
            "pass `--transform-order world` to turn cameras like shapes".to_string(),
        ),
    );
    Some((other_jobs, built))
}
