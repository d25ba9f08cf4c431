use anim::app;
use anim::cli::{Cli, Command};
use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Render(args) => app::run(app::Command::Render(args.config()), args.threads),
        Command::Check(args) => app::run(app::Command::Check(args.config()), None),
        Command::Generate(args) => app::run(
            app::Command::Generate {
                config: args.config(),
                quiet: args.quiet,
                print_dir: args.print_dir,
            },
            None,
        ),
        Command::Bench(args) => app::run(
            app::Command::Bench {
                config: args.config(),
                stress: args.stress,
                out: args.out.clone(),
            },
            args.threads,
        ),
        Command::Preview(args) => app::run(app::Command::Preview(args.config()), args.threads),
    }
}
