//! `--material-fields auto`: which layout of the numbers after the colours a file's materials
//! use, inferred from how plausible each candidate makes every material of the file
//! (`docs/scene-language.md §3.1`).
//!
//! Files written for different course renderers put the extras in different orders (and some
//! put `m` last); read with the wrong order, glass becomes a mirror or an object disappears.
//! Each candidate is scored by the values it gives: fractions in [0, 1], an index of
//! refraction in [1, 3], a Phong exponent of at least 1. The best wins; a tie goes to the
//! default layout, so files every layout reads alike are read as before.

use crate::sdf::MaterialField;

/// One number of a material after its nine colour numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Slot {
    /// The Phong exponent.
    M,
    Field(MaterialField),
    /// A glossiness or roughness number: read and ignored (with a warning).
    Gloss,
}

/// A way to read the numbers after the colours.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Layout {
    /// In order. When `m_last`, `M` is the last slot and a line must have all of them (or
    /// only `m`); otherwise a line may stop after any slot.
    pub(super) slots: Vec<Slot>,
    pub(super) m_last: bool,
    /// Fractions (reflectivity, opacity, transparency) written on a 0–100 scale.
    pub(super) percent: bool,
}

use MaterialField::{Ior as I, Opacity as O, Reflectivity as R, Transparency as T};
use Slot::{Field as F, Gloss as G, M};

/// Every layout seen in the documentation and the corpus, the default first (it wins ties),
/// then by how common they are.
const CANDIDATES: &[(&[Slot], bool)] = &[
    (&[M, F(R), F(O), F(I)], false),
    (&[M, F(R), F(T), F(I)], false),
    (&[M, F(I), F(O)], false),
    (&[M, F(I), F(T)], false),
    (&[M, F(O), F(I)], false),
    (&[M, F(T), F(I)], false),
    (&[M, F(R), F(I), F(O)], false),
    (&[M, F(R), F(I), F(T)], false),
    (&[M, F(R), F(O), F(I), G], false),
    (&[M, F(R), F(T), F(I), G], false),
    (&[M, F(O), F(R), F(I), G], false),
    (&[M, G, F(I), F(T)], false),
    (&[M, G, F(I), F(O)], false),
    (&[M, G, F(O), F(I)], false),
    (&[M, F(O), G, F(I)], false),
    (&[M, F(T), F(I), G], false),
    (&[F(R), F(I), M], true),
    (&[F(R), F(I), F(O), M], true),
    (&[F(R), F(I), F(T), M], true),
    (&[F(R), F(O), F(I), M], true),
];

/// Score subtracted from a reading as percentages: scaling every fraction by 1/100 makes
/// most numbers look like fractions, so it must win clearly.
const PERCENT_HANDICAP: f64 = 0.5;

/// Opacity below this leaves a non-refracting material all but invisible.
const NEARLY_INVISIBLE: f64 = 0.05;

/// The reading of `--material-fields reflectivity,opacity,ior`.
pub(super) fn default_layout() -> Layout {
    Layout::new(CANDIDATES[0].0, false, false)
}

impl Layout {
    fn new(slots: &[Slot], m_last: bool, percent: bool) -> Self {
        Layout {
            slots: slots.to_vec(),
            m_last,
            percent,
        }
    }

    /// The layout an explicit `--material-fields` list names: `m` then the list.
    pub(super) fn explicit(fields: &[MaterialField]) -> Self {
        let mut slots = vec![M];
        slots.extend(fields.iter().map(|&f| F(f)));
        Layout::new(&slots, false, false)
    }

    /// What each number after the colours of a line with `count` of them means; `None` if
    /// this layout cannot read such a line.
    pub(super) fn read(&self, count: usize) -> Option<&[Slot]> {
        if count == 0 {
            return None;
        }
        if self.m_last {
            return match count {
                1 => Some(&[M]),
                n if n == self.slots.len() => Some(&self.slots),
                _ => None,
            };
        }
        self.slots.get(..count)
    }

    pub(super) fn has_gloss(&self) -> bool {
        self.slots.contains(&G)
    }

    /// The layout as words, e.g. `m reflectivity ior transparency` (percentages noted).
    pub(super) fn describe(&self) -> String {
        let words: Vec<&str> = self.slots.iter().map(|s| slot_name(*s)).collect();
        let mut text = words.join(" ");
        if self.percent {
            text.push_str(" (fractions as percentages)");
        }
        text
    }

    /// The `--material-fields` list that forces this layout, when one can (`m` first).
    pub(super) fn flag(&self) -> Option<String> {
        if self.m_last || self.percent {
            return None;
        }
        let fields: Vec<&str> = self.slots[1..]
            .iter()
            .map(|s| match s {
                G => "roughness",
                other => slot_name(*other),
            })
            .collect();
        Some(fields.join(","))
    }

