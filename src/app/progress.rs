//! Progress on the terminal: a bar for a long single-file render, and for a frame directory a
//! bar on a terminal or one plain line per frame otherwise (logs, Slurm output).

use super::shown;
use anim_pipeline::frames::{FrameObserver, FrameOutcome, ImageProgress};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// A bar for the images of one file that appears only once the render has run for about a
/// second (short renders stay quiet), and never when stderr is not a terminal.
pub struct LazyBar {
    bar: Option<ProgressBar>,
    start: Instant,
    shown: AtomicBool,
}

impl LazyBar {
    pub fn new(enabled: bool) -> Self {
        let bar = (enabled && std::io::stderr().is_terminal()).then(|| {
            let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
            if let Ok(style) =
                ProgressStyle::with_template("{spinner} {msg} [{bar:30}] {percent:>3}% ETA {eta}")
            {
                bar.set_style(style.progress_chars("=> "));
            }
            bar
        });
        LazyBar {
            bar,
            start: Instant::now(),
            shown: AtomicBool::new(false),
        }
    }
}

impl ImageProgress for LazyBar {
    fn begin(&self, total_pixels: u64) {
        if let Some(bar) = &self.bar {
            bar.set_length(total_pixels);
        }
    }

    fn image(&self, name: &str) {
        if let Some(bar) = &self.bar {
            bar.set_message(shown(name).into_owned());
        }
    }

    fn advance(&self, pixels: u64) {
        if let Some(bar) = &self.bar {
            bar.inc(pixels);
            if self.start.elapsed() > Duration::from_secs(1)
                && !self.shown.swap(true, Ordering::Relaxed)
            {
                bar.set_draw_target(ProgressDrawTarget::stderr());
            }
        }
    }

    fn end(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

/// Frames of a directory: a bar on a terminal; one plain line per frame otherwise.
pub struct FrameLog {
    bar: std::sync::OnceLock<ProgressBar>,
    total: AtomicUsize,
    done: AtomicUsize,
    quiet: bool,
}

impl FrameLog {
    pub fn new(quiet: bool) -> Self {
        FrameLog {
            bar: std::sync::OnceLock::new(),
            total: AtomicUsize::new(0),
            done: AtomicUsize::new(0),
            quiet,
        }
    }
}

impl FrameObserver for FrameLog {
    fn planned(&self, to_render: usize, skipped: usize) {
        self.total.store(to_render, Ordering::Relaxed);
        if !self.quiet && to_render > 0 && std::io::stderr().is_terminal() {
            let bar =
                ProgressBar::with_draw_target(Some(to_render as u64), ProgressDrawTarget::stderr());
            if let Ok(style) = ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] [{bar:30}] {pos}/{len} frames  {per_sec}  ETA {eta}  {msg}",
            ) {
                bar.set_style(style.progress_chars("=> "));
            }
            if skipped > 0 {
                bar.set_message(format!("({skipped} unchanged, skipped)"));
            }
            bar.enable_steady_tick(Duration::from_millis(200));
            let _ = self.bar.set(bar);
        } else if !self.quiet && skipped > 0 {
            eprintln!("skipping {skipped} unchanged frame{}", plural(skipped));
        }
    }

    fn finished(&self, name: &str, outcome: &FrameOutcome, took: Duration) {
        let n = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        let total = self.total.load(Ordering::Relaxed);
        let width = total.to_string().len();
        let name = shown(name);
        let line = match outcome {
            FrameOutcome::Rendered { .. } => format!(
                "[{n:>width$}/{total}] rendered {name} in {:.2} s",
                took.as_secs_f64()
            ),
            FrameOutcome::Copied { from, .. } => format!(
                "[{n:>width$}/{total}] copied {name} from {} (same scene) in {:.2} s",
                shown(from),
                took.as_secs_f64()
            ),
            FrameOutcome::Failed(diags) => {
                let first = diags
                    .iter()
                    .find(|d| d.is_error())
                    .map(|d| d.to_string().lines().next().unwrap_or_default().to_string())
                    .unwrap_or_default();
                format!("[{n:>width$}/{total}] FAILED {name}: {first}")
            }
        };
        match self.bar.get() {
            Some(bar) => {
                if matches!(outcome, FrameOutcome::Failed(_)) {
                    bar.println(line);
                }
                bar.inc(1);
            }
            None if !self.quiet => eprintln!("{line}"),
            None => {}
        }
    }

    fn end(&self) {
        if let Some(bar) = self.bar.get() {
            bar.finish_and_clear();
        }
    }

    fn note(&self, message: &str) {
        if !self.quiet {
            eprintln!("note: {message}");
        }
    }
}

pub fn plural(n: usize) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}
