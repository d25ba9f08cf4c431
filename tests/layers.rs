//! The architecture, checked: crates depend one way (Cargo enforces it: the `anim` command
//! → {anim-pipeline, anim-bench} → anim-core), imports inside each crate run one way through
//! its layers below, no two files import each other (directly or round a loop), only the
//! command layer knows the command line and prints, and no source file, nor function, grows
//! past what one reader can hold.
//!
//! The layers of each crate, top to bottom (a module may import only modules of lower layers
//! of its own crate):
//!
//! ```text
//! anim (the command):  cli → app
//! anim-pipeline:       {frames, keyframe}
//! anim-bench:          stress → report → {pov, rehit} → {plot, metrics}
//! anim-core:           load → render → scene → sdf → shape → accel → math → limits →
//!                      {diag, util}
//! ```
//!
//! Inside the render core the same holds between its modules ([`RENDER_ORDER`]: entry →
//! samplers → {exposure, integrator} → facade → view → geometry → {policy, leaves}), the
//! integrator and the samplers ask the compiled scene through the facade alone, and no
//! folder of the core has modules that import each other round a loop.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Each crate of the workspace: its source folder (from the workspace root) and its layers.
const CRATES: &[(&str, &[&[&str]])] = &[
    ("src", &[&["cli"], &["app"]]),
    ("crates/anim-pipeline/src", &[&["frames", "keyframe"]]),
    (
        "crates/anim-bench/src",
        &[
            &["stress"],
            &["report"],
            &["pov", "rehit"],
            &["plot", "metrics"],
        ],
    ),
    (
        "crates/anim-core/src",
        &[
            &["load"],
            &["render"],
            &["scene"],
            &["sdf"],
            &["shape"],
            &["accel"],
            &["math"],
            &["limits", "input"],
            &["diag", "util"],
        ],
    ),
];

/// The render core (`crates/anim-core/src/render`), top to bottom: a file may import only
/// modules of lower groups (or files of its own module). `shot` renders the frames of a shot
/// through the entry, `mod` (`render/mod.rs`); then the samplers; the exposure (`motion`) and the integrator; the
/// facade (`compile`); the view and the geometry it asks (the view's lookups are built
/// over the geometry's bounds, so it sits above it); the policy and the leaves every layer
/// may read.
const RENDER_ORDER: &[&[&str]] = &[
    &["shot"],
    &["mod"],
    &["sampler"],
    &["motion", "integrator"],
    &["compile"],
    &["view"],
    &["geometry"],
    &[
        "policy",
        "shading",
        "camera",
        "film",
        "settings",
        "counts",
        "footprint",
    ],
];

/// The render modules that ask the compiled scene only through its facade: they name
/// nothing of `render::geometry`.
const SEALED_OFF: &[&str] = &["integrator", "sampler"];

/// About as much as one reader holds in mind; tests beside the code may run longer.
const MAX_LINES: usize = 900;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The module path of a source file: `src/sdf/parse/mod.rs` → `["sdf", "parse"]`.
fn module_path(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    if parts
        .last()
        .is_some_and(|p| p == "mod" || p == "lib" || p == "main")
    {
        parts.pop();
    }
    parts
}

/// Code lines without comments (`//` to the end of the line; doc comments included).
fn code_lines(text: &str) -> impl Iterator<Item = &str> {
    text.lines().map(|l| match l.find("//") {
        Some(i) => &l[..i],
        None => l,
    })
}

/// Paths written after `prefix` in `line`: `crate::a::b::{c, d::e}` gives `a::b::c` and
/// `a::b::d::e`.
fn paths_after<'a>(line: &'a str, prefix: &str) -> Vec<Vec<&'a str>> {
    let mut found = Vec::new();
    let mut rest = line;
    while let Some(i) = rest.find(prefix) {
        let before = &rest[..i];
        rest = &rest[i + prefix.len()..];
        if before.ends_with(|c: char| c.is_alphanumeric() || c == '_') {
            continue;
        }
        expand(rest, Vec::new(), &mut found);
    }
    found
}

