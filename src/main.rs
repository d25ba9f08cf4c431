use anim::app;
use anim::cli::{BenchArgs, Cli, Command};
use clap::Parser;
use std::process::ExitCode;
use std::time::Instant;

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Render(args) => app::run(app::Command::Render(args.config()), args.threads),
        Command::Check(args) => app::run(app::Command::Check(args.config()), None),
        Command::Generate(args) => anim::anim::generate_command(&args),
        Command::Bench(args) => with_threads(args.threads, || bench_command(&args)),
    }
}

/// Runs `f` on a rayon pool of `threads` workers (default: one per core), with the stack
/// deep recursion needs, as the command layer's pool has.
fn with_threads(threads: Option<u32>, f: impl FnOnce() -> ExitCode + Send) -> ExitCode {
    let mut builder = rayon::ThreadPoolBuilder::new().stack_size(anim::limits::RENDER_STACK_BYTES);
    if let Some(n) = threads {
        builder = builder.num_threads(n as usize);
    }
    match builder.build() {
        Ok(pool) => pool.install(f),
        Err(e) => {
            eprintln!("error: cannot start worker threads: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `anim bench`: progress on stderr, the Markdown tables on stdout, files in `--out`.
fn bench_command(args: &BenchArgs) -> ExitCode {
    let config = args.config(rayon::current_num_threads());
    let start = Instant::now();
    let mut progress = |line: &str| eprintln!("{line}");
    let result = if args.stress {
        anim::bench::stress::run(&config, &mut progress).and_then(|report| {
            print!("{}", anim::bench::stress::markdown(&report));
            match &args.out {
                Some(dir) => anim::bench::stress::write_outputs(&report, dir),
                None => Ok(Vec::new()),
            }
        })
    } else {
        anim::bench::run(&config, &mut progress).and_then(|report| {
            print!("{}", anim::bench::markdown(&report));
            match &args.out {
                Some(dir) => anim::bench::write_outputs(&report, dir),
                None => Ok(Vec::new()),
            }
        })
    };
    match result {
        Ok(written) => {
            for path in written {
                eprintln!("wrote {}", path.display());
            }
            eprintln!("bench took {:.1} s", start.elapsed().as_secs_f64());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
