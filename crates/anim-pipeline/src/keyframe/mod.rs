//! Keyframe animation: a RON spec (see `docs/animation.md`) turned into one complete SDF
//! file per frame.
//!
//! [`spec`] reads and checks the spec, [`interp`] samples keyed values, [`rotation`] handles
//! orientations, [`base`] knows the base scene, [`orbit`] places the turntable camera,
//! [`motion`] turns a track into transforms (and motion during a blurred frame's exposure),
//! [`placement`] places things at a time (centres, pivots, aims, parents), [`follow`] turns a
//! parent's motion into what its followers carry, [`keyed`] writes keyed
//! values into definitions, [`ranges`] keeps ranged values in range between frames, and
//! [`generate`] writes the frames, [`meshes`] puts the meshes they name where they can read
//! them.

pub mod base;
pub mod bounds;
pub mod expr;
pub mod follow;
pub mod generate;
pub mod interp;
pub mod keyed;
pub mod locate;
pub mod meshes;
pub mod motion;
pub mod orbit;
pub mod path;
pub mod placement;
pub mod ranges;
pub mod rotation;
pub mod spec_file;
pub mod split;
pub mod tidy;

use anim_core::diag::{Diagnostic, Loc};
use anim_core::sdf::ast::StatementKind;
use anim_core::sdf::LoadOptions;
use anim_core::util::write_atomically;
use generate::{BaseScene, Generator};
use rayon::prelude::*;
use spec_file::{Animation, SceneSource, Source};
use split::{Split, STATIC_FILE};
use std::collections::{HashMap, HashSet};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// What to generate, and where.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GenerateConfig {
    /// The RON keyframe spec.
    pub spec: PathBuf,
    /// Where the frames go; default: the spec's `frames_dir`, else `frames/<spec name>`
    /// beside the spec.
    pub out: Option<PathBuf>,
    /// Whether each frame file holds the whole scene, rather than including the part no
    /// frame changes from [`split::STATIC_FILE`].
    pub standalone: bool,
    /// Write only the frames from the first to the last of these (counting from 0). Every
    /// frame is still made, so that the static part and the list of frames are the whole
    /// animation's and the frames written are those a full run writes.
    pub frames: Option<(usize, usize)>,
}

/// What `anim generate` did.
#[derive(Debug)]
pub struct GenerateReport {
    /// Where the frames are.
    pub dir: PathBuf,
    /// How many frames the animation has (all of them were checked and are on disk).
    pub frames: usize,
    /// How many frame files were written because they were new or differed.
    pub written: usize,
    /// Frame files an earlier run of `anim generate` wrote here that the animation no longer
    /// has, removed so they cannot be rendered by mistake (`anim render DIR` then removes
    /// their images).
    pub removed: usize,
    pub fps: spec_file::Fps,
    /// The animation's length in seconds (the last frame's time, for `end: Inclusive`).
    pub duration: f64,
    /// Warnings about the spec and the base scene.
    pub warnings: Vec<Diagnostic>,
}

/// `anim generate`: reads the spec, writes the frames. `Err` holds every error found.
pub fn run_generate(config: &GenerateConfig) -> Result<GenerateReport, Vec<Diagnostic>> {
    run_generate_reporting(config, |_| {})
}

