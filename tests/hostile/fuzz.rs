//! A stable-Rust fuzz harness for the readers of user text: the SDF reader (parse and build,
//! no rendering; frame files with `motion` lines among its seeds), the RON keyframe spec
//! reader (parse, then validate against a small base scene), the OBJ mesh reader (scan,
//! `tobj`, the mesh and its hierarchy) and `include` (a scene cut in two files, the second
//! including the first, sometimes round a loop). See FUZZING.md; `scripts/fuzz.sh` runs it.
//!
//! Deterministic: the inputs are mutations of seed files (the shared corpus, and what git
//! tracks in `scenes/` and `animations/`) drawn from the seeded `SplitMix64` of
//! `anim_core::util`, so a run is reproduced by its seed and execution count. Each input runs
//! on a worker thread under `catch_unwind`; the main thread waits for it at most the
//! per-input time limit and otherwise records a hang (and carries on with a fresh worker).
//! Crashing and hanging inputs are saved to the findings directory, to become regression
//! tests in tests/hostile/files.rs.
//!
//! Settings come from the environment (the test harness owns the command line):
//! `FUZZ_EXECS` (default 100 000), `FUZZ_SEED` (1), `FUZZ_CORPUS` (`../shared/corpus`),
//! `FUZZ_TIMEOUT_MS` (2000), `FUZZ_OUT` (`target/fuzz-findings`).

use crate::common;

use anim_core::load::load_str;
use anim_core::sdf::{LoadOptions, MaterialField, TransformOrder};
use anim_core::util::SplitMix64;
use anim_pipeline::keyframe::generate::{BaseScene, Generator};
use anim_pipeline::keyframe::spec_file::{self, Source};
use std::panic::{self, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex};
use std::thread;
use std::time::{Duration, Instant};

/// Inputs grown past this by mutation are cut: the harness looks for wrong behaviour, not
/// for slowness proportional to size (tests/hostile/files.rs checks that with large inputs).
const MAX_INPUT: usize = 64 << 10;

/// Numbers a mutation writes in place of a number: the edges of what parsers get wrong.
const EXTREMES: &[&str] = &[
    "0",
    "-0",
    "0.0",
    "-0.0",
    "1e308",
    "-1e308",
    "1e-308",
    "1e999",
    "4.9e-324",
    "99999999999999999999999999",
    "-99999999999999999999999999",
    "4294967295",
    "4294967296",
    "18446744073709551616",
    "2147483648",
    "-2147483649",
    "999999999999",
    "1e12",
    "65536",
    "65537",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "1,5",
    "1.0f",
    ".",
    "-",
    "1e",
    "0x10",
];

/// Words a mutation inserts: keywords of both languages and bytes that end or split lines.
const WORDS: &[&str] = &[
    "define",
    "shape",
    "composite",
    "sphere",
    "box",
    "triangle",
    "cylinder",
    "cone",
    "plane",
    "obj",
    "material",
    "light",
    "camera",
    "ambient",
    "background",
    "transform",
    "translate",
    "rotate",
    "scale",
    "render",
    "root",
    "#",
    "//",
    "\r",
    "\n",
    "\r\n",
    "\t",
    "\u{1b}[31m",
    "\u{0}",
    "\u{feff}",
    "ö",
    "(",
    ")",
    "[",
    "]",
    "{",
    "}",
    ":",
    ",",
    "\"",
    "r#\"",
    "\"#",
    "Some(",
    "None",
    "File(",
    "Inline(",
    "keys",
    "tracks",
    "target",
    "at",
    "duration",
    "fps",
    "orbit",
];

/// Picks from the one test generator.
trait Pick {
    /// One of `items`, which must not be empty.
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T;
}

