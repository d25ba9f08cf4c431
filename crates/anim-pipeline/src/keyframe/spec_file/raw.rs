//! The spec as the user writes it: serde types that mirror the RON text one to one, so that
//! ron rejects every unknown field and variant with its position.

use super::model::{Blend, End, Follow, Fps};
use crate::keyframe::bounds::shown;
use crate::keyframe::interp::{Cycle, Interp, Side};
use crate::keyframe::rotation::EulerOrder;
use anim_core::limits;
use glam::DVec3;
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::Deserialize;
use std::fmt;

/// The whole spec file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpecFile {
    /// The base scene: `File("showcase.sdf")` (relative to the spec) or `Inline("…")`.
    pub scene: SceneSource,
    /// The camera to render; default: the base scene's `render` camera, else its first camera.
    #[serde(default)]
    pub camera: Option<String>,
    /// Frames per second: a whole number, an NTSC rate (`23.976`) or a ratio (`"24000/1001"`).
    #[serde(default = "default_fps")]
    pub fps: FpsSpec,
    /// `Seconds(5)` or `Frames(120)`.
    pub length: Length,
    /// (width, height) in pixels.
    pub resolution: (u32, u32),
    /// Samples per pixel written into each frame's render line (default: the renderer's).
    #[serde(default)]
    pub samples: Option<u32>,
    /// Image name of each frame; `{frame}` becomes the zero-padded frame number.
    #[serde(default = "default_output")]
    pub output: String,
    /// Where `anim generate` writes the frames, relative to the spec (default `frames/<stem>`).
    #[serde(default)]
    pub frames_dir: Option<String>,
    /// Default for every track's `looping`.
    #[serde(default)]
    pub looping: bool,
    /// The fraction of each frame's interval the shutter stays open, from the frame's time
    /// (0: no motion blur). Read as any number so that a bad value gets a located message.
    #[serde(default)]
    pub shutter: f64,
    /// Circle the camera around a point, always looking at it.
    #[serde(default)]
    pub orbit: Option<OrbitSpec>,
    /// Keyed ambient light (replaces the base scene's).
    #[serde(default)]
    pub ambient: ChannelSpec<Rgb>,
    /// Keyed background colour (replaces the base scene's).
    #[serde(default)]
    pub background: ChannelSpec<Rgb>,
    /// Named values that expressions may use: a number, a vector or an expression (of `t`,
    /// `frame`, `fps` and the values above it), in order.
    #[serde(default)]
    pub values: NamedValues,
    #[serde(default)]
    pub tracks: Vec<TrackSpec>,
    /// Named sets of keyed channels that tracks use with `curve: "name"`.
    #[serde(default)]
    pub curves: Vec<TrackSpec>,
    /// Whether the last frame is one step before `length` (`Cyclic`, the default) or at it.
    #[serde(default)]
    pub end: End,
}

impl SpecFile {
    /// Every key time written in the spec, in seconds, sorted, once each (the preview marks
    /// them). Keys written in frames count at the spec's rate (24 fps where it is wrong).
    pub fn key_times(&self) -> Vec<f64> {
        let fps = self.fps.exact().unwrap_or(Fps::whole(24));
        let mut times: Vec<f64> = key_times(&self.ambient.keys)
            .chain(key_times(&self.background.keys))
            .map(|at| at.seconds(fps))
            .collect();
        for t in self.tracks.iter().chain(&self.curves) {
            times.extend(t.key_times().map(|at| at.seconds(fps) + t.offset));
        }
        times.retain(|t| t.is_finite());
        times.sort_by(f64::total_cmp);
        times.dedup();
        times
    }
}

fn key_times<T>(keys: &[KeySpec<T>]) -> impl Iterator<Item = KeyTime> + '_ {
    keys.iter().map(|k| k.at)
}

fn default_fps() -> FpsSpec {
    FpsSpec::Number(24.0)
}

/// The frame rate as written: a number (whole, or an NTSC rate such as 29.97), or a ratio
/// `"A/B"`. Read as any number so that `24.5` gets a clear message.
#[derive(Clone, Debug, PartialEq)]
pub enum FpsSpec {
    Number(f64),
    Ratio(String),
}

