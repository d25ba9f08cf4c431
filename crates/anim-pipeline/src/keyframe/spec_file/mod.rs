//! The RON keyframe spec: serde types as the user writes them (`raw`), the text with the
//! position of every value (`source`), and the checks ([`validate`]) that turn them into an
//! [`Animation`] (`model`) whose every problem is reported at its line and column.
//!
//! The format is documented for users in `docs/animation.md`.

mod across;
mod checker;
mod model;
mod path;
mod raw;
mod source;
mod track;
mod validate;

pub use model::{
    Aim, AimTarget, AlongPath, Animation, Blend, Channel, End, Follow, Fps, MaterialChannels,
    NamePattern, Orbit, OrientChannel, Parent, PathMotion, SceneNames, TargetKind, Track,
};
pub use raw::{
    AimSpec, FpsSpec, KeySpec, KeyTime, Length, OrbitSpec, Orientation, Rgb, Scale, SceneSource,
    SpecFile, TimeUnit, TrackSpec, V3,
};
pub use source::Source;
pub use validate::validate;

use anim_core::diag::Diagnostic;

/// Reads the spec's RON text. ron stops at the first problem: `Err` holds it, located in
/// `source`.
pub fn parse(source: &Source) -> Result<SpecFile, Vec<Diagnostic>> {
    let options =
        ron::Options::default().with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
    options
        .from_str::<SpecFile>(&source.text)
        .map_err(|e| vec![source.ron_error(&e)])
}
