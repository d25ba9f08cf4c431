//! The checked animation: what the generator needs, with every value valid.

use crate::keyframe::expr::{Expr, Val};
use crate::keyframe::interp::{cycled_time, sample_timed, segment, Interp, Key, Keyable, Timing};
use crate::keyframe::path::Path;
use anim_core::limits;
use glam::{DQuat, DVec3};
use std::sync::Arc;

/// A keyed channel with the path of its key list (for messages about interpolated values),
/// and the expression over it, if any.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel<T> {
    pub keys: Vec<Key<T>>,
    pub timing: Timing,
    pub path: String,
    pub expr: Option<Driven>,
}

/// A channel's expression, with what it reads besides the time.
#[derive(Clone, Debug, PartialEq)]
pub struct Driven {
    pub expr: Arc<Expr>,
    /// `value` where the channel has no keys: the base scene's value (no motion, for motion).
    pub base: Val,
    pub fps: f64,
    /// `wiggle`'s noise: drawn from the target's and the channel's names.
    pub seed: u64,
    /// The expression's text in the spec, for messages.
    pub path: String,
}

impl<T: Keyable> Channel<T> {
    /// The value at time `t`: the keys', then the expression's over them.
    pub fn at(&self, t: f64) -> Option<T> {
        let keyed = sample_timed(&self.keys, t, &self.timing);
        let Some(d) = &self.expr else {
            return keyed;
        };
        let value = keyed.map_or(d.base, T::to_val);
        Some(T::from_val(d.expr.eval(t, d.fps, value, d.seed)))
    }
}

impl<T> Channel<T> {
    /// The path of the key whose segment plays at time `t` (for messages about a value
    /// between keys), else of the whole list.
    pub fn key_path_at(&self, t: f64) -> String {
        let (Some(first), Some(last)) = (self.keys.first(), self.keys.last()) else {
            return self.path.clone();
        };
        let (local, _) = cycled_time(first.at, last.at, t, &self.timing);
        match segment(&self.keys, local) {
            Ok((k, _)) => format!("{}[{k}]", self.path),
            Err(after) => format!(
                "{}[{}]",
                self.path,
                if after { self.keys.len() - 1 } else { 0 }
            ),
        }
    }
}

/// Keyed orientations, turned by slerp along the shorter arc.
pub type OrientChannel = Channel<DQuat>;

impl OrientChannel {
    /// The orientation at time `t`: the segment's easing applied to the slerp fraction.
    pub fn orientation(&self, t: f64) -> Option<DQuat> {
        let (first, last) = (self.keys.first()?, self.keys.last()?);
        let (local, cycles) = cycled_time(first.at, last.at, t, &self.timing);
        let q = match segment(&self.keys, local) {
            Ok((k, s)) => {
                let (a, b) = (&self.keys[k], &self.keys[k + 1]);
                // q and −q are one orientation: the shorter arc starts from the nearer sign.
                let to = if a.value.dot(b.value) < 0.0 {
                    -b.value
                } else {
                    b.value
                };
                a.value.slerp(to, a.interp.ease(s)).normalize()
            }
            Err(after) => {
                if after {
                    last.value
                } else {
                    first.value
                }
            }
        };
        if self.timing.cycle == crate::keyframe::interp::Cycle::RepeatOffset && cycles != 0.0 {
            // Each repetition starts where the last ended: the whole cycle's turn, again.
            let (axis, angle) = (last.value * first.value.inverse()).to_axis_angle();
            let placed = DQuat::from_axis_angle(axis, angle * cycles) * q;
            return Some(placed.normalize());
        }
        Some(q)
    }
}

/// What a `look_at` aims at.
#[derive(Clone, Debug, PartialEq)]
pub enum AimTarget {
    Point(DVec3),
    Keys(Channel<DVec3>),
    /// A shape or composite of the base scene: its animated centre.
    Object(String),
}

/// A track's aim: its target turns to face `target` with `up` kept up, then rolls about the
/// line of sight.
#[derive(Clone, Debug, PartialEq)]
pub struct Aim {
    pub target: AimTarget,
    pub up: DVec3,
    /// Objects only: the direction (in the parent's frame, as the base scene places the
    /// object) that turns to face the target. Cameras face along their view direction.
    pub forward: DVec3,
    pub roll: Option<Channel<f64>>,
    /// `tracks[i].look_at`, for messages.
    pub path: String,
}