impl FpsSpec {
    /// The exact rate, or what is wrong with it. A number with a fraction is an NTSC rate,
    /// `N·1000/1001` written to three decimals or fewer (23.976, 29.97, 59.94); a ratio is
    /// reduced (`48000/2002` is `24000/1001`). Either way from 1 to 1000 frames a second.
    pub fn exact(&self) -> Result<Fps, String> {
        let rates = limits::FPS;
        let (lo, hi) = (f64::from(*rates.start()), f64::from(*rates.end()));
        let expected = format!(
            "fps must be a whole number from {lo} to {hi}, an NTSC rate (23.976, 29.97, 59.94) or a ratio \"A/B\""
        );
        let fps = match self {
            FpsSpec::Number(n) if n.fract() == 0.0 && (lo..=hi).contains(n) => {
                Fps::whole(*n as u32)
            }
            FpsSpec::Number(n) => {
                let whole = (n * 1.001).round();
                let ntsc = whole * 1000.0 / 1001.0;
                if !((lo..=hi).contains(&whole) && (n - ntsc).abs() < 5e-4) {
                    return Err(format!("{expected}, not {}", shown(*n)));
                }
                Fps {
                    num: whole as u32 * 1000,
                    den: 1001,
                }
            }
            FpsSpec::Ratio(text) => {
                let parsed = text.split_once('/').and_then(|(a, b)| {
                    Some((a.trim().parse::<u32>().ok()?, b.trim().parse::<u32>().ok()?))
                });
                let Some((a, b)) = parsed.filter(|&(a, b)| a > 0 && b > 0) else {
                    return Err(format!("{expected}, not \"{text}\""));
                };
                let g = gcd(a, b);
                Fps {
                    num: a / g,
                    den: b / g,
                }
            }
        };
        if (lo..=hi).contains(&fps.as_f64()) {
            Ok(fps)
        } else {
            Err(format!("{expected}, not {fps} ({} fps)", fps.as_f64()))
        }
    }
}

fn gcd(a: u32, b: u32) -> u32 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

