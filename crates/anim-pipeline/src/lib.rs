//! The animation pipeline of anim: [`keyframe`] turns a RON keyframe spec into one SDF file
//! per frame; [`frames`] renders scene files and directories of frames into images, skipping
//! the frames whose input has not changed.
#![forbid(unsafe_code)]

pub mod frames;
pub mod keyframe;
