//! The RON keyframe spec: serde types as the user writes them, and the checks that turn them
//! into an [`Animation`] whose every problem is reported at its line and column in the spec.
//!
//! The format is documented for users in `README.md`.

use super::generate::tidy;
use super::interp::{Interp, Key};
use super::locate::{field, index, Locations, Pos};

use crate::diag::{suggest, Diagnostic, Loc, Severity};
use glam::DVec3;
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::Deserialize;
use std::fmt;
use std::path::Path;
use std::sync::Arc;

// ---------------------------------------------------------------------------------------------
// What the user writes

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

// ---------------------------------------------------------------------------------------------
// The spec text with its locations, for messages

/// A spec's text and where each value stands in it.
pub struct Source {
    pub path: Arc<Path>,
    pub text: String,
    pub locations: Locations,
}

impl Source {
    pub fn new(path: &Path, text: String) -> Source {
        let locations = Locations::scan(&text);
        Source {
            path: Arc::from(path),
            text,
            locations,
        }
    }

    fn line_text(&self, line: u32) -> Option<&str> {
        self.text.lines().nth(line.checked_sub(1)? as usize)
    }

    /// A diagnostic at `pos`, quoting the line.
    pub fn at_pos(
        &self,
        severity: Severity,
        pos: Pos,
        width: u32,
        message: impl Into<String>,
    ) -> Diagnostic {
        let loc = Loc {
            file: self.path.clone(),
            line: pos.line,
            col: pos.col,
        };
        let d = Diagnostic::new(severity, loc, message);
        match self.line_text(pos.line) {
            Some(src) => d.with_source(src, width),
            None => d,
        }
    }

    /// An error at the value found at the first existing path of `paths` (more specific
    /// first); at the whole file if none exists.
    pub fn error(&self, paths: &[&str], message: impl Into<String>) -> Diagnostic {
        match self.locations.first(paths) {
            Some((pos, width)) => self.at_pos(Severity::Error, pos, width, message),
            None => Diagnostic::file_error(&self.path, message),
        }
    }

    /// Turns ron's error into a located diagnostic in the user's terms.
    pub fn ron_error(&self, e: &ron::error::SpannedError) -> Diagnostic {
        use ron::error::Error as E;
        let line = e.position.line.max(1) as u32;
        let line_text = self.line_text(line).unwrap_or("");
        // ron counts columns in bytes, and for a bad name points just past it.
        let byte_col = e.position.col.max(1) - 1;
        let mut byte_col = byte_col.min(line_text.len());
        while !line_text.is_char_boundary(byte_col) {
            byte_col -= 1;
        }
        let mut width = 1;
        let found_name = match &e.code {
            E::NoSuchStructField { found, .. } | E::NoSuchEnumVariant { found, .. } => {
                Some(found.as_str())
            }
            _ => None,
        };
        if let Some(name) = found_name {
            if line_text[..byte_col].ends_with(name) {
                byte_col -= name.len();
                width = name.chars().count().max(1) as u32;
            }
        }
        let col = line_text[..byte_col].chars().count() as u32 + 1;
        let pos = Pos { line, col };
        if found_name.is_none() {
            if let Some((_, w)) = self.locations_at(pos) {
                width = w;
            }
        }
        let (message, help) = describe_ron_error(&e.code);
        // ron reads `64.5` where a whole number belongs as `64` followed by a stray `.5`, and
        // complains about what follows; the real problem is the number.
        let (pos, message, width) = match decimal_before(line_text, byte_col) {
            Some((start, text)) => (
                Pos {
                    line,
                    col: line_text[..start].chars().count() as u32 + 1,
                },
                format!("expected a whole number, found `{text}`"),
                text.chars().count() as u32,
            ),
            None => (pos, message, width),
        };
        let message = match (found_name, self.locations_at(pos)) {
            (None, Some((path, _))) if !path.is_empty() => format!("{message} (in `{path}`)"),
            _ => message,
        };
        let d = self.at_pos(Severity::Error, pos, width, message);
        match help {
            Some(h) => d.with_help(h),
            None => d,
        }
    }

    /// The deepest value starting exactly at `pos`.
    fn locations_at(&self, pos: Pos) -> Option<(String, u32)> {
        self.locations.starting_at(pos)
    }
}

