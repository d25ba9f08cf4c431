//! `define material`: colours, the Phong exponent, and the extras named by
//! `--material-fields`.

use super::{At, PResult, Parser};
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
        let nums = self.numbers(line, 3, toks.len())?;
        let opts = self.opts;
        let fields = &opts.material_fields;
        let field_list = field_names(fields);
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
        let extras = nums.len() - 10;
        if extras > fields.len() {
            let first_surplus = 3 + 10 + fields.len();
            // The current list, padded with the ignored field to the count on this line.
            let mut padded: Vec<&str> = fields.iter().map(field_name).collect();
            padded.resize(extras, "roughness");
            let padded = padded.join(",");
            let help = format!(
                "the numbers after m are read as --material-fields {field_list}; this line has {extras}. \
                 Name them all with --material-fields (from reflectivity, opacity, transparency, ior, \
                 roughness), e.g. `--material-fields {padded}` (roughness is read and ignored)"
            );
            return Err(self.error(
                line,
                At::Span(first_surplus, toks.len() - 1),
                format!(
                    "too many numbers for a material: {} (at most {} with --material-fields {field_list})",
                    nums.len(),
                    10 + fields.len()
                ),
                Some(help),
            ));
        }
        let c3 = |i: usize| Vec3::new(nums[i] as f32, nums[i + 1] as f32, nums[i + 2] as f32);
        let mut def = MaterialDef {
            name,
            ka: c3(0),
            kd: c3(3),
            ks: c3(6),
            m: nums[9] as f32,
            reflectivity: 0.0,
            opacity: 1.0,
            ior: repair::AIR_IOR,
        };
        if def.m < 0.0 {
            self.warn(
                line,
                At::Tok(12),
                format!(
                    "the Phong exponent m must not be negative, found {}; its absolute value is used",
                    nums[9]
                ),
                None,
            );
            def.m = repair::phong_exponent(def.m);
        } else if def.m == 0.0 {
            // Kept: pow(x, 0) = 1 is well defined, and it is what the file's own renderer drew.
            self.warn(
                line,
                At::Tok(12),
                "the Phong exponent m is 0: the highlight covers the whole lit side",
                Some("m is usually between 1 (dull) and a few hundred (sharp)".to_string()),
            );
        }
        let mut opacity_at = None;
        for (k, field) in fields.iter().enumerate().take(extras) {
            let value = nums[10 + k];
            let at = At::Tok(13 + k);
            match field {
                MaterialField::Reflectivity => {
                    def.reflectivity = self.unit_interval(line, at, "reflectivity", value);
                }
                MaterialField::Opacity => {
                    def.opacity = self.unit_interval(line, at, "opacity", value);
                    opacity_at = Some(at);
                }
                MaterialField::Transparency => {
                    def.opacity = 1.0 - self.unit_interval(line, at, "transparency", value);
                }
                MaterialField::Ior => match repair::usable_ior(value) {
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
                MaterialField::Roughness => {}
            }
        }
        if let Some(at) = opacity_at.filter(|_| def.opacity == 0.0 && def.ior == 1.0) {
            // Fully transparent without refraction: invisible. Many files mean transparency
            // by this number (0 = opaque), and this is the symptom. Said once per file.
            self.warn_once(
                line,
                at,
                "invisible-material",
                format!(
                    "material `{}` is invisible: fully transparent (opacity 0) and not refracting (ior 1)",
                    def.name
                ),
                "if this file means transparency by this number, load it with \
                 --material-fields reflectivity,transparency,ior"
                    .to_string(),
            );
        }
        self.emit_named(line, 2, StatementKind::Material(def));
        Ok(())
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
