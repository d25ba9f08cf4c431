//! The spec as the user writes it: serde types that mirror the RON text one to one, so that
//! ron rejects every unknown field and variant with its position.

use crate::keyframe::interp::Interp;
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
    /// Frames per second, a whole number (read as a number so that `24.5` gets a clear message).
    #[serde(default = "default_fps")]
    pub fps: f64,
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
    pub ambient: Vec<KeySpec<Rgb>>,
    /// Keyed background colour (replaces the base scene's).
    #[serde(default)]
    pub background: Vec<KeySpec<Rgb>>,
    #[serde(default)]
    pub tracks: Vec<TrackSpec>,
}

fn default_fps() -> f64 {
    24.0
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

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackSpec {
    /// A shape, composite, camera or light of the base scene.
    pub target: String,
    #[serde(default)]
    pub translate: Vec<KeySpec<V3>>,
    /// Degrees about `axis`.
    #[serde(default)]
    pub rotate: Vec<KeySpec<f64>>,
    #[serde(default)]
    pub axis: Option<V3>,
    /// A number (uniform) or (x, y, z) per key.
    #[serde(default)]
    pub scale: Vec<KeySpec<Scale>>,
    /// Centre of rotation and scaling; default: the object's centre as the base scene places it.
    #[serde(default)]
    pub pivot: Option<V3>,
    /// Lights only.
    #[serde(default)]
    pub brightness: Vec<KeySpec<f64>>,
    /// Lights only.
    #[serde(default)]
    pub color: Vec<KeySpec<Rgb>>,
    /// Cameras only: horizontal field of view in degrees.
    #[serde(default)]
    pub fov: Vec<KeySpec<f64>>,
    /// Repeat the keys (period: last key time − first key time). Default: the spec's `looping`.
    #[serde(default)]
    pub looping: Option<bool>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeySpec<T> {
    /// Seconds from the start of the animation.
    pub at: f64,
    pub value: T,
    /// How to move from this key to the next one.
    #[serde(default)]
    pub interp: Interp,
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
