//! The checks of a light's radius and spot cone and of a camera's lens: the values, that a
//! cone is keyed only on a spot, that a lens has a focus, and what `focus: Object(…)` names.

use super::checker::{non_negative, positive, Checker, ValueCheck};
use super::model::{Focus, OpticsChannels, SceneNames, TargetKind};
use super::track::{target_name, Sources};
use crate::keyframe::interp::Timing;
use crate::keyframe::locate::index;
use anim_core::diag::suggest;
use glam::DVec3;

fn half_angle(v: DVec3) -> Option<String> {
    (!(0.0..=180.0).contains(&v.x)).then(|| "must lie from 0 to 180 degrees".to_string())
}

impl Checker<'_> {
    /// A light's `radius`, `inner` and `outer`, a camera's `aperture` and `focus`; `layered`
    /// values (added or multiplied) are checked once combined, as frames write them.
    pub(super) fn optics(
        &mut self,
        s: &Sources,
        timing: Timing,
        names: &dyn SceneNames,
        layered: bool,
        kind: Option<TargetKind>,
    ) -> OpticsChannels {
        let check = |c: ValueCheck| (!layered).then_some(c);
        let target = target_name(s.track);
        let radius = self.value(
            s,
            names,
            "radius",
            |t| &t.radius,
            timing,
            check(non_negative),
        );
        let angle = check(half_angle);
        let inner = self.value(s, names, "inner", |t| &t.inner, timing, angle);
        let outer = self.value(s, names, "outer", |t| &t.outer, timing, angle);
        let spot = names.base_value(target, "inner").is_some();
        for (name, c) in [("inner", &inner), ("outer", &outer)] {
            if let Some(c) = c
                .as_ref()
                .filter(|_| kind == Some(TargetKind::Light) && !spot)
            {
                self.err(
                    &[&c.path],
                    format!("'{target}' is no spot light: `{name}` keys a spot's cone (give its line `spot [target] <inner-deg> <outer-deg>`)"),
                );
            }
        }
        let aperture = self.value(
            s,
            names,
            "aperture",
            |t| &t.aperture,
            timing,
            check(non_negative),
        );
        let focus = self.focus(s, timing, names, check(positive));
        let has_lens = names.base_value(target, "focus").is_some();
        if let Some(c) = aperture.as_ref().filter(|_| focus.is_none() && !has_lens) {
            if kind == Some(TargetKind::Camera) {
                self.err(
                    &[&c.path],
                    format!("camera '{target}' has no lens line to focus it: key its `focus` too (a distance or `Object(\"name\")`)"),
                );
            }
        }
        OpticsChannels {
            radius,
            inner,
            outer,
            aperture,
            focus,
        }
    }

    /// `focus`: keys or an expression of the distance, or `Object("name")`, a shape or
    /// composite of the base scene.
    fn focus(
        &mut self,
        s: &Sources,
        timing: Timing,
        names: &dyn SceneNames,
        check: Option<ValueCheck>,
    ) -> Option<Focus> {
        let (spec, path) = s.spec("focus", |t| &t.focus);
        if self.src.locations.variant(&path) != Some("Object") {
            let distance = self.value(s, names, "focus", |t| &t.focus, timing, check)?;
            return Some(Focus::Distance(distance));
        }
        let name = spec.expr.clone().unwrap_or_default();
        if !spec.keys.is_empty() {
            self.err(
                &[&path],
                "`focus: Object(\"name\")` takes the name alone: the distance follows the object"
                    .into(),
            );
        }
        if !matches!(
            names.kind_of(&name),
            Some(TargetKind::Shape | TargetKind::Composite)
        ) && !self.full()
        {
            let d = self.src.error(
                &[&index(&path, 0), &path],
                format!("the base scene has no shape or composite named '{name}' to focus on"),
            );
            let d = match suggest(&name, names.names()) {
                Some(n) => d.with_help(format!("did you mean '{n}'?")),
                None => d,
            };
            self.errors.push(d);
        }
        Some(Focus::Object { name, path })
    }
}