impl Pick for SplitMix64 {
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Target {
    Sdf,
    Spec,
    Obj,
    /// A scene cut in two files, the second including the first.
    Include,
}

/// Seeds written here, so that every run has them whatever the corpus holds: frames with the
/// `motion` lines `anim generate` writes for a shutter.
const FRAME_SEEDS: &[&str] = &["define material m 0.2 0.2 0.2 0.8 0.8 0.8 0 0 0 1\n\
     define light l 0 0 5 1 1 1 1\n\
     define shape sphere ball 0 0 -5 1 m\n\
     define shape box crate -1 -1 -7 1 1 -6 m\n\
     define composite pair ball crate\n\
     define camera cam 60 0 0 0 0 0 -1 0 1 0\n\
     render cam frame.png 32 24\n\
     motion ball 0 translate -0.2 0 0\n\
     motion ball 0.5\n\
     motion ball 1 translate 0.2 0 0 rotate 10 0 1 0\n\
     motion pair 0 rotate -5 0 1 0\n\
     motion pair 1 rotate 5 0 1 0 scale 1.1\n\
     motion l 0 translate 0 1 0\n\
     motion l 1\n\
     motion cam 0 rotate 2 0 1 0\n\
     motion cam 1\n"];

/// OBJ seeds written here: faces of every index form, relative indices, normals, texture
/// coordinates, polylines, points, groups, CRLF endings.
const OBJ_SEEDS: &[&str] = &[
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    "o quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
     vn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\nl 1 2 3\np 4\n",
    "g a\r\nv 0 0 0 1\r\nv 1 0 0 1\r\nv 0 1 0 1\r\nvn 0 0 1\r\nf -3//-1 -2//-1 -1//-1\r\n\
     usemtl red\r\ns 1\r\n",
];

/// Seed inputs of one target.
struct Seeds {
    files: Vec<Vec<u8>>,
}

/// The seed files `wanted` takes: those below `corpus` (outside the repository) and those git
/// tracks in the repository's `folders` (never what a run of anim left there).
fn read_seeds(corpus: &Path, folders: &[&str], wanted: &dyn Fn(&Path) -> bool) -> Seeds {
    let mut paths = Vec::new();
    collect(corpus, wanted, &mut paths);
    for folder in folders {
        paths.extend(
            common::repository_files(folder)
                .into_iter()
                .filter(|p| wanted(p)),
        );
    }
    paths.sort();
    let files = paths
        .iter()
        .filter_map(|p| std::fs::read(p).ok())
        .filter(|b| b.len() <= MAX_INPUT)
        .collect();
    Seeds { files }
}

fn collect(dir: &Path, wanted: &dyn Fn(&Path) -> bool, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            collect(&path, wanted, out);
        } else if wanted(&path) {
            out.push(path);
        }
    }
}

fn lines_of(bytes: &[u8]) -> Vec<&[u8]> {
    bytes.split_inclusive(|&b| b == b'\n').collect()
}

/// Byte ranges of the whitespace-separated tokens of `bytes`.
fn token_ranges(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, &b) in bytes.iter().enumerate() {
        if b.is_ascii_whitespace() {
            if let Some(s) = start.take() {
                out.push((s, i));
            }
        } else if start.is_none() {
            start = Some(i);
        }
    }
    if let Some(s) = start {
        out.push((s, bytes.len()));
    }
    out
}