/// If `line[at]` is the `.` of a decimal number (`64.5`), the number's start and text.
fn decimal_before(line: &str, at: usize) -> Option<(usize, &str)> {
    let bytes = line.as_bytes();
    if bytes.get(at) != Some(&b'.') || !at.checked_sub(1).is_some_and(|p| bytes[p].is_ascii_digit())
    {
        return None;
    }
    let start = line[..at]
        .rfind(|c: char| !(c.is_ascii_digit() || c == '-' || c == '+'))
        .map_or(0, |i| i + 1);
    let end = at
        + 1
        + line[at + 1..]
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '-' || c == '+'))
            .unwrap_or(line.len() - at - 1);
    Some((start, &line[start..end]))
}

/// What the user calls each serde type in messages.
fn user_name(outer: &Option<String>) -> &'static str {
    match outer.as_deref() {
        Some("SpecFile") => "the spec",
        Some("OrbitSpec") => "`orbit`",
        Some("TrackSpec") => "a track",
        Some("KeySpec") => "a key",
        Some("SceneSource") => "`scene`",
        Some("Length") => "`length`",
        Some("Interp") => "`interp`",
        _ => "this value",
    }
}

fn list(names: &[&str]) -> String {
    names
        .iter()
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn describe_ron_error(code: &ron::error::Error) -> (String, Option<String>) {
    use ron::error::Error as E;
    match code {
        E::NoSuchStructField {
            expected,
            found,
            outer,
        } => {
            let help = match suggest(found, expected.iter().copied()) {
                Some(s) => format!("did you mean `{s}`?"),
                None => format!("the fields of {} are {}", user_name(outer), list(expected)),
            };
            (
                format!("unknown field `{found}` in {}", user_name(outer)),
                Some(help),
            )
        }
        E::NoSuchEnumVariant {
            expected,
            found,
            outer,
        } => {
            let help = match suggest(found, expected.iter().copied()) {
                Some(s) => format!("did you mean `{s}`?"),
                None => format!("expected one of {}", list(expected)),
            };
            (
                format!("unknown variant `{found}` for {}", user_name(outer)),
                Some(help),
            )
        }
        E::MissingStructField { field, outer } => (
            format!("{} is missing the field `{field}`", user_name(outer)),
            None,
        ),
        E::DuplicateStructField { field, outer } => (
            format!("the field `{field}` is given twice in {}", user_name(outer)),
            None,
        ),
        E::ExpectedInteger => ("expected a whole number".to_string(), None),
        E::ExpectedFloat => ("expected a number".to_string(), None),
        E::ExpectedString => ("expected a string in double quotes".to_string(), None),
        E::ExpectedBoolean => ("expected `true` or `false`".to_string(), None),
        E::InvalidValueForType { expected, found } => {
            (format!("expected {expected}, found {found}"), None)
        }
        E::Message(m) => (lower_first(m), None),
        // ron's own wording ("Expected closing `)`"), in the lower case of the rest.
        other => (lower_first(&other.to_string()), None),
    }
}

fn lower_first(text: &str) -> String {
    let mut chars = text.chars();
    match chars.next() {
        Some(c) => c.to_lowercase().collect::<String>() + chars.as_str(),
        None => String::new(),
    }
}

// ---------------------------------------------------------------------------------------------
// Parsing

/// Reads the spec's RON text. Errors are located in `source`.
pub fn parse(source: &Source) -> Result<SpecFile, Box<Diagnostic>> {
    let options =
        ron::Options::default().with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
    options
        .from_str::<SpecFile>(&source.text)
        .map_err(|e| Box::new(source.ron_error(&e)))
}

// ---------------------------------------------------------------------------------------------
// The checked animation

/// A keyed channel with the path of its key list (for messages about interpolated values).
#[derive(Clone, Debug, PartialEq)]
pub struct Channel<T> {
    pub keys: Vec<Key<T>>,
    pub looping: bool,
    pub path: String,
}

impl<T: super::interp::Keyable> Channel<T> {
    pub fn at(&self, t: f64) -> Option<T> {
        super::interp::sample(&self.keys, t, self.looping)
    }
}

/// What a name in the base scene refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TargetKind {
    Shape,
    Composite,
    Camera,
    Light,
}

