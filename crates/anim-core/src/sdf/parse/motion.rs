//! `motion` lines: where a shape, composite, light or camera is at an instant of the exposure
//! (docs/scene-language.md §10). `anim generate` writes them for specs with a `shutter`; they
//! take the canonical operations only, as a program writes them.
//!
//! Motion, one home per layer: `crate::math::motion` (keys and their interpolation),
//! `crate::sdf::parse::motion` (the `motion` lines), `crate::scene::motion` (what moves in a
//! scene) with `crate::scene::builder::motion` (made from the lines),
//! `crate::render::geometry::motion` (moving shapes as primitives), `crate::render::motion`
//! (the exposure, as the samplers see it), and the animation pipeline's `keyframe::motion`
//! (the lines a spec with a `shutter` writes).

use super::{At, Parser};
use crate::diag::{suggest, Diagnostic, Loc, Severity};
use crate::sdf::ast::{MotionDef, Statement, StatementKind, TransformOp};
use crate::sdf::lexer::{self, Line};
use glam::DVec3;
use std::collections::{HashMap, HashSet};

const FORM: &str = "motion <target> <u from 0 to 1> [translate [v] | rotate <degrees> [axis] | scale <s> | scale [sx sy sz]] ...";
const OPERATIONS: [&str; 3] = ["translate", "rotate", "scale"];

