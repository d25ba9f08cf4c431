//! The checks that look at the tracks together: aims that fit (one per target, an object to
//! look at that exists), values that several tracks set and how they combine (`blend`), and
//! last keys that no frame shows.

use super::checker::{names_list, Checker};
use super::model::{Aim, AimTarget, Blend, Channel, SceneNames, TargetKind, Track};
use crate::keyframe::interp::Cycle;
use crate::keyframe::locate::{field, index};
use anim_core::diag::suggest;
use glam::DVec3;

impl Checker<'_> {
    /// Parents that can be followed: a thing of the base scene other than the target, the
    /// same for every track on a target, never round a loop; children placed by no composite
    /// (a composite's child follows the composite) and not the orbiting camera.
    pub(super) fn parents_fit(
        &mut self,
        tracks: &[Track],
        names: &dyn SceneNames,
        orbit_camera: Option<&str>,
    ) {
        for (k, track) in tracks.iter().enumerate() {
            let Some(parent) = &track.parent else {
                continue;
            };
            let at = [parent.path.as_str(), track.path.as_str()];
            let name = &parent.name;
            match names.kind_of(name) {
                _ if *name == track.target => {
                    self.err(&at, format!("'{name}' cannot follow itself"));
                    continue;
                }
                Some(TargetKind::Material) | None => {
                    let d = self.src.error(&at, format!("the base scene has no shape, composite, light or camera named '{name}' to follow"));
                    let d = match suggest(name, names.names()) {
                        Some(s) => d.with_help(format!("did you mean '{s}'?")),
                        None => d,
                    };
                    if !self.full() {
                        self.errors.push(d);
                    }
                    continue;
                }
                Some(_) => {}
            }
            if let Some(composite) = names.containers(&track.target).first() {
                self.err(
                    &at,
                    format!(
                        "'{}' is placed by composite '{composite}': give the composite the parent",
                        track.target
                    ),
                );
            }
            if orbit_camera == Some(track.target.as_str()) {
                self.err(
                    &at,
                    format!(
                        "camera '{}' follows the orbit; it cannot follow '{name}' too",
                        track.target
                    ),
                );
            }
            if orbit_camera == Some(name.as_str()) {
                self.err(
                    &at,
                    format!("'{name}' is the orbiting camera, which cannot lead others"),
                );
            }
            let other = tracks[..k].iter().filter_map(|t| {
                let p = t.parent.as_ref()?;
                (t.target == track.target && p.name != *name).then_some(t)
            });
            if let Some(first) = other.into_iter().next() {
                self.err(
                    &at,
                    format!(
                        "'{}' follows another parent in {} already",
                        track.target, first.path
                    ),
                );
            }
            // Round a loop: from the parent, follow parents until the target comes back.
            let parent_of = |n: &str| {
                tracks
                    .iter()
                    .find_map(|t| (t.target == n).then_some(t.parent.as_ref()?.name.as_str()))
            };
            let mut chain = vec![track.target.as_str(), name.as_str()];
            while let Some(next) = parent_of(chain[chain.len() - 1]) {
                if chain.len() > tracks.len() + 1 {
                    break;
                }
                chain.push(next);
                if next == track.target {
                    self.err(
                        &at,
                        format!("parents go round a loop: {}", chain.join(" → ")),
                    );
                    break;
                }
            }
        }
    }

    /// Tracks that set one value of one target say how they combine: without `blend`, a
    /// second track keying the same value is an error naming both. A `blend` must have a
    /// value to combine, and `visible` is shown or not: it only replaces.
    pub(super) fn layers_fit(&mut self, tracks: &[Track]) {
        for (k, track) in tracks.iter().enumerate() {
            let values = track.values();
            if let Some(blend) = track.blend {
                let at = field(&track.path, "blend");
                if values.is_empty() {
                    self.err(
                        &[&at, &track.path],
                        "`blend` combines the values a track sets (brightness, colours, fov, material values): motion from several tracks always composes in order".into(),
                    );
                }
                if blend != Blend::Replace && values.iter().any(|(n, _)| *n == "visible") {
                    self.err(
                        &[&at, &track.path],
                        format!("`visible` is shown or not: it cannot be combined by `{blend:?}` (use `Replace`)"),
                    );
                }
            }
            for (name, path) in values {
                let earlier = tracks[..k].iter().find(|t| {
                    t.target == track.target && t.values().iter().any(|(n, _)| *n == name)
                });
                if let (Some(first), None) = (earlier, track.blend) {
                    self.err(
                        &[path, &track.path],
                        format!(
                            "{} and {} both key the {name} of '{}': give {} a `blend` (Replace, Add or Multiply) to say how they combine",
                            first.path, track.path, track.target, track.path
                        ),
                    );
                }
            }
        }
    }

    /// What the aims need of the whole animation: an object to look at that exists, one aim
    /// per target, and a camera that no other track turns.
    pub(super) fn aims_fit(&mut self, tracks: &[Track], names: &dyn SceneNames) {
        for (i, track) in tracks.iter().enumerate() {
            let Some(aim) = &track.aim else {
                continue;
            };
            if let AimTarget::Object(name) = &aim.target {
                self.aimed_at(track, aim, name, names);
            }
            let same: Vec<&Track> = tracks.iter().filter(|t| t.target == track.target).collect();
            if tracks[..i]
                .iter()
                .any(|t| t.target == track.target && t.aim.is_some())
            {
                self.err(
                    &[&aim.path],
                    format!(
                        "'{}' has a `look_at` in an earlier track already",
                        track.target
                    ),
                );
            }
            // An aimed camera's eye moves by translations only: its pose is set outright.
            let camera = track.kind == TargetKind::Camera;
            let turned = same.iter().find(|t| {
                t.rotate.is_some() || t.orient.is_some() || (camera && t.scale.is_some())
            });
            if let Some(other) = turned.filter(|t| t.path != track.path) {
                self.err(
                    &[&other.path],
                    format!(
                        "'{}' looks at its target (`look_at` in {}): this track would turn it away",
                        track.target, track.path
                    ),
                );
            }
        }
    }

    fn aimed_at(&mut self, track: &Track, aim: &Aim, name: &str, names: &dyn SceneNames) {
        let at = [index(&aim.path, 0), aim.path.clone()];
        match names.kind_of(name) {
            _ if name == track.target => {
                self.err(&[&at[0], &at[1]], format!("'{name}' cannot look at itself"))
            }
            Some(TargetKind::Shape | TargetKind::Composite | TargetKind::Light) => {}
            Some(kind) => self.err(
                &[&at[0], &at[1]],
                format!(
                    "'{name}' is a {}: `look_at: Object(…)` follows a shape, composite or light",
                    kind.noun()
                ),
            ),
            None => {
                let objects: Vec<&str> = names
                    .names()
                    .into_iter()
                    .filter(|n| {
                        matches!(
                            names.kind_of(n),
                            Some(TargetKind::Shape | TargetKind::Composite)
                        )
                    })
                    .collect();
                let d = self.src.error(
                    &[&at[0], &at[1]],
                    format!("the base scene has no object named '{name}' to look at"),
                );
                let d = match suggest(name, objects.iter().copied()) {
                    Some(s) => d.with_help(format!("did you mean '{s}'?")),
                    None if objects.len() <= 12 && !objects.is_empty() => {
                        d.with_help(format!("its objects: {}", names_list(&objects)))
                    }
                    None => d,
                };
                if !self.full() {
                    self.errors.push(d);
                }
            }
        }
    }
}