/// The paths a `use` tree starting at `text` names, each after `base`.
fn expand<'a>(text: &'a str, base: Vec<&'a str>, out: &mut Vec<Vec<&'a str>>) {
    let mut path = base;
    let mut rest = text;
    loop {
        if let Some(group) = rest.strip_prefix('{') {
            // Items of a group, split at the commas of its own level.
            let (mut depth, mut start) = (0usize, 0usize);
            for (i, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        expand(group[start..i].trim_start(), path.clone(), out);
                        return;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        expand(group[start..i].trim_start(), path.clone(), out);
                        start = i + 1;
                    }
                    _ => {}
                }
            }
            return;
        }
        let end = rest
            .find(|c: char| !(c.is_alphanumeric() || c == '_'))
            .unwrap_or(rest.len());
        if end == 0 {
            break;
        }
        path.push(&rest[..end]);
        match rest[end..].strip_prefix("::") {
            Some(next) => rest = next,
            None => break,
        }
    }
    if !path.is_empty() {
        out.push(path);
    }
}

struct Crate {
    /// The crate's source folder, from the workspace root.
    src: &'static str,
    layers: &'static [&'static [&'static str]],
    /// Module path → file.
    files: BTreeMap<Vec<String>, PathBuf>,
}

impl Crate {
    fn all() -> Vec<Crate> {
        CRATES
            .iter()
            .map(|&(src, layers)| {
                let dir = root().join(src);
                let mut paths = Vec::new();
                rust_files(&dir, &mut paths);
                let files = paths
                    .into_iter()
                    .map(|f| (module_path(&dir, &f), f))
                    .collect();
                Crate { src, layers, files }
            })
            .collect()
    }

    fn layer_of(&self, module: &str) -> Option<usize> {
        self.layers.iter().position(|l| l.contains(&module))
    }

    /// The longest module path of a file that prefixes `path`.
    fn resolve(&self, path: &[String]) -> Option<Vec<String>> {
        (1..=path.len())
            .rev()
            .map(|n| path[..n].to_vec())
            .find(|p| self.files.contains_key(p))
    }

    /// Module files a file refers to through `crate::…` and `super::…` paths, outside its
    /// tests (which may drive it through higher layers, as the files named `tests` may).
    fn references(&self, module: &[String]) -> BTreeSet<Vec<String>> {
        let text = std::fs::read_to_string(&self.files[module]).unwrap();
        let code = text.split("#[cfg(test)]\nmod tests {").next().unwrap_or("");
        let mut refs = BTreeSet::new();
        for line in code_lines(code) {
            for path in paths_after(line, "crate::") {
                let path: Vec<String> = path.iter().map(|s| s.to_string()).collect();
                refs.extend(self.resolve(&path));
            }
            for path in paths_after(line, "super::") {
                let mut base = module.to_vec();
                base.pop();
                let mut full = base;
                full.extend(
                    path.iter()
                        .filter(|s| **s != "super")
                        .map(|s| s.to_string()),
                );
                refs.extend(self.resolve(&full));
            }
        }
        refs.remove(module);
        refs
    }

