//! The checks that turn a [`SpecFile`] into an [`Animation`]: every value, every key time and
//! every name against the base scene. All problems are collected, each at its place in the
//! spec, so that one run shows everything to fix.

use super::model::{Animation, Channel, NamePattern, Orbit, SceneNames, TargetKind, Track};
use super::raw::{KeySpec, Length, OrbitSpec, Rgb, Scale, SpecFile, TrackSpec, V3};
use super::source::Source;
use crate::keyframe::interp::Key;
use crate::keyframe::locate::{field, index};
use crate::keyframe::tidy::tidy;
use anim_core::diag::{suggest, Diagnostic};
use anim_core::limits::{self, MAX_DIAGNOSTICS};
use anim_core::load::not_shown;
use glam::DVec3;

/// Largest frame count accepted: far beyond any real use, small enough to catch `fps: 24000`.
const MAX_FRAMES: f64 = 1_000_000.0;

/// Where errors about the animation's length point.
const LENGTH_PATHS: [&str; 2] = ["length[0]", "length"];

/// Checks `spec` against the base scene. Every problem found is returned, each located.
pub fn validate(
    spec: &SpecFile,
    names: &dyn SceneNames,
    src: &Source,
) -> Result<Animation, Vec<Diagnostic>> {
    let mut c = Checker {
        duration: 0.0,
        src,
        errors: Vec::new(),
        unshown: 0,
    };
    let fps = c.fps(spec.fps);
    let frames = c.frame_count(spec.length, fps);
    c.duration = frames as f64 / fps as f64;
    let (width, height) = c.image_size(spec);
    let output = c.output(spec);
    let camera = c.camera(spec.camera.as_deref(), names);
    let orbit = spec.orbit.as_ref().map(|o| c.orbit(o));
    let shutter = c.shutter(spec.shutter);
    let ambient = c.channel(
        &spec.ambient,
        "ambient",
        spec.looping,
        rgb,
        Some(non_negative3),
    );
    let background = c.channel(
        &spec.background,
        "background",
        spec.looping,
        rgb,
        Some(non_negative3),
    );
    let orbit_camera = orbit.is_some().then_some(camera.as_str());
    let tracks = spec
        .tracks
        .iter()
        .enumerate()
        .filter_map(|(i, t)| c.track(i, t, spec.looping, names, orbit_camera))
        .collect();
    match (c.errors.is_empty(), output) {
        (true, Some(output)) => Ok(Animation {
            fps,
            frames,
            width,
            height,
            samples: spec.samples,
            output,
            camera,
            orbit,
            ambient,
            background,
            tracks,
            shutter,
        }),
        _ => Err(c.into_errors()),
    }
}

fn rgb(v: &Rgb) -> DVec3 {
    v.0
}

fn number(v: &f64) -> f64 {
    *v
}

// The checks of keyed values: each sees a value as a vector (a number as `x`) and says what is
// wrong with it, to follow the channel's name in the message.

fn non_negative(v: DVec3) -> Option<String> {
    (v.x < 0.0).then(|| "must not be negative".to_string())
}

fn non_negative3(v: DVec3) -> Option<String> {
    v.cmplt(DVec3::ZERO)
        .any()
        .then(|| "must not be negative".to_string())
}

fn non_zero3(v: DVec3) -> Option<String> {
    v.cmpeq(DVec3::ZERO)
        .any()
        .then(|| "must not be 0 on any axis (a scale of 0 cannot be undone)".to_string())
}

fn valid_fov(v: DVec3) -> Option<String> {
    (!limits::fov_is_valid(v.x)).then(|| format!("must be {}", limits::FOV_RULE))
}