/// A material's keyed values.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct MaterialChannels {
    pub ka: Option<Channel<DVec3>>,
    pub kd: Option<Channel<DVec3>>,
    pub ks: Option<Channel<DVec3>>,
    pub reflectivity: Option<Channel<f64>>,
    pub opacity: Option<Channel<f64>>,
    pub ior: Option<Channel<f64>>,
}

impl MaterialChannels {
    pub fn any(&self) -> bool {
        self.ka.is_some()
            || self.kd.is_some()
            || self.ks.is_some()
            || self.reflectivity.is_some()
            || self.opacity.is_some()
            || self.ior.is_some()
    }
}

/// The keyed size and cone of a light and lens of a camera (docs/scene-language.md §5, §6.1).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct OpticsChannels {
    /// A light's radius (a spherical light's soft shadows).
    pub radius: Option<Channel<f64>>,
    /// A spot's half-angles, in degrees.
    pub inner: Option<Channel<f64>>,
    pub outer: Option<Channel<f64>>,
    /// A camera's aperture radius.
    pub aperture: Option<Channel<f64>>,
    /// A camera's focus distance.
    pub focus: Option<Focus>,
}

/// Where a camera's lens focuses.
#[derive(Clone, Debug, PartialEq)]
pub enum Focus {
    /// A keyed distance along the view direction.
    Distance(Channel<f64>),
    /// The centre of a shape or composite, wherever it is: its distance along the view
    /// direction at every instant (a rack focus).
    Object {
        name: String,
        /// `tracks[i].focus`, for messages.
        path: String,
    },
}

impl Focus {
    /// The path of its keys or of its object, for messages.
    pub fn path(&self) -> &str {
        match self {
            Focus::Distance(c) => &c.path,
            Focus::Object { path, .. } => path,
        }
    }
}

/// What of a parent's motion a child follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
pub enum Follow {
    /// Where the parent's centre goes.
    Translate,
    /// How the parent turns, about its centre.
    Rotate,
    /// How it scales, about its centre.
    Scale,
}

/// A target that follows another's motion: `parent` and what it follows.
#[derive(Clone, Debug, PartialEq)]
pub struct Parent {
    pub name: String,
    pub follow: Vec<Follow>,
    /// `tracks[i].parent`, for messages.
    pub path: String,
}

/// A translation along a path, at the distance `progress` says (default: constant speed over
/// the animation).
#[derive(Clone, Debug, PartialEq)]
pub struct PathMotion {
    pub path: Path,
    pub progress: Option<Channel<f64>>,
    /// The animation's length: the default progress goes from 0 to 1 over it.
    pub duration: f64,
}

impl PathMotion {
    /// The fraction of the path travelled at time `t`.
    pub fn progress(&self, t: f64) -> f64 {
        match &self.progress {
            Some(c) => c.at(t).unwrap_or(0.0),
            None if self.duration > 0.0 => t / self.duration,
            None => 0.0,
        }
    }

    /// Where on the path the target is at time `t`.
    pub fn at(&self, t: f64) -> DVec3 {
        self.path.at(self.progress(t))
    }

    /// Its speed along the path at time `t`, in units a second.
    pub fn speed(&self, t: f64) -> f64 {
        let h = 1e-4;
        let f = (self.progress(t + h) - self.progress(t - h)) / (2.0 * h);
        f.abs() * self.path.length()
    }
}

/// `orient: AlongPath`: the target turns so that `forward` points the way the path goes, with
/// `up` kept up, leaning into turns by `bank`.
#[derive(Clone, Debug, PartialEq)]
pub struct AlongPath {
    /// In the parent's frame as the base scene places the target (for a camera: `None`, its
    /// own view direction).
    pub forward: Option<DVec3>,
    pub up: DVec3,
    pub bank: f64,
    /// `tracks[i].orient`, for messages.
    pub path: String,
}

/// What a name in the base scene refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TargetKind {
    Shape,
    Composite,
    Camera,
    Light,
    Material,
}

impl TargetKind {
    pub fn noun(self) -> &'static str {
        match self {
            TargetKind::Shape => "shape",
            TargetKind::Composite => "composite",
            TargetKind::Camera => "camera",
            TargetKind::Light => "light",
            TargetKind::Material => "material",
        }
    }
}

/// How a track's values combine with what the tracks before it on the same target (or the
/// base scene) give the same channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize)]
pub enum Blend {
    /// This track's value.
    Replace,
    /// The sum.
    Add,
    /// The product (each part of a colour by the same part).
    Multiply,
}

