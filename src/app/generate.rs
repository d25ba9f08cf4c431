//! `anim generate SPEC.ron`: one SDF file per frame of a keyframe spec.

use anim_pipeline::keyframe::{self, GenerateConfig};
use std::process::ExitCode;

/// Prints warnings (unless `quiet`: once the spec and the base scene are checked, before any
/// frame is written), errors and what was written; with `print_dir`, the frame directory
/// alone on stdout and the rest on stderr.
pub fn run(config: &GenerateConfig, quiet: bool, print_dir: bool) -> ExitCode {
    let print_warnings = |warnings: &[anim_core::diag::Diagnostic]| {
        if !quiet {
            for w in warnings {
                eprintln!("{w}");
            }
        }
    };
    match keyframe::run_generate_reporting(config, print_warnings) {
        Ok(report) => {
            if !quiet {
                let length = format!(
                    "{} s at {} fps",
                    keyframe::tidy::tidy(report.duration),
                    report.fps
                );
                let mut line = if let Some((a, b)) = config.frames {
                    let last = b.min(report.frames.saturating_sub(1));
                    format!(
                        "wrote {} of frames {a}..{last} of {} ({length}) to {}; the others were unchanged or not asked for",
                        report.written,
                        report.frames,
                        super::shown(&report.dir)
                    )
                } else if report.written == report.frames {
                    format!(
                        "wrote {} frames ({length}) to {}",
                        report.frames,
                        super::shown(&report.dir)
                    )
                } else {
                    format!(
                        "wrote {} of {} frames ({length}) to {}; the others were unchanged",
                        report.written,
                        report.frames,
                        super::shown(&report.dir)
                    )
                };
                if report.removed > 0 {
                    line += &format!(
                        "; removed {} file{} of frames the animation no longer has",
                        report.removed,
                        if report.removed == 1 { "" } else { "s" }
                    );
                }
                if print_dir {
                    eprintln!("{line}");
                } else {
                    println!("{line}");
                }
            }
            if print_dir {
                println!("{}", report.dir.display());
            }
            ExitCode::SUCCESS
        }
        Err(diags) => {
            let errors = diags.iter().filter(|d| d.is_error()).count();
            for d in &diags {
                if d.is_error() || !quiet {
                    eprintln!("{d}");
                }
            }
            eprintln!(
                "error: {} not generated: {errors} error{}",
                super::shown(&config.spec),
                if errors == 1 { "" } else { "s" }
            );
            ExitCode::FAILURE
        }
    }
}