    /// The value a slot's number stands for (percentages scaled to fractions).
    pub(super) fn value(&self, slot: Slot, v: f64) -> f64 {
        match slot {
            F(R | O | T) if self.percent => v / 100.0,
            _ => v,
        }
    }
}

pub(super) fn slot_name(s: Slot) -> &'static str {
    match s {
        M => "m",
        G => "glossiness",
        F(R) => "reflectivity",
        F(O) => "opacity",
        F(T) => "transparency",
        F(I) => "ior",
        F(MaterialField::Roughness) => "roughness",
    }
}

/// How plausible `layout` makes one material whose numbers after the colours are `extras`;
/// `None` if the layout cannot read it.
fn score_material(layout: &Layout, extras: &[f64]) -> Option<f64> {
    let slots = layout.read(extras.len())?;
    let mut score = 0.0;
    let (mut opacity, mut ior) = (1.0, 1.0);
    for (&slot, &raw) in slots.iter().zip(extras) {
        let v = layout.value(slot, raw);
        score += match slot {
            // A Phong exponent is at least 1 and usually large.
            M if v >= 5.0 => 1.5,
            M if v >= 1.0 => 1.0,
            M if v >= 0.0 => -1.0,
            M => -2.0,
            F(f) => {
                let fraction = (0.0..=1.0).contains(&v);
                match f {
                    O => opacity = v,
                    T => opacity = 1.0 - v,
                    // The reader repairs an unusable index to air's.
                    I => ior = if v > 0.0 { v } else { 1.0 },
                    R | MaterialField::Roughness => {}
                }
                let raw_fraction = raw > 0.0 && raw <= 1.0;
                match f {
                    // "1 %" or "0.5 %" is not how percentages are written: these numbers are
                    // fractions, and the file is not on a 0–100 scale.
                    R | O | T if layout.percent && raw_fraction => -1.0,
                    R | O | T | MaterialField::Roughness if fraction => 1.0,
                    R | O | T | MaterialField::Roughness => -3.0,
                    // 0 is often written for "no refraction".
                    I if v == 0.0 => -0.5,
                    I if (1.0..=3.0).contains(&v) => 1.0,
                    I => -2.0,
                }
            }
            // Data thrown away: a layout that uses the number is preferred.
            G if (0.0..=1000.0).contains(&v) => -0.25,
            G => -1.0,
        };
    }
    // A material nobody can see is almost never what the author meant.
    // (The shading model weighs the mirror term by the opacity, so reflectivity does not
    // make a transparent material visible.)
    if opacity < NEARLY_INVISIBLE && (ior - 1.0).abs() < 1e-9 {
        score -= 2.0;
    }
    Some(score)
}

/// The total score of `layout` over every material, `None` if it cannot read one of them.
fn score(layout: &Layout, materials: &[Vec<f64>]) -> Option<f64> {
    let total: f64 = materials
        .iter()
        .map(|e| score_material(layout, e))
        .sum::<Option<f64>>()?;
    // One perfect mirror is a common showpiece; a file of mostly perfect mirrors is a file
    // read in the wrong layout.
    let mirrors = materials
        .iter()
        .filter(|e| perfect_mirror(layout, e))
        .count();
    if materials.len() >= 2 && 2 * mirrors > materials.len() {
        return Some(total - MIRROR_FILE_PENALTY * mirrors as f64);
    }
    Some(total)
}

/// Whether `layout` reads the material as a mirror that shows almost nothing of its own
/// colour (reflectivity [`NEAR_PERFECT_MIRROR`] or more): in a file of such mirrors the
/// image is the mirrors showing each other, black.
fn perfect_mirror(layout: &Layout, extras: &[f64]) -> bool {
    layout.read(extras.len()).is_some_and(|slots| {
        slots
            .iter()
            .zip(extras)
            .any(|(&slot, &v)| slot == F(R) && layout.value(slot, v) >= NEAR_PERFECT_MIRROR)
    })
}

/// Reflectivity from which a mirror counts as perfect for the layout's plausibility: a
/// 0.999 column read as reflectivity leaves a surface a thousandth of its colour.
const NEAR_PERFECT_MIRROR: f64 = 0.99;

/// Score taken per perfect mirror from a reading that makes most of a file's materials ones.
const MIRROR_FILE_PENALTY: f64 = 2.0;

