//! Lights, ambient light and the background colour.

use super::{At, Fail, PResult, Parser};
use crate::diag::suggest;
use crate::sdf::ast::{LightDef, SpotDef, StatementKind};
use crate::sdf::lexer::{looks_numeric, Line};
use glam::{DVec3, Vec3};

const FORM_LIGHT: &str = "define light <name> [pos] [color] <brightness>";
const FORM_CLAUSES: &str = "define light <name> [pos] [color] <brightness> [radius <r>] [spot [target] <inner-deg> <outer-deg>]";
/// The words that may follow a point light's numbers, each with its own.
const CLAUSES: [&str; 2] = ["radius", "spot"];
const FORM_AMBIENT_LIGHT: &str = "define light ambient <name> [rgb]";
const FORM_AMBIENT: &str = "ambient [rgb]";
const FORM_BACKGROUND: &str = "background [rgb]";

/// The numbers of a point light's line, after its name, for each way of reading them.
struct LightNumbers<'a> {
    name: &'a str,
    nums: &'a [f64],
}

impl LightNumbers<'_> {
    /// Numbers `i..i + 3` as a colour.
    fn color(&self, i: usize) -> Vec3 {
        let nums = self.nums;
        Vec3::new(nums[i] as f32, nums[i + 1] as f32, nums[i + 2] as f32)
    }

    /// The point light at the position of the first three numbers, with `color` and
    /// `brightness`.
    fn light(&self, color: Vec3, brightness: f32) -> LightDef {
        LightDef {
            name: self.name.to_string(),
            position: self.position(),
            color,
            brightness,
            radius: 0.0,
            spot: None,
        }
    }

    /// The first three numbers.
    fn position(&self) -> DVec3 {
        let nums = self.nums;
        DVec3::new(nums[0], nums[1], nums[2])
    }
}

