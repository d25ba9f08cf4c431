//! `anim check FILE|DIR...`: load scene files without rendering and report every problem.

use crate::sdf::LoadOptions;
use std::path::PathBuf;
use std::process::ExitCode;

/// Everything `anim check` was asked to do.
#[derive(Clone, Debug)]
pub struct CheckConfig {
    pub inputs: Vec<PathBuf>,
    pub load: LoadOptions,
    pub quiet: bool,
}

pub fn run(config: &CheckConfig) -> ExitCode {
    crate::sdf::check_paths(&config.inputs, &config.load, config.quiet)
}
