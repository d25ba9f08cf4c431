//! The checked animation: what the generator needs, with every value valid.

use crate::keyframe::interp::{sample, Interp, Key, Keyable};
use anim_core::limits;
use glam::DVec3;

/// A keyed channel with the path of its key list (for messages about interpolated values).
#[derive(Clone, Debug, PartialEq)]
pub struct Channel<T> {
    pub keys: Vec<Key<T>>,
    pub looping: bool,
    pub path: String,
}

impl<T: Keyable> Channel<T> {
    pub fn at(&self, t: f64) -> Option<T> {
        sample(&self.keys, t, self.looping)
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
    /// The fraction of each frame's interval the shutter stays open (0: an instant).
    pub shutter: f64,
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

    /// How long the shutter stays open, in seconds.
    pub fn exposure(&self) -> f64 {
        self.shutter / self.fps as f64
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
    /// Every targetable name, for suggestions.
    fn names(&self) -> Vec<&str>;
    /// The camera used when the spec names none.
    fn default_camera(&self) -> Option<&str>;
}
