//! The checks of tracks and named curves: each channel's keys, what the target is and which
//! channels fit it, the timing of the keys, orientations and aims.

use super::checker::{
    non_negative, non_negative3, non_zero3, number, positive, rgb, unit_interval, valid_fov,
    ChannelAt, Checker, ValueCheck,
};
use super::model::{
    Aim, AimTarget, Blend, Channel, Follow, MaterialChannels, OrientChannel, Parent, SceneNames,
    TargetKind, Track,
};
use super::raw::{AimSpec, ChannelSpec, KeySpec, Orientation, Scale, SpecFile, TrackSpec, V3};
use crate::keyframe::bounds::{self, shown};
use crate::keyframe::expr::Val;
use crate::keyframe::interp::{Cycle, Interp, Key, Timing};
use crate::keyframe::locate::{field, index};
use crate::keyframe::rotation::{euler, EulerOrder};
use anim_core::diag::suggest;
use glam::{DQuat, DVec3};

/// Where a track's channels come from: its own keys, else those of the curve it uses.
pub(super) struct Sources<'s> {
    pub(super) track: &'s TrackSpec,
    pub(super) path: String,
    pub(super) curve: Option<(&'s TrackSpec, String)>,
}

impl<'s> Sources<'s> {
    /// Channel `name` as written (keys, an expression, or both) and its path in the spec: the
    /// track's own, else its curve's.
    pub(super) fn spec<S>(
        &self,
        name: &str,
        get: impl Fn(&'s TrackSpec) -> &'s ChannelSpec<S>,
    ) -> (&'s ChannelSpec<S>, String) {
        let own = get(self.track);
        match &self.curve {
            Some((curve, path)) if own.is_empty() => (get(curve), field(path, name)),
            _ => (own, field(&self.path, name)),
        }
    }

    /// The keys of channel `name` and their path in the spec.
    fn keys<S>(
        &self,
        name: &str,
        get: impl Fn(&'s TrackSpec) -> &'s [KeySpec<S>],
    ) -> (&'s [KeySpec<S>], String) {
        let own = get(self.track);
        match &self.curve {
            Some((curve, path)) if own.is_empty() => (get(curve), field(path, name)),
            _ => (own, field(&self.path, name)),
        }
    }

    /// A per-track setting: the track's own, else its curve's.
    pub(super) fn setting<T>(
        &self,
        get: impl Fn(&'s TrackSpec) -> Option<T>,
    ) -> Option<(T, String)> {
        get(self.track).map(|v| (v, self.path.clone())).or_else(|| {
            let (curve, path) = self.curve.as_ref()?;
            get(curve).map(|v| (v, path.clone()))
        })
    }

    pub(super) fn either(&self, keyed: impl Fn(&TrackSpec) -> bool) -> bool {
        keyed(self.track) || self.curve.as_ref().is_some_and(|(c, _)| keyed(c))
    }
}

/// Which channels a kind of target accepts, by field name.
fn fits(kind: TargetKind, channel: &str) -> bool {
    const MOTION: [&str; 7] = [
        "translate",
        "path",
        "rotate",
        "scale",
        "orient",
        "pivot",
        "parent",
    ];
    let moving = MOTION.contains(&channel);
    match kind {
        TargetKind::Shape | TargetKind::Composite => {
            moving || matches!(channel, "look_at" | "visible")
        }
        TargetKind::Camera => moving || matches!(channel, "look_at" | "fov" | "aperture" | "focus"),
        TargetKind::Light => {
            moving
                || matches!(
                    channel,
                    "brightness" | "color" | "radius" | "inner" | "outer"
                )
        }
        TargetKind::Material => matches!(
            channel,
            "ka" | "kd" | "ks" | "reflectivity" | "opacity" | "ior"
        ),
    }
}

/// The kinds that accept a channel, for messages.
fn kinds_for(channel: &str) -> String {
    let kinds = [
        TargetKind::Shape,
        TargetKind::Composite,
        TargetKind::Camera,
        TargetKind::Light,
        TargetKind::Material,
    ];
    let nouns: Vec<String> = kinds
        .into_iter()
        .filter(|k| fits(*k, channel))
        .map(|k| format!("{}s", k.noun()))
        .collect();
    match nouns.as_slice() {
        [one] => one.clone(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
        [] => String::new(),
    }
}

/// Every channel field of a track, with whether it keys anything.
fn keyed_channels(t: &TrackSpec) -> [(&'static str, bool); 24] {
    [
        ("translate", !t.translate.is_empty()),
        ("path", t.path.is_some()),
        ("rotate", !t.rotate.is_empty()),
        ("scale", !t.scale.is_empty()),
        ("orient", !t.orient.is_empty()),
        ("look_at", t.look_at.is_some()),
        ("brightness", !t.brightness.is_empty()),
        ("color", !t.color.is_empty()),
        ("fov", !t.fov.is_empty()),
        ("radius", !t.radius.is_empty()),
        ("inner", !t.inner.is_empty()),
        ("outer", !t.outer.is_empty()),
        ("aperture", !t.aperture.is_empty()),
        ("focus", !t.focus.is_empty()),
        ("ka", !t.ka.is_empty()),
        ("kd", !t.kd.is_empty()),
        ("ks", !t.ks.is_empty()),
        ("reflectivity", !t.reflectivity.is_empty()),
        ("opacity", !t.opacity.is_empty()),
        ("ior", !t.ior.is_empty()),
        ("visible", !t.visible.is_empty()),
        ("roll", !t.roll.is_empty()),
        ("pivot", t.pivot.is_some()),
        ("parent", t.parent.is_some()),
    ]
}

impl Checker<'_> {
    /// Every track whose target exists, checked; the curves checked where they are used.
    pub fn tracks(
        &mut self,
        spec: &SpecFile,
        names: &dyn SceneNames,
        orbit_camera: Option<&str>,
    ) -> Vec<Track> {
        let curves = self.curve_names(spec);
        let tracks: Vec<Track> = spec
            .tracks
            .iter()
            .enumerate()
            .filter_map(|(i, t)| {
                let path = index("tracks", i);
                let curve = self.used_curve(t, &path, spec, &curves);
                let sources = Sources {
                    track: t,
                    path,
                    curve,
                };
                self.track(&sources, spec.looping, names, orbit_camera)
            })
            .collect();
        self.aims_fit(&tracks, names);
        self.layers_fit(&tracks);
        self.parents_fit(&tracks, names, orbit_camera);
        tracks
    }

    /// The curves' names, each checked; a curve with no name cannot be used.
    fn curve_names(&mut self, spec: &SpecFile) -> Vec<Option<String>> {
        let mut seen: Vec<Option<String>> = Vec::new();
        for (i, c) in spec.curves.iter().enumerate() {
            let path = index("curves", i);
            if c.target.is_some() {
                self.err(
                    &[&field(&path, "target"), &path],
                    "a curve has a `name`, not a `target`: tracks name their targets and use the curve with `curve: \"…\"`".into(),
                );
            }
            if c.curve.is_some() {
                self.err(
                    &[&field(&path, "curve"), &path],
                    "a curve cannot use another curve".into(),
                );
            }
            match &c.name {
                None => self.err(&[&path], "this curve has no `name`".into()),
                Some(n) if seen.iter().flatten().any(|s| s == n) => self.err(
                    &[&field(&path, "name"), &path],
                    format!("a curve named '{n}' is defined already"),
                ),
                Some(_) => {}
            }
            seen.push(c.name.clone());
        }
        seen
    }

    /// The curve track `t` uses, with its path.
    fn used_curve<'s>(
        &mut self,
        t: &TrackSpec,
        path: &str,
        spec: &'s SpecFile,
        curves: &[Option<String>],
    ) -> Option<(&'s TrackSpec, String)> {
        let name = t.curve.as_ref()?;
        match curves.iter().position(|c| c.as_deref() == Some(name)) {
            Some(i) => Some((&spec.curves[i], index("curves", i))),
            None => {
                let d = self.src.error(
                    &[&field(path, "curve"), path],
                    format!("the spec defines no curve named '{name}'"),
                );
                let known = curves.iter().flatten().map(String::as_str);
                let d = match suggest(name, known) {
                    Some(s) => d.with_help(format!("did you mean '{s}'?")),
                    None => d.with_help("define it under `curves: [(name: \"…\", …)]`"),
                };
                if !self.full() {
                    self.errors.push(d);
                }
                None
            }
        }
    }

    /// A track, if its target exists.
    fn track(
        &mut self,
        s: &Sources,
        default_looping: bool,
        names: &dyn SceneNames,
        orbit_camera: Option<&str>,
    ) -> Option<Track> {
        let t = s.track;
        let path = s.path.clone();
        if t.name.is_some() {
            self.err(
                &[&field(&path, "name"), &path],
                "`name` belongs to curves: a track says which thing it moves with `target`".into(),
            );
        }
        let kind = self.target_kind(t, &path, names).map(|kind| {
            // A material that shares its name with a thing: a track that keys only
            // material channels means the material.
            let keyed = keyed_channels(t).into_iter().filter(|(_, k)| *k);
            let material_only = keyed.clone().count() > 0
                && keyed
                    .into_iter()
                    .all(|(c, _)| fits(TargetKind::Material, c));
            if material_only && names.has_material(target_name(t)) {
                TargetKind::Material
            } else {
                kind
            }
        });
        let timing = self.timing(s, default_looping);
        let motion = |c: &mut Self, name: &str, get: fn(&TrackSpec) -> &ChannelSpec<_>| {
            let (spec, path) = s.spec(name, get);
            let at = ChannelAt::new(&path, target_name(t), name, Val::Vec(DVec3::ZERO));
            c.keyed(spec, at, timing, |v: &V3| v.0, None)
        };
        let translate = motion(self, "translate", |t| &t.translate);
        let (spec, at_path) = s.spec("rotate", |t| &t.rotate);
        let at = ChannelAt::new(&at_path, target_name(t), "rotate", Val::Num(0.0));
        let rotate = self.keyed(spec, at, timing, number, None);
        let (spec, at_path) = s.spec("scale", |t| &t.scale);
        let at = ChannelAt::new(&at_path, target_name(t), "scale", Val::Vec(DVec3::ONE));
        let scale = self.keyed(spec, at, timing, |v: &Scale| v.0, Some(non_zero3));
        let orient = self.orient(s, timing);
        let path_motion = self.path_motion(s, timing);
        let along_path = self.along_path(s, kind);
        let aim = self.aim(s, timing, kind);
        // Values added to or multiplied with others may leave their range alone: what the
        // frames carry is checked once combined.
        let layered = matches!(
            s.setting(|t| t.blend),
            Some((Blend::Add | Blend::Multiply, _))
        );
        let (brightness, color, fov) = self.parameters(s, timing, names, layered);
        let material = self.material(s, timing, names, layered);
        let optics = self.optics(s, timing, names, layered, kind);
        let visible = self.visible(s, timing);
        let axis = self.axis_and_pivot(s);
        if !keyed_channels(t).iter().any(|(_, keyed)| *keyed) && s.curve.is_none() {
            self.err(
                &[&field(&path, "target"), &path],
                format!("the track for '{}' keys nothing", target_name(t)),
            );
        }
        let kind = kind?;
        self.channels_fit(s, kind);
        if kind == TargetKind::Camera && orbit_camera == t.target.as_deref() {
            self.not_moved_off_orbit(s);
        }
        Some(Track {
            target: target_name(t).to_string(),
            kind,
            blend: s.setting(|t| t.blend).map(|(b, _)| b),
            translate,
            rotate,
            axis,
            scale,
            pivot: s.setting(|t| t.pivot).map(|(p, _)| p.0),
            brightness,
            color,
            fov,
            orient,
            travel: path_motion,
            along_path,
            parent: s.setting(|t| t.parent.clone()).map(|(name, p)| Parent {
                name,
                follow: s.setting(|t| t.follow.clone()).map_or(
                    vec![Follow::Translate, Follow::Rotate, Follow::Scale],
                    |(f, _)| f,
                ),
                path: field(&p, "parent"),
            }),
            aim,
            material,
            optics,
            visible,
            path,
        })
    }

    /// Light and camera parameters: brightness, colour, field of view.
    #[allow(clippy::type_complexity)]
    fn parameters(
        &mut self,
        s: &Sources,
        timing: Timing,
        names: &dyn SceneNames,
        layered: bool,
    ) -> (
        Option<Channel<f64>>,
        Option<Channel<DVec3>>,
        Option<Channel<f64>>,
    ) {
        let check = |c: ValueCheck| (!layered).then_some(c);
        let brightness = self.value(
            s,
            names,
            "brightness",
            |t| &t.brightness,
            timing,
            check(non_negative),
        );
        let (spec, path) = s.spec("color", |t| &t.color);
        let at = self.base_of(s, names, &path, "color");
        let color = self.keyed(spec, at, timing, rgb, check(non_negative3));
        let fov = self.value(s, names, "fov", |t| &t.fov, timing, check(valid_fov));
        (brightness, color, fov)
    }

    /// Where channel `name` of the track's target is, reading the base scene's value where no
    /// key sets it.
    pub(super) fn base_of<'p>(
        &self,
        s: &Sources,
        names: &dyn SceneNames,
        path: &'p str,
        name: &str,
    ) -> ChannelAt<'p> {
        let target = target_name(s.track);
        let base = names.base_value(target, name).unwrap_or(Val::Num(0.0));
        ChannelAt::new(path, target, name, base)
    }

    /// A numeric channel of the target's definition, its keys checked by `check`.
    pub(super) fn value(
        &mut self,
        s: &Sources,
        names: &dyn SceneNames,
        name: &str,
        get: fn(&TrackSpec) -> &ChannelSpec<f64>,
        timing: Timing,
        check: Option<ValueCheck>,
    ) -> Option<Channel<f64>> {
        let (spec, path) = s.spec(name, get);
        let at = self.base_of(s, names, &path, name);
        self.keyed(spec, at, timing, number, check)
    }

    fn material(
        &mut self,
        s: &Sources,
        timing: Timing,
        names: &dyn SceneNames,
        layered: bool,
    ) -> MaterialChannels {
        let check = |c: ValueCheck| (!layered).then_some(c);
        let colour = |c: &mut Self, name: &str, get: fn(&TrackSpec) -> &ChannelSpec<_>| {
            let (spec, path) = s.spec(name, get);
            let at = c.base_of(s, names, &path, name);
            c.keyed(spec, at, timing, rgb, check(non_negative3))
        };
        let ka = colour(self, "ka", |t| &t.ka);
        let kd = colour(self, "kd", |t| &t.kd);
        let ks = colour(self, "ks", |t| &t.ks);
        let unit = check(unit_interval);
        let reflectivity = self.value(s, names, "reflectivity", |t| &t.reflectivity, timing, unit);
        let opacity = self.value(s, names, "opacity", |t| &t.opacity, timing, unit);
        let ior = self.value(s, names, "ior", |t| &t.ior, timing, check(positive));
        MaterialChannels {
            ka,
            kd,
            ks,
            reflectivity,
            opacity,
            ior,
        }
    }

    /// `visible` keys: 1 shown, 0 hidden, always stepped (a thing is there or it is not).
    fn visible(&mut self, s: &Sources, timing: Timing) -> Option<Channel<f64>> {
        let (keys, path) = s.keys("visible", |t| &t.visible);
        let mut channel = self.channel(
            keys,
            &path,
            timing,
            |v: &bool| f64::from(u8::from(*v)),
            None,
        )?;
        for (i, (key, raw)) in channel.keys.iter_mut().zip(keys).enumerate() {
            if !matches!(raw.interp, Interp::Linear | Interp::Step) {
                self.err(
                    &[&field(&index(&path, i), "interp"), &index(&path, i)],
                    "`visible` steps from key to key: it takes no easing".into(),
                );
            }
            key.interp = Interp::Step;
        }
        Some(channel)
    }

    /// When the keys play: the cycle (`looping` is `cycle: Repeat`), its count and the offset.
    fn timing(&mut self, s: &Sources, default_looping: bool) -> Timing {
        let looping = s.setting(|t| t.looping);
        let cycle = match (s.setting(|t| t.cycle), looping) {
            (Some((c, p)), Some((l, _))) if (c == Cycle::Repeat) != l => {
                self.err(
                    &[&field(&p, "cycle"), &p],
                    format!("`cycle: {c:?}` and `looping: {l}` say different things: keep one"),
                );
                c
            }
            (Some((c, _)), _) => c,
            (None, Some((l, _))) => Timing::looping(l).cycle,
            (None, None) => Timing::looping(default_looping).cycle,
        };
        let count = match s.setting(|t| t.cycles) {
            None => None,
            Some((n, p)) => {
                let at = [field(&p, "cycles"), p.clone()];
                if cycle == Cycle::Hold {
                    self.err(
                        &[&at[0], &at[1]],
                        "`cycles` counts the repeats of a `cycle`: give one (Repeat, PingPong or RepeatOffset)".into(),
                    );
                }
                if !(n.fract() == 0.0 && (1.0..=f64::from(u32::MAX)).contains(&n)) {
                    self.err(
                        &[&at[0], &at[1]],
                        format!(
                            "cycles must be a whole number from 1 to {}, not {}",
                            u32::MAX,
                            shown(n)
                        ),
                    );
                    None
                } else {
                    Some(n as u32)
                }
            }
        };
        let offset = s.track.offset + s.curve.as_ref().map_or(0.0, |(c, _)| c.offset);
        let refused = bounds::refusal("the offset in seconds", offset);
        if let Some(why) = &refused {
            self.err(&[&field(&s.path, "offset"), &s.path], why.clone());
        }
        Timing {
            offset: if refused.is_none() { offset } else { 0.0 },
            cycle,
            count,
        }
    }

    /// Orientation keys as quaternions.
    fn orient(&mut self, s: &Sources, timing: Timing) -> Option<OrientChannel> {
        let (keys, path) = s.keys("orient", |t| &t.orient.keys);
        if keys.is_empty() {
            return None;
        }
        let order = s
            .setting(|t| t.euler_order)
            .map_or(EulerOrder::XYZ, |(o, _)| o);
        let mut out = Vec::with_capacity(keys.len());
        for (i, k) in keys.iter().enumerate() {
            let key_path = index(&path, i);
            let at = k.at.seconds(self.fps);
            let previous = i.checked_sub(1).map(|p| keys[p].at.seconds(self.fps));
            self.key_time(at, previous, &key_path);
            self.key_curve(k, &key_path);
            if k.interp.is_spline() {
                self.err(
                    &[&field(&key_path, "interp"), &key_path],
                    format!(
                        "orientations turn by slerp: `{:?}` is for numbers; use Linear or an easing",
                        k.interp
                    ),
                );
            }
            let value_path = field(&key_path, "value");
            let value = match self.orientation(k.value, order) {
                Ok(q) => q,
                Err(why) => {
                    self.err(&[&value_path, &key_path], why);
                    DQuat::IDENTITY
                }
            };
            out.push(Key {
                at,
                value,
                interp: k.interp,
            });
        }
        self.key_sides(keys, &path, &mut out);
        Some(Channel {
            keys: out,
            timing,
            path,
            expr: None,
        })
    }

    fn orientation(&self, o: Orientation, order: EulerOrder) -> Result<DQuat, String> {
        match o {
            Orientation::Euler(x, y, z) => {
                let v = DVec3::new(x, y, z);
                match bounds::refusal3("the Euler angles", v) {
                    None => Ok(euler(v, order)),
                    Some(why) => Err(why),
                }
            }
            Orientation::AxisAngle(axis, degrees) => {
                let refused = bounds::refusal3("the axis", axis.0)
                    .or_else(|| bounds::refusal("the angle", degrees));
                match (refused, axis.0.try_normalize()) {
                    (Some(why), _) => Err(why),
                    (None, Some(a)) => Ok(DQuat::from_axis_angle(a, degrees.to_radians())),
                    (None, None) => Err("AxisAngle needs a non-zero axis".into()),
                }
            }
            Orientation::Quat { x, y, z, w } => {
                let refused = [x, y, z, w]
                    .into_iter()
                    .find_map(|p| bounds::refusal("each part of a quaternion", p));
                let q = DQuat::from_xyzw(x, y, z, w);
                match (refused, q.length()) {
                    (Some(why), _) => Err(why),
                    (None, l) if l > 0.0 => Ok(q / l),
                    _ => Err("a quaternion must not be zero".into()),
                }
            }
        }
    }

    /// The track's `look_at`, with its `up`, `forward` and `roll`.
    fn aim(&mut self, s: &Sources, timing: Timing, kind: Option<TargetKind>) -> Option<Aim> {
        let Some((spec, path)) = s.setting(|t| t.look_at.as_ref()) else {
            for extra in ["up", "forward", "roll"] {
                let given = match extra {
                    "up" => s.either(|t| t.up.is_some()),
                    "forward" => s.either(|t| t.forward.is_some()),
                    _ => s.either(|t| !t.roll.is_empty()),
                };
                let along = extra != "roll" && s.either(|t| t.orient.along_path);
                if given && !along {
                    self.err(
                        &[&field(&s.path, extra), &s.path],
                        format!("`{extra}` goes with `look_at` (or `orient: AlongPath`), which this track does not have"),
                    );
                }
            }
            return None;
        };
        let path = field(&path, "look_at");
        let target = match spec {
            AimSpec::Point(p) => {
                if let Some(why) = bounds::refusal3("the point looked at", p.0) {
                    self.err(&[&path], why);
                }
                AimTarget::Point(p.0)
            }
            AimSpec::Keys(keys) => AimTarget::Keys(
                self.channel(keys, &index(&path, 0), timing, |v: &V3| v.0, None)
                    .unwrap_or(Channel {
                        keys: Vec::new(),
                        timing,
                        path: path.clone(),
                        expr: None,
                    }),
            ),
            AimSpec::Object(name) => AimTarget::Object(name.clone()),
        };
        if let AimTarget::Keys(ch) = &target {
            if ch.keys.is_empty() {
                self.err(
                    &[&path],
                    "`look_at: Keys([…])` needs at least one key".into(),
                );
            }
        }
        let direction = |c: &mut Self, what: &str, v: Option<(V3, String)>, default: DVec3| {
            let Some((v, p)) = v else {
                return default;
            };
            if let Some(why) = bounds::direction_refusal(&format!("`{what}`"), v.0) {
                c.err(&[&field(&p, what), &p], why);
                return default;
            }
            v.0
        };
        let up = direction(self, "up", s.setting(|t| t.up), DVec3::Y);
        let forward = direction(self, "forward", s.setting(|t| t.forward), DVec3::NEG_Z);
        if kind == Some(TargetKind::Camera) && s.either(|t| t.forward.is_some()) {
            self.err(
                &[&field(&s.path, "forward"), &s.path],
                "a camera faces along its view direction: `forward` is for objects".into(),
            );
        }
        let object = matches!(kind, Some(TargetKind::Shape | TargetKind::Composite));
        if object && forward.cross(up).length() <= 1e-9 * forward.length() * up.length() {
            self.err(
                &[&field(&s.path, "up"), &field(&s.path, "forward"), &s.path],
                format!(
                    "`forward` ({}, {}, {}) and `up` ({}, {}, {}) are parallel: up must say which way the object is turned about its line of sight",
                    forward.x, forward.y, forward.z, up.x, up.y, up.z
                ),
            );
        }
        let (spec, roll_path) = s.spec("roll", |t| &t.roll);
        let at = ChannelAt::new(&roll_path, target_name(s.track), "roll", Val::Num(0.0));
        let roll = self.keyed(spec, at, timing, number, None);
        Some(Aim {
            target,
            up,
            forward,
            roll,
            path,
        })
    }

    /// What the track's target is; `None` (reported) if the base scene has no such name.
    fn target_kind(
        &mut self,
        t: &TrackSpec,
        path: &str,
        names: &dyn SceneNames,
    ) -> Option<TargetKind> {
        let Some(target) = &t.target else {
            self.err(
                &[path],
                "this track has no `target`: name the shape, composite, camera, light or material it keys".into(),
            );
            return None;
        };
        let kind = names.kind_of(target);
        if kind.is_none() && !self.full() {
            let d = self.src.error(
                &[&field(path, "target"), path],
                format!(
                    "the base scene has no shape, composite, camera, light or material named '{target}'"
                ),
            );
            let d = match suggest(target, names.names()) {
                Some(s) => d.with_help(format!("did you mean '{s}'?")),
                None => d,
            };
            self.errors.push(d);
        }
        kind
    }

    /// The rotation axis (default +y), with the axis and pivot checked.
    fn axis_and_pivot(&mut self, s: &Sources) -> DVec3 {
        let axis = s.setting(|t| t.axis);
        let at = |p: &str, f: &str| [field(p, f), p.to_string()];
        if let Some((a, p)) = &axis {
            if let Some(why) = bounds::direction_refusal("the rotation axis", a.0) {
                let at = at(p, "axis");
                self.err(&[&at[0], &at[1]], why);
            }
            if !s.either(|t| !t.rotate.is_empty()) {
                let at = at(p, "axis");
                self.err(
                    &[&at[0], &at[1]],
                    "`axis` without `rotate` keys does nothing".into(),
                );
            }
        }
        if let Some((pivot, p)) = s.setting(|t| t.pivot) {
            if let Some(why) = bounds::refusal3("the pivot", pivot.0) {
                let at = at(&p, "pivot");
                self.err(&[&at[0], &at[1]], why);
            }
        }
        axis.map_or(DVec3::Y, |(a, _)| a.0)
    }

    /// Each channel only on the kinds of target it means something for.
    fn channels_fit(&mut self, s: &Sources, kind: TargetKind) {
        let target = target_name(s.track).to_string();
        let mut sources = vec![(s.track, s.path.clone())];
        sources.extend(s.curve.iter().map(|(c, p)| (*c, p.clone())));
        for (spec, path) in sources {
            for (channel, keyed) in keyed_channels(spec) {
                if keyed && !fits(kind, channel) && channel != "roll" {
                    let why = if kind == TargetKind::Light && channel == "look_at" {
                        format!("'{target}' is a light: `look_at` aims shapes, composites and cameras; a point light shines every way, and a spot points at the target of its `define light` line, which turns with the light's own transforms")
                    } else {
                        format!(
                            "'{target}' is a {}: `{channel}` can only be keyed on {}",
                            kind.noun(),
                            kinds_for(channel)
                        )
                    };
                    self.err(&[&field(&path, channel), &path], why);
                }
            }
        }
        let aimed = s.either(|t| t.look_at.is_some());
        let turned = ["rotate", "orient", "scale"]
            .into_iter()
            .find(|c| s.either(|t| keyed_channels(t).iter().any(|(n, k)| n == c && *k)));
        match turned {
            Some(c) if aimed && (kind == TargetKind::Camera || c != "scale") => self.err(
                &[&field(&s.path, c), &s.path],
                format!("`look_at` turns '{target}' to face its target: `{c}` would turn it away"),
            ),
            _ => {}
        }
    }

    /// The orbit sets its camera's pose outright: keyed motion would fight it.
    fn not_moved_off_orbit(&mut self, s: &Sources) {
        let moving = [
            "translate",
            "path",
            "rotate",
            "scale",
            "orient",
            "look_at",
            "parent",
        ]
        .into_iter()
        .find(|c| s.either(|t| keyed_channels(t).iter().any(|(n, k)| n == c && *k)));
        if let Some(channel) = moving {
            self.err(
                &[&field(&s.path, channel), &s.path],
                format!(
                    "camera '{}' follows the orbit; moving it too would take it off the orbit",
                    target_name(s.track)
                ),
            );
        }
    }
}

pub(super) fn target_name(t: &TrackSpec) -> &str {
    t.target.as_deref().unwrap_or("")
}