impl Parser<'_> {
    /// `motion <target> <u> <op> <args> ...`.
    pub(super) fn motion(&mut self, line: &Line) {
        let help = || Some(FORM.to_string());
        let toks = &line.tokens;
        if toks.len() < 2 {
            self.error(
                line,
                At::End,
                "expected the name of a shape, composite, camera or light, found end of line",
                help(),
            );
            return;
        }
        let Some(u_tok) = toks.get(2) else {
            self.error(
                line,
                At::End,
                "expected the fraction of the exposure (0 to 1), found end of line",
                help(),
            );
            return;
        };
        let Ok(u) = self.numbers(line, 2, 3).map(|n| n[0]) else {
            return;
        };
        if !(0.0..=1.0).contains(&u) {
            let text = u_tok.text.to_string();
            self.error(
                line,
                At::Tok(2),
                format!("the fraction of the exposure must be from 0 to 1, not {text}"),
                help(),
            );
            return;
        }
        let mut ops = Vec::new();
        let mut failed = false;
        let mut i = 3;
        while i < toks.len() {
            let from = i + 1;
            let to = Self::number_run_end(line, from);
            let keyword = toks[i].text;
            if !OPERATIONS.contains(&keyword) {
                let hint = suggest(keyword, OPERATIONS).map(|s| format!("did you mean `{s}`?"));
                self.error(
                    line,
                    At::Tok(i),
                    format!("expected translate, rotate or scale, found '{keyword}'"),
                    hint.or_else(help),
                );
                return;
            }
            let Ok(nums) = self.numbers(line, from, to) else {
                failed = true;
                i = to.max(i + 1);
                continue;
            };
            let at = if nums.is_empty() {
                At::Tok(i)
            } else {
                At::Span(from, to - 1)
            };
            match self.motion_op(line, keyword, &nums, at) {
                Some(op) => ops.push(op),
                None => failed = true,
            }
            i = to;
        }
        if failed {
            return;
        }
        let target = self.name_ref(line, 1);
        self.emit_named(
            line,
            1,
            StatementKind::Motion(MotionDef { target, at: u, ops }),
        );
    }

    /// The operation `keyword` of a motion line with its numbers `nums` (at `at`), or `None`
    /// once its problem is reported.
    fn motion_op(
        &mut self,
        line: &Line,
        keyword: &str,
        nums: &[f64],
        at: At,
    ) -> Option<TransformOp> {
        let help = || Some(FORM.to_string());
        let v = |k: usize| DVec3::new(nums[k], nums[k + 1], nums[k + 2]);
        match (keyword, nums.len()) {
            ("translate", 3) => Some(TransformOp::Translate(v(0))),
            ("rotate", 4) if v(1) != DVec3::ZERO => Some(TransformOp::Rotate {
                degrees: nums[0],
                axis: v(1),
            }),
            ("rotate", 4) => {
                self.error(line, at, "a rotation needs a non-zero axis", help());
                None
            }
            ("scale", 1 | 3) => {
                let s = if nums.len() == 1 {
                    DVec3::splat(nums[0])
                } else {
                    v(0)
                };
                if s.cmpeq(DVec3::ZERO).any() {
                    self.error(line, at, "a scale of 0 cannot be undone", help());
                    None
                } else {
                    Some(TransformOp::Scale(s))
                }
            }
            (k, n) => {
                let wanted = match k {
                    "translate" => "3 numbers",
                    "rotate" => "4 numbers (degrees, then the axis)",
                    _ => "1 or 3 numbers",
                };
                self.error(line, at, format!("`{k}` takes {wanted}, found {n}"), help());
                None
            }
        }
    }

    /// Once the whole file is read: every motion names a thing the file defines, and the
    /// instants of one thing's motion lines increase. Offending lines are dropped.
    pub(super) fn resolve_motion(&mut self, text: &str) {
        if !self
            .statements
            .iter()
            .any(|s| matches!(s.kind, StatementKind::Motion(_)))
        {
            return;
        }
        let defined = self.defined_names();
        let included = self.chain.is_included();
        let mut last: HashMap<&str, f64> = HashMap::new();
        // Motion of a thing whose definition was rejected (and reported) goes quietly.
        let mut drop = HashSet::new();
        let mut problems: Vec<(usize, String, Option<String>)> = Vec::new();
        for (k, s) in self.statements.iter().enumerate() {
            let StatementKind::Motion(m) = &s.kind else {
                continue;
            };
            let name = m.target.name.as_str();
            if !defined.contains(name) {
                if included {
                    // The file including this one may define it (as for a transform): it
                    // checks the motion once this file is spliced in.
                    continue;
                }
                if self.skipped.contains(name) {
                    drop.insert(k);
                } else {
                    let hint = suggest(name, defined.iter().copied())
                        .map(|s| format!("did you mean `{s}`?"));
                    problems.push((
                        k,
                        format!("motion of '{name}', which is not a shape, composite, camera or light of this file"),
                        hint,
                    ));
                }
                continue;
            }
            match last.insert(name, m.at) {
                Some(before) if before >= m.at => problems.push((
                    k,
                    format!(
                        "the motion of '{name}' at {} comes after one at {before}: the instants of one thing's motion must increase",
                        m.at
                    ),
                    None,
                )),
                _ => {}
            }
        }
        if problems.is_empty() && drop.is_empty() {
            return;
        }
        let lines: Vec<&str> = lexer::raw_lines(text).collect();
        for (k, message, help) in problems {
            let s = &self.statements[k];
            // A line of an included file is quoted from that file, later (load/).
            let own = *s.loc.file == *self.file;
            let d = located(s, if own { &lines } else { &[] }, message);
            self.diagnostics.push(match help {
                Some(h) => d.with_help(h),
                None => d,
            });
            drop.insert(k);
        }
        let mut k = 0;
        self.statements.retain(|_| {
            k += 1;
            !drop.contains(&(k - 1))
        });
    }
}

/// An error at the name a statement is about, quoting its line.
fn located(s: &Statement, lines: &[&str], message: String) -> Diagnostic {
    let span = s.spans.as_ref().and_then(|sp| sp.name);
    let loc = Loc {
        col: span.map_or(s.loc.col, |sp| sp.col),
        ..s.loc.clone()
    };
    let mut d = Diagnostic::new(Severity::Error, loc, message);
    let width = span.map_or(1, |sp| sp.width);
    match lines.get((s.loc.line as usize).saturating_sub(1)) {
        Some(text) => d.with_source(*text, width),
        None => {
            d.width = width;
            d
        }
    }
}
