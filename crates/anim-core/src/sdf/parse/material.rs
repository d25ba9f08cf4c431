//! `define material`: colours, the Phong exponent, and the extras named by
//! `--material-fields`.

use super::layout::{default_layout, Layout, Slot};
use super::{At, Fail, PResult, Parser};
use crate::limits;
use crate::sdf::ast::{MaterialDef, StatementKind};
use crate::sdf::lexer::Line;
use crate::sdf::{repair, MaterialField};
use glam::Vec3;

const FORM_MATERIAL: &str = "define material <name> [Ka] [Kd] [Ks] <m> [extras...]";

impl Parser<'_> {
    pub(super) fn material(&mut self, line: &Line) {
        if self.material_inner(line).is_err() {
            self.skip_name(line, 2);
        }
    }

    fn material_inner(&mut self, line: &Line) -> PResult<()> {
        let toks = &line.tokens;
        if toks.len() < 3 {
            return Err(self.error(
                line,
                At::End,
                "expected a material name, found end of line",
                Some(format!("canonical form: `{FORM_MATERIAL}`")),
            ));
        }
        let name = toks[2].text.to_string();
        let mut nums = self.numbers(line, 3, toks.len())?;
        if nums.len() == 9 {
            // What a C++ stream reader leaves in a number it finds no text for.
            self.warn(
                line,
                At::End,
                "a material with 9 numbers has no exponent m: read as 0, as a C++ stream reader leaves it",
                Some(format!("canonical form: `{FORM_MATERIAL}`")),
            );
            nums.push(0.0);
        }
        if nums.len() < 10 {
            return Err(self.error(
                line,
                At::End,
                format!(
                    "a material needs 10 numbers ([Ka] [Kd] [Ks] <m>), found {}",
                    nums.len()
                ),
                Some(format!("canonical form: `{FORM_MATERIAL}`")),
            ));
        }
        let count = nums.len() - 9;
        let layout = self.layout.clone();
        let Some(slots) = layout.read(count) else {
            return Err(self.too_many_numbers(line, nums.len()));
        };
        if count > 1 {
            self.explain_layout(line);
        }
        let c3 = |i: usize| Vec3::new(nums[i] as f32, nums[i + 1] as f32, nums[i + 2] as f32);
        for (what, at) in [("Ka", 3), ("Kd", 6), ("Ks", 9)] {
            if c3(at - 3).min_element() < 0.0 {
                self.warn(
                    line,
                    At::Span(at, at + 2),
                    format!("negative {what} in material `{name}`: it takes light away"),
                    Some("reflection coefficients lie between 0 and 1".to_string()),
                );
            }
        }
        let mut def = MaterialDef {
            name,
            ka: c3(0),
            kd: c3(3),
            ks: c3(6),
            m: 1.0,
            reflectivity: 0.0,
            opacity: 1.0,
            ior: repair::AIR_IOR,
        };
        let opacity_at = self.material_extras(line, &layout, slots, &nums[9..], &mut def);
        // A generated frame means what it says: its invisible material is a fade, not a
        // layout misread.
        let invisible = def.opacity == 0.0 && def.ior == 1.0 && !self.chain.generated;
        if let Some(at) = opacity_at.filter(|_| invisible) {
            self.warn_invisible(line, at, &def);
        }
        self.emit_named(line, 2, StatementKind::Material(def));
        Ok(())
    }

    /// The numbers after m, `extras` (read by `slots` of `layout`), into `def`: where the
    /// opacity was set, if it was.
    fn material_extras(
        &mut self,
        line: &Line,
        layout: &Layout,
        slots: &[Slot],
        extras: &[f64],
        def: &mut MaterialDef,
    ) -> Option<At> {
        let mut opacity_at = None;
        for (k, &slot) in slots.iter().enumerate() {
            let value = layout.value(slot, extras[k]);
            let at = At::Tok(12 + k);
            match slot {
                Slot::M => self.phong(line, at, value, def),
                Slot::Gloss | Slot::Field(MaterialField::Roughness) => {}
                Slot::Field(MaterialField::Reflectivity) => {
                    def.reflectivity = self.unit_interval(line, at, "reflectivity", value);
                }
                Slot::Field(MaterialField::Opacity) => {
                    def.opacity = self.unit_interval(line, at, "opacity", value);
                    opacity_at = Some(at);
                }
                Slot::Field(MaterialField::Transparency) => {
                    def.opacity = 1.0 - self.unit_interval(line, at, "transparency", value);
                    opacity_at = Some(at);
                }
                Slot::Field(MaterialField::Ior) => match repair::usable_ior(value) {
                    Some(ior) => def.ior = ior as f32,
                    None => self.warn(
                        line,
                        at,
                        format!(
                            "the index of refraction must be positive, found {value}; {} used",
                            repair::AIR_IOR
                        ),
                        None,
                    ),
                },
            }
        }
        opacity_at
    }

    /// Warns that material `def` is invisible: fully transparent (by the number at `at`)
    /// without refraction. Every such material is named (a file often has several); the hint
    /// about the field list is given once.
    fn warn_invisible(&mut self, line: &Line, at: At, def: &MaterialDef) {
        let hint = if self.variants_noted.insert("invisible-material") {
            "if this file means transparency by this number, load it with \
             --material-fields reflectivity,transparency,ior"
                .to_string()
        } else {
            "see the first invisible material for the field list to try".to_string()
        };
        self.warn(
            line,
            at,
            format!(
                "material `{}` is invisible: fully transparent (opacity 0) and not refracting (ior 1)",
                def.name
            ),
            Some(hint),
        );
    }

    /// The Phong exponent `m` at `at`, repaired with a warning where it means nothing.
    fn phong(&mut self, line: &Line, at: At, value: f64, def: &mut MaterialDef) {
        def.m = value as f32;
        if def.m < 0.0 {
            self.warn(
                line,
                at,
                format!(
                    "the Phong exponent m must not be negative, found {value}; its absolute value is used"
                ),
                None,
            );
            def.m = repair::phong_exponent(def.m);
        } else if def.m == 0.0 {
            // Kept: pow(x, 0) = 1 is well defined, and it is what the file's own renderer drew.
            self.warn(
                line,
                at,
                "the Phong exponent m is 0: the highlight covers the whole lit side",
                Some("m is usually between 1 (dull) and a few hundred (sharp)".to_string()),
            );
        }
    }

    /// Says once, at the first material with extras, how they were read when the layout was
    /// inferred and is not the default (`--material-fields auto`).
    fn explain_layout(&mut self, line: &Line) {
        if self.opts.material_fields.explicit().is_some() || self.layout == default_layout() {
            return;
        }
        if !self.variants_noted.insert("material-layout") {
            return;
        }
        let layout = &self.layout;
        let mut message = format!(
            "the numbers after the colours of this file's materials are read as `{}`, the layout that makes them plausible",
            layout.describe()
        );
        if layout.has_gloss() {
            message.push_str("; glossiness is ignored");
        }
        let force = match layout.flag() {
            Some(list) => format!("this reading is `--material-fields {list}`; "),
            None => String::new(),
        };
        let help = format!(
            "{force}force another with --material-fields LIST, e.g. the default \
             `--material-fields reflectivity,opacity,ior`"
        );
        self.warn(
            line,
            At::Span(12, line.tokens.len() - 1),
            message,
            Some(help),
        );
    }

    fn too_many_numbers(&mut self, line: &Line, n: usize) -> Fail {
        // No fields: the layout was inferred (`--material-fields auto`).
        let fields = self.opts.material_fields.explicit().unwrap_or(&[]);
        let field_list = field_names(fields);
        let extras = n - 10;
        let most = self.layout.slots.len() + 9;
        let mut padded: Vec<&str> = fields.iter().map(field_name).collect();
        padded.resize(extras, "roughness");
        let padded = padded.join(",");
        let reading = if fields.is_empty() {
            "no known layout reads them all (--material-fields auto)".to_string()
        } else {
            format!("the numbers after m are read as --material-fields {field_list}")
        };
        let help = format!(
            "{reading}; this line has {extras}. Name them all with --material-fields (from \
             reflectivity, opacity, transparency, ior, roughness), e.g. \
             `--material-fields {padded}` (roughness is read and ignored)"
        );
        self.error(
            line,
            At::Span((3 + most).min(line.tokens.len() - 1), line.tokens.len() - 1),
            format!("too many numbers for a material: {n} (at most {most} with this layout)"),
            Some(help),
        )
    }

    /// A value that must lie in [0, 1]: clamped with a warning.
    fn unit_interval(&mut self, line: &Line, at: At, what: &str, value: f64) -> f32 {
        let clamped = limits::clamp_fraction(value);
        if clamped != value {
            self.warn(
                line,
                at,
                format!("{what} {value} is outside [0, 1]; clamped to {clamped}"),
                None,
            );
        }
        clamped as f32
    }
}

fn field_name(field: &MaterialField) -> &'static str {
    match field {
        MaterialField::Reflectivity => "reflectivity",
        MaterialField::Opacity => "opacity",
        MaterialField::Transparency => "transparency",
        MaterialField::Ior => "ior",
        MaterialField::Roughness => "roughness",
    }
}

fn field_names(fields: &[MaterialField]) -> String {
    if fields.is_empty() {
        "(none)".to_string()
    } else {
        fields.iter().map(field_name).collect::<Vec<_>>().join(",")
    }
}
