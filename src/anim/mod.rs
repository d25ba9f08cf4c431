//! Keyframe animation: a RON spec (see `README.md`) turned into one complete SDF
//! file per frame.
//!
//! [`spec`] reads and checks the spec, [`interp`] samples keyed values, [`orbit`] places the
//! turntable camera and [`generate`] writes the frames.

pub mod generate;
pub mod interp;
pub mod locate;
pub mod orbit;
pub mod spec;

use crate::cli::GenerateArgs;
use crate::diag::{Diagnostic, Loc};
use crate::sdf::LoadOptions;
use crate::util::write_atomically;
use generate::{BaseScene, Generator};
use spec::{Animation, SceneSource, Source};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

/// What `anim generate` did.
#[derive(Debug)]
pub struct GenerateReport {
    /// Where the frames are.
    pub dir: PathBuf,
    /// How many frames the animation has (all of them were checked and are on disk).
    pub frames: usize,
    /// How many frame files were written because they were new or differed.
    pub written: usize,
    /// Frame files (and their images) of an earlier, longer version of the animation that
    /// were removed so they cannot be rendered or encoded by mistake.
    pub removed: usize,
    pub fps: u32,
    /// Warnings about the base scene.
    pub warnings: Vec<Diagnostic>,
}

/// `anim generate`: reads the spec, writes the frames. `Err` holds every error found.
pub fn run_generate(args: &GenerateArgs) -> Result<GenerateReport, Vec<Diagnostic>> {
    let spec_path = args.spec.as_path();
    let bytes = std::fs::read(spec_path).map_err(|e| {
        vec![Diagnostic::file_error(
            spec_path,
            format!("cannot read the spec: {e}"),
        )]
    })?;
    let text = String::from_utf8(bytes).map_err(|_| {
        vec![Diagnostic::file_error(
            spec_path,
            "the spec is not UTF-8 text",
        )]
    })?;
    let src = Source::new(spec_path, text);
    let spec_file = spec::parse(&src).map_err(|d| vec![*d])?;
    let spec_dir = spec_path
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();

    let (statements, warnings) = load_base(&spec_file.scene, &spec_dir, &src)?;
    let base = BaseScene::new(statements);
    let anim = spec::validate(&spec_file, &base, &src)?;

    let dir = match (&args.out, &spec_file.frames_dir) {
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
    let texts = frame_texts(&base, &anim, &src, &dir)?;
    std::fs::create_dir_all(&dir).map_err(|e| {
        vec![Diagnostic::file_error(
            &dir,
            format!("cannot create the frame directory: {e}"),
        )]
    })?;
    let mut written = 0;
    for (i, text) in texts.iter().enumerate() {
        let path = dir.join(anim.output.sdf(i, anim.digits()));
        // Unchanged frames are left alone, so their files keep their identity for tools
        // that look at modification times.
        if std::fs::read(&path).ok().as_deref() == Some(text.as_bytes()) {
            continue;
        }
        write_atomically(&path, |w| w.write_all(text.as_bytes())).map_err(|e| {
            vec![Diagnostic::file_error(
                &path,
                format!("cannot write the frame: {e}"),
            )]
        })?;
        written += 1;
    }
    let removed = remove_stale(&dir, &anim).map_err(|e| {
        vec![Diagnostic::file_error(
            &dir,
            format!("cannot remove old frames: {e}"),
        )]
    })?;
    Ok(GenerateReport {
        dir,
        frames: anim.frames,
        written,
        removed,
        fps: anim.fps,
        warnings,
    })
}

/// `anim generate` as a command: prints warnings, errors and what was written.
pub fn generate_command(args: &GenerateArgs) -> ExitCode {
    match run_generate(args) {
        Ok(report) => {
            if !args.quiet {
                for w in &report.warnings {
                    eprintln!("{w}");
                }
                let length = format!(
                    "{} s at {} fps",
                    generate::tidy(report.frames as f64 / report.fps as f64),
                    report.fps
                );
                let mut line = if report.written == report.frames {
                    format!(
                        "wrote {} frames ({length}) to {}",
                        report.frames,
                        report.dir.display()
                    )
                } else {
                    format!(
                        "wrote {} of {} frames ({length}) to {}; the others were unchanged",
                        report.written,
                        report.frames,
                        report.dir.display()
                    )
                };
                if report.removed > 0 {
                    line += &format!(
                        "; removed {} file{} of frames past the end",
                        report.removed,
                        if report.removed == 1 { "" } else { "s" }
                    );
                }
                println!("{line}");
            }
            ExitCode::SUCCESS
        }
        Err(diags) => {
            let errors = diags.iter().filter(|d| d.is_error()).count();
            for d in &diags {
                if d.is_error() || !args.quiet {
                    eprintln!("{d}");
                }
            }
            eprintln!(
                "error: {} not generated: {errors} error{}",
                args.spec.display(),
                if errors == 1 { "" } else { "s" }
            );
            ExitCode::FAILURE
        }
    }
}

/// Parses the base scene. Errors stop generation; warnings are passed on.
fn load_base(
    scene: &SceneSource,
    spec_dir: &Path,
    src: &Source,
) -> Result<(Vec<crate::sdf::ast::Statement>, Vec<Diagnostic>), Vec<Diagnostic>> {
    let opts = LoadOptions::default();
    let (statements, mut diags, path) = match scene {
        SceneSource::File(rel) => {
            let path = spec_dir.join(rel);
            let bytes = std::fs::read(&path).map_err(|e| {
                vec![src.error(
                    &["scene[0]", "scene"],
                    format!("cannot read the base scene '{}': {e}", path.display()),
                )]
            })?;
            let (statements, diags) =
                crate::sdf::parse(&String::from_utf8_lossy(&bytes), &path, &opts);
            (statements, diags, path)
        }
        SceneSource::Inline(text) => {
            let (statements, diags) = crate::sdf::parse(text, &src.path, &opts);
            (statements, diags, src.path.to_path_buf())
        }
    };
    // Building the scene finds what parsing alone cannot (an unknown material, a composite
    // child defined nowhere), located in the base scene rather than in a generated frame.
    if !diags.iter().any(Diagnostic::is_error) {
        if let Err(built) = crate::sdf::build(&statements, &path, &opts) {
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

/// Every frame's text, each checked by loading it as the renderer will.
fn frame_texts(
    base: &BaseScene,
    anim: &Animation,
    src: &Source,
    dir: &Path,
) -> Result<Vec<String>, Vec<Diagnostic>> {
    let generator = Generator::new(base, anim, src);
    let opts = LoadOptions::default();
    let mut texts = Vec::with_capacity(anim.frames);
    for i in 0..anim.frames {
        let text = generator.frame_text(i).map_err(|d| vec![*d])?;
        let path: Arc<Path> = Arc::from(dir.join(anim.output.sdf(i, anim.digits())).as_path());
        if let Err(diags) = crate::sdf::load_str(&text, &path, &opts) {
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
        texts.push(text);
    }
    Ok(texts)
}

/// Removes frame files (`.sdf`, image and render record) numbered at or beyond the frame
/// count, or with a different number of digits: leftovers of an earlier version of the spec.
fn remove_stale(dir: &Path, anim: &Animation) -> std::io::Result<usize> {
    let digits = anim.digits();
    let image_ext = anim
        .output
        .suffix
        .rsplit_once('.')
        .map(|(_, e)| e)
        .unwrap_or("");
    let stem_suffix = anim.output.suffix_stem();
    let mut removed = 0;
    let mut names: Vec<String> = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok())
        .filter_map(|e| e.file_name().into_string().ok())
        .collect();
    names.sort();
    for name in names {
        let Some(rest) = name.strip_prefix(anim.output.prefix.as_str()) else {
            continue;
        };
        let num_len = rest.chars().take_while(char::is_ascii_digit).count();
        if num_len == 0 {
            continue;
        }
        let (num, tail) = rest.split_at(num_len);
        let is_frame_file =
            tail == format!("{stem_suffix}.sdf") || tail == format!("{stem_suffix}.{image_ext}");
        if !is_frame_file {
            continue;
        }
        let stale = num.len() != digits || num.parse::<usize>().map_or(true, |n| n >= anim.frames);
        if stale {
            std::fs::remove_file(dir.join(&name))?;
            if name.ends_with(".sdf") {
                let record = crate::pipeline::record_path(dir, &name);
                if record.exists() {
                    std::fs::remove_file(record)?;
                }
            }
            removed += 1;
        }
    }
    Ok(removed)
}
