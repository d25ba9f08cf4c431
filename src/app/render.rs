//! `anim render FILE|DIR ...`: scene files rendered one by one (rows in parallel), frame
//! directories rendered frames in parallel; warnings, errors and a summary on stderr.

use super::progress::{plural, FrameLog, LazyBar};
use super::shown;
use anim_core::render::RenderSettings;
use anim_core::sdf::LoadOptions;
use anim_pipeline::frames::{self, FrameOptions, Summary};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// Everything `anim render` was asked to do.
#[derive(Clone, Debug)]
pub struct RenderConfig {
    pub inputs: Vec<PathBuf>,
    pub settings: RenderSettings,
    pub load: LoadOptions,
    pub frames: FrameOptions,
    pub quiet: bool,
}

pub fn run(config: &RenderConfig) -> ExitCode {
    let mut failed = false;
    for input in &config.inputs {
        let ok = if input.is_dir() {
            render_dir(input, config)
        } else {
            render_file(input, config)
        };
        failed |= !ok;
    }
    if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

fn render_file(input: &Path, config: &RenderConfig) -> bool {
    let start = Instant::now();
    let bar = LazyBar::new(!config.quiet);
    match frames::render_scene_file(input, &config.load, &config.settings, &bar) {
        Ok(outcome) => {
            if !config.quiet {
                for w in &outcome.warnings {
                    eprintln!("{w}");
                }
                let secs = start.elapsed().as_secs_f64();
                for out in &outcome.outputs {
                    eprintln!("wrote {}", shown(&out.path));
                }
                let r = outcome.rays;
                eprintln!(
                    "{}: {} image(s) in {:.2} s, {:.1} Mrays/s (primary {}, shadow {}, reflected {}, refracted {})",
                    shown(input),
                    outcome.outputs.len(),
                    secs,
                    r.total() as f64 / secs.max(1e-9) / 1e6,
                    r.primary,
                    r.shadow,
                    r.reflected,
                    r.refracted
                );
            }
            true
        }
        Err(diagnostics) => {
            for d in diagnostics.iter().filter(|d| !config.quiet || d.is_error()) {
                eprintln!("{d}");
            }
            false
        }
    }
}

/// Renders a frame directory and prints its summary; false if any frame failed (or the
/// directory cannot be read or holds no `.sdf` file).
fn render_dir(dir: &Path, config: &RenderConfig) -> bool {
    let log = FrameLog::new(config.quiet);
    match frames::render_dir(dir, &config.settings, &config.load, &config.frames, &log) {
        Ok(summary) => {
            print_summary(dir, &summary, config.frames.range, config.quiet);
            summary.failed.is_empty()
        }
        Err(diagnostics) => {
            for d in diagnostics {
                eprintln!("{d}");
            }
            false
        }
    }
}

/// Prints warnings (unless quiet), failures with their located errors, and the totals.
fn print_summary(dir: &Path, s: &Summary, range: Option<(usize, usize)>, quiet: bool) {
    if !quiet {
        for (d, count) in &s.warnings {
            eprintln!("{}", in_frames(&d.to_string(), *count));
        }
    }
    if !s.failed.is_empty() {
        eprintln!("{} frame{} failed:", s.failed.len(), plural(s.failed.len()));
        for (name, diags) in &s.failed {
            eprintln!("  {}:", shown(name));
            for d in diags.iter().filter(|d| d.is_error() || !quiet) {
                for line in d.to_string().lines() {
                    eprintln!("    {line}");
                }
            }
        }
    }
    if quiet && s.failed.is_empty() {
        return;
    }
    let secs = s.wall.as_secs_f64();
    let shard = match s.shard {
        Some(sh) => format!(
            "shard {}/{} ({} of {} frames): ",
            sh.index,
            sh.count,
            s.selected(),
            s.total
        ),
        None => String::new(),
    };
    let shard = match range {
        Some((a, b)) => {
            let last = if b == usize::MAX {
                String::new()
            } else {
                b.to_string()
            };
            format!(
                "{shard}frames {a}..{last} ({} of {} frames): ",
                s.selected(),
                s.total
            )
        }
        None => shard,
    };
    let rates = if secs > 0.0 && !s.rendered.is_empty() {
        format!(
            " ({:.2} frames/s, {:.2} Mrays/s)",
            s.rendered.len() as f64 / secs,
            s.rays as f64 / secs / 1e6
        )
    } else {
        String::new()
    };
    let copied = match s.copied.len() {
        0 => String::new(),
        n => format!(", {n} copied (same scene as an earlier frame)"),
    };
    eprintln!(
        "{}: {shard}{} rendered{copied}, {} skipped (unchanged), {} failed in {:.2} s{rates}",
        shown(dir),
        s.rendered.len(),
        s.skipped.len(),
        s.failed.len(),
        secs
    );
}

/// A warning that `count` frames of a run had, as the run's summary shows it (the preview's
/// page too): the first frame's, and how many others had it.
pub(super) fn in_frames(warning: &str, count: usize) -> String {
    if count > 1 {
        let others = count - 1;
        format!(
            "{warning}\n  (and in {others} other frame{})",
            plural(others)
        )
    } else {
        warning.to_string()
    }
}