impl TargetKind {
    pub fn noun(self) -> &'static str {
        match self {
            TargetKind::Shape => "shape",
            TargetKind::Composite => "composite",
            TargetKind::Camera => "camera",
            TargetKind::Light => "light",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Track {
    pub target: String,
    pub kind: TargetKind,
    pub translate: Option<Channel<DVec3>>,
    pub rotate: Option<Channel<f64>>,
    /// Unit-free, non-zero.
    pub axis: DVec3,
    pub scale: Option<Channel<DVec3>>,
    pub pivot: Option<DVec3>,
    pub brightness: Option<Channel<f64>>,
    pub color: Option<Channel<DVec3>>,
    pub fov: Option<Channel<f64>>,
    /// `tracks[i]`, for messages.
    pub path: String,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Orbit {
    pub center: DVec3,
    pub radius: f64,
    pub height: f64,
    pub turns: f64,
    pub start_angle: f64,
    pub look_at: DVec3,
    pub interp: Interp,
}

/// Output names: `prefix` + zero-padded number + `suffix` (`.png` etc.).
#[derive(Clone, Debug, PartialEq)]
pub struct NamePattern {
    pub prefix: String,
    /// The part after `{frame}`, extension included.
    pub suffix: String,
}

impl NamePattern {
    /// The image file name of frame `i`.
    pub fn image(&self, i: usize, digits: usize) -> String {
        format!("{}{i:0digits$}{}", self.prefix, self.suffix)
    }

    /// The SDF file name of frame `i`: the image name with `.sdf` for its extension.
    pub fn sdf(&self, i: usize, digits: usize) -> String {
        format!("{}{i:0digits$}{}.sdf", self.prefix, self.suffix_stem())
    }

    pub fn suffix_stem(&self) -> &str {
        match self.suffix.rfind('.') {
            Some(dot) => &self.suffix[..dot],
            None => &self.suffix,
        }
    }
}

/// A validated animation, ready to generate frames from.
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    pub fps: u32,
    pub frames: usize,
    pub width: u32,
    pub height: u32,
    pub samples: Option<u32>,
    pub output: NamePattern,
    pub camera: String,
    pub orbit: Option<Orbit>,
    pub ambient: Option<Channel<DVec3>>,
    pub background: Option<Channel<DVec3>>,
    pub tracks: Vec<Track>,
}

impl Animation {
    /// Digits in frame numbers: enough for the last frame, at least 4.
    pub fn digits(&self) -> usize {
        self.frames.saturating_sub(1).to_string().len().max(4)
    }

    /// Length in seconds.
    pub fn duration(&self) -> f64 {
        self.frames as f64 / self.fps as f64
    }

    /// Time of frame `i` in seconds.
    pub fn time(&self, i: usize) -> f64 {
        i as f64 / self.fps as f64
    }
}

/// The names the spec can refer to, from the base scene.
pub trait SceneNames {
    /// What `name` is, if the base scene defines it.
    fn kind_of(&self, name: &str) -> Option<TargetKind>;
    /// Every targetable name, for suggestions.
    fn names(&self) -> Vec<&str>;
    /// The camera used when the spec names none.
    fn default_camera(&self) -> Option<&str>;
}

/// Largest frame count accepted: far beyond any real use, small enough to catch `fps: 24000`.
const MAX_FRAMES: f64 = 1_000_000.0;

/// Image extensions the renderer writes.
const IMAGE_EXTENSIONS: &[&str] = &["png", "ppm", "bmp", "jpg", "jpeg", "tga"];

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
    };

    let fps_ok = spec.fps.fract() == 0.0 && (1.0..=1000.0).contains(&spec.fps);
    if !fps_ok {
        c.err(
            &["fps"],
            format!(
                "fps must be a whole number from 1 to 1000, not {}",
                spec.fps
            ),
        );
    }
    let fps = if fps_ok { spec.fps as u32 } else { 24 };
    let frames = match spec.length {
        Length::Frames(n) => {
            if !(n.fract() == 0.0 && n >= 1.0) {
                c.err(
                    &["length[0]", "length"],
                    format!("the number of frames must be a whole number, at least 1, not {n}"),
                );
            }
            n
        }
        Length::Seconds(s) => {
            let exact = s * fps as f64;
            let n = exact.round();
            if !s.is_finite() || s <= 0.0 {
                c.err(
                    &["length[0]", "length"],
                    format!("the length must be a positive number of seconds, not {s}"),
                );
            } else if n < 1.0 {
                c.err(
                    &["length[0]", "length"],
                    format!("{s} s at {fps} fps is less than one frame"),
                );
            } else if (exact - n).abs() > 1e-6 {
                // Rounding silently would make the video longer or shorter than asked.
                c.err(
                    &["length[0]", "length"],
                    format!(
                        "{s} s at {fps} fps is {} frames: the length must be a whole number of frames (e.g. Frames({n}))",
                        tidy(exact)
                    ),
                );
            }
            n
        }
    };
    if frames > MAX_FRAMES {
        c.err(
            &["length[0]", "length"],
            format!("{frames} frames is more than the {MAX_FRAMES} allowed"),
        );
    }
    let frames = if frames.is_finite() {
        frames.clamp(1.0, MAX_FRAMES) as usize
    } else {
        1
    };
    c.duration = frames as f64 / fps as f64;