fn names_list(names: &[&str]) -> String {
    names
        .iter()
        .map(|c| format!("'{c}'"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Collects errors while the spec is checked part by part.
struct Checker<'a> {
    /// The animation's length in seconds, once known: keys must fall inside it.
    duration: f64,
    src: &'a Source,
    errors: Vec<Diagnostic>,
    /// Errors found past the first `MAX_DIAGNOSTICS`, counted but not made (quoting a line
    /// costs its length, and a spec may hold a million bad keys).
    unshown: usize,
}

impl Checker<'_> {
    fn err(&mut self, paths: &[&str], msg: String) {
        if !self.full() {
            self.errors.push(self.src.error(paths, msg));
        }
    }

    /// Whether as many errors as are listed are found already; counts the one about to be.
    fn full(&mut self) -> bool {
        let full = self.errors.len() >= MAX_DIAGNOSTICS;
        self.unshown += usize::from(full);
        full
    }

    /// The errors listed, and one counting those that were not.
    fn into_errors(mut self) -> Vec<Diagnostic> {
        if self.unshown > 0 {
            self.errors.push(not_shown(&self.src.path, self.unshown, 0));
        }
        self.errors
    }

    /// The frame rate; the default rate when it is wrong, so that checking can go on.
    fn fps(&mut self, fps: f64) -> u32 {
        let rates = limits::FPS;
        if fps.fract() == 0.0 && (*rates.start() as f64..=*rates.end() as f64).contains(&fps) {
            return fps as u32;
        }
        self.err(
            &["fps"],
            format!(
                "fps must be a whole number from {} to {}, not {fps}",
                rates.start(),
                rates.end()
            ),
        );
        24
    }

    /// The shutter fraction; 0 (no blur) when it is wrong, so that checking can go on.
    fn shutter(&mut self, shutter: f64) -> f64 {
        if limits::shutter_is_valid(shutter) {
            return shutter;
        }
        self.err(
            &["shutter"],
            format!("shutter must be {}, not {shutter}", limits::SHUTTER_RULE),
        );
        0.0
    }

    /// The number of frames; a usable stand-in when the length is wrong.
    fn frame_count(&mut self, length: Length, fps: u32) -> usize {
        let frames = match length {
            Length::Frames(n) => {
                if !(n.fract() == 0.0 && n >= 1.0) {
                    self.err(
                        &LENGTH_PATHS,
                        format!("the number of frames must be a whole number, at least 1, not {n}"),
                    );
                }
                n
            }
            Length::Seconds(s) => self.frames_in_seconds(s, fps),
        };
        if frames > MAX_FRAMES {
            self.err(
                &LENGTH_PATHS,
                format!("{frames} frames is more than the {MAX_FRAMES} allowed"),
            );
        }
        if frames.is_finite() {
            frames.clamp(1.0, MAX_FRAMES) as usize
        } else {
            1
        }
    }

    fn frames_in_seconds(&mut self, s: f64, fps: u32) -> f64 {
        let exact = s * fps as f64;
        let n = exact.round();
        if !s.is_finite() || s <= 0.0 {
            self.err(
                &LENGTH_PATHS,
                format!("the length must be a positive number of seconds, not {s}"),
            );
        } else if n < 1.0 {
            self.err(
                &LENGTH_PATHS,
                format!("{s} s at {fps} fps is less than one frame"),
            );
        } else if (exact - n).abs() > 1e-6 {
            // Rounding silently would make the video longer or shorter than asked.
            self.err(
                &LENGTH_PATHS,
                format!(
                    "{s} s at {fps} fps is {} frames: the length must be a whole number of frames (e.g. Frames({n}))",
                    tidy(exact)
                ),
            );
        }
        n
    }

    /// The resolution, and the samples per pixel of each frame's render line.
    fn image_size(&mut self, spec: &SpecFile) -> (u32, u32) {
        let (width, height) = spec.resolution;
        let sides = limits::IMAGE_SIDE;
        for (v, p) in [(width, "resolution[0]"), (height, "resolution[1]")] {
            if !sides.contains(&v) {
                self.err(
                    &[p, "resolution"],
                    format!(
                        "image sizes run from {} to {} pixels, not {v}",
                        sides.start(),
                        sides.end()
                    ),
                );
            }
        }
        if let Some(s) = spec.samples.filter(|s| !limits::SAMPLES.contains(s)) {
            self.err(
                &["samples"],
                format!(
                    "samples per pixel run from {} to {}, not {s}",
                    limits::SAMPLES.start(),
                    limits::SAMPLES.end()
                ),
            );
        }
        (width, height)
    }

    /// The frame names, and the directory they go to.
    fn output(&mut self, spec: &SpecFile) -> Option<NamePattern> {
        let output = match NamePattern::parse(&spec.output) {
            Ok(p) => Some(p),
            Err(msg) => {
                self.err(&["output"], msg);
                None
            }
        };
        if spec
            .frames_dir
            .as_ref()
            .is_some_and(|d| d.trim().is_empty())
        {
            self.err(&["frames_dir"], "frames_dir is empty".into());
        }
        output
    }

    /// The camera to render: the one named, else the base scene's default.
    fn camera(&mut self, named: Option<&str>, names: &dyn SceneNames) -> String {
        let Some(name) = named else {
            if let Some(cam) = names.default_camera() {
                return cam.to_string();
            }
            self.errors.push(
                self.src
                    .error(&["scene"], "the base scene defines no camera")
                    .with_help(
                        "add `define camera cam 60 …` to the scene, then name it with `camera: \"cam\"`",
                    ),
            );
            return String::new();
        };
        match names.kind_of(name) {
            Some(TargetKind::Camera) => {}
            Some(kind) => self.err(
                &["camera"],
                format!("'{name}' is a {}, not a camera", kind.noun()),
            ),
            None => {
                let cameras: Vec<&str> = names
                    .names()
                    .into_iter()
                    .filter(|n| names.kind_of(n) == Some(TargetKind::Camera))
                    .collect();
                let d = self.src.error(
                    &["camera"],
                    format!("the base scene has no camera named '{name}'"),
                );
                let d = match suggest(name, cameras.iter().copied()) {
                    Some(s) => d.with_help(format!("did you mean '{s}'?")),
                    None if !cameras.is_empty() => d.with_help(format!(
                        "the base scene's cameras: {}",
                        names_list(&cameras)
                    )),
                    None => d,
                };
                self.errors.push(d);
            }
        }
        name.to_string()
    }

    fn orbit(&mut self, o: &OrbitSpec) -> Orbit {
        if !(o.radius.is_finite() && o.radius > 0.0) {
            self.err(
                &["orbit.radius", "orbit"],
                format!(
                    "the orbit radius must be a positive number, not {}",
                    o.radius
                ),
            );
        }
        let finite_numbers = [
            (
                o.height,
                "orbit.height",
                "the orbit height must be a finite number",
            ),
            (o.turns, "orbit.turns", "turns must be a finite number"),
            (
                o.start_angle,
                "orbit.start_angle",
                "start_angle must be a finite number",
            ),
        ];
        for (value, path, message) in finite_numbers {
            if !value.is_finite() {
                self.err(&[path, "orbit"], message.into());
            }
        }
        if !o.center.0.is_finite() {
            self.err(
                &["orbit.center", "orbit"],
                "the orbit centre must be finite".into(),
            );
        }
        let look_at = o.look_at.map_or(o.center.0, |v| v.0);
        if !look_at.is_finite() {
            self.err(&["orbit.look_at", "orbit"], "look_at must be finite".into());
        }
        Orbit {
            center: o.center.0,
            radius: o.radius,
            height: o.height,
            turns: o.turns,
            start_angle: o.start_angle,
            look_at,
            interp: o.interp,
        }
    }

    /// Track `i`, if its target exists. `orbit_camera` is the camera the orbit moves.
    fn track(
        &mut self,
        i: usize,
        t: &TrackSpec,
        default_looping: bool,
        names: &dyn SceneNames,
        orbit_camera: Option<&str>,
    ) -> Option<Track> {
        let path = index("tracks", i);
        let kind = self.target_kind(t, &path, names);
        let looping = t.looping.unwrap_or(default_looping);
        let at = |name: &str| field(&path, name);
        let translate = self.channel(&t.translate, &at("translate"), looping, |v: &V3| v.0, None);
        let rotate = self.channel(&t.rotate, &at("rotate"), looping, number, None);
        let scale = self.channel(
            &t.scale,
            &at("scale"),
            looping,
            |v: &Scale| v.0,
            Some(non_zero3),
        );
        let brightness = self.channel(
            &t.brightness,
            &at("brightness"),
            looping,
            number,
            Some(non_negative),
        );
        let color = self.channel(&t.color, &at("color"), looping, rgb, Some(non_negative3));
        let fov = self.channel(&t.fov, &at("fov"), looping, number, Some(valid_fov));
        let axis = self.axis_and_pivot(t, &path);
        self.keys_something(t, &path);
        let kind = kind?;
        self.channels_fit(t, kind, &path);
        if kind == TargetKind::Camera && orbit_camera == Some(t.target.as_str()) {
            self.not_moved_off_orbit(t, &path);
        }
        Some(Track {
            target: t.target.clone(),
            kind,
            translate,
            rotate,
            axis,
            scale,
            pivot: t.pivot.map(|p| p.0),
            brightness,
            color,
            fov,
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
        let kind = names.kind_of(&t.target);
        if kind.is_none() && !self.full() {
            let d = self.src.error(
                &[&field(path, "target"), path],
                format!(
                    "the base scene has no shape, composite, camera or light named '{}'",
                    t.target
                ),
            );
            let d = match suggest(&t.target, names.names()) {
                Some(s) => d.with_help(format!("did you mean '{s}'?")),
                None => d,
            };
            self.errors.push(d);
        }
        kind
    }

    /// The rotation axis (default +y), with the axis and pivot checked.
    fn axis_and_pivot(&mut self, t: &TrackSpec, path: &str) -> DVec3 {
        let axis = t.axis.map_or(DVec3::Y, |a| a.0);
        if !(axis.is_finite() && axis.length_squared() > 0.0) {
            self.err(
                &[&field(path, "axis")],
                "the rotation axis must be a non-zero vector".into(),
            );
        }
        if t.axis.is_some() && t.rotate.is_empty() {
            self.err(
                &[&field(path, "axis")],
                "`axis` without `rotate` keys does nothing".into(),
            );
        }
        if t.pivot.is_some_and(|p| !p.0.is_finite()) {
            self.err(&[&field(path, "pivot")], "the pivot must be finite".into());
        }
        axis
    }

    fn keys_something(&mut self, t: &TrackSpec, path: &str) {
        let keyed = [
            !t.translate.is_empty(),
            !t.rotate.is_empty(),
            !t.scale.is_empty(),
            !t.brightness.is_empty(),
            !t.color.is_empty(),
            !t.fov.is_empty(),
        ];
        if !keyed.contains(&true) {
            self.err(
                &[&field(path, "target"), path],
                format!("the track for '{}' keys nothing", t.target),
            );
        }
    }

    /// Light channels only on lights, the field of view only on cameras.
    fn channels_fit(&mut self, t: &TrackSpec, kind: TargetKind, path: &str) {
        let wrong = |channel: &str, allowed: &str| {
            format!(
                "'{}' is a {}: `{channel}` can only be keyed on {allowed}",
                t.target,
                kind.noun()
            )
        };
        if kind != TargetKind::Light {
            if !t.brightness.is_empty() {
                self.err(&[&field(path, "brightness")], wrong("brightness", "lights"));
            }
            if !t.color.is_empty() {
                self.err(&[&field(path, "color")], wrong("color", "lights"));
            }
        }
        if kind != TargetKind::Camera && !t.fov.is_empty() {
            self.err(&[&field(path, "fov")], wrong("fov", "cameras"));
        }
    }

    /// The orbit sets its camera's pose outright: keyed motion would fight it.
    fn not_moved_off_orbit(&mut self, t: &TrackSpec, path: &str) {
        let moving = [
            ("translate", t.translate.is_empty()),
            ("rotate", t.rotate.is_empty()),
            ("scale", t.scale.is_empty()),
        ]
        .into_iter()
        .find(|(_, empty)| !empty);
        if let Some((channel, _)) = moving {
            self.err(
                &[&field(path, channel)],
                format!(
                    "camera '{}' follows the orbit; moving it too would take it off the orbit",
                    t.target
                ),
            );
        }
    }

    /// The keys at `path` as a channel, each key's time and value checked. `check` sees each
    /// value as a vector (numbers as `x`) and names what is wrong.
    fn channel<S, T: Copy + Into3>(
        &mut self,
        keys: &[KeySpec<S>],
        path: &str,
        looping: bool,
        value: impl Fn(&S) -> T,
        check: Option<fn(DVec3) -> Option<String>>,
    ) -> Option<Channel<T>> {
        if keys.is_empty() {
            return None;
        }
        let what = path.rsplit('.').next().unwrap_or(path);
        let mut out = Vec::with_capacity(keys.len());
        for (i, k) in keys.iter().enumerate() {
            let key_path = index(path, i);
            let previous = i.checked_sub(1).map(|p| keys[p].at);
            self.key_time(k.at, previous, &key_path);
            let v = value(&k.value).into3();
            let value_path = field(&key_path, "value");
            if !v.is_finite() {
                self.err(
                    &[&value_path, &key_path],
                    format!("the {what} value must be finite"),
                );
            } else if let Some(problem) = check.and_then(|c| c(v)) {
                self.err(&[&value_path, &key_path], format!("{what} {problem}"));
            }
            out.push(Key {
                at: k.at,
                value: value(&k.value),
                interp: k.interp,
            });
        }
        Some(Channel {
            keys: out,
            looping,
            path: path.to_string(),
        })
    }

    /// A key's time: finite, inside the animation, after the key before it.
    fn key_time(&mut self, at: f64, previous: Option<f64>, key_path: &str) {
        let paths = [field(key_path, "at"), key_path.to_string()];
        let paths = [paths[0].as_str(), paths[1].as_str()];
        if !at.is_finite() {
            self.err(
                &paths,
                "a key's time must be a finite number of seconds".into(),
            );
        } else if at < 0.0 {
            self.err(
                &paths,
                format!("the key at {at} s is before the start of the animation (0 s)"),
            );
        } else if at > self.duration + 1e-9 {
            self.err(
                &paths,
                format!(
                    "the key at {at} s is after the end of the animation ({} s)",
                    self.duration
                ),
            );
        }
        if let Some(p) = previous.filter(|&p| at <= p) {
            self.err(
                &paths,
                format!("keys must be in time order: this key at {at} s follows a key at {p} s"),
            );
        }
    }
}

/// Numbers seen as vectors for the shared value checks.
trait Into3 {
    fn into3(self) -> DVec3;
}

impl Into3 for f64 {
    fn into3(self) -> DVec3 {
        DVec3::splat(self)
    }
}

impl Into3 for DVec3 {
    fn into3(self) -> DVec3 {
        self
    }
}
