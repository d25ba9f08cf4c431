//! `define camera` and the `camera` variant.

use super::{At, PResult, Parser};
use crate::limits::{self, FOV_RULE};
use crate::sdf::ast::{CameraDef, StatementKind};
use crate::sdf::lexer::Line;
use crate::shape::geometry::{is_zero, parallel};
use glam::DVec3;

const FORM_CAMERA: &str = "define camera <name> <fov-x> [eye] [dir] [up]";

impl Parser<'_> {
    pub(super) fn camera(&mut self, line: &Line, name_at: usize) {
        if let Some(t) = line.tokens.get(name_at) {
            self.camera_names.push(t.text.to_string());
        }
        if self.camera_inner(line, name_at).is_err() {
            self.cameras_rejected = true;
            self.skip_name(line, name_at);
        }
    }

    fn camera_inner(&mut self, line: &Line, name_at: usize) -> PResult<()> {
        let toks = &line.tokens;
        let form = Some(format!("canonical form: `{FORM_CAMERA}`"));
        let Some(name_tok) = toks.get(name_at) else {
            return Err(self.error(
                line,
                At::End,
                "expected the camera's name, found end of line",
                form,
            ));
        };
        let name = name_tok.text.to_string();
        let first = name_at + 1;
        let mut nums = self.numbers(line, first, toks.len())?;
        // Two unambiguous layouts that their authors' renderers drew: the eye alone (looking
        // along -z with y up), and the full form with one stray number after it.
        if nums.len() == 4 {
            self.warn(
                line,
                At::Span(first + 1, first + 3),
                "camera with an eye position but no direction or up vector: looking along -z with y up",
                Some(format!("canonical form: `{FORM_CAMERA}`")),
            );
        } else if nums.len() == 11 {
            self.warn(
                line,
                At::Tok(first + 10),
                format!(
                    "extra number '{}' after the camera's up vector ignored",
                    toks[first + 10].text
                ),
                Some(format!("canonical form: `{FORM_CAMERA}`")),
            );
            nums.truncate(10);
        } else if nums.len() != 1 && nums.len() != 10 {
            let n = nums.len();
            let mut help = format!("canonical form: `{FORM_CAMERA}` (1 or 10 numbers)");
            if n == 3 || n == 9 {
                help.push_str("; the image size belongs on the render line, not after the fov");
            }
            return Err(self.error(
                line,
                if n == 0 { At::End } else { At::Span(first, toks.len() - 1) },
                format!("a camera takes <fov-x> or <fov-x> [eye] [dir] [up] (1 or 10 numbers), found {n}"),
                Some(help),
            ));
        }
        let fov = nums[0];
        if !limits::fov_is_valid(fov) {
            let fov_last = nums.len() == 10 && limits::fov_is_valid(nums[9]);
            let help = if fov_last {
                format!("the fov comes first: `{FORM_CAMERA}`")
            } else {
                format!("canonical form: `{FORM_CAMERA}`")
            };
            return Err(self.error(
                line,
                At::Tok(first),
                format!("the horizontal field of view must be {FOV_RULE}, found {fov}"),
                Some(help),
            ));
        }
        if fov < std::f64::consts::PI {
            self.warn(
                line,
                At::Tok(first),
                format!("a field of view of {fov}° is very narrow"),
                Some(format!(
                    "the fov is in degrees; {fov} radians would be {:.1}",
                    fov.to_degrees()
                )),
            );
        }
        let mut def = CameraDef::at_origin(&name, fov);
        if nums.len() == 4 {
            def.eye = DVec3::new(nums[1], nums[2], nums[3]);
        }
        if nums.len() == 10 {
            let v = |i: usize| DVec3::new(nums[i], nums[i + 1], nums[i + 2]);
            def.eye = v(1);
            def.dir = v(4);
            def.up = v(7);
            if is_zero(def.dir) {
                return Err(self.error(
                    line,
                    At::Span(first + 4, first + 6),
                    "the camera's viewing direction is zero",
                    form,
                ));
            }
            if parallel(def.dir, def.up) {
                return Err(self.error(
                    line,
                    At::Span(first + 7, first + 9),
                    "the camera's up vector is zero or parallel to its viewing direction",
                    Some("up must point away from the viewing direction, e.g. 0 1 0 when looking along -z".to_string()),
                ));
            }
        }
        self.emit_named(line, name_at, StatementKind::Camera(def));
        Ok(())
    }
}