/// One mutation of `input`, using `other` (another seed) for splices.
fn mutate_once(rng: &mut SplitMix64, input: &mut Vec<u8>, other: &[u8]) {
    match rng.below(12) {
        // Flip one bit.
        0 if !input.is_empty() => {
            let i = rng.below(input.len());
            input[i] ^= 1 << rng.below(8);
        }
        // Overwrite one byte with a byte parsers treat specially.
        1 if !input.is_empty() => {
            let i = rng.below(input.len());
            input[i] = *rng.pick(&[
                0u8, 0x1b, b'\r', b'\n', b'#', b' ', 0xff, 0xc3, b'(', b')', b'"', b',', b'-',
                b'.', b'e', b'/',
            ]);
        }
        2 => insert_line(rng, input, other),
        // Delete a line.
        3 => {
            let ranges = line_ranges(input);
            if !ranges.is_empty() {
                let (a, b) = *rng.pick(&ranges);
                input.drain(a..b);
            }
        }
        4 => duplicate_line(rng, input),
        // Replace a token by one of the other seed.
        5 => {
            let mine = token_ranges(input);
            let theirs = token_ranges(other);
            if mine.is_empty() || theirs.is_empty() {
                return;
            }
            let (a, b) = *rng.pick(&mine);
            let (c, d) = *rng.pick(&theirs);
            input.splice(a..b, other[c..d].iter().copied());
        }
        6 | 7 => replace_number(rng, input),
        // Insert a word.
        8 => {
            let at = rng.below(input.len() + 1);
            let word = format!(" {} ", rng.pick(WORDS));
            input.splice(at..at, word.bytes());
        }
        // Cut the input short.
        9 if !input.is_empty() => {
            let at = rng.below(input.len());
            input.truncate(at);
        }
        // Swap two lines.
        10 => {
            let mut lines: Vec<Vec<u8>> = lines_of(input).iter().map(|l| l.to_vec()).collect();
            if lines.len() >= 2 {
                let (i, j) = (rng.below(lines.len()), rng.below(lines.len()));
                lines.swap(i, j);
                *input = lines.concat();
            }
        }
        // Delete a token.
        _ => {
            let tokens = token_ranges(input);
            if !tokens.is_empty() {
                let (a, b) = *rng.pick(&tokens);
                input.drain(a..b);
            }
        }
    }
}

/// Inserts a line, from `input` or from `other`, at the start of a line of `input`.
fn insert_line(rng: &mut SplitMix64, input: &mut Vec<u8>, other: &[u8]) {
    let source = if rng.below(2) == 0 { &input[..] } else { other };
    let lines = lines_of(source);
    if lines.is_empty() {
        return;
    }
    let line = rng.pick(&lines).to_vec();
    let at = line_start(input, rng);
    input.splice(at..at, line);
}

/// Repeats a line of `input` after itself, a few or many times.
fn duplicate_line(rng: &mut SplitMix64, input: &mut Vec<u8>) {
    let ranges = line_ranges(input);
    if !ranges.is_empty() {
        let (a, b) = *rng.pick(&ranges);
        let line = input[a..b].to_vec();
        let times = if rng.below(8) == 0 {
            1 + rng.below(200)
        } else {
            1
        };
        for _ in 0..times {
            input.splice(b..b, line.iter().copied());
        }
    }
}

/// Replaces a number of `input` by an extreme one.
fn replace_number(rng: &mut SplitMix64, input: &mut Vec<u8>) {
    let numbers: Vec<(usize, usize)> = token_ranges(input)
        .into_iter()
        .filter(|&(a, _)| {
            let c = input[a];
            c.is_ascii_digit() || c == b'-' || c == b'.' || c == b'+'
        })
        .collect();
    if numbers.is_empty() {
        return;
    }
    let (a, b) = *rng.pick(&numbers);
    input.splice(a..b, rng.pick(EXTREMES).bytes());
}

fn line_ranges(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for line in lines_of(bytes) {
        out.push((start, start + line.len()));
        start += line.len();
    }
    out
}

fn line_start(bytes: &[u8], rng: &mut SplitMix64) -> usize {
    let ranges = line_ranges(bytes);
    if ranges.is_empty() {
        0
    } else {
        rng.pick(&ranges).0
    }
}