    let (width, height) = spec.resolution;
    for (v, p) in [(width, "resolution[0]"), (height, "resolution[1]")] {
        if !(1..=65536).contains(&v) {
            c.err(
                &[p, "resolution"],
                format!("image sizes run from 1 to 65536 pixels, not {v}"),
            );
        }
    }
    if let Some(s) = spec.samples {
        if !(1..=4096).contains(&s) {
            c.err(
                &["samples"],
                format!("samples per pixel run from 1 to 4096, not {s}"),
            );
        }
    }
    let output = match name_pattern(&spec.output) {
        Ok(p) => Some(p),
        Err(msg) => {
            c.err(&["output"], msg);
            None
        }
    };
    if let Some(dir) = &spec.frames_dir {
        if dir.trim().is_empty() {
            c.err(&["frames_dir"], "frames_dir is empty".into());
        }
    }

    // The camera.
    let camera = match &spec.camera {
        Some(name) => {
            match names.kind_of(name) {
                Some(TargetKind::Camera) => {}
                Some(kind) => c.err(
                    &["camera"],
                    format!("'{name}' is a {}, not a camera", kind.noun()),
                ),
                None => {
                    let all = names.names();
                    let cams: Vec<&str> = all
                        .iter()
                        .copied()
                        .filter(|n| names.kind_of(n) == Some(TargetKind::Camera))
                        .collect();
                    let d = src.error(
                        &["camera"],
                        format!("the base scene has no camera named '{name}'"),
                    );
                    let d = match suggest(name, cams.iter().copied()) {
                        Some(s) => d.with_help(format!("did you mean '{s}'?")),
                        None if !cams.is_empty() => d.with_help(format!(
                            "the base scene's cameras: {}",
                            cams.iter()
                                .map(|c| format!("'{c}'"))
                                .collect::<Vec<_>>()
                                .join(", ")
                        )),
                        None => d,
                    };
                    c.errors.push(d);
                }
            }
            name.clone()
        }
        None => match names.default_camera() {
            Some(cam) => cam.to_string(),
            None => {
                c.errors.push(
                    src.error(&["scene"], "the base scene defines no camera").with_help(
                        "add `define camera cam 60 …` to the scene, then name it with `camera: \"cam\"`",
                    ),
                );
                String::new()
            }
        },
    };

    let finite3 = |v: DVec3| v.is_finite();