impl Parser<'_> {
    pub(super) fn light(&mut self, line: &Line) {
        let toks = &line.tokens;
        // `define light ambient|diffuse <name> ...` is the typed form only when a name
        // follows; `define light ambient 0 0 0 ...` is a point light named `ambient`.
        let typed = toks
            .get(2)
            .filter(|t| matches!(t.text, "ambient" | "diffuse"))
            .is_some_and(|_| toks.get(3).is_some_and(|n| !looks_numeric(n.text)));
        let name_at = if typed { 3 } else { 2 };
        let result = if typed && toks[2].text == "ambient" {
            self.ambient_light(line, name_at)
        } else {
            self.point_light(line, name_at)
        };
        if result.is_err() {
            self.skip_name(line, name_at);
        }
    }

    fn ambient_light(&mut self, line: &Line, name_at: usize) -> PResult<()> {
        let nums = self.numbers(line, name_at + 1, line.tokens.len())?;
        let rgb = match nums.len() {
            1 => Vec3::splat(nums[0] as f32),
            3 => Vec3::new(nums[0] as f32, nums[1] as f32, nums[2] as f32),
            n => {
                return Err(self.error(
                    line,
                    At::Span(
                        name_at + 1,
                        line.tokens.len().saturating_sub(1).max(name_at + 1),
                    ),
                    format!("an ambient light takes 3 numbers (r g b), found {n}"),
                    Some(format!("canonical form: `{FORM_AMBIENT_LIGHT}`")),
                ))
            }
        };
        // The name is not needed: ambient light is one value for the whole scene.
        self.skipped.insert(line.tokens[name_at].text.to_string());
        self.emit(line, StatementKind::Ambient(rgb));
        Ok(())
    }

    fn point_light(&mut self, line: &Line, name_at: usize) -> PResult<()> {
        let toks = &line.tokens;
        let Some(name_tok) = toks.get(name_at) else {
            return Err(self.error(
                line,
                At::End,
                "expected the light's name, found end of line",
                Some(format!("canonical form: `{FORM_LIGHT}`")),
            ));
        };
        let name = name_tok.text.to_string();
        let clauses_at = (name_at + 1..toks.len())
            .find(|&i| CLAUSES.contains(&toks[i].text))
            .unwrap_or(toks.len());
        let nums = self.numbers(line, name_at + 1, clauses_at)?;
        if let Some(worst) = nums
            .iter()
            .skip(3)
            .copied()
            .reduce(f64::min)
            .filter(|&v| v < 0.0)
        {
            self.warn(
                line,
                At::Span(name_at + 4, clauses_at - 1),
                format!("light `{name}` has a negative colour or brightness ({worst}): it takes light away"),
                Some("colours lie between 0 and 1, brightness is at least 0".to_string()),
            );
        }
        let numbers = LightNumbers {
            name: &name,
            nums: &nums,
        };
        if clauses_at < toks.len() {
            return self.light_with_clauses(line, (name_at, clauses_at), &numbers);
        }
        match nums.len() {
            10 => self.lecture_light_with_brightness(line, name_at, &numbers),
            7 => {
                let l = numbers.light(numbers.color(3), nums[6] as f32);
                self.emit_named(line, name_at, StatementKind::Light(l));
            }
            6 => {
                let l = numbers.light(numbers.color(3), 1.0);
                self.emit_named(line, name_at, StatementKind::Light(l));
            }
            9 => self.nine_number_light(line, name_at, &numbers),
            8 if !(0.0..=1.0).contains(&nums[3])
                && nums[4..7].iter().all(|v| (0.0..=1.0).contains(v)) =>
            {
                self.light_with_radius(line, name_at, &numbers);
            }
            4 => self.light_without_position(line, name_at, &numbers),
            n => return Err(self.light_count_error(line, name_at, n)),
        }
        Ok(())
    }

    /// Ten numbers, `[pos] [La] [Ld] <brightness>`: the lecture's form with a brightness.
    fn lecture_light_with_brightness(
        &mut self,
        line: &Line,
        name_at: usize,
        numbers: &LightNumbers,
    ) {
        let toks = &line.tokens;
        let ambient = numbers.color(3);
        let l = numbers.light(numbers.color(6), numbers.nums[9] as f32);
        self.variant(
            line,
            At::Span(name_at + 4, toks.len() - 1),
            "ten-number-light",
            "10-number light read as [pos] [La] [Ld] <brightness>: La is added to the \
             ambient light, the intensity is Ld × brightness"
                .to_string(),
            format!("read as `{}`", StatementKind::Light(l.clone())),
        );
        if ambient != Vec3::ZERO {
            self.emit(line, StatementKind::AmbientAdd(ambient));
        }
        self.emit_named(line, name_at, StatementKind::Light(l));
    }

    /// Nine numbers: [pos] [color] [rgb-brightness] when one of the last three exceeds 1,
    /// else the lecture's form [pos] [La] [Ld]. Each reading is explained once per file.
    fn nine_number_light(&mut self, line: &Line, name_at: usize, numbers: &LightNumbers) {
        let toks = &line.tokens;
        let last = numbers.color(6);
        let nums_at = At::Span(name_at + 4, toks.len() - 1);
        if last.max_element() > 1.0 {
            let l = numbers.light(numbers.color(3) * last, 1.0);
            if !self.nine_number_noted[0] {
                self.nine_number_noted[0] = true;
                self.warn(
                    line,
                    nums_at,
                    "9-number light read as [pos] [color] [rgb-brightness] (a brightness above 1); \
                     intensity = color × brightness per channel",
                    Some(format!("read as `{}`", StatementKind::Light(l.clone()))),
                );
            }
            self.emit_named(line, name_at, StatementKind::Light(l));
        } else {
            let ambient = numbers.color(3);
            let diffuse = last;
            if !self.nine_number_noted[1] {
                self.nine_number_noted[1] = true;
                self.warn(
                    line,
                    nums_at,
                    "9-number light read as the lecture form [pos] [La] [Ld] (no number above 1): \
                     La is added to the ambient light, Ld is the light's intensity",
                    Some(format!(
                        "for a brightness per channel, one of the last three numbers must exceed 1; \
                         canonical form: `{FORM_LIGHT}`"
                    )),
                );
            }
            if ambient != Vec3::ZERO {
                self.emit(line, StatementKind::AmbientAdd(ambient));
            }
            if diffuse == Vec3::ZERO {
                // A pure ambient term: there is no point light to place.
                self.skipped.insert(numbers.name.to_string());
            } else {
                let l = numbers.light(diffuse, 1.0);
                self.emit_named(line, name_at, StatementKind::Light(l));
            }
        }
    }

    /// `[pos] <radius> [color] <brightness>`: a spherical light of renderers with soft shadows.
    /// The fourth number cannot be a colour component and the next three can, so the layout
    /// is clear.
    fn light_with_radius(&mut self, line: &Line, name_at: usize, numbers: &LightNumbers) {
        let l = LightDef {
            radius: numbers.nums[3].abs(),
            ..numbers.light(numbers.color(4), numbers.nums[7] as f32)
        };
        self.variant(
            line,
            At::Tok(name_at + 4),
            "light-radius",
            format!(
                "8-number light read as [pos] <radius> [color] <brightness>: a spherical \
                 light of radius {}",
                l.radius
            ),
            format!("read as `{}`", StatementKind::Light(l.clone())),
        );
        self.emit_named(line, name_at, StatementKind::Light(l));
    }

    /// A point light's 6 or 7 numbers (`numbers`) followed by `radius` and `spot` clauses
    /// from token `clauses_at` on.
    fn light_with_clauses(
        &mut self,
        line: &Line,
        (name_at, clauses_at): (usize, usize),
        numbers: &LightNumbers,
    ) -> PResult<()> {
        let brightness = match numbers.nums.len() {
            6 => 1.0,
            7 => numbers.nums[6] as f32,
            n => {
                return Err(self.error(
                    line,
                    At::Tok(clauses_at),
                    format!(
                    "`{}` follows the 7 numbers [pos] [color] <brightness>, found {n} before it",
                    line.tokens[clauses_at].text
                ),
                    Some(format!("canonical form: `{FORM_CLAUSES}`")),
                ))
            }
        };
        let mut l = numbers.light(numbers.color(3), brightness);
        let mut seen = [false; CLAUSES.len()];
        let mut i = clauses_at;
        while i < line.tokens.len() {
            let to = Self::number_run_end(line, i + 1);
            let word = line.tokens[i].text;
            let Some(k) = CLAUSES.iter().position(|&c| c == word) else {
                let hint = suggest(word, CLAUSES).map(|s| format!("did you mean `{s}`?"));
                return Err(self.error(
                    line,
                    At::Tok(i),
                    format!("expected `radius` or `spot`, found '{word}'"),
                    hint.or_else(|| Some(format!("canonical form: `{FORM_CLAUSES}`"))),
                ));
            };
            if std::mem::replace(&mut seen[k], true) {
                return Err(self.error(
                    line,
                    At::Tok(i),
                    format!("a light takes one `{word}`"),
                    Some(format!("canonical form: `{FORM_CLAUSES}`")),
                ));
            }
            let nums = self.numbers(line, i + 1, to)?;
            if k == 0 {
                l.radius = self.light_radius(line, i, &nums)?;
            } else {
                l.spot = Some(self.spot(line, i, &nums, l.position)?);
            }
            i = to;
        }
        self.emit_named(line, name_at, StatementKind::Light(l));
        Ok(())
    }

    /// The numbers `nums` after `radius` (token `at`): one radius, read as its size when
    /// negative.
    fn light_radius(&mut self, line: &Line, at: usize, nums: &[f64]) -> PResult<f64> {
        let [r] = nums[..] else {
            return Err(self.error(
                line,
                if nums.is_empty() {
                    At::Tok(at)
                } else {
                    At::Span(at + 1, at + nums.len())
                },
                format!(
                    "`radius` takes 1 number (the light's radius), found {}",
                    nums.len()
                ),
                Some(format!("canonical form: `{FORM_CLAUSES}`")),
            ));
        };
        if r < 0.0 {
            self.warn(
                line,
                At::Tok(at + 1),
                format!("negative light radius {r}: read as {}", -r),
                None,
            );
        }
        Ok(r.abs())
    }

    /// The numbers `nums` after `spot` (token `at`) of a light at `position`: a target and
    /// two half-angles, 0 ≤ inner ≤ outer ≤ 180 with outer above 0.
    fn spot(&mut self, line: &Line, at: usize, nums: &[f64], position: DVec3) -> PResult<SpotDef> {
        let help = || Some(format!("canonical form: `{FORM_CLAUSES}`"));
        let [x, y, z, inner_deg, outer_deg] = nums[..] else {
            return Err(self.error(
                line,
                if nums.is_empty() {
                    At::Tok(at)
                } else {
                    At::Span(at + 1, at + nums.len())
                },
                format!(
                    "`spot` takes 5 numbers ([target] <inner-deg> <outer-deg>), found {}",
                    nums.len()
                ),
                help(),
            ));
        };
        let target = DVec3::new(x, y, z);
        if target == position {
            return Err(self.error(
                line,
                At::Span(at + 1, at + 3),
                "a spot's target must differ from the light's position (it gives the direction)",
                help(),
            ));
        }
        let angles = At::Span(at + 4, at + 5);
        if !(0.0..=180.0).contains(&inner_deg)
            || !(0.0..=180.0).contains(&outer_deg)
            || outer_deg == 0.0
        {
            return Err(self.error(
                line,
                angles,
                format!("a spot's half-angles lie from 0 to 180 degrees, the outer above 0: found {inner_deg} and {outer_deg}"),
                help(),
            ));
        }
        if inner_deg > outer_deg {
            return Err(self.error(
                line,
                angles,
                format!("a spot's inner half-angle ({inner_deg}) is larger than its outer one ({outer_deg})"),
                Some("full intensity inside the inner half-angle, none beyond the outer: write the inner one first".into()),
            ));
        }
        Ok(SpotDef {
            target,
            inner_deg,
            outer_deg,
        })
    }

    /// Four numbers, no position: the only meaning left is an ambient term, colour ×
    /// brightness (`define light ambient1 .3 .2 .6 5`), added like the lecture form's La.
    fn light_without_position(&mut self, line: &Line, name_at: usize, numbers: &LightNumbers) {
        let toks = &line.tokens;
        let rgb = numbers.color(0) * numbers.nums[3] as f32;
        self.warn(
            line,
            At::Span(name_at + 1, toks.len() - 1),
            "a light with 4 numbers has no position: read as ambient light [rgb] <brightness>, \
             added to the scene's ambient light",
            Some(format!(
                "write `{FORM_AMBIENT}` for ambient light, or `{FORM_LIGHT}` for a point light"
            )),
        );
        self.skipped.insert(numbers.name.to_string());
        self.emit(line, StatementKind::AmbientAdd(rgb));
    }

    /// The error of a light line with `n` numbers, a count no reading takes.
    fn light_count_error(&mut self, line: &Line, name_at: usize, n: usize) -> Fail {
        let toks = &line.tokens;
        let at = if n > 7 {
            At::Span(name_at + 8, toks.len() - 1)
        } else {
            At::End
        };
        let mut help = format!(
            "canonical form: `{FORM_LIGHT}`; 6 numbers (no brightness), 9 and 10 are also read, \
             and 8 as [pos] <radius> [color] <brightness> when the colour lies in 0..1 and the radius does not"
        );
        if matches!(n, 1 | 3) {
            help.push_str(&format!(
                ". An ambient light is written `{FORM_AMBIENT}` or `{FORM_AMBIENT_LIGHT}`"
            ));
        }
        self.error(
            line,
            at,
            format!("a light takes 7 numbers ([pos] [color] <brightness>), found {n}"),
            Some(help),
        )
    }

    /// `ambient [<name>] <s>|[rgb]`, `define ambient [<name>] [rgb] [<k>]`.
    pub(super) fn ambient(&mut self, line: &Line, from: usize) {
        let toks = &line.tokens;
        let mut at = from;
        if toks.get(at).is_some_and(|t| !looks_numeric(t.text)) {
            at += 1; // an ambient light's name, not needed
        }
        let Ok(nums) = self.numbers(line, at, toks.len()) else {
            return;
        };
        let c = |i: usize| Vec3::new(nums[i] as f32, nums[i + 1] as f32, nums[i + 2] as f32);
        let rgb = match nums.len() {
            1 => Vec3::splat(nums[0] as f32),
            3 => c(0),
            4 => c(0) * nums[3] as f32,
            n => {
                self.error(
                    line,
                    if n == 0 { At::End } else { At::Span(at, toks.len() - 1) },
                    format!("ambient takes 3 numbers (r g b), found {n}"),
                    Some(format!(
                        "canonical form: `{FORM_AMBIENT}`; also read: `ambient <s>`, `define ambient <name> [rgb] <k>`"
                    )),
                );
                return;
            }
        };
        self.emit(line, StatementKind::Ambient(rgb));
    }

    pub(super) fn background(&mut self, line: &Line, from: usize) {
        let toks = &line.tokens;
        let Ok(nums) = self.numbers(line, from, toks.len()) else {
            return;
        };
        match nums.len() {
            3 => {
                let rgb = Vec3::new(nums[0] as f32, nums[1] as f32, nums[2] as f32);
                self.emit(line, StatementKind::Background(rgb));
            }
            1 => {
                let kind = StatementKind::Background(Vec3::splat(nums[0] as f32));
                self.warn(
                    line,
                    At::Tok(from),
                    "background with one number read as a grey",
                    Some(format!("read as `{kind}`")),
                );
                self.emit(line, kind);
            }
            n => {
                self.error(
                    line,
                    if n == 0 {
                        At::End
                    } else {
                        At::Span(from, toks.len() - 1)
                    },
                    format!("background takes 3 numbers (r g b), found {n}"),
                    Some(format!("canonical form: `{FORM_BACKGROUND}`")),
                );
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::diag::Severity;
    use crate::sdf::ast::{LightDef, StatementKind};
    use crate::sdf::{parse, LoadOptions};
    use glam::{DVec3, Vec3};
    use std::path::Path;

    fn lights(text: &str, strict: bool) -> (Vec<LightDef>, Vec<crate::diag::Diagnostic>) {
        let opts = LoadOptions {
            strict,
            ..LoadOptions::default()
        };
        let (statements, ds) = parse(text, Path::new("s.sdf"), &opts);
        let lights = statements
            .into_iter()
            .filter_map(|s| match s.kind {
                StatementKind::Light(l) => Some(l),
                _ => None,
            })
            .collect();
        (lights, ds)
    }

    #[test]
    fn eight_number_lights_carry_a_radius_before_the_colour() {
        let text = "define light small 0 100 0 10 1 0.5 1 0.7\n";
        let (l, ds) = lights(text, false);
        assert_eq!(l.len(), 1, "{ds:?}");
        assert_eq!(l[0].position, DVec3::new(0.0, 100.0, 0.0));
        assert_eq!(l[0].color, Vec3::new(1.0, 0.5, 1.0));
        assert_eq!(l[0].brightness, 0.7);
        assert_eq!(l[0].radius, 10.0);
        assert!(ds.iter().all(|d| d.severity == Severity::Warning), "{ds:?}");
        assert!(ds.iter().any(|d| d.message.contains("<radius> [color]")));
        let (_, ds) = lights(text, true);
        assert!(ds.iter().any(|d| d.severity == Severity::Error));
    }

    #[test]
    fn eight_number_lights_without_that_layout_stay_errors() {
        // The fourth number could be a colour component: no clear reading.
        let (l, ds) = lights("define light l 0 1 0 0.5 1 1 1 0.7\n", false);
        assert!(l.is_empty());
        assert!(ds.iter().any(|d| d.severity == Severity::Error), "{ds:?}");
    }

    #[test]
    fn radius_and_spot_clauses_read_back_as_written_in_either_order() {
        let canonical = "define light l 0 5 0 1 1 1 2 radius 0.5 spot 0 0 -1 20 30";
        for text in [
            canonical,
            "define light l 0 5 0 1 1 1 2 spot 0 0 -1 20 30 radius 0.5",
        ] {
            let (l, ds) = lights(&format!("{text}\n"), true);
            assert!(ds.is_empty(), "{ds:?}");
            assert_eq!(l[0].radius, 0.5);
            let spot = l[0].spot.expect("a spot");
            assert_eq!(spot.target, DVec3::new(0.0, 0.0, -1.0));
            assert_eq!((spot.inner_deg, spot.outer_deg), (20.0, 30.0));
            assert_eq!(StatementKind::Light(l[0].clone()).to_string(), canonical);
        }
        // Six numbers (brightness 1) take clauses too; a radius of 0 is a point light.
        let (l, ds) = lights("define light l 0 5 0 1 1 1 radius 0\n", true);
        assert!(ds.is_empty(), "{ds:?}");
        assert_eq!((l[0].brightness, l[0].radius), (1.0, 0.0));
        let text = StatementKind::Light(l[0].clone()).to_string();
        assert_eq!(text, "define light l 0 5 0 1 1 1 1");
    }

    #[test]
    fn a_transform_carries_a_spot_s_target_with_the_light() {
        let text = "define light l 0 5 0 1 1 1 1 spot 0 0 0 10 20 radius 1\n\
                    transform l translate 3 0 0\n\
                    define camera c 60\nrender c o.png 4 4\n";
        let loaded = crate::load::load_str(text, Path::new("s.sdf"), &LoadOptions::default())
            .expect("loads");
        let light = &loaded.jobs[0].scene.lights[0];
        assert_eq!(light.position, DVec3::new(3.0, 5.0, 0.0));
        assert_eq!(
            light.spot.map(|s| s.target),
            Some(DVec3::new(3.0, 0.0, 0.0))
        );
        assert_eq!(light.radius, 1.0);
    }
}