/// [`run_generate`], handing the warnings to `checked` once everything is checked and before
/// any frame is written (the report holds them too).
pub fn run_generate_reporting(
    config: &GenerateConfig,
    checked: impl FnOnce(&[Diagnostic]),
) -> Result<GenerateReport, Vec<Diagnostic>> {
    let spec_path = config.spec.as_path();
    let src = Source::read(spec_path, Source::MAX_BYTES)?;
    let spec_file = spec_file::parse(&src)?;
    let spec_dir = spec_path
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();

    let (statements, mut warnings) = load_base(&spec_file.scene, &spec_dir, &src)?;
    let mut base = BaseScene::new(statements);
    let anim = spec_file::validate(&spec_file, &base, &src)?;
    warnings.extend(anim.warnings.iter().cloned());
    for w in first_frame_warnings(&base, &anim, &src, &spec_file.scene, &spec_dir) {
        // The base scene's own warnings are said already, at the same place.
        if !warnings
            .iter()
            .any(|d| d.loc == w.loc && d.message == w.message)
        {
            warnings.push(w);
        }
    }
    checked(&warnings);

    let dir = match (&config.out, &spec_file.frames_dir) {
        (Some(out), _) => out.clone(),
        (None, Some(d)) => spec_dir.join(d),
        (None, None) => {
            let stem = spec_path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "animation".to_string());
            spec_dir.join("frames").join(stem)
        }
    };
    let scene_path = match &spec_file.scene {
        SceneSource::File(rel) => spec_dir.join(rel),
        SceneSource::Inline(_) => src.path.to_path_buf(),
    };
    // The frame directory exists while the frames are checked, because the paths of their
    // mesh files climb out of it; a run that fails removes the directories it made, so an
    // invalid spec leaves nothing behind.
    let created = create_dirs(&dir).map_err(|e| {
        vec![Diagnostic::file_error(
            &dir,
            format!("cannot create the frame directory: {e}"),
        )]
    })?;
    let manifest_path = dir.join(MANIFEST);
    let mut placed = meshes::Placed::default();
    let result = read_manifest(&manifest_path)
        .map_err(|e| {
            let why = format!("cannot read the list of generated frames: {e}");
            vec![Diagnostic::file_error(&manifest_path, why)]
        })
        .and_then(|previous| {
            placed =
                meshes::place_meshes(&mut base.statements, &scene_path, &dir, &previous, &src)?;
            let chosen = selected_frames(config.frames, &anim, &src)?;
            let listed = Listed {
                previous,
                copies: &placed.listed,
            };
            write_frames(&base, &anim, &src, &dir, config.standalone, chosen, &listed)
        });
    match result {
        Ok((written, removed)) => Ok(GenerateReport {
            dir,
            frames: anim.frames,
            written,
            removed,
            fps: anim.fps,
            duration: anim.duration(),
            warnings,
        }),
        Err(e) => {
            placed.undo();
            // Deepest first; a directory that holds anything is not removed.
            for d in &created {
                let _ = std::fs::remove_dir(d);
            }
            Err(e)
        }
    }
}

/// Creates `dir` and its missing parents; returns the ones it created, deepest first.
fn create_dirs(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let missing: Vec<PathBuf> = dir
        .ancestors()
        .take_while(|d| !d.as_os_str().is_empty() && !d.exists())
        .map(Path::to_path_buf)
        .collect();
    std::fs::create_dir_all(dir)?;
    Ok(missing)
}

/// The frames `--frames A..B` asks for, within the animation's; an error when it has none of
/// them.
fn selected_frames(
    range: Option<(usize, usize)>,
    anim: &Animation,
    src: &Source,
) -> Result<std::ops::RangeInclusive<usize>, Vec<Diagnostic>> {
    let last = anim.frames - 1;
    match range {
        None => Ok(0..=last),
        Some((a, _)) if a > last => Err(vec![Diagnostic::file_error(
            &src.path,
            format!("--frames asks for frames from {a}, but the animation's last frame is {last}"),
        )]),
        Some((a, b)) => Ok(a..=b.min(last)),
    }
}

