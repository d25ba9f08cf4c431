//! The command layer: the only code that prints, builds the thread pool and chooses the exit
//! code. Each command gets a plain configuration (made from the command line by `cli`) and
//! calls the library, which returns values and diagnostics.

mod bench;
mod check;
mod generate;
mod preview;
mod progress;
mod render;

pub use anim_bench::BenchConfig;
pub use anim_pipeline::keyframe::GenerateConfig;
pub use check::CheckConfig;
pub use preview::PreviewConfig;
pub use render::RenderConfig;

use anim_core::limits;
use std::borrow::Cow;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// A command with its configuration.
#[derive(Clone, Debug)]
pub enum Command {
    Render(RenderConfig),
    Check(CheckConfig),
    Generate {
        config: GenerateConfig,
        quiet: bool,
        /// Print the frame directory alone on stdout, the summary on stderr.
        print_dir: bool,
    },
    /// The time-against-error benchmark, or with `stress` the numerical stress table; files
    /// go to `out`.
    Bench {
        config: BenchConfig,
        stress: bool,
        out: Option<PathBuf>,
    },
    Preview(PreviewConfig),
}

/// Runs `command` on a rayon pool of `threads` workers (default: one per core), the one pool
/// of the process: the rows of a frame and the frames of a directory share it.
pub fn run(command: Command, threads: Option<u32>) -> ExitCode {
    let Some(pool) = worker_pool(threads) else {
        return ExitCode::FAILURE;
    };
    // The preview serves pages from this thread while the pool renders.
    if let Command::Preview(config) = &command {
        return preview::run(config, &pool);
    }
    pool.install(|| match &command {
        Command::Render(config) => render::run(config),
        Command::Check(config) => check::run(config),
        Command::Generate {
            config,
            quiet,
            print_dir,
        } => generate::run(config, *quiet, *print_dir),
        Command::Bench {
            config,
            stress,
            out,
        } => bench::run(config, *stress, out.as_deref()),
        Command::Preview(config) => preview::run(config, &pool),
    })
}

/// The pool of `threads` workers (default: one per core, else one when the process may not
/// have that many stacks), or `None` after saying why none can start.
fn worker_pool(threads: Option<u32>) -> Option<rayon::ThreadPool> {
    // Deep mirror recursion (up to limits::MAX_DEPTH) runs on these threads.
    let build = |n: Option<u32>| {
        let mut builder = rayon::ThreadPoolBuilder::new().stack_size(limits::RENDER_STACK_BYTES);
        if let Some(n) = n {
            builder = builder.num_threads(n as usize);
        }
        builder.build()
    };
    let error = match build(threads) {
        Ok(pool) => return Some(pool),
        Err(e) => e,
    };
    if threads.is_none() {
        if let Ok(pool) = build(Some(1)) {
            return Some(pool);
        }
    }
    let stack = anim_core::util::human_bytes(limits::RENDER_STACK_BYTES as u64);
    let room = match anim_core::util::memory_limit() {
        Some(limit) => format!(
            ", and this process may use {} in all (ulimit -v, or the machine's or its control group's memory)",
            anim_core::util::human_bytes(limit)
        ),
        None => String::new(),
    };
    eprintln!(
        "error: cannot start worker threads ({error}): each reserves {stack} of address space for its stack (deep reflections recurse on it){room}"
    );
    None
}

/// A path or name as printed: control characters written as escapes (`\u{1b}`), as
/// diagnostics write them, so that no file name can move the cursor or ring the terminal.
fn shown(name: &(impl AsRef<Path> + ?Sized)) -> Cow<'static, str> {
    let text = name.as_ref().to_string_lossy();
    Cow::Owned(anim_core::diag::escape(&text).into_owned())
}
