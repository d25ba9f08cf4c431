//! `define camera` and the `camera` variant.

use super::{At, PResult, Parser};
use crate::limits::{self, FOV_RULE};
use crate::sdf::ast::{CameraDef, StatementKind};
use crate::sdf::lexer::Line;
use crate::shape::geometry::{is_zero, parallel};
use glam::DVec3;

const FORM_CAMERA: &str = "define camera <name> <fov-x> [eye] [dir] [up]";

/// A horizontal field of view above this many degrees is more likely a mistake (a half fov,
/// another unit) than a view anyone composes: it is warned of.
const WIDE_FOV_DEG: f64 = 170.0;

/// Whether a camera line's number can be an image side (a whole number of pixels).
fn is_image_side(v: f64) -> bool {
    v.fract() == 0.0
        && v >= f64::from(*limits::IMAGE_SIDE.start())
        && v <= f64::from(*limits::IMAGE_SIDE.end())
}

/// Tokens `from..to` joined by spaces, as written.
fn joined(toks: &[crate::sdf::lexer::Token], from: usize, to: usize) -> String {
    toks[from..to]
        .iter()
        .map(|t| t.text)
        .collect::<Vec<_>>()
        .join(" ")
}

/// The eye and direction of `<fov> <angle> [center] <radius>`: a camera at `angle` degrees
/// from +x on a circle of `radius` about `center` in the xz-plane, looking at the center.
/// `None` unless the six numbers can be that (a field of view and a positive radius).
fn orbit(nums: &[f64]) -> Option<(DVec3, DVec3)> {
    let [fov, angle, cx, cy, cz, radius] = *nums else {
        return None;
    };
    if !limits::fov_is_valid(fov) || radius <= 0.0 {
        return None;
    }
    let center = DVec3::new(cx, cy, cz);
    let a = angle.to_radians();
    let eye = center + radius * DVec3::new(a.cos(), 0.0, a.sin());
    Some((eye, center - eye))
}