/// Runs one input through a reader. Errors are the expected outcome of most inputs: only a
/// panic (caught by the caller) or not returning is a finding.
fn execute(target: Target, input: &[u8], variant: u64, base: &BaseScene) {
    let text = String::from_utf8_lossy(input);
    match target {
        Target::Sdf => {
            let opts = match variant % 4 {
                0 => LoadOptions::default(),
                1 => LoadOptions {
                    strict: true,
                    ..LoadOptions::default()
                },
                2 => LoadOptions {
                    transform_order: TransformOrder::Local,
                    ..LoadOptions::default()
                },
                _ => LoadOptions {
                    material_fields: anim_core::sdf::MaterialLayout::Fields(vec![
                        MaterialField::Reflectivity,
                        MaterialField::Transparency,
                        MaterialField::Ior,
                        MaterialField::Roughness,
                    ]),
                    ..LoadOptions::default()
                },
            };
            assert_printable(&load_str(&text, Path::new("fuzz.sdf"), &opts));
        }
        Target::Obj => {
            // The mesh reader reads a file: each input gets its own, gone afterwards.
            static INPUTS: AtomicU64 = AtomicU64::new(0);
            let n = INPUTS.fetch_add(1, Ordering::Relaxed);
            let path =
                std::env::temp_dir().join(format!("anim-fuzz-{}-{n}.obj", std::process::id()));
            std::fs::write(&path, input).expect("a temporary file");
            let result = anim_core::shape::mesh::load(&path, MAX_INPUT as u64);
            let _ = std::fs::remove_file(&path);
            if let Err(d) = result {
                let shown = d.to_string();
                assert!(
                    !shown.contains('\u{1b}') && !shown.contains('\0'),
                    "a raw control byte reaches the terminal: {shown:?}"
                );
            }
        }
        Target::Include if variant.is_multiple_of(4) => diamond(input, variant / 4),
        Target::Include => included(input, variant),
        Target::Spec => {
            let src = Source::new(Path::new("fuzz.ron"), text.into_owned());
            if let Ok(file) = spec_file::parse(&src) {
                let names = match &file.scene {
                    spec_file::SceneSource::Inline(scene) => {
                        let (statements, _) = anim_core::sdf::parse(
                            scene,
                            Path::new("fuzz.ron"),
                            &LoadOptions::default(),
                        );
                        Some(BaseScene::new(statements))
                    }
                    spec_file::SceneSource::File(_) => None,
                };
                let scene = names.as_ref().unwrap_or(base);
                if let Ok(anim) = spec_file::validate(&file, scene, &src) {
                    // A valid spec's first and last frames are made as `anim generate` makes
                    // them (aims, orientations, ranges, visibility), in memory.
                    let generator = Generator::new(scene, &anim, &src);
                    for i in [0, anim.frames.saturating_sub(1)] {
                        let _ = generator.frame_text(i);
                    }
                }
            }
        }
    }
}

