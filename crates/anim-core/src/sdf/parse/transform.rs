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

/// Variant spellings read on a line: (where, key, description).
type Notes = Vec<(At, &'static str, String)>;

/// One operation of a transform line as its tokens lie: the keyword at token `at`, the run of
/// numbers `nums_from..nums_to` after it, and the axis letter of `rotate <degrees> x`.
struct OpTokens<'l> {
    at: usize,
    keyword: &'l str,
    nums: Vec<f64>,
    nums_from: usize,
    nums_to: usize,
    axis_letter: Option<DVec3>,
}

impl OpTokens<'_> {
    /// The numbers, or the keyword when there are none.
    fn span(&self) -> At {
        if self.nums.is_empty() {
            At::Tok(self.at)
        } else {
            At::Span(self.nums_from, self.nums_to - 1)
        }
    }
}

/// What became of one operation.
enum Outcome {
    Op(TransformOp),
    /// It has no effect: warned about and left out.
    Ignored,
    /// An error was reported: the statement is dropped, the rest of the line still checked.
    Failed,
    /// Not an operation at all: nothing after it can be trusted.
    Unknown,
}

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
        let Some(target_tok) = toks.get(target_at) else {
            self.error(
                line,
                At::End,
                "expected the name of a shape, composite, camera or light, found end of line",
                Some(canonical_form()),
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
                Some(canonical_form()),
            );
            return;
        }
        let target = self.name_ref(line, target_at);
        let mut ops = Vec::new();
        let mut notes = Notes::new();
        if let Some(v) = variant {
            // The description doubles as the key: each keyword variant is explained once.
            notes.push((At::Span(0, target_at - 1), v, v.to_string()));
        }
        let mut failed = false;
        let mut i = target_at + 1;
        while i < toks.len() {
            let nums_from = i + 1;
            let nums_to = Self::number_run_end(line, nums_from);
            let axis_letter = if toks[i].text == "rotate" {
                toks.get(nums_to).and_then(|t| axis_of_letter(t.text))
            } else {
                None
            };
            let next = nums_to + usize::from(axis_letter.is_some());
            let Ok(nums) = self.numbers(line, nums_from, nums_to) else {
                failed = true;
                i = next.max(i + 1);
                continue;
            };
            let op = OpTokens {
                at: i,
                keyword: toks[i].text,
                nums,
                nums_from,
                nums_to,
                axis_letter,
            };
            match self.operation(line, &op, &mut notes) {
                Outcome::Op(op) => ops.push(op),
                Outcome::Ignored => {}
                Outcome::Failed => failed = true,
                Outcome::Unknown => {
                    failed = true;
                    break;
                }
            }
            i = next;
        }
        if failed || ops.is_empty() {
            return;
        }
        let kind = StatementKind::Transform { target, ops };
        self.explain_variants(line, notes, &kind);
        self.emit_named(line, target_at, kind);
    }

    /// Warns once about the variant spellings of a line, each explained once per file.
    fn explain_variants(&mut self, line: &Line, mut notes: Notes, kind: &StatementKind) {
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
    }

    fn operation(&mut self, line: &Line, op: &OpTokens, notes: &mut Notes) -> Outcome {
        let nums = &op.nums;
        match op.keyword {
            "translate" if nums.len() == 3 => Outcome::Op(TransformOp::Translate(DVec3::new(
                nums[0], nums[1], nums[2],
            ))),
            // A homogeneous point `x y z 1`: the 1 is the w of 4×4 matrix code.
            "translate" if nums.len() == 4 && nums[3] == 1.0 => {
                notes.push((
                    At::Tok(op.nums_to - 1),
                    "translate-homogeneous",
                    "translate with a fourth number 1 (a homogeneous coordinate) read as x y z"
                        .to_string(),
                ));
                Outcome::Op(TransformOp::Translate(DVec3::new(
                    nums[0], nums[1], nums[2],
                )))
            }
            "translate" => self.wrong_count(
                line,
                op,
                format!("translate takes 3 numbers, found {}", nums.len()),
            ),
            "scale" => self.scale(line, op),
            "rotate" => self.rotate(line, op, notes),
            keyword => match keyword.to_ascii_lowercase().as_str() {
                "rotatex" => self.rotate_about(line, op, 0, notes),
                "rotatey" => self.rotate_about(line, op, 1, notes),
                "rotatez" => self.rotate_about(line, op, 2, notes),
                _ => {
                    let help = suggest(keyword, ["translate", "rotate", "scale"])
                        .map(|s| format!("did you mean `{s}`?"))
                        .or(Some(canonical_form()));
                    self.error(
                        line,
                        At::Tok(op.at),
                        format!("expected translate, rotate or scale, found '{keyword}'"),
                        help,
                    );
                    Outcome::Unknown
                }
            },
        }
    }

    /// An operation with the wrong number of arguments.
    fn wrong_count(&mut self, line: &Line, op: &OpTokens, message: String) -> Outcome {
        self.error(line, op.span(), message, Some(canonical_form()));
        Outcome::Failed
    }

    fn scale(&mut self, line: &Line, op: &OpTokens) -> Outcome {
        let nums = &op.nums;
        let s = match nums.len() {
            1 => DVec3::splat(nums[0]),
            3 => DVec3::new(nums[0], nums[1], nums[2]),
            n => {
                return self.wrong_count(line, op, format!("scale takes 1 or 3 numbers, found {n}"))
            }
        };
        if s.cmpeq(DVec3::ZERO).any() {
            self.error(
                line,
                op.span(),
                "scale by 0 flattens the object and cannot be undone (the matrix has no inverse)",
                Some("use a small factor such as 0.001 instead".to_string()),
            );
            return Outcome::Failed;
        }
        if s.abs().min_element() < MIN_SCALE {
            // Its inverse would be astronomically large: rays mapped into the object's space
            // would overflow.
            self.error(
                line,
                op.span(),
                format!("scale factor too close to 0 (below {MIN_SCALE:e})"),
                Some("use a factor such as 0.001 instead".to_string()),
            );
            return Outcome::Failed;
        }
        Outcome::Op(TransformOp::Scale(s))
    }

    /// `rotate <degrees> <axis>`, `rotate <degrees> x|y|z`, or three Euler angles.
    fn rotate(&mut self, line: &Line, op: &OpTokens, notes: &mut Notes) -> Outcome {
        let nums = &op.nums;
        match (nums.len(), op.axis_letter) {
            (1, Some(axis)) => Outcome::Op(TransformOp::Rotate {
                degrees: nums[0],
                axis,
            }),
            (4, None) => self.rotate_about_vector(line, op),
            (3, None) => self.euler_angles(line, op, notes),
            (n, Some(_)) => self.wrong_count(
                line,
                op,
                format!("rotate with an axis letter takes 1 number (degrees), found {n}"),
            ),
            (n, None) => self.wrong_count(
                line,
                op,
                format!(
                    "rotate takes <degrees> <axis x y z> (4 numbers) or <degrees> x|y|z, found {n} numbers"
                ),
            ),
        }
    }

    fn rotate_about_vector(&mut self, line: &Line, op: &OpTokens) -> Outcome {
        let nums = &op.nums;
        let axis = DVec3::new(nums[1], nums[2], nums[3]);
        if is_zero(axis) && nums[0] == 0.0 {
            // Turning by 0° is the identity whatever the axis: nothing to do.
            self.warn(
                line,
                op.span(),
                "rotation by 0° about a zero axis has no effect; ignored",
                None,
            );
            return Outcome::Ignored;
        }
        if is_zero(axis) {
            self.error(
                line,
                At::Span(op.nums_from + 1, op.nums_to - 1),
                "rotation about a zero axis",
                Some("the axis must be a non-zero vector, e.g. 0 1 0".to_string()),
            );
            return Outcome::Failed;
        }
        Outcome::Op(TransformOp::Rotate {
            degrees: nums[0],
            axis,
        })
    }

    /// Three angles about x, y and z: read only when their order cannot matter.
    fn euler_angles(&mut self, line: &Line, op: &OpTokens, notes: &mut Notes) -> Outcome {
        let nums = &op.nums;
        let nonzero: Vec<usize> = (0..3).filter(|&k| nums[k] != 0.0).collect();
        if nonzero.len() > 1 {
            self.error(
                line,
                op.span(),
                "`rotate` with 3 numbers reads as Euler angles, and with more than one \
                 non-zero angle their order is ambiguous",
                Some(
                    "write one `rotate <degrees> <axis>` per axis, in the order meant, \
                     e.g. `rotate 30 1 0 0 rotate 45 0 1 0`"
                        .to_string(),
                ),
            );
            return Outcome::Failed;
        }
        let k = nonzero.first().copied().unwrap_or(0);
        notes.push((
            op.span(),
            "euler",
            "`rotate` with 3 numbers read as Euler angles about x, y and z \
             (only one of them is non-zero, so their order does not matter)"
                .to_string(),
        ));
        Outcome::Op(TransformOp::Rotate {
            degrees: nums[k],
            axis: unit_axis(k),
        })
    }

    /// `rotatex <degrees>` and its kin: a rotation about coordinate axis `k`.
    fn rotate_about(&mut self, line: &Line, op: &OpTokens, k: usize, notes: &mut Notes) -> Outcome {
        if op.nums.len() != 1 {
            let message = format!(
                "{} takes 1 number (degrees), found {}",
                op.keyword,
                op.nums.len()
            );
            return self.wrong_count(line, op, message);
        }
        notes.push((
            At::Tok(op.at),
            "rotatexyz",
            format!("`{}` read as `rotate`", op.keyword),
        ));
        Outcome::Op(TransformOp::Rotate {
            degrees: op.nums[0],
            axis: unit_axis(k),
        })
    }
}

fn canonical_form() -> String {
    format!("canonical form: `{FORM_TRANSFORM}`")
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