/// Checks every frame in `chosen`, then writes those that changed (and, unless `standalone`,
/// the static part they include), trims frames an earlier run wrote that the animation no
/// longer has, and records the list. Returns (written, removed).
fn write_frames(
    base: &BaseScene,
    anim: &Animation,
    src: &Source,
    dir: &Path,
    standalone: bool,
    chosen: std::ops::RangeInclusive<usize>,
    listed: &Listed,
) -> Result<(usize, usize), Vec<Diagnostic>> {
    // Every frame is made and checked (loaded as the renderer will) before any is written,
    // so an invalid spec writes nothing: in parallel, as the frames are independent, and the
    // earliest frame that fails is the one reported. Then they are made again one at a time
    // as they are written, so memory holds one frame a thread, however long the animation;
    // generation is deterministic, so what is written is what was checked.
    let generator = Generator::new(base, anim, src);
    let groups = (!standalone).then(|| split::by_subject(&base.statements));
    let changed = check_frames(&generator, dir, &chosen, groups.as_ref())?;
    let split = groups
        .map(|_| Split::new(&base.statements, changed))
        .filter(|split| !split.is_empty());
    let mut written = 0;
    let mut manifest: String = listed.copies.iter().map(|c| format!("{c}\n")).collect();
    // Files this run adds: a run that fails (a full disk) takes them away again, so that no
    // frame is left that no list names.
    let mut created: Vec<PathBuf> = Vec::new();
    // Lists one file and writes it unless it holds `text` already (or no text is given: a
    // frame outside `chosen`); whether it was written.
    let mut put = |name: &str, text: Option<&str>, created: &mut Vec<PathBuf>| {
        let path = dir.join(name);
        manifest.push_str(name);
        manifest.push('\n');
        let Some(text) = text else {
            return Ok(false);
        };
        // Unchanged files are left alone, so they keep their identity for tools that look
        // at modification times.
        let before = std::fs::read(&path).ok();
        if before.as_deref() == Some(text.as_bytes()) {
            return Ok(false);
        }
        write_atomically(&path, |w| w.write_all(text.as_bytes()))
            .map_err(|e| undo(created, io_error(&path, "cannot write the frame", e)))?;
        if before.is_none() {
            created.push(path);
        }
        Ok::<bool, Vec<Diagnostic>>(true)
    };
    if let Some(split) = &split {
        put(
            STATIC_FILE,
            Some(&generator.static_text(split)),
            &mut created,
        )?;
    }
    for i in 0..anim.frames {
        let name = anim.output.sdf(i, anim.digits());
        if !chosen.contains(&i) {
            // Listed all the same: it is one of the animation's frames.
            put(&name, None, &mut created)?;
            continue;
        }
        let statements = generator
            .frame_statements(i)
            .map_err(|e| undo(&created, e))?;
        let text = generator.write_frame(i, &statements, split.as_ref());
        written += usize::from(put(&name, Some(&text), &mut created)?);
    }
    let removed = trim_and_record(dir, listed, &manifest, &created)?;
    Ok((written, removed))
}

/// Removes what the earlier run listed and this one does not (`manifest`), then records
/// `manifest`; returns how many frames went. A failure takes away the files this run
/// `created`.
fn trim_and_record(
    dir: &Path,
    listed: &Listed,
    manifest: &str,
    created: &[PathBuf],
) -> Result<usize, Vec<Diagnostic>> {
    let current: HashSet<&str> = manifest.lines().collect();
    let mut removed = 0;
    for stale in listed
        .previous
        .iter()
        .filter(|f| !current.contains(f.as_str()))
    {
        let path = dir.join(stale);
        match std::fs::remove_file(&path) {
            // The static part and the copies of meshes are not frames.
            Ok(()) => removed += usize::from(stale != STATIC_FILE && !meshes::is_copy(stale)),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => {
                return Err(undo(
                    created,
                    io_error(&path, "cannot remove an old frame", e),
                ))
            }
        }
    }
    if listed.copies.is_empty() {
        // Gone when the last copy in it went, unless it holds files of the user's.
        let _ = std::fs::remove_dir(dir.join(meshes::COPY_DIR));
    }
    let manifest_path = dir.join(MANIFEST);
    write_atomically(&manifest_path, |w| w.write_all(manifest.as_bytes())).map_err(|e| {
        let e = io_error(&manifest_path, "cannot record the generated frames", e);
        undo(created, e)
    })?;
    Ok(removed)
}

/// Takes away the files a failed run `created`, and passes its error on.
fn undo(created: &[PathBuf], e: Vec<Diagnostic>) -> Vec<Diagnostic> {
    for path in created {
        let _ = std::fs::remove_file(path);
    }
    e
}

fn io_error(path: &Path, what: &str, e: std::io::Error) -> Vec<Diagnostic> {
    vec![Diagnostic::file_error(path, format!("{what}: {e}"))]
}

/// Makes every frame, checks those in `chosen` by loading them, and returns the subjects of
/// `groups` that some frame changes; the earliest frame that fails is the one reported.
fn check_frames(
    generator: &Generator,
    dir: &Path,
    chosen: &std::ops::RangeInclusive<usize>,
    groups: Option<&HashMap<&str, Vec<&StatementKind>>>,
) -> Result<HashSet<String>, Vec<Diagnostic>> {
    let (anim, src) = (generator.anim, generator.src);
    let checked: Vec<Result<HashSet<String>, Vec<Diagnostic>>> = (0..anim.frames)
        .into_par_iter()
        .map(|i| {
            if chosen.contains(&i) {
                check_frame(generator, anim, src, dir, i, groups)
            } else {
                // Not written: only what it changes counts, for the static part.
                let statements = generator.frame_statements(i)?;
                Ok(groups.map_or_else(HashSet::new, |g| split::changed_subjects(g, &statements)))
            }
        })
        .collect();
    let mut changed = HashSet::new();
    for frame in checked {
        changed.extend(frame?);
    }
    Ok(changed)
}

