//! `transform` lines: one or more translate, rotate and scale operations on one target.

use super::{At, Parser};
use crate::diag::suggest;
use crate::sdf::ast::{StatementKind, TransformOp};
use crate::sdf::lexer::Line;
use crate::shape::geometry::is_zero;
use glam::DVec3;

/// Smallest scale factor accepted (besides the error for 0 itself).
const MIN_SCALE: f64 = 1e-9;
const FORM_TRANSFORM: &str =
    "transform <target> translate [v] | rotate <degrees> [axis] | scale <s> | scale [sx sy sz]";

impl Parser<'_> {
    /// `transform <target> <op> <args> [<op> <args> ...]` with the target at `target_at`;
    /// `variant` names the accepted variant spelling of the statement, if any.
    pub(super) fn transform(
        &mut self,
        line: &Line,
        target_at: usize,
        variant: Option<&'static str>,
    ) {
        let toks = &line.tokens;
        let form = Some(format!("canonical form: `{FORM_TRANSFORM}`"));
        let Some(target_tok) = toks.get(target_at) else {
            self.error(
                line,
                At::End,
                "expected the name of a shape, composite, camera or light, found end of line",
                form,
            );
            return;
        };
        if toks.len() == target_at + 1 {
            self.error(
                line,
                At::End,
                format!(
                    "expected translate, rotate or scale after `{}`, found end of line",
                    target_tok.text
                ),
                form,
            );
            return;
        }
        let target = self.name_ref(line, target_at);
        let mut ops = Vec::new();
        // Variant spellings read on this line: (where, kind, description).
        let mut notes: Vec<(At, &'static str, String)> = Vec::new();
        if let Some(v) = variant {
            // The description doubles as the key: each keyword variant is explained once.
            notes.push((At::Span(0, target_at - 1), v, v.to_string()));
        }
        let mut failed = false;
        let mut i = target_at + 1;
        while i < toks.len() {
            let op_at = i;
            let op = toks[i].text;
            let nums_from = i + 1;
            let nums_to = Self::number_run_end(line, nums_from);
            let mut next = nums_to;
            let lower = op.to_ascii_lowercase();
            let axis_letter = if op == "rotate" {
                toks.get(nums_to).and_then(|t| axis_of_letter(t.text))
            } else {
                None
            };
            if axis_letter.is_some() {
                next += 1;
            }
            let Ok(nums) = self.numbers(line, nums_from, nums_to) else {
                failed = true;
                i = next.max(i + 1);
                continue;
            };
            let span = if nums.is_empty() {
                At::Tok(op_at)
            } else {
                At::Span(nums_from, nums_to - 1)
            };
            let result = match (op, lower.as_str()) {
                ("translate", _) => {
                    if nums.len() == 3 {
                        Ok(TransformOp::Translate(DVec3::new(nums[0], nums[1], nums[2])))
                    } else {
                        Err(format!("translate takes 3 numbers, found {}", nums.len()))
                    }
                }
                ("scale", _) => {
                    let s = match nums.len() {
                        1 => Ok(DVec3::splat(nums[0])),
                        3 => Ok(DVec3::new(nums[0], nums[1], nums[2])),
                        n => Err(format!("scale takes 1 or 3 numbers, found {n}")),
                    };
                    match s {
                                                Ok(s) if s.cmpeq(DVec3::ZERO).any() => {
                            self.error(
                                line,
                                span,
                                "scale by 0 flattens the object and cannot be undone (the matrix has no inverse)",
                                Some("use a small factor such as 0.001 instead".to_string()),
                            );
                            failed = true;
                            i = next;
                            continue;
                        }
                        Ok(s) if s.abs().min_element() < MIN_SCALE => {
                            // Its inverse would be astronomically large: rays mapped into the
                            // object's space would overflow.
                            self.error(
                                line,
                                span,
                                format!("scale factor too close to 0 (below {MIN_SCALE:e})"),
                                Some("use a factor such as 0.001 instead".to_string()),
                            );
                            failed = true;
                            i = next;
                            continue;
                        }
                        Ok(s) => Ok(TransformOp::Scale(s)),
                        Err(e) => Err(e),
                    }
                }
                ("rotate", _) => match (nums.len(), axis_letter) {
                    (1, Some(axis)) => Ok(TransformOp::Rotate {
                        degrees: nums[0],
                        axis,
                    }),
                    (4, None) => {
                        let axis = DVec3::new(nums[1], nums[2], nums[3]);
                                                if is_zero(axis) && nums[0] == 0.0 {
                            // Turning by 0° is the identity whatever the axis: nothing to do.
                            self.warn(
                                line,
                                span,
                                "rotation by 0° about a zero axis has no effect; ignored",
                                None,
                            );
                            i = next;
                            continue;
                        }
                        if is_zero(axis) {
                            self.error(
                                line,
                                At::Span(nums_from + 1, nums_to - 1),
                                "rotation about a zero axis",
                                Some("the axis must be a non-zero vector, e.g. 0 1 0".to_string()),
                            );
                            failed = true;
                            i = next;
                            continue;
                        }
                        Ok(TransformOp::Rotate {
                            degrees: nums[0],
                            axis,
                        })
                    }
                    (3, None) => {
                        let nonzero: Vec<usize> = (0..3).filter(|&k| nums[k] != 0.0).collect();
                        if nonzero.len() <= 1 {
                            let k = nonzero.first().copied().unwrap_or(0);
                            let op = TransformOp::Rotate {
                                degrees: nums[k],
                                axis: unit_axis(k),
                            };
                                                        notes.push((
                                span,
                                "euler",
                                "`rotate` with 3 numbers read as Euler angles about x, y and z \
                                 (only one of them is non-zero, so their order does not matter)"
                                    .to_string(),
                            ));
                            Ok(op)
                        } else {
                            self.error(
                                line,
                                span,
                                "`rotate` with 3 numbers reads as Euler angles, and with more than one \
                                 non-zero angle their order is ambiguous",
                                Some(
                                    "write one `rotate <degrees> <axis>` per axis, in the order meant, \
                                     e.g. `rotate 30 1 0 0 rotate 45 0 1 0`"
                                        .to_string(),
                                ),
                            );
                            failed = true;
                            i = next;
                            continue;
                        }
                    }
                    (n, Some(_)) => Err(format!("rotate with an axis letter takes 1 number (degrees), found {n}")),
                    (n, None) => Err(format!(
                        "rotate takes <degrees> <axis x y z> (4 numbers) or <degrees> x|y|z, found {n} numbers"
                    )),
                },
                (_, "rotatex" | "rotatey" | "rotatez") => {
                    if nums.len() == 1 {
                        let k = match lower.as_str() {
                            "rotatex" => 0,
                            "rotatey" => 1,
                            _ => 2,
                        };
                        notes.push((At::Tok(op_at), "rotatexyz", format!("`{op}` read as `rotate`")));
                        Ok(TransformOp::Rotate {
                            degrees: nums[0],
                            axis: unit_axis(k),
                        })
                    } else {
                        Err(format!("{op} takes 1 number (degrees), found {}", nums.len()))
                    }
                }
                _ => {
                    let help = suggest(op, ["translate", "rotate", "scale"])
                        .map(|s| format!("did you mean `{s}`?"))
                        .or(form.clone());
                    self.error(
                        line,
                        At::Tok(op_at),
                        format!("expected translate, rotate or scale, found '{op}'"),
                        help,
                    );
                    failed = true;
                    // Nothing after an unknown operation can be trusted.
                    break;
                }
            };
            match result {
                Ok(op) => ops.push(op),
                Err(message) => {
                    let at = if nums.is_empty() {
                        At::Tok(op_at)
                    } else {
                        span
                    };
                    self.error(line, at, message, form.clone());
                    failed = true;
                }
            }
            i = next;
        }
        if failed || ops.is_empty() {
            return;
        }
        let kind = StatementKind::Transform { target, ops };
        // Each variant is explained once per file.
        notes.retain(|(_, key, _)| self.variants_noted.insert(key));
        if let Some((at, _, _)) = notes.first() {
            let what: Vec<&str> = notes.iter().map(|(_, _, n)| n.as_str()).collect();
            self.warn(
                line,
                *at,
                what.join("; "),
                Some(format!(
                    "read as `{kind}` (later lines written this way are read the same, without a warning)"
                )),
            );
        }
        self.emit(line, kind);
    }
}

fn axis_of_letter(s: &str) -> Option<DVec3> {
    match s {
        "x" | "X" => Some(DVec3::X),
        "y" | "Y" => Some(DVec3::Y),
        "z" | "Z" => Some(DVec3::Z),
        _ => None,
    }
}

fn unit_axis(k: usize) -> DVec3 {
    match k {
        0 => DVec3::X,
        1 => DVec3::Y,
        _ => DVec3::Z,
    }
}