impl<'de> Deserialize<'de> for FpsSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Rate;
        impl Visitor<'_> for Rate {
            type Value = FpsSpec;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number of frames per second or a ratio \"A/B\"")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<FpsSpec, E> {
                Ok(FpsSpec::Number(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<FpsSpec, E> {
                Ok(FpsSpec::Number(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<FpsSpec, E> {
                Ok(FpsSpec::Number(v as f64))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<FpsSpec, E> {
                Ok(FpsSpec::Ratio(v.to_string()))
            }
        }
        d.deserialize_any(Rate)
    }
}

/// A key's time: seconds, or `Frames(n)` at the spec's rate.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(untagged, expecting = "expected a number of seconds, or `Frames(n)`")]
pub enum KeyTime {
    Seconds(f64),
    Counted(TimeUnit),
}

/// A time written with its unit.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
pub enum TimeUnit {
    Frames(f64),
    Seconds(f64),
}

impl KeyTime {
    /// The time in seconds at `fps`.
    pub fn seconds(self, fps: Fps) -> f64 {
        match self {
            KeyTime::Seconds(s) | KeyTime::Counted(TimeUnit::Seconds(s)) => s,
            KeyTime::Counted(TimeUnit::Frames(n)) => fps.seconds(n),
        }
    }
}

fn default_output() -> String {
    "frame_{frame}.png".to_string()
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum SceneSource {
    File(String),
    Inline(String),
}

#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Length {
    Seconds(f64),
    /// A whole number, read as a number so that `Frames(2.5)` gets a clear message.
    Frames(f64),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OrbitSpec {
    /// The point circled (and looked at, unless `look_at` says otherwise).
    pub center: V3,
    /// Horizontal distance of the eye from the centre.
    pub radius: f64,
    /// Eye height above the centre.
    #[serde(default)]
    pub height: f64,
    /// Full circles over the whole animation; negative turns clockwise seen from above.
    #[serde(default = "one")]
    pub turns: f64,
    /// Degrees; 0 puts the eye on the +z side of the centre, 90 on the +x side.
    #[serde(default)]
    pub start_angle: f64,
    #[serde(default)]
    pub look_at: Option<V3>,
    /// Speed profile of the angle over the whole animation (Linear: constant speed).
    #[serde(default)]
    pub interp: Interp,
}

fn one() -> f64 {
    1.0
}

/// A track (with a `target`) or a named curve (with a `name`): keyed channels.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackSpec {
    /// A shape, composite, camera, light or material of the base scene (tracks only).
    #[serde(default)]
    pub target: Option<String>,
    /// The name a curve is used by (curves only).
    #[serde(default)]
    pub name: Option<String>,
    /// A named curve whose channels this track plays where it keys none of its own.
    #[serde(default)]
    pub curve: Option<String>,
    #[serde(default)]
    pub translate: ChannelSpec<V3>,
    /// Degrees about `axis`.
    #[serde(default)]
    pub rotate: ChannelSpec<f64>,
    #[serde(default)]
    pub axis: Option<V3>,
    /// A number (uniform) or (x, y, z) per key.
    #[serde(default)]
    pub scale: ChannelSpec<Scale>,
    /// Centre of rotation and scaling; default: the object's centre as the base scene places it.
    #[serde(default)]
    pub pivot: Option<V3>,
    /// Full 3-D orientation keys, slerped, or `AlongPath`: facing the way the `path` goes.
    #[serde(default)]
    pub orient: OrientSpec,
    /// The translation as a path travelled at constant speed (instead of `translate` keys).
    #[serde(default)]
    pub path: Option<PathSpec>,
    /// With `orient: AlongPath`: how far the target leans into turns (0: level; 1: as an
    /// aircraft in a coordinated turn, scene units as metres).
    #[serde(default)]
    pub bank: Option<f64>,
    /// The order of `Euler` angles: `XYZ` turns about x first (the parent's axes).
    #[serde(default)]
    pub euler_order: Option<EulerOrder>,
    /// Turn to face a point, keyed points or an object.
    #[serde(default)]
    pub look_at: Option<AimSpec>,
    /// With `look_at`: the direction kept up (default +y).
    #[serde(default)]
    pub up: Option<V3>,
    /// With `look_at`: degrees about the line of sight.
    #[serde(default)]
    pub roll: ChannelSpec<f64>,
    /// With `look_at` on an object: the direction that faces the target (default −z).
    #[serde(default)]
    pub forward: Option<V3>,
    /// Lights only.
    #[serde(default)]
    pub brightness: ChannelSpec<f64>,
    /// Lights only.
    #[serde(default)]
    pub color: ChannelSpec<Rgb>,
    /// Cameras only: horizontal field of view in degrees.
    #[serde(default)]
    pub fov: ChannelSpec<f64>,
    /// Lights only: the radius of a spherical light.
    #[serde(default)]
    pub radius: ChannelSpec<f64>,
    /// Spot lights only: the half-angles of full light and of none, in degrees.
    #[serde(default)]
    pub inner: ChannelSpec<f64>,
    #[serde(default)]
    pub outer: ChannelSpec<f64>,
    /// Cameras only: the lens's aperture radius.
    #[serde(default)]
    pub aperture: ChannelSpec<f64>,
    /// Cameras only: the focus distance, or `Object("name")` (read as a channel whose one
    /// part is the name; the variant's name is checked against the text).
    #[serde(default)]
    pub focus: ChannelSpec<f64>,
    /// Materials only: ambient, diffuse and specular colours.
    #[serde(default)]
    pub ka: ChannelSpec<Rgb>,
    #[serde(default)]
    pub kd: ChannelSpec<Rgb>,
    #[serde(default)]
    pub ks: ChannelSpec<Rgb>,
    /// Materials only: 0–1.
    #[serde(default)]
    pub reflectivity: ChannelSpec<f64>,
    /// Materials only: 0–1, 1 opaque.
    #[serde(default)]
    pub opacity: ChannelSpec<f64>,
    /// Materials only: index of refraction, > 0.
    #[serde(default)]
    pub ior: ChannelSpec<f64>,
    /// Shapes and composites: shown (`true`) or not, stepped.
    #[serde(default)]
    pub visible: Vec<KeySpec<bool>>,
    /// Repeat the keys (period: last key time − first key time). Default: the spec's `looping`.
    #[serde(default)]
    pub looping: Option<bool>,
    /// What the keys do outside their span (`Repeat` is `looping: true`).
    #[serde(default)]
    pub cycle: Option<Cycle>,
    /// How many times a cycling track plays its keys (default: forever).
    #[serde(default)]
    pub cycles: Option<f64>,
    /// Seconds by which every key of the track plays later.
    #[serde(default)]
    pub offset: f64,
    /// How the values this track sets combine with those of the tracks before it on the same
    /// target (and with the base scene's).
    #[serde(default)]
    pub blend: Option<Blend>,
    /// A shape, composite, light or camera whose motion the target follows.
    #[serde(default)]
    pub parent: Option<String>,
    /// What of the parent's motion it follows (default all three).
    #[serde(default)]
    pub follow: Option<Vec<Follow>>,
}

impl TrackSpec {
    /// The times of every key the track itself writes.
    pub fn key_times(&self) -> impl Iterator<Item = KeyTime> + '_ {
        key_times(&self.translate.keys)
            .chain(key_times(&self.rotate.keys))
            .chain(key_times(&self.scale.keys))
            .chain(key_times(&self.orient.keys))
            .chain(self.path.iter().flat_map(|p| key_times(&p.progress.keys)))
            .chain(key_times(&self.roll.keys))
            .chain(key_times(&self.brightness.keys))
            .chain(key_times(&self.color.keys))
            .chain(key_times(&self.fov.keys))
            .chain(key_times(&self.radius.keys))
            .chain(key_times(&self.inner.keys))
            .chain(key_times(&self.outer.keys))
            .chain(key_times(&self.aperture.keys))
            .chain(key_times(&self.focus.keys))
            .chain(key_times(&self.ka.keys))
            .chain(key_times(&self.kd.keys))
            .chain(key_times(&self.ks.keys))
            .chain(key_times(&self.reflectivity.keys))
            .chain(key_times(&self.opacity.keys))
            .chain(key_times(&self.ior.keys))
            .chain(key_times(&self.visible))
            .chain(match &self.look_at {
                Some(AimSpec::Keys(k)) => k.iter().map(|k| k.at).collect::<Vec<_>>(),
                _ => Vec::new(),
            })
    }
}

/// An orientation key's value.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Orientation {
    /// Degrees about x, y and z, applied in the track's `euler_order`.
    Euler(f64, f64, f64),
    /// `(axis, degrees)`, right-handed.
    AxisAngle(V3, f64),
    /// A unit quaternion (normalised when it is not), its parts named.
    Quat { x: f64, y: f64, z: f64, w: f64 },
}

/// What `look_at` aims at.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum AimSpec {
    Point(V3),
    Keys(Vec<KeySpec<V3>>),
    /// A shape or composite: its centre, wherever the tracks move it.
    Object(String),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeySpec<T> {
    /// Seconds from the start of the animation, or `Frames(n)`.
    pub at: KeyTime,
    pub value: T,
    /// How to move from this key to the next one.
    #[serde(default)]
    pub interp: Interp,
    /// How the segment before this key arrives at it.
    #[serde(default, rename = "in")]
    pub ease_in: Option<Side>,
    /// How the segment after this key leaves it.
    #[serde(default, rename = "out")]
    pub ease_out: Option<Side>,
}

/// `(x, y, z)` (or `[x, y, z]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct V3(pub DVec3);

/// A number for all three axes, or `(x, y, z)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scale(pub DVec3);

/// A number for grey, or `(r, g, b)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rgb(pub DVec3);

struct TripleVisitor {
    what: &'static str,
    scalar_ok: bool,
}

impl<'de> Visitor<'de> for TripleVisitor {
    type Value = DVec3;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(self.what)
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<DVec3, E> {
        if !self.scalar_ok {
            return Err(E::invalid_type(de::Unexpected::Float(v), &self));
        }
        Ok(DVec3::splat(v))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<DVec3, E> {
        if !self.scalar_ok {
            return Err(E::invalid_type(de::Unexpected::Signed(v), &self));
        }
        Ok(DVec3::splat(v as f64))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<DVec3, E> {
        if !self.scalar_ok {
            return Err(E::invalid_type(de::Unexpected::Unsigned(v), &self));
        }
        Ok(DVec3::splat(v as f64))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<DVec3, A::Error> {
        let mut v = [0.0; 3];
        for (i, slot) in v.iter_mut().enumerate() {
            *slot = seq
                .next_element::<f64>()?
                .ok_or_else(|| de::Error::invalid_length(i, &self))?;
        }
        if seq.next_element::<de::IgnoredAny>()?.is_some() {
            return Err(de::Error::invalid_length(4, &self));
        }
        Ok(DVec3::from_array(v))
    }
}

impl<'de> Deserialize<'de> for V3 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(TripleVisitor {
            what: "three numbers (x, y, z)",
            scalar_ok: false,
        })
        .map(V3)
    }
}

impl<'de> Deserialize<'de> for Scale {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(TripleVisitor {
            what: "a number or three numbers (x, y, z)",
            scalar_ok: true,
        })
        .map(Scale)
    }
}

impl<'de> Deserialize<'de> for Rgb {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(TripleVisitor {
            what: "a number or three numbers (r, g, b)",
            scalar_ok: true,
        })
        .map(Rgb)
    }
}

/// A keyed channel as written: a list of keys, `Expr("…")` (the whole channel a formula) or
/// `Expr("…", [keys])` (a formula over the keyed value). The name `Expr` itself is checked
/// against the text ([`super::source::Source`] records it), as serde passes it over.
#[derive(Debug)]
pub struct ChannelSpec<T> {
    pub keys: Vec<KeySpec<T>>,
    pub expr: Option<String>,
}

impl<T> Default for ChannelSpec<T> {
    fn default() -> Self {
        ChannelSpec {
            keys: Vec::new(),
            expr: None,
        }
    }
}

impl<T> ChannelSpec<T> {
    /// Whether it keys nothing.
    pub fn is_empty(&self) -> bool {
        self.keys.is_empty() && self.expr.is_none()
    }

    /// The path of its keys, given the channel's: inside `Expr("…", [keys])` they are its
    /// second part.
    pub fn keys_path(&self, path: &str) -> String {
        match self.expr {
            Some(_) => format!("{path}[1]"),
            None => path.to_string(),
        }
    }
}

/// One part of a channel's list: a key, the text of an expression, or a list of keys.
enum ChannelPart<T> {
    Key(KeySpec<T>),
    Text(String),
    Keys(Vec<KeySpec<T>>),
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for ChannelPart<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Part<T>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de>> Visitor<'de> for Part<T> {
            type Value = ChannelPart<T>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a key `(at: …, value: …)`")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Self::Value, E> {
                Ok(ChannelPart::Text(v.to_string()))
            }
            fn visit_map<A: de::MapAccess<'de>>(self, m: A) -> Result<Self::Value, A::Error> {
                KeySpec::deserialize(de::value::MapAccessDeserializer::new(m)).map(ChannelPart::Key)
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
                let mut keys = Vec::new();
                while let Some(k) = seq.next_element::<KeySpec<T>>()? {
                    keys.push(k);
                }
                Ok(ChannelPart::Keys(keys))
            }
        }
        d.deserialize_any(Part(std::marker::PhantomData))
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for ChannelSpec<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Channel<T>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de>> Visitor<'de> for Channel<T> {
            type Value = ChannelSpec<T>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a list of keys `[(at: …, value: …), …]` or `Expr(\"…\")`")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
                let mut parts = Vec::new();
                while let Some(p) = seq.next_element::<ChannelPart<T>>()? {
                    parts.push(p);
                }
                let mut out = ChannelSpec::default();
                let mut parts = parts.into_iter();
                match parts.next() {
                    Some(ChannelPart::Text(text)) => {
                        out.expr = Some(text);
                        match (parts.next(), parts.next()) {
                            (None, _) => {}
                            (Some(ChannelPart::Keys(keys)), None) => out.keys = keys,
                            _ => return Err(de::Error::custom(EXPR_FORM)),
                        }
                    }
                    Some(ChannelPart::Key(first)) => {
                        out.keys.push(first);
                        for p in parts {
                            match p {
                                ChannelPart::Key(k) => out.keys.push(k),
                                _ => return Err(de::Error::custom("expected a key `(at: …, value: …)`: a list of keys holds keys only")),
                            }
                        }
                    }
                    Some(ChannelPart::Keys(_)) => return Err(de::Error::custom(EXPR_FORM)),
                    None => {}
                }
                Ok(out)
            }
        }
        d.deserialize_any(Channel(std::marker::PhantomData))
    }
}