/// Parses the base scene. Errors stop generation; warnings are passed on.
fn load_base(
    scene: &SceneSource,
    spec_dir: &Path,
    src: &Source,
) -> Result<(Vec<anim_core::sdf::ast::Statement>, Vec<Diagnostic>), Vec<Diagnostic>> {
    // The base scene is a file written by hand, read as `anim render` reads one: with its
    // material layout inferred. The frames then print the materials in the standard layout,
    // which inference reads back as written.
    let opts = LoadOptions {
        material_fields: anim_core::sdf::MaterialLayout::Auto,
        ..LoadOptions::default()
    };
    let (statements, mut diags, path) = match scene {
        SceneSource::File(rel) => {
            let path = spec_dir.join(rel);
            let bytes = anim_core::load::read_input(&path, opts.max_input, "the base scene")
                .map_err(|e| {
                    // The reader's own words, naming the file.
                    let why = e.first().map_or(String::new(), |d| d.message.clone());
                    let named = format!("the base scene '{}'", path.display());
                    vec![src.error(
                        &["scene[0]", "scene"],
                        why.replacen("the base scene", &named, 1),
                    )]
                })?;
            let (statements, diags) =
                anim_core::sdf::parse(&String::from_utf8_lossy(&bytes), &path, &opts);
            (statements, diags, path)
        }
        SceneSource::Inline(text) => {
            let (statements, diags) = anim_core::sdf::parse(text, &src.path, &opts);
            (statements, diags, src.path.to_path_buf())
        }
    };
    // Building the scene finds what parsing alone cannot (an unknown material, a composite
    // child defined nowhere), located in the base scene rather than in a generated frame.
    if !diags.iter().any(Diagnostic::is_error) {
        if let Err(built) = anim_core::load::build(&statements, &path, &opts) {
            diags.extend(built.into_iter().filter(Diagnostic::is_error));
        }
    }
    if matches!(scene, SceneSource::Inline(_)) {
        diags = diags.into_iter().map(|d| shift_into_spec(d, src)).collect();
    }
    if diags.iter().any(Diagnostic::is_error) {
        return Err(diags);
    }
    Ok((statements, diags))
}

/// What `anim check` would say of the first frame file, said once here rather than by every
/// frame at render time, in the base scene where a base statement is the cause: the frame's
/// statements built as the renderer builds them (each warning at the statement's own place),
/// what the camera would show, and then every other warning of the frame's text loaded as
/// `anim check` loads a file, moved from the frame's line to the statement written there. A
/// frame that cannot be made yields nothing: writing the frames reports that.
fn first_frame_warnings(
    base: &BaseScene,
    anim: &Animation,
    src: &Source,
    scene: &SceneSource,
    spec_dir: &Path,
) -> Vec<Diagnostic> {
    let generator = Generator::new(base, anim, src);
    let Ok(statements) = generator.frame_statements(0) else {
        return Vec::new();
    };
    let path = match scene {
        SceneSource::File(rel) => spec_dir.join(rel),
        SceneSource::Inline(_) => src.path.to_path_buf(),
    };
    let Ok(built) = anim_core::load::build(&statements, &path, &LoadOptions::default()) else {
        return Vec::new();
    };
    let mut warnings = built.diagnostics;
    warnings.extend(anim_core::load::probe::blank_image_warnings(
        &built.jobs,
        &path,
    ));
    let text = generator.write_frame(0, &statements, None);
    // Read where the base scene is, so that its mesh files are found as written there.
    let opts = LoadOptions {
        material_fields: anim_core::sdf::MaterialLayout::Auto,
        infer_transform_order: true,
        allow_any_input: true,
        ..LoadOptions::default()
    };
    if let Ok(loaded) = anim_core::load::load_str(&text, &path, &opts) {
        // The frame's lines: its header, then one statement a line.
        let header = text.lines().count() - statements.len();
        for mut d in loaded.diagnostics {
            let made_by = d.loc.as_ref().filter(|l| *l.file == *path).and_then(|l| {
                let line = (l.line as usize).checked_sub(header + 1)?;
                statements.get(line)
            });
            if let Some(s) = made_by {
                d.loc = Some(s.loc.clone());
                d.file = s.loc.file.to_path_buf();
                d.source_line = None;
            }
            let line = |d: &Diagnostic| d.loc.as_ref().map(|l| (l.file.clone(), l.line));
            if !warnings
                .iter()
                .any(|w| w.message == d.message && line(w) == line(&d))
            {
                warnings.push(d);
            }
        }
    }
    if matches!(scene, SceneSource::Inline(_)) {
        warnings = warnings
            .into_iter()
            .map(|d| shift_into_spec(d, src))
            .collect();
    }
    warnings
}

