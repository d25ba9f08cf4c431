//! The checks that turn a [`SpecFile`] into an [`Animation`]: every value, every key time and
//! every name against the base scene. All problems are collected, each at its place in the
//! spec, so that one run shows everything to fix.

use super::checker::{names_list, non_negative3, rgb, ChannelAt, Checker};
use super::model::{Animation, End, Fps, NamePattern, Orbit, SceneNames, TargetKind};
use super::raw::{ChannelSpec, FpsSpec, Length, NamedValue, NamedValues, OrbitSpec, Rgb, SpecFile};
use super::source::Source;
use crate::keyframe::bounds::{self, shown};
use crate::keyframe::expr::{Expr, Func, Val, Var};
use crate::keyframe::interp::Timing;
use crate::keyframe::locate::index;
use crate::keyframe::tidy::tidy;
use anim_core::diag::{suggest, Diagnostic};
use anim_core::limits;
use glam::DVec3;
use std::sync::Arc;

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
    let mut c = Checker::new(src);
    let fps = c.fps(&spec.fps);
    c.fps = fps;
    let frames = c.frame_count(spec.length, fps, spec.end);
    c.duration = match spec.end {
        End::Cyclic => fps.seconds(frames as f64),
        End::Inclusive => fps.seconds(frames.saturating_sub(1) as f64),
    };
    let (width, height) = c.image_size(spec);
    let output = c.output(spec);
    let camera = c.camera(spec.camera.as_deref(), names);
    let orbit = spec.orbit.as_ref().map(|o| c.orbit(o));
    let shutter = c.shutter(spec.shutter);
    c.named_values(&spec.values);
    let spec_looping = spec.looping;
    let mut scene_colour = |name: &str, spec: &ChannelSpec<Rgb>| {
        let base = names.base_value("", name).unwrap_or(Val::Vec(DVec3::ZERO));
        let at = ChannelAt::new(name, "", name, base);
        let timing = Timing::looping(spec_looping);
        c.keyed(spec, at, timing, rgb, Some(non_negative3))
    };
    let ambient = scene_colour("ambient", &spec.ambient);
    let background = scene_colour("background", &spec.background);
    let orbit_camera = orbit.is_some().then_some(camera.as_str());
    let tracks = c.tracks(spec, names, orbit_camera);
    let last_frame = fps.seconds(frames.saturating_sub(1) as f64);
    if spec.end == End::Cyclic {
        c.unshown_last_keys(&tracks, &ambient, &background, last_frame);
    }
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
            end: spec.end,
            warnings: c.warnings,
        }),
        _ => Err(c.into_errors()),
    }
}