/// The best layout for the materials (each given by its numbers after the nine colours) and
/// whether it differs from the default. `None` when no candidate reads every material (the
/// default then reports what is wrong).
pub(super) fn infer(materials: &[Vec<f64>]) -> Option<Layout> {
    let mut best: Option<(f64, Layout)> = None;
    // Percentages only when plain fractions read worse: tried last, with a small handicap.
    for percent in [false, true] {
        for &(slots, m_last) in CANDIDATES {
            let layout = Layout::new(slots, m_last, percent);
            if percent && !uses_percentages(&layout, materials) {
                continue;
            }
            let Some(mut s) = score(&layout, materials) else {
                continue;
            };
            if percent {
                s -= PERCENT_HANDICAP;
            }
            // Strictly better only: ties keep the earlier candidate (the default first).
            if best.as_ref().is_none_or(|(b, _)| s > *b + 1e-9) {
                best = Some((s, layout));
            }
        }
    }
    best.map(|(_, l)| l)
}

/// Whether some fraction of the file is above 1 (so a 0–100 scale is worth trying), and none
/// above 100.
fn uses_percentages(layout: &Layout, materials: &[Vec<f64>]) -> bool {
    let mut above_one = false;
    for extras in materials {
        let Some(slots) = layout.read(extras.len()) else {
            return false;
        };
        for (&slot, &v) in slots.iter().zip(extras) {
            if matches!(slot, F(R | O | T)) {
                if !(0.0..=100.0).contains(&v) {
                    return false;
                }
                above_one |= v > 1.0;
            }
        }
    }
    above_one
}

#[cfg(test)]
mod tests {
    use super::*;

    fn best(materials: &[&[f64]]) -> Layout {
        let m: Vec<Vec<f64>> = materials.iter().map(|e| e.to_vec()).collect();
        infer(&m).expect("a layout")
    }

    fn names(l: &Layout) -> String {
        l.describe()
    }

    #[test]
    fn plain_materials_keep_the_default() {
        assert_eq!(best(&[&[20.0], &[100.0]]), default_layout());
        assert_eq!(best(&[&[20.0, 0.5, 1.0, 1.0]]), default_layout());
    }

    #[test]
    fn a_file_of_near_perfect_mirrors_is_read_another_way() {
        // A 0.999 column read as reflectivity would leave every surface a mirror of black;
        // read as opacity, the surfaces show their colours.
        let l = best(&[&[20.0, 0.999], &[50.0, 0.999], &[10.0, 0.999]]);
        assert!(!names(&l).starts_with("m reflectivity"), "{}", names(&l));
        // One such mirror among plain materials is a showpiece, read as written.
        assert_eq!(
            best(&[&[20.0, 0.999], &[50.0, 0.2], &[10.0, 0.0]]),
            default_layout()
        );
    }

    #[test]
    fn a_tie_goes_to_the_default() {
        // 0.5 reads as well as reflectivity as as opacity.
        assert_eq!(best(&[&[10.0, 0.5]]), default_layout());
    }

    #[test]
    fn ior_then_opacity_after_m() {
        let l = best(&[&[20.0, 1.5, 0.5], &[10.0, 1.0, 1.0]]);
        assert_eq!(names(&l), "m ior opacity");
        assert_eq!(l.flag().as_deref(), Some("ior,opacity"));
    }

    #[test]
    fn reflectivity_ior_transparency() {
        let l = best(&[&[50.0, 0.2, 1.5, 0.0], &[50.0, 0.0, 1.0, 0.0]]);
        assert_eq!(names(&l), "m reflectivity ior transparency");
    }

    #[test]
    fn mirror_ior_opacity() {
        let l = best(&[&[50.0, 0.2, 1.5, 1.0], &[50.0, 0.9, 1.3, 0.5]]);
        assert_eq!(names(&l), "m reflectivity ior opacity");
    }

    #[test]
    fn m_last_with_a_small_tenth_number() {
        let l = best(&[&[0.3, 1.0, 0.0, 60.0], &[0.0, 1.0, 0.0, 100.0]]);
        assert!(l.m_last, "{l:?}");
        assert_eq!(l.flag(), None);
    }

    #[test]
    fn fourteen_numbers_read_with_a_glossiness_field() {
        let l = best(&[&[30.0, 0.1, 1.0, 1.0, 0.5]]);
        assert!(l.has_gloss() || l.slots.len() == 5, "{l:?}");
        assert!(l.read(5).is_some());
    }

    #[test]
    fn opacity_written_as_transparency() {
        // Every material fully "transparent" without refraction under the default reading.
        let l = best(&[&[20.0, 0.0, 0.0, 1.0], &[20.0, 0.2, 0.0, 1.0]]);
        assert_eq!(names(&l), "m reflectivity transparency ior");
    }

    #[test]
    fn percentages() {
        let l = best(&[&[20.0, 50.0, 100.0, 1.0], &[20.0, 0.0, 100.0, 1.5]]);
        assert!(l.percent, "{l:?}");
        assert_eq!(l.value(Slot::Field(R), 50.0), 0.5);
    }

    #[test]
    fn unreadable_counts_leave_no_layout() {
        assert_eq!(infer(&[vec![1.0; 9]]), None);
    }
}