impl Blend {
    /// `new` combined with `current` (a track without `blend` replaces).
    pub fn combine(blend: Option<Blend>, current: f64, new: f64) -> f64 {
        match blend {
            None | Some(Blend::Replace) => new,
            Some(Blend::Add) => current + new,
            Some(Blend::Multiply) => current * new,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Track {
    pub target: String,
    pub kind: TargetKind,
    /// How its values combine with the earlier tracks' (`None`: not said; only the first
    /// track keying a channel may leave it out).
    pub blend: Option<Blend>,
    pub translate: Option<Channel<DVec3>>,
    pub rotate: Option<Channel<f64>>,
    /// Unit-free, non-zero.
    pub axis: DVec3,
    pub scale: Option<Channel<DVec3>>,
    pub pivot: Option<DVec3>,
    pub brightness: Option<Channel<f64>>,
    pub color: Option<Channel<DVec3>>,
    pub fov: Option<Channel<f64>>,
    /// Keyed orientation, applied about the pivot before `rotate`.
    pub orient: Option<OrientChannel>,
    /// The translation along a `path`, instead of `translate` keys.
    pub travel: Option<PathMotion>,
    /// `orient: AlongPath`: facing the way the path goes.
    pub along_path: Option<AlongPath>,
    /// The thing whose motion the target follows, after its own tracks'.
    pub parent: Option<Parent>,
    pub aim: Option<Aim>,
    pub material: MaterialChannels,
    /// A light's radius and cone, a camera's lens.
    pub optics: OpticsChannels,
    /// 1 shown, 0 hidden; stepped.
    pub visible: Option<Channel<f64>>,
    /// `tracks[i]`, for messages.
    pub path: String,
}

impl Track {
    /// The values it sets in its target's definition (not motion), each named as in the spec,
    /// with the path of its keys or expression.
    pub fn values(&self) -> Vec<(&'static str, &str)> {
        let (m, o) = (&self.material, &self.optics);
        let numbers = [
            ("brightness", &self.brightness),
            ("fov", &self.fov),
            ("radius", &o.radius),
            ("inner", &o.inner),
            ("outer", &o.outer),
            ("aperture", &o.aperture),
            ("reflectivity", &m.reflectivity),
            ("opacity", &m.opacity),
            ("ior", &m.ior),
            ("visible", &self.visible),
        ];
        let colours = [
            ("color", &self.color),
            ("ka", &m.ka),
            ("kd", &m.kd),
            ("ks", &m.ks),
        ];
        let mut out: Vec<(&'static str, &str)> = numbers
            .into_iter()
            .filter_map(|(n, c)| Some((n, c.as_ref()?.path.as_str())))
            .collect();
        out.extend(
            colours
                .into_iter()
                .filter_map(|(n, c)| Some((n, c.as_ref()?.path.as_str()))),
        );
        out.extend(o.focus.as_ref().map(|f| ("focus", f.path())));
        out
    }

    /// Whether the track moves its target (rather than setting its parameters only).
    pub fn moves(&self) -> bool {
        self.translate.is_some()
            || self.travel.is_some()
            || self.rotate.is_some()
            || self.scale.is_some()
            || self.orient.is_some()
            || self.aim.is_some()
    }
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
    /// The pattern written in the spec, e.g. `frame_{frame}.png`; `Err` says what is wrong.
    pub fn parse(s: &str) -> Result<NamePattern, String> {
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
        if s.starts_with('.') {
            return Err(format!(
                "output '{s}' starts with a dot: its frames would be hidden files, which \
                 `anim render DIR` passes over"
            ));
        }
        if s.contains(char::is_control) {
            return Err(format!(
                "output '{}' contains a control character, which a file name should not hold",
                s.escape_default()
            ));
        }
        if s.contains(|c: char| c.is_whitespace() || c == '#') {
            return Err(format!(
                "output '{s}' contains a space or '#', which the SDF render line cannot hold"
            ));
        }
        match suffix.rsplit_once('.') {
            Some((_, ext)) if limits::is_image_extension(ext) => Ok(NamePattern {
                prefix: prefix.to_string(),
                suffix: suffix.to_string(),
            }),
            _ => Err(format!(
                "output '{s}' must end in an image extension after `{{frame}}` ({})",
                limits::IMAGE_EXTENSIONS.join(", ")
            )),
        }
    }

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

/// Where the last frame falls.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Deserialize)]
pub enum End {
    /// One step before `length`: the frame after the last is the first again, so a loop has
    /// no doubled frame.
    #[default]
    Cyclic,
    /// At `length`: `length·fps + 1` frames, the last showing the pose keyed at `length`.
    Inclusive,
}

/// A frame rate, exact: `num` frames every `den` seconds (`24000/1001` is 23.976 fps). Frame
/// times are computed from the ratio, never from a rounded rate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fps {
    pub num: u32,
    pub den: u32,
}

impl Fps {
    /// A whole number of frames per second.
    pub fn whole(n: u32) -> Fps {
        Fps { num: n, den: 1 }
    }

    /// `frames` frame intervals, in seconds. For a whole rate `n` this is `frames / n`, as
    /// frame times always were.
    pub fn seconds(self, frames: f64) -> f64 {
        frames * f64::from(self.den) / f64::from(self.num)
    }

    /// Frames per second, rounded (for messages and players).
    pub fn as_f64(self) -> f64 {
        f64::from(self.num) / f64::from(self.den)
    }

    /// The frames of one second of timecode, which `Seconds(s)` lengths count: the rate
    /// itself, but for the NTSC rates (`N·1000/1001`), whose timecode counts `N` frames a
    /// second (two seconds at 23.976 fps are 48 frames, lasting 2.002 s).
    pub fn timecode_rate(self) -> f64 {
        if self.den == 1001 && self.num.is_multiple_of(1000) {
            f64::from(self.num / 1000)
        } else {
            self.as_f64()
        }
    }
}

/// As the frame header writes it: `24`, or the exact ratio `24000/1001`.
impl std::fmt::Display for Fps {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.den == 1 {
            write!(f, "{}", self.num)
        } else {
            write!(f, "{}/{}", self.num, self.den)
        }
    }
}

/// A validated animation, ready to generate frames from.
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    pub fps: Fps,
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
    /// The fraction of each frame's interval the shutter stays open (0: an instant).
    pub shutter: f64,
    pub end: End,
    /// What the checks found worth saying that does not stop generation.
    pub warnings: Vec<anim_core::diag::Diagnostic>,
}

impl Animation {
    /// Digits in frame numbers: enough for the last frame, at least 4.
    pub fn digits(&self) -> usize {
        self.frames.saturating_sub(1).to_string().len().max(4)
    }

    /// Length in seconds: the time of the frame after the last (cyclic), or of the last
    /// frame (inclusive).
    pub fn duration(&self) -> f64 {
        match self.end {
            End::Cyclic => self.fps.seconds(self.frames as f64),
            End::Inclusive => self.fps.seconds(self.frames.saturating_sub(1) as f64),
        }
    }

    /// The span of time frame `i` stands for: up to the next frame (the last frame of a
    /// cyclic animation up to its end; of an inclusive one, its instant).
    pub fn frame_span(&self, i: usize) -> (f64, f64) {
        let start = self.time(i);
        let end = if i + 1 < self.frames {
            self.time(i + 1)
        } else {
            self.duration().max(start)
        };
        (start, end)
    }

    /// Time of frame `i` in seconds.
    pub fn time(&self, i: usize) -> f64 {
        self.fps.seconds(i as f64)
    }

    /// How long the shutter stays open, in seconds.
    pub fn exposure(&self) -> f64 {
        self.fps.seconds(self.shutter)
    }

    /// The time `u` of the way through frame `i`'s exposure (0 at shutter open, 1 at close).
    pub fn shutter_time(&self, i: usize, u: f64) -> f64 {
        self.time(i) + u * self.exposure()
    }
}

/// The names the spec can refer to, from the base scene.
pub trait SceneNames {
    /// What `name` is, if the base scene defines it.
    fn kind_of(&self, name: &str) -> Option<TargetKind>;
    /// The composites that list `name` among their children.
    fn containers(&self, name: &str) -> Vec<&str>;
    /// Every targetable name, for suggestions.
    fn names(&self) -> Vec<&str>;
    /// The camera used when the spec names none.
    fn default_camera(&self) -> Option<&str>;
    /// Whether the base scene defines a material named `name` (a thing of the same name
    /// shadows it for tracks that key the thing's own channels).
    fn has_material(&self, name: &str) -> bool;
    /// The value the base scene gives `channel` of `target` (of the scene for `ambient` and
    /// `background`), as an expression reads it as `value` where no key sets it.
    fn base_value(&self, target: &str, channel: &str) -> Option<Val>;
}
