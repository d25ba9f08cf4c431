//! `anim bench`: progress on stderr, the Markdown tables on stdout, files in `--out`.

use anim_bench::{stress, BenchConfig};
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

pub fn run(config: &BenchConfig, stress_table: bool, out: Option<&Path>) -> ExitCode {
    let start = Instant::now();
    let mut progress = |line: &str| eprintln!("{line}");
    let result = if stress_table {
        stress::run(config, &mut progress).and_then(|report| {
            print!("{}", stress::markdown(&report));
            match out {
                Some(dir) => stress::write_outputs(&report, dir),
                None => Ok(Vec::new()),
            }
        })
    } else {
        anim_bench::run(config, &mut progress).and_then(|report| {
            print!("{}", anim_bench::markdown(&report));
            match out {
                Some(dir) => anim_bench::write_outputs(&report, dir),
                None => Ok(Vec::new()),
            }
        })
    };
    match result {
        Ok(written) => {
            for path in written {
                eprintln!("wrote {}", super::shown(&path));
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