    fn is_test_file(&self, module: &[String]) -> bool {
        module.last().is_some_and(|m| m == "tests")
    }
}

#[test]
fn imports_run_down_the_layers() {
    let mut problems = Vec::new();
    for krate in Crate::all() {
        // Tests beside the code may drive their module through higher layers (a parser test
        // that builds the scene, say): they are not part of the layering.
        for module in krate.files.keys().filter(|m| !krate.is_test_file(m)) {
            let Some(top) = module.first() else { continue };
            let Some(from) = krate.layer_of(top) else {
                if top != "main" {
                    problems.push(format!(
                        "{}/{top}: not in any layer of this test",
                        krate.src
                    ));
                }
                continue;
            };
            for target in krate.references(module) {
                let Some(to_top) = target.first() else {
                    // The crate's root (its `lib.rs`) is the crate's face.
                    continue;
                };
                if to_top == top {
                    continue;
                }
                match krate.layer_of(to_top) {
                    Some(to) if to > from => {}
                    _ => problems.push(format!(
                        "{}: {} imports {} (layer {from} may import only lower layers)",
                        krate.src,
                        module.join("::"),
                        target.join("::")
                    )),
                }
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// Module path → the module files it refers to (test files and tests beside the code left
/// out).
type Refs = BTreeMap<Vec<String>, BTreeSet<Vec<String>>>;

/// Within a module, no two files import each other, directly or round a loop. A folder's
/// `mod.rs` is the folder's face (it declares and re-exports its files), so references
/// between it and its own files are not counted.
#[test]
fn no_import_circles_between_files() {
    for krate in Crate::all() {
        no_circles_in(&krate);
    }
}

fn no_circles_in(krate: &Crate) {
    let edges: Refs = krate
        .refs()
        .into_iter()
        .map(|(module, targets)| {
            let related = |t: &Vec<String>| t.starts_with(&module) || module.starts_with(t);
            let others = targets.into_iter().filter(|t| !related(t)).collect();
            (module, others)
        })
        .collect();
    let circles = find_circles(&edges);
    assert!(
        circles.is_empty(),
        "import circles:\n{}",
        circles.join("\n")
    );
}

impl Crate {
    fn refs(&self) -> Refs {
        self.files
            .keys()
            .filter(|m| !self.is_test_file(m))
            .map(|m| {
                let targets = self.references(m);
                let kept = targets.into_iter().filter(|t| !self.is_test_file(t));
                (m.clone(), kept.collect())
            })
            .collect()
    }

    fn core() -> Crate {
        Crate::all()
            .into_iter()
            .find(|k| k.src == "crates/anim-core/src")
            .unwrap()
    }
}

/// Where a module of the render core sits in [`RENDER_ORDER`]: its name there (`mod` for
/// the entry) and its group; `None` outside `render`.
fn render_place(module: &[String]) -> Option<(&str, Option<usize>)> {
    if module.first().is_none_or(|m| m != "render") {
        return None;
    }
    let name = module.get(1).map_or("mod", String::as_str);
    Some((name, RENDER_ORDER.iter().position(|g| g.contains(&name))))
}

/// The imports of `refs` that run against [`RENDER_ORDER`]: from a module of the render
/// core to one of its own group or a higher one.
fn render_order_problems(refs: &Refs) -> Vec<String> {
    let mut problems = Vec::new();
    for (module, targets) in refs {
        let Some((name, from)) = render_place(module) else {
            continue;
        };
        let Some(from) = from else {
            problems.push(format!("render::{name} is not in RENDER_ORDER"));
            continue;
        };
        for target in targets {
            let Some((to_name, to)) = render_place(target) else {
                continue;
            };
            if to_name == name && name != "mod" {
                continue;
            }
            if to.is_none_or(|to| to <= from) {
                problems.push(format!(
                    "{} imports {} (render::{name} may import only lower groups of RENDER_ORDER)",
                    module.join("::"),
                    target.join("::")
                ));
            }
        }
    }
    problems
}

/// The modules of [`SEALED_OFF`] that name something of `render::geometry`.
fn sealing_problems(refs: &Refs) -> Vec<String> {
    let mut problems = Vec::new();
    for (module, targets) in refs {
        match render_place(module) {
            Some((name, _)) if SEALED_OFF.contains(&name) => {}
            _ => continue,
        }
        for target in targets {
            if render_place(target).is_some_and(|(to, _)| to == "geometry") {
                problems.push(format!(
                    "{} names {}: it asks the facade (render::compile) only",
                    module.join("::"),
                    target.join("::")
                ));
            }
        }
    }
    problems
}

/// Circles between the modules of one folder: for each folder, its files and subfolders,
/// with an arrow from one to another where a file inside the first imports a file inside
/// the second (the folder's own face, its `mod.rs`, left out: its files may read it). A
/// circle between two files is one between their folders too, and so is one through
/// modules the files never name each other in.
fn module_circles(refs: &Refs) -> Vec<String> {
    // The child of `folder` that `module` lies in, if it lies below it.
    let child = |folder: &[String], module: &[String]| {
        (module.len() > folder.len() && module.starts_with(folder))
            .then(|| module[..folder.len() + 1].to_vec())
    };
    let folders: BTreeSet<Vec<String>> = refs
        .keys()
        .flat_map(|m| (0..m.len()).map(|n| m[..n].to_vec()))
        .collect();
    let mut circles = Vec::new();
    for folder in &folders {
        let mut edges = Refs::new();
        for (module, targets) in refs {
            let Some(from) = child(folder, module) else {
                continue;
            };
            for to in targets.iter().filter_map(|t| child(folder, t)) {
                if to != from {
                    edges.entry(from.clone()).or_default().insert(to);
                }
            }
        }
        circles.extend(find_circles(&edges));
    }
    circles
}

/// The circles of a directed graph, each as `a -> b -> … -> a`.
fn find_circles(edges: &Refs) -> Vec<String> {
    fn visit(
        node: &Vec<String>,
        edges: &Refs,
        state: &mut BTreeMap<Vec<String>, u8>,
        stack: &mut Vec<Vec<String>>,
        circles: &mut Vec<String>,
    ) {
        state.insert(node.clone(), 1);
        stack.push(node.clone());
        for next in edges.get(node).into_iter().flatten() {
            match state.get(next).copied().unwrap_or(0) {
                0 => visit(next, edges, state, stack, circles),
                1 => {
                    let start = stack.iter().position(|n| n == next).unwrap();
                    let names: Vec<String> = stack[start..].iter().map(|n| n.join("::")).collect();
                    circles.push(format!("{} -> {}", names.join(" -> "), next.join("::")));
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(node.clone(), 2);
    }
    let mut state = BTreeMap::new();
    let mut circles = Vec::new();
    for node in edges.keys() {
        if !state.contains_key(node) {
            visit(node, edges, &mut state, &mut Vec::new(), &mut circles);
        }
    }
    circles
}

#[test]
fn the_render_core_runs_downhill() {
    let problems = render_order_problems(&Crate::core().refs());
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The integrator and the samplers ask the compiled scene through its facade alone: they
/// neither import `render::geometry` nor reach the aggregate through the facade's accessor
/// for tools.
#[test]
fn the_facade_is_sealed() {
    let core = Crate::core();
    let mut problems = sealing_problems(&core.refs());
    for (module, file) in &core.files {
        match render_place(module) {
            Some((name, _)) if SEALED_OFF.contains(&name) => {}
            _ => continue,
        }
        let text = std::fs::read_to_string(file).unwrap();
        let code = text.split("#[cfg(test)]").next().unwrap_or("");
        if code_lines(code).any(|l| l.contains(".aggregate()")) {
            problems.push(format!("{} asks for the aggregate", module.join("::")));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// No import circle anywhere in the core: not between two files, nor between the modules of
/// any folder (the layers of the core, the render core's modules, the files of a folder).
#[test]
fn the_core_has_no_import_circle() {
    let circles = module_circles(&Crate::core().refs());
    assert!(
        circles.is_empty(),
        "import circles:\n{}",
        circles.join("\n")
    );
}

/// The three checks above find what they claim, on imports written to break them.
#[test]
fn the_render_checks_catch_wrong_imports() {
    let path = |p: &str| p.split("::").map(String::from).collect::<Vec<String>>();
    let refs = |pairs: &[(&str, &str)]| {
        let mut refs = Refs::new();
        for (from, to) in pairs {
            refs.entry(path(from)).or_default().insert(path(to));
        }
        refs
    };
    // Downhill, sealed, and no circle.
    let good = refs(&[
        ("render", "render::sampler"),
        ("render::sampler::adaptive", "render::integrator"),
        ("render::sampler::adaptive", "render::sampler::pattern"),
        ("render::integrator", "render::compile"),
        ("render::compile", "render::geometry"),
        ("render::geometry::closest", "render::geometry::leaf"),
        ("render::geometry::leaf", "render::policy"),
    ]);
    assert!(render_order_problems(&good).is_empty());
    assert!(sealing_problems(&good).is_empty());
    assert!(module_circles(&good).is_empty());
    // Back up from the facade to the integrator, sideways from the exposure to the
    // integrator, and up to the entry.
    for (from, to) in [
        ("render::compile", "render::integrator"),
        ("render::motion", "render::integrator"),
        ("render::sampler::adaptive", "render"),
    ] {
        let problems = render_order_problems(&refs(&[(from, to)]));
        assert_eq!(problems.len(), 1, "{from} -> {to}: {problems:?}");
    }
    // The integrator past the facade.
    let past = refs(&[("render::integrator", "render::geometry::motion")]);
    assert_eq!(sealing_problems(&past).len(), 1);
    // Two modules of a folder round a loop, though no two files import each other.
    let circle = refs(&[
        ("render::motion", "render::sampler::pattern"),
        ("render::sampler::first_pass", "render::motion"),
    ]);
    assert_eq!(
        module_circles(&circle).len(),
        1,
        "{:?}",
        module_circles(&circle)
    );
}

#[test]
fn only_the_command_layer_knows_the_command_line() {
    for krate in Crate::all() {
        let offenders: Vec<String> = krate
            .files
            .keys()
            .filter(|m| m.first().is_some_and(|t| t != "cli" && t != "main"))
            .filter(|m| {
                krate
                    .references(m)
                    .iter()
                    .any(|t| t.first().is_some_and(|t| t == "cli"))
            })
            .map(|m| m.join("::"))
            .collect();
        assert!(offenders.is_empty(), "import the CLI types: {offenders:?}");
        // Printing and exit codes belong to the command layer (of the `anim` crate) alone.
        let mut printers = Vec::new();
        for (module, file) in &krate.files {
            let command_layer =
                krate.src == "src" && module.first().is_none_or(|t| t == "app" || t == "main");
            if command_layer || krate.is_test_file(module) {
                continue;
            }
            let text = std::fs::read_to_string(file).unwrap();
            let body = text.split("#[cfg(test)]").next().unwrap_or("");
            for word in ["print!", "println!", "eprint!", "eprintln!", "ExitCode"] {
                if code_lines(body).any(|l| l.contains(word)) {
                    printers.push(format!("{}: {} uses {word}", krate.src, module.join("::")));
                }
            }
        }
        assert!(printers.is_empty(), "{}", printers.join("\n"));
    }
}

/// Every Rust file of the workspace: the crates' sources and the integration tests.
fn workspace_files() -> Vec<PathBuf> {
    let mut files = Vec::new();
    for (src, _) in CRATES {
        rust_files(&root().join(src), &mut files);
    }
    rust_files(&root().join("tests"), &mut files);
    files
}

#[test]
fn no_source_file_is_longer_than_a_reader_can_hold() {
    let long: Vec<String> = workspace_files()
        .iter()
        .filter_map(|f| {
            let n = std::fs::read_to_string(f).unwrap().lines().count();
            (n > MAX_LINES).then(|| format!("{} has {n} lines", f.display()))
        })
        .collect();
    assert!(long.is_empty(), "{}", long.join("\n"));
}
/// Most lines of one function, its signature and closing brace included: what can be read
/// as one piece.
const MAX_FUNCTION_LINES: usize = 100;

/// The functions of `text` (formatted by rustfmt, so a body closes at its `fn`'s indentation)
/// longer than [`MAX_FUNCTION_LINES`]: name, first line, length.
fn long_functions(text: &str) -> Vec<(String, usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut long = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let code = line.trim_start();
        let indent = &line[..line.len() - code.len()];
        let after_fn = [
            "fn ",
            "pub fn ",
            "pub(crate) fn ",
            "pub(super) fn ",
            "const fn ",
        ]
        .iter()
        .chain(&["pub const fn ", "pub(crate) const fn "])
        .find_map(|p| code.strip_prefix(p));
        let Some(rest) = after_fn else { continue };
        let name: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        // A declaration without a body (in a trait) ends with `;` before any `{`.
        let Some(open) = (i..lines.len()).find(|&j| {
            let l = lines[j].trim_end();
            l.ends_with('{') || l.ends_with(';')
        }) else {
            continue;
        };
        if lines[open].trim_end().ends_with(';') {
            continue;
        }
        let close = format!("{indent}}}");
        if let Some(end) = (open..lines.len())
            .find(|&j| lines[j] == close || lines[j].trim_end().ends_with('}') && j == open)
        {
            let n = end - i + 1;
            if n > MAX_FUNCTION_LINES {
                long.push((name, i + 1, n));
            }
        }
    }
    long
}

#[test]
fn no_function_is_longer_than_a_reader_can_hold() {
    let mut long = Vec::new();
    for f in workspace_files() {
        let text = std::fs::read_to_string(&f).unwrap();
        for (name, line, n) in long_functions(&text) {
            long.push(format!("{}:{line}: fn {name} has {n} lines", f.display()));
        }
    }
    assert!(long.is_empty(), "{}", long.join("\n"));
}

#[test]
fn the_function_length_check_measures_what_it_claims() {
    let body = "    let x = 1;\n".repeat(MAX_FUNCTION_LINES - 2);
    let exact = format!("fn fits() {{\n{body}}}\n");
    assert!(long_functions(&exact).is_empty());
    let over = format!("    pub fn grown(\n        a: u32,\n    ) -> u32 {{\n{body}    }}\n");
    assert_eq!(
        long_functions(&over),
        vec![("grown".to_string(), 1, MAX_FUNCTION_LINES + 2)]
    );
    let declared = "    fn declared(&self) -> u32;\n}\n";
    assert!(long_functions(declared).is_empty());
}

/// Whether a comment line quotes a measurement of speed: an instruction count, or a
/// percentage or ratio of time or cost. Such figures go stale silently where they sit; they
/// live in BENCHMARKS.md and its history, which comments may cite.
fn quotes_a_speed(comment: &str) -> bool {
    let lower = comment.to_lowercase();
    let chars: Vec<char> = lower.chars().collect();
    // Numbers standing alone (not the digits of `i32` or `x86`), and what follows each.
    let mut numbers = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let starts = chars[i].is_ascii_digit()
            && (i == 0 || !(chars[i - 1].is_alphanumeric() || chars[i - 1] == '_'));
        if !starts {
            i += 1;
            continue;
        }
        while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
            i += 1;
        }
        numbers.push(chars[i..].iter().collect::<String>());
    }
    // A share (`5 %`) or a ratio (`0.97×`, not a size like `4×4` or `3 × f32`).
    let ratio = numbers.iter().any(|rest| {
        rest.trim_start().starts_with('%')
            || (rest.starts_with('×')
                && !rest['×'.len_utf8()..].starts_with(|c: char| c.is_ascii_digit()))
    });
    let speed_words = ["instruction", "cpu", "faster", "slower", "cost", "time"];
    let speaks_of_speed = speed_words.iter().any(|w| lower.contains(w));
    (lower.contains("instruction") && !numbers.is_empty()) || (speaks_of_speed && ratio)
}

#[test]
fn no_comment_quotes_a_measurement_of_speed() {
    let mut quoted = Vec::new();
    for (src, _) in CRATES {
        let mut files = Vec::new();
        rust_files(&root().join(src), &mut files);
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap();
            for (n, line) in text.lines().enumerate() {
                let Some(at) = line.find("//") else { continue };
                if quotes_a_speed(&line[at..]) {
                    quoted.push(format!("{}:{}: {}", f.display(), n + 1, line.trim()));
                }
            }
        }
    }
    assert!(quoted.is_empty(), "{}", quoted.join("\n"));
}

#[test]
fn the_measurement_check_tells_a_speed_from_a_size() {
    assert!(quotes_a_speed("// costs 5 % of the render"));
    assert!(quotes_a_speed("/// about 90 instructions per camera ray"));
    assert!(quotes_a_speed("// 1.06× main's CPU time in turns"));
    assert!(!quotes_a_speed(
        "/// half-way between keys 90° apart to 71 % of its size"
    ));
    assert!(!quotes_a_speed(
        "// one conversion instruction where `usize` takes several"
    ));
    assert!(!quotes_a_speed(
        "/// 4×4 walks the tree once for twice the rays, at little cost"
    ));
    assert!(!quotes_a_speed(
        "/// Bytes an image costs per pixel: radiance (3 × f32)"
    ));
}