impl Checker<'_> {
    /// The frame rate; the default rate when it is wrong, so that checking can go on.
    fn fps(&mut self, fps: &FpsSpec) -> Fps {
        fps.exact().unwrap_or_else(|why| {
            self.err(&["fps"], why);
            Fps::whole(24)
        })
    }

    /// The spec's named values, in order, each checked (and usable by those below it and by
    /// every channel's expression).
    fn named_values(&mut self, values: &NamedValues) {
        let mut compiled: Vec<Expr> = Vec::new();
        for (i, (name, value)) in values.0.iter().enumerate() {
            let (key_path, path) = (format!("values{{key {i}}}"), index("values", i));
            let word = name
                .chars()
                .next()
                .is_some_and(|c| c.is_alphabetic() || c == '_')
                && name.chars().all(|c| c.is_alphanumeric() || c == '_');
            if !word {
                self.err(
                    &[&key_path, "values"],
                    format!("'{name}' is not a name an expression can use: letters, digits and `_`, not starting with a digit"),
                );
            } else if Var::named(name).is_some() || Func::named(name).is_some() {
                self.err(
                    &[&key_path, "values"],
                    format!("`{name}` is a name of the expression language already"),
                );
            } else if self.named_types.iter().any(|(n, _)| n == name) {
                self.err(
                    &[&key_path, "values"],
                    format!("a value named '{name}' is defined already"),
                );
            }
            let expr = match value {
                NamedValue::Number(n) => Some(Expr::constant(Val::Num(*n))),
                NamedValue::Vector(v) => Some(Expr::constant(Val::Vec(*v))),
                NamedValue::Expr(text) => self.expression(text, &path, None),
            };
            let expr = expr.unwrap_or_else(|| Expr::constant(Val::Num(0.0)));
            if !matches!(value, NamedValue::Expr(_))
                && !expr.eval(0.0, 1.0, Val::Num(0.0), 0).is_finite()
            {
                self.err(
                    &[&path, "values"],
                    format!("the value of '{name}' must be finite"),
                );
            }
            self.named_types.push((name.clone(), expr.ty));
            compiled.push(expr);
            self.named = Arc::new(compiled.clone());
        }
    }

    /// The shutter fraction; 0 (no blur) when it is wrong, so that checking can go on.
    fn shutter(&mut self, shutter: f64) -> f64 {
        if limits::shutter_is_valid(shutter) {
            return shutter;
        }
        self.err(
            &["shutter"],
            format!(
                "shutter must be {}, not {}",
                limits::SHUTTER_RULE,
                shown(shutter)
            ),
        );
        0.0
    }

    /// The number of frames; a usable stand-in when the length is wrong.
    fn frame_count(&mut self, length: Length, fps: Fps, end: End) -> usize {
        let frames = match length {
            Length::Frames(n) => {
                if !(n.fract() == 0.0 && n >= 1.0) {
                    self.err(
                        &LENGTH_PATHS,
                        format!(
                            "the number of frames must be a whole number, at least 1, not {}",
                            shown(n)
                        ),
                    );
                }
                n
            }
            // The frame at `length` itself is one more.
            Length::Seconds(s) => self.frames_in_seconds(s, fps) + f64::from(end == End::Inclusive),
        };
        if frames > MAX_FRAMES {
            self.err(
                &LENGTH_PATHS,
                format!(
                    "{} frames is more than the {MAX_FRAMES} allowed",
                    shown(frames)
                ),
            );
        }
        if frames.is_finite() {
            frames.clamp(1.0, MAX_FRAMES) as usize
        } else {
            1
        }
    }

    /// The frames in `s` seconds of timecode at `fps` (`Fps::timecode_rate`).
    fn frames_in_seconds(&mut self, s: f64, fps: Fps) -> f64 {
        let exact = s * fps.timecode_rate();
        let n = exact.round();
        if !s.is_finite() || s <= 0.0 {
            self.err(
                &LENGTH_PATHS,
                format!(
                    "the length must be a positive number of seconds, not {}",
                    shown(s)
                ),
            );
        } else if n < 1.0 {
            self.err(
                &LENGTH_PATHS,
                format!("{} s at {fps} fps is less than one frame", shown(s)),
            );
        } else if (exact - n).abs() > 1e-6 {
            // Rounding silently would make the video longer or shorter than asked.
            self.err(
                &LENGTH_PATHS,
                format!(
                    "{} s at {fps} fps is {} frames: the length must be a whole number of frames (e.g. Frames({n}))",
                    shown(s),
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
        if let Some(why) = bounds::refusal("the orbit radius", o.radius) {
            self.err(&["orbit.radius", "orbit"], why);
        } else if o.radius <= 0.0 {
            self.err(
                &["orbit.radius", "orbit"],
                format!(
                    "the orbit radius must be a positive number, not {}",
                    shown(o.radius)
                ),
            );
        }
        let numbers = [
            (o.height, "orbit.height", "the orbit height"),
            (o.turns, "orbit.turns", "turns"),
            (o.start_angle, "orbit.start_angle", "start_angle"),
        ];
        for (value, path, what) in numbers {
            if let Some(why) = bounds::refusal(what, value) {
                self.err(&[path, "orbit"], why);
            }
        }
        if let Some(why) = bounds::refusal3("the orbit centre", o.center.0) {
            self.err(&["orbit.center", "orbit"], why);
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
}