/// An input cut in two files of a folder of their own: `main.sdf` includes `part.sdfi` (the
/// input's head), then holds its tail; the part sometimes ends by including main (a loop),
/// itself, its folder or a file outside it.
fn included(input: &[u8], variant: u64) {
    static INPUTS: AtomicU64 = AtomicU64::new(0);
    let n = INPUTS.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("anim-fuzz-include-{}-{n}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let cut = (variant as usize / 4) % (input.len() + 1);
    let (head, tail) = input.split_at(cut);
    let mut part = head.to_vec();
    let ending: &[u8] = match (variant / 4 / 65536) % 5 {
        0 => b"\ninclude main.sdf\n",
        1 => b"\ninclude part.sdfi\n",
        2 => b"\ninclude .\n",
        3 => b"\ninclude ../outside.sdf\n",
        _ => b"",
    };
    part.extend_from_slice(ending);
    std::fs::write(dir.join("part.sdfi"), &part).expect("a temporary file");
    let main = [b"include part.sdfi\n".as_slice(), tail].concat();
    std::fs::write(dir.join("main.sdf"), main).expect("a temporary file");
    let result = anim_core::load::load_file(&dir.join("main.sdf"), &LoadOptions::default());
    let _ = std::fs::remove_dir_all(&dir);
    assert_printable(&result);
}

/// The input at the foot of a diamond of includes: `main.sdf` includes `d0.sdfi`, each
/// `dN.sdfi` includes `dN+1.sdfi` 1 to 10 times (some lines spelling it `./dN+1.sdfi`), 1 to
/// 8 levels deep, and the last holds the input's head (sometimes including `d0.sdfi` again:
/// a loop); `main.sdf` holds its tail. 8 levels of 10 would splice the foot 10^8 times.
fn diamond(input: &[u8], variant: u64) {
    static INPUTS: AtomicU64 = AtomicU64::new(0);
    let n = INPUTS.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("anim-fuzz-diamond-{}-{n}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let levels = 1 + (variant % 8) as usize;
    let width = 1 + ((variant / 8) % 10) as usize;
    let cut = ((variant / 80) as usize) % (input.len() + 1);
    let (head, tail) = input.split_at(cut);
    for level in 0..levels {
        let lines: String = (0..width)
            .map(|i| {
                let dot = if i % 3 == 2 { "./" } else { "" };
                format!("include {dot}d{}.sdfi\n", level + 1)
            })
            .collect();
        std::fs::write(dir.join(format!("d{level}.sdfi")), lines).expect("a temporary file");
    }
    let mut foot = head.to_vec();
    if (variant / 80 / 65536).is_multiple_of(4) {
        foot.extend_from_slice(b"\ninclude d0.sdfi\n");
    }
    std::fs::write(dir.join(format!("d{levels}.sdfi")), foot).expect("a temporary file");
    let main = [b"include d0.sdfi\n".as_slice(), tail].concat();
    std::fs::write(dir.join("main.sdf"), main).expect("a temporary file");
    let result = anim_core::load::load_file(&dir.join("main.sdf"), &LoadOptions::default());
    let _ = std::fs::remove_dir_all(&dir);
    assert_printable(&result);
}

/// Every message of a load formats (the windowing and escaping of long or hostile lines)
/// and holds no raw ESC or NUL.
fn assert_printable(result: &Result<anim_core::load::Loaded, Vec<anim_core::diag::Diagnostic>>) {
    let diagnostics = match result {
        Ok(loaded) => &loaded.diagnostics,
        Err(d) => d,
    };
    for d in diagnostics {
        let shown = d.to_string();
        assert!(
            !shown.contains('\u{1b}') && !shown.contains('\0'),
            "a raw control byte reaches the terminal: {shown:?}"
        );
    }
}

/// The scene specs are validated against when they name a file: every name the example
/// specs use.
fn base_scene(repo: &Path) -> BaseScene {
    let mut text = String::new();
    for f in [
        "animations/showcase.sdf",
        "animations/motion.sdf",
        "animations/flyby.sdf",
        "animations/logo.sdf",
        "animations/crowd.sdf",
        "scenes/assignment.sdf",
    ] {
        text.push_str(&std::fs::read_to_string(repo.join(f)).unwrap_or_default());
        text.push('\n');
    }
    let (statements, _) =
        anim_core::sdf::parse(&text, Path::new("base.sdf"), &LoadOptions::default());
    BaseScene::new(statements)
}

type Job = (Target, Vec<u8>, u64);
/// `Err` holds the panic message.
type Outcome = Result<(), String>;

/// A worker thread running inputs; replaced when one hangs (the hung thread is left behind).
struct Worker {
    jobs: Sender<Job>,
    outcomes: Receiver<Outcome>,
}

fn spawn_worker(base: Arc<BaseScene>, last_panic: Arc<Mutex<String>>) -> Worker {
    let (job_tx, job_rx) = mpsc::channel::<Job>();
    let (out_tx, out_rx) = mpsc::channel::<Outcome>();
    thread::Builder::new()
        .name("fuzz-worker".to_string())
        // As deep as the render threads may recurse; the readers must not need more.
        .stack_size(8 << 20)
        .spawn(move || {
            for (target, input, variant) in job_rx {
                let outcome = panic::catch_unwind(AssertUnwindSafe(|| {
                    execute(target, &input, variant, &base)
                }))
                .map_err(|_| last_panic.lock().map(|m| m.clone()).unwrap_or_default());
                if out_tx.send(outcome).is_err() {
                    return;
                }
            }
        })
        .expect("a worker thread starts");
    Worker {
        jobs: job_tx,
        outcomes: out_rx,
    }
}

struct Settings {
    execs: u64,
    seed: u64,
    timeout: Duration,
    corpus: PathBuf,
    out: PathBuf,
    /// Runs only this execution (the others are drawn, not run): a finding reproduced.
    replay: Option<u64>,
}

fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or(default)
}

struct Report {
    execs: u64,
    crashes: u64,
    hangs: u64,
    elapsed: Duration,
}

/// The SDF and spec seeds (the corpus's and the repository's scenes and specs), announced with
/// the run's settings.
/// The seeds of each target: the corpus and the repository's files, and those written here.
struct AllSeeds {
    sdf: Seeds,
    spec: Seeds,
    obj: Seeds,
}

fn seeds(settings: &Settings) -> AllSeeds {
    let corpus = &settings.corpus;
    let mut sdf = read_seeds(corpus, &["scenes", "animations"], &|p| {
        let name = p.to_string_lossy();
        name.ends_with(".sdf") || name.ends_with(".txt")
    });
    sdf.files
        .extend(FRAME_SEEDS.iter().map(|s| s.as_bytes().to_vec()));
    let spec = read_seeds(corpus, &["animations"], &|p| {
        p.extension().is_some_and(|e| e == "ron")
    });
    let mut obj = read_seeds(corpus, &["scenes"], &|p| {
        p.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"))
    });
    obj.files
        .extend(OBJ_SEEDS.iter().map(|s| s.as_bytes().to_vec()));
    assert!(
        !sdf.files.is_empty() && !spec.files.is_empty(),
        "no seeds found (corpus {})",
        settings.corpus.display()
    );
    eprintln!(
        "fuzz: {} SDF seeds, {} spec seeds, {} OBJ seeds, seed {}, {} executions, {:?} per input",
        sdf.files.len(),
        spec.files.len(),
        obj.files.len(),
        settings.seed,
        settings.execs,
        settings.timeout
    );
    AllSeeds { sdf, spec, obj }
}

/// The message of the last panic, kept by a panic hook (until `panic::take_hook`) for the
/// worker to report.
fn record_panics() -> Arc<Mutex<String>> {
    let last_panic = Arc::new(Mutex::new(String::new()));
    {
        let last_panic = last_panic.clone();
        panic::set_hook(Box::new(move |info| {
            if let Ok(mut m) = last_panic.lock() {
                *m = info.to_string();
            }
        }));
    }
    last_panic
}

/// The next input: a seed of the target chosen, mutated a few times with another seed.
fn next_input(rng: &mut SplitMix64, seeds: &AllSeeds) -> (Target, Vec<u8>) {
    // Half the inputs are scenes: the SDF reader has far more paths than the others.
    let (target, seeds) = match rng.below(6) {
        0 => (Target::Spec, &seeds.spec),
        1 => (Target::Obj, &seeds.obj),
        2 => (Target::Include, &seeds.sdf),
        _ => (Target::Sdf, &seeds.sdf),
    };
    let mut input = rng.pick(&seeds.files).clone();
    let other = rng.pick(&seeds.files);
    for _ in 0..1 + rng.below(4) {
        mutate_once(rng, &mut input, other);
    }
    input.truncate(MAX_INPUT);
    (target, input)
}

fn run(settings: &Settings) -> Report {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let seeds = seeds(settings);
    let base = Arc::new(base_scene(repo));
    let last_panic = record_panics();
    let mut worker = spawn_worker(base.clone(), last_panic.clone());
    let mut rng = SplitMix64::new(settings.seed);
    let start = Instant::now();
    let (mut crashes, mut hangs) = (0u64, 0u64);
    let mut slowest = (Duration::ZERO, 0u64);
    let report_every = (settings.execs / 20).max(1);
    for exec in 0..settings.execs {
        let (target, input) = next_input(&mut rng, &seeds);
        let variant = rng.next_u64();
        if settings.replay.is_some_and(|only| only != exec) {
            continue;
        }
        if settings.replay.is_some() {
            eprintln!("fuzz: replaying exec {exec}: {target:?}, variant {variant}");
        }
        let began = Instant::now();
        worker
            .jobs
            .send((target, input.clone(), variant))
            .expect("the worker takes inputs");
        match worker.outcomes.recv_timeout(settings.timeout) {
            Ok(Ok(())) => {}
            Ok(Err(message)) => {
                crashes += 1;
                let path = save(settings, "crash", exec, target, &input);
                eprintln!("fuzz: CRASH at exec {exec}: {message}\n  saved to {path:?}");
            }
            Err(RecvTimeoutError::Timeout) => {
                hangs += 1;
                let path = save(settings, "hang", exec, target, &input);
                eprintln!(
                    "fuzz: HANG at exec {exec} (over {:?}), saved to {path:?}",
                    settings.timeout
                );
                // The hung thread keeps running its input; later inputs get a new worker.
                worker = spawn_worker(base.clone(), last_panic.clone());
            }
            Err(RecvTimeoutError::Disconnected) => {
                crashes += 1;
                save(settings, "crash", exec, target, &input);
                worker = spawn_worker(base.clone(), last_panic.clone());
            }
        }
        let took = began.elapsed();
        if settings.replay.is_some() {
            eprintln!("fuzz: exec {exec} took {took:?}");
        }
        if took > slowest.0 {
            slowest = (took, exec);
        }
        if (exec + 1) % report_every == 0 {
            let secs = start.elapsed().as_secs_f64();
            eprintln!(
                "fuzz: {} execs, {:.0}/s, {crashes} crashes, {hangs} hangs, slowest input {:?} (exec {})",
                exec + 1,
                (exec + 1) as f64 / secs,
                slowest.0,
                slowest.1
            );
        }
        if hangs >= 20 {
            eprintln!("fuzz: stopping after 20 hangs");
            let _ = panic::take_hook();
            return Report {
                execs: exec + 1,
                crashes,
                hangs,
                elapsed: start.elapsed(),
            };
        }
    }
    let _ = panic::take_hook();
    Report {
        execs: settings.execs,
        crashes,
        hangs,
        elapsed: start.elapsed(),
    }
}

fn save(settings: &Settings, kind: &str, exec: u64, target: Target, input: &[u8]) -> PathBuf {
    let ext = match target {
        Target::Sdf => "sdf",
        Target::Spec => "ron",
        Target::Obj => "obj",
        Target::Include => "include.sdf",
    };
    let _ = std::fs::create_dir_all(&settings.out);
    let path = settings
        .out
        .join(format!("{kind}-seed{}-{exec}.{ext}", settings.seed));
    let _ = std::fs::write(&path, input);
    path
}

fn settings_from_env(default_execs: u64) -> Settings {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    Settings {
        execs: env_or("FUZZ_EXECS", default_execs),
        seed: env_or("FUZZ_SEED", 1),
        timeout: Duration::from_millis(env_or("FUZZ_TIMEOUT_MS", 2000)),
        corpus: std::env::var_os("FUZZ_CORPUS")
            .map(PathBuf::from)
            .unwrap_or_else(|| repo.join("../shared/corpus")),
        out: std::env::var_os("FUZZ_OUT")
            .map(PathBuf::from)
            .unwrap_or_else(|| repo.join("target/fuzz-findings")),
        replay: std::env::var("FUZZ_REPLAY")
            .ok()
            .and_then(|v| v.trim().parse().ok()),
    }
}

/// The fuzz run proper (`scripts/fuzz.sh`).
#[test]
#[ignore = "long; run with scripts/fuzz.sh"]
fn fuzz() {
    let report = run(&settings_from_env(100_000));
    let secs = report.elapsed.as_secs_f64();
    eprintln!(
        "fuzz: done: {} execs in {secs:.1} s ({:.0}/s), {} crashes, {} hangs",
        report.execs,
        report.execs as f64 / secs.max(1e-9),
        report.crashes,
        report.hangs
    );
    assert_eq!((report.crashes, report.hangs), (0, 0));
}

/// A short run on every test pass, so the harness keeps compiling and working.
#[test]
fn fuzz_smoke() {
    let mut settings = settings_from_env(2_000);
    settings.execs = 2_000;
    settings.replay = None;
    // The shared corpus may be absent on other machines; the repository's seeds suffice.
    let report = run(&settings);
    assert_eq!((report.crashes, report.hangs), (0, 0));
}

/// Mutations insert every keyword of a primitive, so a new primitive's reader is fuzzed too.
#[test]
fn the_vocabulary_names_every_primitive() {
    for kind in anim_core::shape::Shape::KINDS {
        let keyword = if kind == "mesh" { "obj" } else { kind };
        assert!(
            WORDS.contains(&keyword),
            "WORDS lacks the primitive keyword {keyword}"
        );
    }
}