/// How an expression over keys is written.
const EXPR_FORM: &str =
    "an expression is written `Expr(\"…\")`, or `Expr(\"…\", [keys])` over keys that it reads as `value`";

/// The spec's named values, in the order written.
#[derive(Debug, Default)]
pub struct NamedValues(pub Vec<(String, NamedValue)>);

/// A named value: a number, a vector, or an expression.
#[derive(Debug, Clone, PartialEq)]
pub enum NamedValue {
    Number(f64),
    Vector(DVec3),
    Expr(String),
}

impl<'de> Deserialize<'de> for NamedValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Value;
        impl<'de> Visitor<'de> for Value {
            type Value = NamedValue;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number, three numbers (x, y, z) or an expression in double quotes")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<NamedValue, E> {
                Ok(NamedValue::Number(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<NamedValue, E> {
                Ok(NamedValue::Number(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<NamedValue, E> {
                Ok(NamedValue::Number(v as f64))
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<NamedValue, E> {
                Ok(NamedValue::Expr(v.to_string()))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<NamedValue, A::Error> {
                let v = TripleVisitor {
                    what: "three numbers (x, y, z)",
                    scalar_ok: false,
                }
                .visit_seq(seq)?;
                Ok(NamedValue::Vector(v))
            }
        }
        d.deserialize_any(Value)
    }
}

impl<'de> Deserialize<'de> for NamedValues {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Values;
        impl<'de> Visitor<'de> for Values {
            type Value = NamedValues;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("named values `{\"name\": value, …}`")
            }
            fn visit_map<A: de::MapAccess<'de>>(self, mut m: A) -> Result<NamedValues, A::Error> {
                let mut out = Vec::new();
                while let Some((name, value)) = m.next_entry::<String, NamedValue>()? {
                    out.push((name, value));
                }
                Ok(NamedValues(out))
            }
        }
        d.deserialize_map(Values)
    }
}

/// `orient` as written: orientation keys, or `AlongPath`.
#[derive(Debug, Default)]
pub struct OrientSpec {
    pub keys: Vec<KeySpec<Orientation>>,
    /// `orient: AlongPath`; the name is checked against the text, which records it.
    pub along_path: bool,
}

impl OrientSpec {
    pub fn is_empty(&self) -> bool {
        self.keys.is_empty() && !self.along_path
    }
}

impl<'de> Deserialize<'de> for OrientSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Orient;
        impl<'de> Visitor<'de> for Orient {
            type Value = OrientSpec;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("orientation keys `[(at: …, value: Euler(…)), …]` or `AlongPath`")
            }
            fn visit_unit<E: de::Error>(self) -> Result<OrientSpec, E> {
                Ok(OrientSpec {
                    keys: Vec::new(),
                    along_path: true,
                })
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<OrientSpec, A::Error> {
                let mut keys = Vec::new();
                while let Some(k) = seq.next_element::<KeySpec<Orientation>>()? {
                    keys.push(k);
                }
                Ok(OrientSpec {
                    keys,
                    along_path: false,
                })
            }
        }
        d.deserialize_any(Orient)
    }
}

/// A path: the points it passes, whether it closes, its shape, and how far along it the
/// target is over time.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PathSpec {
    pub points: Vec<V3>,
    #[serde(default)]
    pub closed: bool,
    #[serde(default)]
    pub spline: PathSpline,
    /// The fraction of the path's length travelled (0 its start, 1 its end); default: from 0
    /// at the start of the animation to 1 at its end, at constant speed.
    #[serde(default)]
    pub progress: ChannelSpec<f64>,
}

/// The curve through a path's points.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
pub enum PathSpline {
    /// Catmull-Rom: through every point without corners.
    #[default]
    Smooth,
    /// Straight lines from point to point.
    Linear,
}