impl Parser<'_> {
    pub(super) fn camera(&mut self, line: &Line, name_at: usize) {
        if let Some(t) = line.tokens.get(name_at) {
            self.camera_names.push(t.text.to_string());
        }
        let reported = self.diagnostics.len();
        if self.camera_inner(line, name_at).is_err() {
            self.cameras_rejected = true;
            self.skip_name(line, name_at);
            // Whether that stops the file depends on its other cameras and render lines.
            let problems = self.diagnostics.split_off(reported);
            let name = line.tokens.get(name_at).map_or("", |t| t.text).to_string();
            self.camera_errors.push((name, problems));
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
        let nums = self.numbers(line, first, toks.len())?;
        let nums = self.camera_layout(line, first, &name, nums)?;
        let fov = self.camera_fov(line, first, &nums)?;
        let mut def = CameraDef::at_origin(&name, fov);
        if nums.len() == 4 {
            def.eye = DVec3::new(nums[1], nums[2], nums[3]);
        }
        if nums.len() == 10 {
            self.camera_pose(line, first, &name, &nums, &mut def)?;
        }
        self.emit_named(line, name_at, StatementKind::Camera(def));
        Ok(())
    }

    /// The numbers `nums` of a camera line (from token `first`) in one of the canonical
    /// layouts, <fov-x>, <fov-x> [eye] or <fov-x> [eye] [dir] [up] (1, 4 or 10 numbers), each
    /// other layout that can be read warned of.
    fn camera_layout(
        &mut self,
        line: &Line,
        first: usize,
        name: &str,
        mut nums: Vec<f64>,
    ) -> PResult<Vec<f64>> {
        let toks = &line.tokens;
        // Two unambiguous layouts that their authors' renderers drew: the eye alone (looking
        // along -z with y up), and the full form with one stray number after it.
        if nums.len() == 4 {
            self.warn(
                line,
                At::Span(first + 1, first + 3),
                "camera with an eye position but no direction or up vector: looking along -z with y up",
                Some(format!("canonical form: `{FORM_CAMERA}`")),
            );
        } else if nums.len() == 3 && is_image_side(nums[1]) && is_image_side(nums[2]) {
            self.read_size_after_fov(line, first, name, &mut nums);
        } else if nums.len() == 7 && !limits::fov_is_valid(nums[0]) && limits::fov_is_valid(nums[6])
        {
            // `[eye] [dir] <fov>`: the first number cannot be a field of view, the last can.
            self.warn(
                line,
                At::Tok(first + 6),
                "camera written as [eye] [dir] <fov-x>, the field of view last: +y is up",
                Some(format!("canonical form: `{FORM_CAMERA}`")),
            );
            if is_zero(DVec3::new(nums[3], nums[4], nums[5])) {
                self.warn_zero_direction(line, name, first + 3, first + 6);
                nums = vec![nums[6]];
            } else {
                nums.rotate_right(1);
                nums.extend([0.0, 1.0, 0.0]);
            }
        } else if nums.len() == 7 && is_zero(DVec3::new(nums[4], nums[5], nums[6])) {
            self.read_default_view_angles(line, first, name, &mut nums);
        } else if nums.len() == 7 {
            self.warn(
                line,
                At::End,
                "camera with an eye position and a direction but no up vector: +y is up",
                Some(format!("canonical form: `{FORM_CAMERA}`")),
            );
            nums.extend([0.0, 1.0, 0.0]);
        } else if nums.len() == 9 && is_image_side(nums[1]) && is_image_side(nums[2]) {
            self.read_size_before_pose(line, first, name, &mut nums);
        } else if let Some(orbit) = orbit(&nums) {
            self.read_orbit(line, first, name, orbit, &mut nums);
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
        if nums.len() == 10 && !limits::fov_is_valid(nums[0]) && limits::fov_is_valid(nums[9]) {
            // `[eye] [dir] [up] <fov>`: the first number cannot be a field of view, the last
            // can, so the order is clear.
            self.warn(
                line,
                At::Tok(first),
                "camera written with the field of view last: read as [eye] [dir] [up] <fov-x>",
                Some(format!("the fov comes first: `{FORM_CAMERA}`")),
            );
            nums.rotate_right(1);
        }
        Ok(nums)
    }

    /// `camera eye 45 500 500`: renderers that size the image by the camera. Keeps the size
    /// for the render lines of the camera that give none.
    fn read_size_after_fov(&mut self, line: &Line, first: usize, name: &str, nums: &mut Vec<f64>) {
        let size = (nums[1] as u32, nums[2] as u32);
        self.warn(
            line,
            At::Span(first, first + 2),
            format!(
                "image size {}×{} after the field of view: used by render lines of this camera that give none",
                size.0, size.1
            ),
            Some(format!(
                "the image size belongs on the render line: `render {name} <file> {} {}`",
                size.0, size.1
            )),
        );
        self.camera_sizes.insert(name.to_string(), size);
        nums.truncate(1);
    }

    /// `[eye] <yaw> <pitch> <roll>` in degrees (renderers that turn the default view): 0 0 0
    /// is no turn, whereas as a direction it would be none.
    fn read_default_view_angles(
        &mut self,
        line: &Line,
        first: usize,
        name: &str,
        nums: &mut Vec<f64>,
    ) {
        let toks = &line.tokens;
        self.warn(
            line,
            At::Span(first + 4, first + 6),
            "camera with an eye position and `0 0 0` read as the yaw, pitch and roll of \
             the default view: looking along -z with +y up",
            Some(format!(
                "write `define camera {name} {} {} 0 0 -1 0 1 0`",
                toks[first].text,
                joined(toks, first + 1, first + 4)
            )),
        );
        nums.truncate(4);
        nums.extend([0.0, 0.0, -1.0, 0.0, 1.0, 0.0]);
    }

    /// `<fov> <width> <height> [eye] [dir]`: cameras that carry the image size, in the order
    /// of their constructor. Keeps the size for the render lines of the camera that give
    /// none.
    fn read_size_before_pose(
        &mut self,
        line: &Line,
        first: usize,
        name: &str,
        nums: &mut Vec<f64>,
    ) {
        let toks = &line.tokens;
        let size = (nums[1] as u32, nums[2] as u32);
        self.warn(
            line,
            At::Span(first + 1, first + 2),
            format!(
                "camera read as <fov-x> <width> <height> [eye] [dir]: image size {}×{} for \
                 render lines of this camera that give none, +y is up",
                size.0, size.1
            ),
            Some(format!(
                "the image size belongs on the render line: write `define camera {name} {} {}` \
                 and `render {name} <file> {} {}`",
                toks[first].text,
                joined(toks, first + 3, first + 9),
                toks[first + 1].text,
                toks[first + 2].text
            )),
        );
        self.camera_sizes.insert(name.to_string(), size);
        nums.drain(1..3);
        nums.extend([0.0, 1.0, 0.0]);
    }

    /// `<fov> <angle> [center] <radius>`: a camera on a circle about the scene's center, as
    /// written by animation generators that circle the scene; `orbit` is its eye and
    /// direction.
    fn read_orbit(
        &mut self,
        line: &Line,
        first: usize,
        name: &str,
        orbit: (DVec3, DVec3),
        nums: &mut Vec<f64>,
    ) {
        let toks = &line.tokens;
        self.warn(
            line,
            At::Span(first + 1, first + 5),
            format!(
                "6-number camera read as <fov-x> <angle> [center] <radius>: the eye on a \
                 circle of radius {} about {} in the xz-plane, {}° from +x, looking at the \
                 center with +y up",
                nums[5],
                joined(toks, first + 2, first + 5),
                nums[1]
            ),
            Some(format!(
                "write the pose it gives: `define camera {name} {} {} {} {} {} {} {} 0 1 0`",
                toks[first].text, orbit.0.x, orbit.0.y, orbit.0.z, orbit.1.x, orbit.1.y, orbit.1.z
            )),
        );
        *nums = vec![
            nums[0], orbit.0.x, orbit.0.y, orbit.0.z, orbit.1.x, orbit.1.y, orbit.1.z, 0.0, 1.0,
            0.0,
        ];
    }

    /// The field of view, the first of a camera line's numbers `nums` (from token `first`).
    fn camera_fov(&mut self, line: &Line, first: usize, nums: &[f64]) -> PResult<f64> {
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
        if fov > WIDE_FOV_DEG {
            self.warn(
                line,
                At::Tok(first),
                format!("a field of view of {fov}° is nearly a half turn: the picture is stretched to its edges"),
                Some("the fov is the full horizontal angle in degrees; 60 is a common view".into()),
            );
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
        Ok(fov)
    }

    /// The eye, direction and up vector of a camera line's ten numbers `nums` (from token
    /// `first`) into `def`, with an up vector that gives no roll replaced by +y.
    /// Warns that a camera's viewing direction (the three tokens from `dir_at`) is zero, and
    /// that it is read as its field of view (token `fov_at`) alone: the renderers that wrote
    /// such lines looked along -z from the origin, and so does this reading.
    fn warn_zero_direction(&mut self, line: &Line, name: &str, dir_at: usize, fov_at: usize) {
        let fov = line.tokens[fov_at].text;
        self.warn(
            line,
            At::Span(dir_at, dir_at + 2),
            "the camera's viewing direction is zero: read as its field of view alone, at the origin looking along -z with +y up",
            Some(format!(
                "that is `define camera {name} {fov}`; to place the camera, give a direction: `{FORM_CAMERA}`"
            )),
        );
    }

    fn camera_pose(
        &mut self,
        line: &Line,
        first: usize,
        name: &str,
        nums: &[f64],
        def: &mut CameraDef,
    ) -> PResult<()> {
        let toks = &line.tokens;
        let v = |i: usize| DVec3::new(nums[i], nums[i + 1], nums[i + 2]);
        def.eye = v(1);
        def.dir = v(4);
        def.up = v(7);
        if is_zero(def.dir) {
            self.warn_zero_direction(line, name, first + 4, first);
            def.eye = DVec3::ZERO;
            def.dir = DVec3::NEG_Z;
            def.up = DVec3::Y;
            return Ok(());
        }
        if parallel(def.dir, def.up) && !parallel(def.dir, DVec3::Y) && toks.len() > first + 9 {
            // An up vector that is zero or along the view gives no roll: nothing of the
            // author's is lost by taking the default one (renderers that ignore it drew
            // the view that way).
            let what = if is_zero(def.up) {
                "zero"
            } else {
                "parallel to its viewing direction"
            };
            self.warn(
                line,
                At::Span(first + 7, first + 9),
                format!("the camera's up vector is {what}: +y is up"),
                Some(format!(
                    "up must point away from the viewing direction, e.g. 0 1 0; canonical form: `{FORM_CAMERA}`"
                )),
            );
            def.up = DVec3::Y;
        }
        if parallel(def.dir, def.up) {
            // Without an up vector in the file, point at the direction that needs one.
            let at = if toks.len() > first + 9 {
                At::Span(first + 7, first + 9)
            } else {
                At::Span(first + 4, first + 6)
            };
            return Err(self.error(
                line,
                at,
                "the camera's up vector is zero or parallel to its viewing direction",
                Some("up must point away from the viewing direction, e.g. 0 1 0 when looking along -z".to_string()),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::diag::{Diagnostic, Severity};
    use crate::sdf::ast::{CameraDef, StatementKind};
    use crate::sdf::{parse, LoadOptions};
    use glam::DVec3;
    use std::path::Path;

    /// The camera `c` read from `line`, with the diagnostics; and whether `--strict` rejects it.
    fn read(line: &str) -> (Option<CameraDef>, Vec<Diagnostic>, bool) {
        let text = format!("{line}\nrender c out.png 8 8\n");
        let (statements, ds) = parse(&text, Path::new("s.sdf"), &LoadOptions::default());
        let camera = statements.into_iter().find_map(|s| match s.kind {
            StatementKind::Camera(c) => Some(c),
            _ => None,
        });
        let strict = LoadOptions {
            strict: true,
            ..LoadOptions::default()
        };
        let (_, strict_ds) = parse(&text, Path::new("s.sdf"), &strict);
        let strict_rejects = strict_ds.iter().any(|d| d.severity == Severity::Error);
        (camera, ds, strict_rejects)
    }

    fn close(a: DVec3, b: DVec3) -> bool {
        a.abs_diff_eq(b, 1e-9)
    }

    /// One warning containing `text`, no error, and an error under `--strict`.
    fn accepted(ds: &[Diagnostic], strict_rejects: bool, text: &str) {
        assert!(ds.iter().all(|d| d.severity == Severity::Warning), "{ds:?}");
        assert!(ds.iter().any(|d| d.message.contains(text)), "{ds:?}");
        assert!(strict_rejects, "--strict must reject the form");
    }

    #[test]
    fn image_size_then_eye_and_direction() {
        let (c, ds, strict) = read("define camera c 60 800 600 0 0 45 0 0 -45");
        let c = c.expect("camera read");
        assert_eq!(c.fov_x_deg, 60.0);
        assert!(close(c.eye, DVec3::new(0.0, 0.0, 45.0)));
        assert!(close(c.dir, DVec3::new(0.0, 0.0, -45.0)));
        assert!(close(c.up, DVec3::Y));
        accepted(&ds, strict, "<fov-x> <width> <height> [eye] [dir]");
    }

    #[test]
    fn zero_angles_after_the_eye_are_the_default_view() {
        let (c, ds, strict) = read("define camera c 60 0 5 13.66 0 0 0");
        let c = c.expect("camera read");
        assert!(close(c.eye, DVec3::new(0.0, 5.0, 13.66)));
        assert!(close(c.dir, DVec3::NEG_Z));
        assert!(close(c.up, DVec3::Y));
        accepted(&ds, strict, "yaw, pitch and roll");
    }

    #[test]
    fn orbit_camera_looks_at_the_center_from_the_circle() {
        let (c, ds, strict) = read("define camera c 45 90 0 1 -30 10");
        let c = c.expect("camera read");
        // 90° from +x on the circle of radius 10 about (0, 1, -30): +z of the center.
        assert!(close(c.eye, DVec3::new(0.0, 1.0, -20.0)), "{:?}", c.eye);
        assert!(close(c.dir.normalize(), DVec3::NEG_Z), "{:?}", c.dir);
        accepted(&ds, strict, "<fov-x> <angle> [center] <radius>");
        // Not an orbit: no valid fov, or no positive radius.
        assert!(read("define camera c 45 90 0 1 -30 0").0.is_none());
        assert!(read("define camera c 200 90 0 1 -30 10").0.is_none());
    }

    #[test]
    fn an_up_vector_along_the_view_means_y_up() {
        let (c, ds, strict) = read("define camera c 0 0 0 0 0 -1 0 0 1 1.5");
        let c = c.expect("camera read");
        assert!(close(c.up, DVec3::Y));
        assert!(ds.iter().all(|d| d.severity == Severity::Warning), "{ds:?}");
        accepted(&ds, strict, "parallel to its viewing direction: +y is up");
        // Looking along y, +y is no up either: still an error.
        let (c, ds, _) = read("define camera c 60 0 0 0 0 1 0 0 2 0");
        assert!(c.is_none());
        assert!(ds.iter().any(|d| d.severity == Severity::Error), "{ds:?}");
    }

    #[test]
    fn a_broken_camera_skips_only_its_render_lines_when_another_stands() {
        // Looking along +y with +y up: no reading gives it a roll.
        let text = "define camera good 60\ndefine camera bad 60 0 0 0 0 1 0 0 1 0\n\
                    render bad a.png 8 8\nrender good b.png 8 8\n";
        let (statements, ds) = parse(text, Path::new("s.sdf"), &LoadOptions::default());
        assert!(ds.iter().all(|d| d.severity == Severity::Warning), "{ds:?}");
        let skipped = ds
            .iter()
            .find(|d| d.message.contains("camera `bad` is skipped"))
            .expect("the skipped camera is reported");
        assert!(skipped.message.contains("(line 3)"), "{}", skipped.message);
        let renders: Vec<String> = statements
            .iter()
            .filter_map(|s| match &s.kind {
                StatementKind::Render(r) => Some(r.output.clone()),
                _ => None,
            })
            .collect();
        assert_eq!(renders, ["b.png"]);
        // A render line naming no camera takes the first one: when that one is rejected, the
        // line goes with it.
        let text = "define camera bad 60 0 0 0 0 1 0 0 1 0\ndefine camera good 60\n\
                    render a.png 8 8\nrender good b.png 8 8\n";
        let (statements, ds) = parse(text, Path::new("s.sdf"), &LoadOptions::default());
        assert!(ds.iter().all(|d| d.severity == Severity::Warning), "{ds:?}");
        let cameras: Vec<String> = statements
            .iter()
            .filter_map(|s| match &s.kind {
                StatementKind::Render(r) => Some(r.camera.name.clone()),
                _ => None,
            })
            .collect();
        assert_eq!(cameras, ["good"]);
        // As the only render line's camera it stops the file.
        let text = "define camera bad 60 0 0 0 0 1 0 0 1 0\nrender bad a.png 8 8\n";
        let (_, ds) = parse(text, Path::new("s.sdf"), &LoadOptions::default());
        assert!(ds.iter().any(|d| d.severity == Severity::Error), "{ds:?}");
    }
}
