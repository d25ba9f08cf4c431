use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = anim::cli::Cli::parse();
    let _ = cli;
    ExitCode::SUCCESS
}
