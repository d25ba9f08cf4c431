//! What a render wrote: the one type that the writing of images and the render records share.

use anim_core::render::film::ImageBytes;
use std::path::PathBuf;

/// An image file written, with what was written to it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Output {
    pub path: PathBuf,
    pub bytes: ImageBytes,
}