/// Moves a diagnostic about an inline scene from the scene text's own line:col to where that
/// text stands in the spec (exact for raw strings and strings without escapes).
fn shift_into_spec(mut d: Diagnostic, src: &Source) -> Diagnostic {
    let Some((start, _)) = src.locations.get("scene[0]") else {
        return d;
    };
    // Past the opening delimiter: `"` or `r#…#"`.
    let line_text = src.text.lines().nth(start.line as usize - 1).unwrap_or("");
    let from_start: String = line_text.chars().skip(start.col as usize - 1).collect();
    let delimiter = if from_start.starts_with('r') {
        from_start.chars().take_while(|&c| c != '"').count() + 1
    } else {
        1
    } as u32;
    if let Some(loc) = &d.loc {
        let (line, col) = if loc.line == 1 {
            (start.line, start.col + delimiter + loc.col - 1)
        } else {
            (start.line + loc.line - 1, loc.col)
        };
        d.loc = Some(Loc {
            file: src.path.clone(),
            line,
            col,
        });
    }
    d.file = src.path.to_path_buf();
    d
}

/// Checks frame `i` by loading its whole text as the renderer will; with the base scene's
/// statements by subject (`groups`), returns the subjects the frame changes
/// ([`split::changed_subjects`]).
fn check_frame(
    generator: &Generator,
    anim: &Animation,
    src: &Source,
    dir: &Path,
    i: usize,
    groups: Option<&HashMap<&str, Vec<&StatementKind>>>,
) -> Result<HashSet<String>, Vec<Diagnostic>> {
    let statements = generator.frame_statements(i)?;
    let text = generator.write_frame(i, &statements, None);
    let path: Arc<Path> = Arc::from(dir.join(anim.output.sdf(i, anim.digits())).as_path());
    // Confined as `anim render DIR` confines it: the meshes it names are inside its folder.
    if let Err(diags) = anim_core::load::load_str(&text, &path, &LoadOptions::default()) {
        // A frame that does not load is a bug or a combination the spec checks missed;
        // show the loader's own words with the frame text they are about.
        let mut out = vec![Diagnostic::file_error(
            &path,
            format!(
                "frame {i} generated from {} does not load:",
                src.path.display()
            ),
        )];
        out.extend(diags.into_iter().filter(Diagnostic::is_error));
        return Err(out);
    }
    Ok(groups.map_or_else(HashSet::new, |g| split::changed_subjects(g, &statements)))
}

/// The frame files `anim generate` wrote into a frame directory, one a line. Only files listed
/// here are ever removed: a frame directory may hold the user's own files with names like
/// frames. The images of removed frames are the renderer's: `anim render DIR` removes those
/// whose bytes are still exactly the ones it wrote.
const MANIFEST: &str = ".anim-generated";

/// The generated files a run knows of besides its frames.
struct Listed<'a> {
    /// The earlier run's list: what this run may replace or remove.
    previous: Vec<String>,
    /// The copies of meshes this run's frames name ([`meshes::place_meshes`]).
    copies: &'a [String],
}

/// The files listed by an earlier run's manifest (none without one).
fn read_manifest(path: &Path) -> std::io::Result<Vec<String>> {
    match std::fs::read_to_string(path) {
        Ok(text) => Ok(text
            .lines()
            // Only plain names in the directory itself, or copies of meshes in their folder,
            // whatever the file says.
            .filter(|f| {
                !f.is_empty()
                    && (Path::new(f).file_name() == Some(f.as_ref()) || meshes::is_copy(f))
            })
            .map(str::to_string)
            .collect()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Vec::new()),
        Err(e) => Err(e),
    }
}
