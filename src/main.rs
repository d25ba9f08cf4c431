use anim::cli::{BenchArgs, Cli, Command, RenderArgs};
use anim::render;
use clap::Parser;
use std::process::ExitCode;
use std::time::Instant;

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Render(args) => with_threads(args.threads, || render_command(&args)),
        Command::Check(args) => {
            anim::sdf::check_paths(&args.inputs, &args.scene.load_options(), args.quiet)
        }
        Command::Generate(args) => anim::anim::generate_command(&args),
        Command::Bench(args) => with_threads(args.threads, || bench_command(&args)),
    }
}

/// Runs `f` on a rayon pool of `threads` workers (default: one per core).
fn with_threads(threads: Option<u32>, f: impl FnOnce() -> ExitCode + Send) -> ExitCode {
    let mut builder = rayon::ThreadPoolBuilder::new();
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

fn render_command(args: &RenderArgs) -> ExitCode {
    let settings = args.settings();
    let load = args.scene.load_options();
    let mut failed = false;
    for input in &args.inputs {
        if input.is_dir() {
            if anim::pipeline::render_dir(input, args) != ExitCode::SUCCESS {
                failed = true;
            }
            continue;
        }
        let start = Instant::now();
        match render::render_file(input, &load, &settings, !args.quiet) {
            Ok(outcome) => {
                if !args.quiet {
                    for w in &outcome.warnings {
                        eprintln!("{w}");
                    }
                    let secs = start.elapsed().as_secs_f64();
                    for out in &outcome.outputs {
                        eprintln!("wrote {}", out.display());
                    }
                    let r = outcome.rays;
                    eprintln!(
                        "{}: {} image(s) in {:.2} s, {:.1} Mrays/s (primary {}, shadow {}, reflected {}, refracted {})",
                        input.display(),
                        outcome.outputs.len(),
                        secs,
                        r.total() as f64 / secs.max(1e-9) / 1e6,
                        r.primary,
                        r.shadow,
                        r.reflected,
                        r.refracted
                    );
                }
            }
            Err(diagnostics) => {
                failed = true;
                for d in diagnostics.iter().filter(|d| !args.quiet || d.is_error()) {
                    eprintln!("{d}");
                }
            }
        }
    }
    if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
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