    let orbit = spec.orbit.as_ref().map(|o| {
        let mut err = |paths: &[&str], msg: String| c.err(paths, msg);
        if !(o.radius.is_finite() && o.radius > 0.0) {
            err(
                &["orbit.radius", "orbit"],
                format!(
                    "the orbit radius must be a positive number, not {}",
                    o.radius
                ),
            );
        }
        if !o.height.is_finite() {
            err(
                &["orbit.height", "orbit"],
                "the orbit height must be a finite number".into(),
            );
        }
        if !o.turns.is_finite() {
            err(
                &["orbit.turns", "orbit"],
                "turns must be a finite number".into(),
            );
        }
        if !o.start_angle.is_finite() {
            err(
                &["orbit.start_angle", "orbit"],
                "start_angle must be a finite number".into(),
            );
        }
        if !finite3(o.center.0) {
            err(
                &["orbit.center", "orbit"],
                "the orbit centre must be finite".into(),
            );
        }
        let look_at = o.look_at.map(|v| v.0).unwrap_or(o.center.0);
        if !finite3(look_at) {
            err(&["orbit.look_at", "orbit"], "look_at must be finite".into());
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
    });

    let checker = &mut c;
    let ambient = checker.channel(
        &spec.ambient,
        "ambient",
        spec.looping,
        |v: &Rgb| v.0,
        Some(non_negative3),
    );
    let background = checker.channel(
        &spec.background,
        "background",
        spec.looping,
        |v: &Rgb| v.0,
        Some(non_negative3),
    );

    let mut tracks = Vec::new();
    for (i, t) in spec.tracks.iter().enumerate() {
        let path = index("tracks", i);
        let target_path = field(&path, "target");
        let kind = match names.kind_of(&t.target) {
            Some(k) => Some(k),
            None => {
                let all = names.names();
                let d = src.error(
                    &[&target_path, &path],
                    format!(
                        "the base scene has no shape, composite, camera or light named '{}'",
                        t.target
                    ),
                );
                let d = match suggest(&t.target, all.iter().copied()) {
                    Some(s) => d.with_help(format!("did you mean '{s}'?")),
                    None => d,
                };
                checker.errors.push(d);
                None
            }
        };
        let looping = t.looping.unwrap_or(spec.looping);
        let translate = checker.channel(
            &t.translate,
            &field(&path, "translate"),
            looping,
            |v: &V3| v.0,
            None,
        );
        let rotate = checker.channel(
            &t.rotate,
            &field(&path, "rotate"),
            looping,
            |v: &f64| *v,
            None,
        );
        let scale = checker.channel(
            &t.scale,
            &field(&path, "scale"),
            looping,
            |v: &Scale| v.0,
            Some(non_zero3),
        );
        let brightness = checker.channel(
            &t.brightness,
            &field(&path, "brightness"),
            looping,
            |v: &f64| *v,
            Some(non_negative),
        );
        let color = checker.channel(
            &t.color,
            &field(&path, "color"),
            looping,
            |v: &Rgb| v.0,
            Some(non_negative3),
        );
        let fov = checker.channel(
            &t.fov,
            &field(&path, "fov"),
            looping,
            |v: &f64| *v,
            Some(fov_range),
        );
        let axis = t.axis.map(|a| a.0).unwrap_or(DVec3::Y);
        if !(finite3(axis) && axis.length_squared() > 0.0) {
            checker.err(
                &[&field(&path, "axis")],
                "the rotation axis must be a non-zero vector".into(),
            );
        }
        if t.axis.is_some() && t.rotate.is_empty() {
            checker.err(
                &[&field(&path, "axis")],
                "`axis` without `rotate` keys does nothing".into(),
            );
        }
        if let Some(p) = t.pivot {
            if !finite3(p.0) {
                checker.err(&[&field(&path, "pivot")], "the pivot must be finite".into());
            }
        }
        let keyed = [
            !t.translate.is_empty(),
            !t.rotate.is_empty(),
            !t.scale.is_empty(),
            !t.brightness.is_empty(),
            !t.color.is_empty(),
            !t.fov.is_empty(),
        ];
        if !keyed.iter().any(|&k| k) {
            checker.err(
                &[&target_path, &path],
                format!("the track for '{}' keys nothing", t.target),
            );
        }
        if let Some(kind) = kind {
            let wrong = |channel: &str, allowed: &str| {
                format!(
                    "'{}' is a {}: `{channel}` can only be keyed on {allowed}",
                    t.target,
                    kind.noun()
                )
            };
            if kind != TargetKind::Light {
                if !t.brightness.is_empty() {
                    checker.err(
                        &[&field(&path, "brightness")],
                        wrong("brightness", "lights"),
                    );
                }
                if !t.color.is_empty() {
                    checker.err(&[&field(&path, "color")], wrong("color", "lights"));
                }
            }
            if kind != TargetKind::Camera && !t.fov.is_empty() {
                checker.err(&[&field(&path, "fov")], wrong("fov", "cameras"));
            }
            let moves = !(t.translate.is_empty() && t.rotate.is_empty() && t.scale.is_empty());
            if kind == TargetKind::Camera && t.target == camera && orbit.is_some() && moves {
                let p = if !t.translate.is_empty() {
                    "translate"
                } else if !t.rotate.is_empty() {
                    "rotate"
                } else {
                    "scale"
                };
                checker.err(
                    &[&field(&path, p)],
                    format!(
                        "camera '{}' follows the orbit; moving it too would take it off the orbit",
                        t.target
                    ),
                );
            }
            tracks.push(Track {
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
            });
        }
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
        }),
        _ => Err(c.errors),
    }
}

fn non_negative(v: DVec3) -> Option<&'static str> {
    (v.x < 0.0).then_some("must not be negative")
}

fn non_negative3(v: DVec3) -> Option<&'static str> {
    if v.cmplt(DVec3::ZERO).any() {
        Some("must not be negative")
    } else {
        None
    }
}

