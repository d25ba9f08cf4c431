//! Every real-world scene file of the public sets (`../shared/corpus/wild` and `wild2`) either
//! loads or is rejected with located errors, and none makes the reader panic.

use crate::common;

use anim_core::diag::Diagnostic;
use anim_core::load::load_file;
use anim_core::sdf::LoadOptions;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// The public sets of real files, below `corpus`.
const SETS: [&str; 2] = ["wild", "wild2"];

/// Every scene file of the public sets (their MANIFEST.tsv aside), sorted.
fn corpus_files(corpus: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut files = Vec::new();
    for set in SETS {
        common::files_below(&corpus.join(set), &mut files);
    }
    files.retain(|f| f.file_name().is_some_and(|n| n != "MANIFEST.tsv"));
    files.sort();
    files
}

/// Whether a file-wide diagnostic (no line) is about reading the file rather than its text.
fn is_io_problem(d: &Diagnostic) -> bool {
    d.message.starts_with("cannot read")
}

#[test]
fn every_corpus_file_loads_or_is_rejected_with_located_errors() {
    let Some(shared) = common::shared_dir("corpus") else {
        return;
    };
    let corpus = shared.join("corpus");
    let dir = corpus.as_path();
    let files = corpus_files(dir);
    assert!(!files.is_empty(), "the corpus folder holds no files");

    let opts = LoadOptions::default();
    let (mut loaded, mut rejected) = (Vec::new(), Vec::new());
    let mut problems = Vec::new();
    for file in &files {
        let name = file.strip_prefix(dir).unwrap_or(file).display().to_string();
        match catch_unwind(AssertUnwindSafe(|| load_file(file, &opts))) {
            Err(_) => problems.push(format!("{name}: the reader panicked")),
            Ok(Ok(l)) => loaded.push(format!(
                "{name}: {} job(s), {} warning(s)",
                l.jobs.len(),
                l.diagnostics.len()
            )),
            Ok(Err(diagnostics)) => {
                for d in diagnostics.iter().filter(|d| d.is_error()) {
                    if d.loc.is_none() && !is_io_problem(d) {
                        problems.push(format!("{name}: error without a location: {d}"));
                    }
                }
                let first = diagnostics
                    .iter()
                    .find(|d| d.is_error())
                    .map(|d| d.to_string().lines().next().unwrap_or_default().to_string())
                    .unwrap_or_default();
                rejected.push(format!("{name}: {first}"));
            }
        }
    }
    println!("loaded {} of {} files:", loaded.len(), files.len());
    for l in &loaded {
        println!("  {l}");
    }
    println!("rejected {}:", rejected.len());
    for r in &rejected {
        println!("  {r}");
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The canonical text of every file that loads (statements written back with `Display`, as
/// the animation generator does) loads to the same render jobs.
#[test]
fn canonical_text_of_corpus_files_loads_to_the_same_jobs() {
    let Some(shared) = common::shared_dir("corpus") else {
        return;
    };
    let corpus = shared.join("corpus");
    let dir = corpus.as_path();
    let files = corpus_files(dir);
    let opts = LoadOptions::default();
    let mut compared = 0;
    for file in &files {
        let Ok(bytes) = std::fs::read(file) else {
            continue;
        };
        let text = String::from_utf8_lossy(&bytes);
        let Ok(original) = anim_core::load::load_str(&text, file, &opts) else {
            continue;
        };
        let (statements, _) = anim_core::sdf::parse(&text, file, &opts);
        let canonical: String = statements.iter().map(|s| format!("{s}\n")).collect();
        let again = anim_core::load::load_str(&canonical, file, &opts).unwrap_or_else(|ds| {
            panic!(
                "{}: canonical text rejected:\n{}\n{canonical}",
                file.display(),
                ds.iter()
                    .map(|d| d.to_string())
                    .collect::<Vec<_>>()
                    .join("\n")
            )
        });
        assert_eq!(original.jobs.len(), again.jobs.len(), "{}", file.display());
        for (a, b) in original.jobs.iter().zip(&again.jobs) {
            let name = file.display();
            assert_eq!(a.camera, b.camera, "{name}");
            assert_eq!(a.output, b.output, "{name}");
            assert_eq!(
                (a.width, a.height, a.samples),
                (b.width, b.height, b.samples),
                "{name}"
            );
            assert_eq!(a.scene.materials, b.scene.materials, "{name}");
            assert_eq!(a.scene.lights, b.scene.lights, "{name}");
            assert_eq!(a.scene.ambient, b.scene.ambient, "{name}");
            assert_eq!(a.scene.background, b.scene.background, "{name}");
            assert_eq!(a.scene.instances.len(), b.scene.instances.len(), "{name}");
            for (x, y) in a.scene.instances.iter().zip(b.scene.instances.iter()) {
                assert_eq!(
                    (
                        a.scene.instance_name(x),
                        &x.geometry,
                        x.material,
                        a.scene.transform_of(x)
                    ),
                    (
                        b.scene.instance_name(y),
                        &y.geometry,
                        y.material,
                        b.scene.transform_of(y)
                    ),
                    "{name}"
                );
            }
        }
        compared += 1;
    }
    println!("{compared} corpus files round-trip through their canonical text");
}

/// The corpus summary of `anim check --summary` (BENCHMARKS.md, "The public corpus") as a
/// regression test: how many files of each public set render an image that is not blank,
/// render blank (each with its reason) or are rejected, over its distinct files and over all
/// of them with their `.fake.sdf` twins. A change in these numbers is a change in what the
/// reader accepts: update them with BENCHMARKS.md.
#[test]
fn corpus_summary_counts() {
    use anim_core::load::probe::{classify, Classification};
    let Some(shared) = common::shared_dir("corpus_summary_counts") else {
        return;
    };
    // The command line's defaults: both the material layout and the transform order inferred.
    let opts = LoadOptions {
        material_fields: anim_core::sdf::MaterialLayout::Auto,
        infer_transform_order: true,
        ..LoadOptions::default()
    };
    // Per set, [renders, blank, rejected] of the distinct files, then of all files.
    let expected = [
        ("wild", ([73, 8, 2], [136, 13, 5])),
        ("wild2", ([51, 18, 2], [51, 18, 2])),
    ];
    for (set, counts) in expected {
        let mut files = Vec::new();
        common::files_below(&shared.join("corpus").join(set), &mut files);
        files.retain(|f| f.file_name().is_some_and(|n| n != "MANIFEST.tsv"));
        let (mut all, mut distinct) = ([0usize; 3], [0usize; 3]);
        let mut silent = Vec::new();
        for file in &files {
            let k = match classify(file, &opts) {
                Classification::Renders => 0,
                Classification::BlankExplained(why) => {
                    if why.is_empty() {
                        silent.push(file.display().to_string());
                    }
                    1
                }
                Classification::Rejected(_) => 2,
            };
            all[k] += 1;
            if !file.to_string_lossy().ends_with(".fake.sdf") {
                distinct[k] += 1;
            }
        }
        assert!(
            silent.is_empty(),
            "{set}: blank without a reason: {silent:?}"
        );
        assert_eq!(
            (distinct, all),
            counts,
            "{set}: [renders, blank, rejected] of the distinct files, then of all files"
        );
    }
}