impl Checker<'_> {
    /// Warns, at the key, of every last key that no frame shows: the last frame of a cyclic
    /// animation is one step before `length`. A channel that ends where it began is a loop,
    /// whose last key the next first frame shows, and is left alone.
    pub fn unshown_last_keys(
        &mut self,
        tracks: &[Track],
        ambient: &Option<Channel<DVec3>>,
        background: &Option<Channel<DVec3>>,
        last_frame: f64,
    ) {
        let mut late = Vec::new();
        never_shown(&mut late, ambient, last_frame);
        never_shown(&mut late, background, last_frame);
        for t in tracks {
            never_shown(&mut late, &t.translate, last_frame);
            // A turn that ends a whole number of turns from where it began is back at its start.
            let whole_turns = t
                .rotate
                .as_ref()
                .and_then(|c| Some((c.keys.last()?.value - c.keys.first()?.value) % 360.0 == 0.0));
            if whole_turns != Some(true) {
                never_shown(&mut late, &t.rotate, last_frame);
            }
            never_shown(&mut late, &t.scale, last_frame);
            never_shown(&mut late, &t.brightness, last_frame);
            never_shown(&mut late, &t.color, last_frame);
            never_shown(&mut late, &t.fov, last_frame);
            never_shown(&mut late, &t.visible, last_frame);
            let m = &t.material;
            for c in [&m.ka, &m.kd, &m.ks] {
                never_shown(&mut late, c, last_frame);
            }
            for c in [&m.reflectivity, &m.opacity, &m.ior] {
                never_shown(&mut late, c, last_frame);
            }
            if let Some(aim) = &t.aim {
                never_shown(&mut late, &aim.roll, last_frame);
                if let AimTarget::Keys(k) = &aim.target {
                    never_shown(&mut late, &Some(k.clone()), last_frame);
                }
            }
            if let Some(o) = &t.orient {
                let ends = o.keys.first().zip(o.keys.last());
                let returns = ends.is_some_and(|(a, b)| a.value.abs_diff_eq(b.value, 1e-12));
                let shown = o.orientation(last_frame) == o.keys.last().map(|k| k.value);
                if let Some(last) = o.keys.last().filter(|_| !returns && !shown) {
                    let played = last.at + o.timing.offset;
                    if o.timing.cycle == Cycle::Hold && played > last_frame + 1e-9 {
                        late.push((index(&o.path, o.keys.len() - 1), played));
                    }
                }
            }
        }
        for (path, at) in late {
            let at_path = field(&path, "at");
            self.warn(
                &[&at_path, &path],
                format!(
                    "this key at {} s comes after the last frame ({} s), so no frame shows it",
                    crate::keyframe::tidy::tidy(at),
                    crate::keyframe::tidy::tidy(last_frame)
                ),
            );
            if let Some(w) = self.warnings.pop() {
                self.warnings.push(w.with_help(
                    "`end: Inclusive` adds a frame at `length` that shows the last keys; the default, `end: Cyclic`, stops one frame short so that loops do not show one pose twice",
                ));
            }
        }
    }
}

/// Adds channel `c`'s last key to `late` if no frame up to `last_frame` shows it.
fn never_shown<T: crate::keyframe::interp::Keyable + PartialEq>(
    late: &mut Vec<(String, f64)>,
    c: &Option<Channel<T>>,
    last_frame: f64,
) {
    // An expression shows on every frame whatever its keys do.
    let Some(c) = c.as_ref().filter(|c| c.expr.is_none()) else {
        return;
    };
    let (Some(first), Some(last)) = (c.keys.first(), c.keys.last()) else {
        return;
    };
    let played = last.at + c.timing.offset;
    let loops_back = c.keys.len() > 1 && first.value == last.value;
    if c.timing.cycle != Cycle::Hold || played <= last_frame + 1e-9 || loops_back {
        return;
    }
    if c.at(last_frame) != Some(last.value) {
        late.push((index(&c.path, c.keys.len() - 1), played));
    }
}