fn non_zero3(v: DVec3) -> Option<&'static str> {
    if v.cmpeq(DVec3::ZERO).any() {
        Some("must not be 0 on any axis (a scale of 0 cannot be undone)")
    } else {
        None
    }
}

fn fov_range(v: DVec3) -> Option<&'static str> {
    if v.x > 0.0 && v.x < 180.0 {
        None
    } else {
        Some("must be between 0 and 180 degrees")
    }
}

/// The name pattern of the frame images, e.g. `frame_{frame}.png`.
fn name_pattern(s: &str) -> Result<NamePattern, String> {
    let Some((prefix, suffix)) = s.split_once("{frame}") else {
        return Err(format!(
            "output '{s}' must contain `{{frame}}` where the frame number goes"
        ));
    };
    if suffix.contains("{frame}") {
        return Err(format!("output '{s}' contains `{{frame}}` twice"));
    }
    if s.contains(['/', '\\']) {
        return Err(format!(
            "output '{s}' is a file name, not a path: frames go into frames_dir (or -o)"
        ));
    }
    if s.contains(|c: char| c.is_whitespace() || c == '#') {
        return Err(format!(
            "output '{s}' contains a space or '#', which the SDF render line cannot hold"
        ));
    }
    let ext = suffix.rsplit_once('.').map(|(_, e)| e.to_ascii_lowercase());
    match ext {
        Some(e) if IMAGE_EXTENSIONS.contains(&e.as_str()) => Ok(NamePattern {
            prefix: prefix.to_string(),
            suffix: suffix.to_string(),
        }),
        _ => Err(format!(
            "output '{s}' must end in an image extension after `{{frame}}` ({})",
            IMAGE_EXTENSIONS.join(", ")
        )),
    }
}

/// Collects errors; converts key lists into channels, checking times and values.
struct Checker<'a> {
    duration: f64,
    src: &'a Source,
    errors: Vec<Diagnostic>,
}

impl Checker<'_> {
    fn err(&mut self, paths: &[&str], msg: String) {
        self.errors.push(self.src.error(paths, msg));
    }

    /// `check` sees each key's value as a vector (numbers as `x`) and names what is wrong.
    fn channel<S, T: Copy + Into3>(
        &mut self,
        keys: &[KeySpec<S>],
        path: &str,
        looping: bool,
        value: impl Fn(&S) -> T,
        check: Option<fn(DVec3) -> Option<&'static str>>,
    ) -> Option<Channel<T>> {
        if keys.is_empty() {
            return None;
        }
        let mut out = Vec::with_capacity(keys.len());
        let mut prev: Option<f64> = None;
        let what = path.rsplit('.').next().unwrap_or(path);
        for (i, k) in keys.iter().enumerate() {
            let kp = index(path, i);
            let at_path = field(&kp, "at");
            let value_path = field(&kp, "value");
            let v = value(&k.value);
            if !k.at.is_finite() {
                self.err(
                    &[&at_path, &kp],
                    "a key's time must be a finite number of seconds".into(),
                );
            } else if k.at < 0.0 {
                self.err(
                    &[&at_path, &kp],
                    format!(
                        "the key at {} s is before the start of the animation (0 s)",
                        k.at
                    ),
                );
            } else if k.at > self.duration + 1e-9 {
                self.err(
                    &[&at_path, &kp],
                    format!(
                        "the key at {} s is after the end of the animation ({} s)",
                        k.at, self.duration
                    ),
                );
            }
            if let Some(p) = prev {
                if k.at <= p {
                    self.err(
                        &[&at_path, &kp],
                        format!(
                            "keys must be in time order: this key at {} s follows a key at {} s",
                            k.at, p
                        ),
                    );
                }
            }
            prev = Some(k.at);
            if !v.into3().is_finite() {
                self.err(
                    &[&value_path, &kp],
                    format!("the {what} value must be finite"),
                );
            } else if let Some(problem) = check.and_then(|c| c(v.into3())) {
                self.err(&[&value_path, &kp], format!("{what} {problem}"));
            }
            out.push(Key {
                at: k.at,
                value: v,
                interp: k.interp,
            });
        }
        Some(Channel {
            keys: out,
            looping,
            path: path.to_string(),
        })
    }
}

/// Numbers seen as vectors for the shared value checks.
trait Into3 {
    fn into3(self) -> DVec3;
}

impl Into3 for f64 {
    fn into3(self) -> DVec3 {
        DVec3::new(self, self, self)
    }
}

impl Into3 for DVec3 {
    fn into3(self) -> DVec3 {
        self
    }
}
