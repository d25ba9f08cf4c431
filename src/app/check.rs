//! `anim check FILE|DIR...`: load scene files without rendering and report every problem.

use anim_core::diag::Diagnostic;
use anim_core::load::{load_file, probe};
use anim_core::sdf::LoadOptions;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Everything `anim check` was asked to do.
#[derive(Clone, Debug)]
pub struct CheckConfig {
    pub inputs: Vec<PathBuf>,
    pub load: LoadOptions,
    pub quiet: bool,
    /// Also print a table saying of each file whether it renders, renders blank (and why) or
    /// is rejected (and why).
    pub summary: bool,
}

/// Checks every input (directories recursively: files ending in `.sdf` or `.txt`, or
/// without an extension). Prints each diagnostic to stderr (only errors when `quiet`) and a
/// summary line to stdout. Exit status 1 if any file was rejected or an input is unreadable.
pub fn run(config: &CheckConfig) -> ExitCode {
    let (inputs, opts, quiet) = (&config.inputs, &config.load, config.quiet);
    let mut files = Vec::new();
    let mut failed = false;
    for input in inputs {
        if input.is_dir() {
            let mut found = Vec::new();
            if let Err(e) = collect(input, &mut found) {
                eprintln!(
                    "{}",
                    Diagnostic::file_error(input, format!("cannot read directory: {e}"))
                );
                failed = true;
            }
            found.sort();
            files.extend(found);
        } else {
            // A file named explicitly is checked whatever its extension (and reported if it
            // does not exist).
            files.push(input.clone());
        }
    }
    let (mut ok, mut warned, mut rejected) = (0usize, 0usize, 0usize);
    let mut table = Vec::new();
    for file in &files {
        match load_file(file, opts) {
            Ok(mut loaded) => {
                table.push(match loaded.jobs.iter().find_map(probe::blank_image) {
                    Some(blank) => (file, "blank", blank.reason),
                    None => (file, "renders", String::new()),
                });
                // What the camera would see, as `anim render` checks it.
                loaded
                    .diagnostics
                    .extend(probe::blank_image_warnings(&loaded.jobs, file));
                if loaded.diagnostics.is_empty() {
                    ok += 1;
                } else {
                    warned += 1;
                }
                if !quiet {
                    for d in &loaded.diagnostics {
                        eprintln!("{d}");
                    }
                }
            }
            Err(diagnostics) => {
                let first = diagnostics.iter().find(|d| d.is_error());
                let why = first.map(|d| d.to_string()).unwrap_or_default();
                table.push((
                    file,
                    "rejected",
                    why.lines().next().unwrap_or("").to_string(),
                ));
                rejected += 1;
                for d in diagnostics.iter().filter(|d| !quiet || d.is_error()) {
                    eprintln!("{d}");
                }
            }
        }
    }
    if config.summary {
        print_summary_table(&table);
    }
    println!(
        "{} files: {ok} ok, {warned} with warnings, {rejected} rejected",
        files.len()
    );
    if failed || rejected > 0 {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

/// Whether a file found in a directory is a scene file to check.
fn is_scene_file(path: &Path) -> bool {
    match path.extension().and_then(|e| e.to_str()) {
        None => true,
        Some(ext) => ext.eq_ignore_ascii_case("sdf") || ext.eq_ignore_ascii_case("txt"),
    }
}

/// Scene files below `dir`, skipping hidden entries (`.git`, editor files).
fn collect(dir: &Path, out: &mut Vec<PathBuf>) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let path = entry.path();
        if entry.file_name().to_string_lossy().starts_with('.') {
            continue;
        }
        let kind = entry.file_type()?;
        if kind.is_dir() {
            collect(&path, out)?;
        } else if kind.is_file() && is_scene_file(&path) {
            out.push(path);
        }
    }
    Ok(())
}

/// What the camera would show of each file: `renders`, `blank` (with the reason the warning
/// gives) or `rejected` (with the first error), then the counts of each.
fn print_summary_table(table: &[(&PathBuf, &str, String)]) {
    println!("| file | result | why |");
    println!("|---|---|---|");
    for (file, result, why) in table {
        println!(
            "| {} | {result} | {} |",
            super::shown(file),
            why.replace('|', "\\|")
        );
    }
    let count = |what: &str| table.iter().filter(|(_, r, _)| *r == what).count();
    println!(
        "renders: {}, blank with a reason: {}, rejected with a reason: {}",
        count("renders"),
        count("blank"),
        count("rejected")
    );
}
