//! What is previewed: a keyframe spec turned into frame files by the pipeline's own
//! `run_generate` (into the preview's temporary folder), or one scene file; with the files an
//! edit of which changes the picture (the pipeline's `referenced_files`), and each frame's
//! fingerprint (the pipeline's `frame_hash`, which `anim render DIR`'s records hold).

use anim_core::diag::Diagnostic;
use anim_core::render::RenderSettings;
use anim_core::sdf::LoadOptions;
use anim_pipeline::frames::{frame_hash, list_frames, referenced_files, settings_fingerprint};
use anim_pipeline::keyframe::spec_file::{self, SceneSource, Source, SpecFile};
use anim_pipeline::keyframe::{run_generate, GenerateConfig};
use std::path::{Path, PathBuf};

/// One frame to render: its scene file and a fingerprint of everything that draws it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FrameSource {
    pub path: PathBuf,
    pub key: u64,
}

/// A successful build of the animation.
#[derive(Clone, Debug)]
pub struct Built {
    pub frames: Vec<FrameSource>,
    pub fps: f64,
    /// Times (seconds) of the spec's keys, for the timeline.
    pub keys: Vec<f64>,
    /// Warnings met on the way, as the terminal shows them.
    pub warnings: Vec<String>,
}

/// The previewed file, where its frames are generated, and how they are read and drawn.
#[derive(Clone, Debug)]
pub struct Project {
    pub input: PathBuf,
    pub frames_dir: PathBuf,
    pub load: LoadOptions,
    pub settings: RenderSettings,
}

impl Project {
    /// Whether the input is a keyframe spec (else a scene file).
    pub fn is_spec(&self) -> bool {
        self.input.extension().is_some_and(|e| e == "ron")
    }

    /// The files whose edits change the frames: the input, its base scene, the files that
    /// includes and the meshes they name. Files that cannot be read are still listed, so that
    /// creating them is seen.
    pub fn watched(&self) -> Vec<PathBuf> {
        let mut files = vec![self.input.clone()];
        let scene = if self.is_spec() {
            spec_scene(&self.input)
        } else {
            Some(self.input.clone())
        };
        if let Some(scene) = scene {
            files.extend(referenced_files(&scene, &self.load));
            files.push(scene);
        }
        files.sort();
        files.dedup();
        files
    }

    /// Generates the frames (for a spec) and fingerprints them. `Err` holds every diagnostic
    /// as the terminal prints it.
    pub fn build(&self) -> Result<Built, Vec<String>> {
        let text = |ds: Vec<Diagnostic>| ds.iter().map(ToString::to_string).collect();
        let fingerprint = settings_fingerprint(&self.settings, &self.load);
        // A frame's key is what `anim render DIR` records for it: the spec is not part of it,
        // as the frame texts say all it means.
        let key = |path: &Path, bytes: &[u8]| frame_hash(bytes, path, &fingerprint, &self.load);
        if !self.is_spec() {
            // Checked here, so that an error shows as the build's, with the last good frame.
            let loaded = anim_core::load::load_file(&self.input, &self.load).map_err(text)?;
            // Read as the loader reads (bounded, never waiting on a pipe): the file may have
            // been replaced since.
            let bytes = anim_core::load::read_input(&self.input, self.load.max_input, "file")
                .map_err(text)?;
            let key = key(&self.input, &bytes);
            return Ok(Built {
                frames: vec![FrameSource {
                    path: self.input.clone(),
                    key,
                }],
                fps: 1.0,
                keys: Vec::new(),
                warnings: text(loaded.diagnostics),
            });
        }
        let report = run_generate(&GenerateConfig {
            spec: self.input.clone(),
            out: Some(self.frames_dir.clone()),
            standalone: false,
            frames: None,
        })
        .map_err(text)?;
        let paths = list_frames(&report.dir)
            .map_err(|e| vec![format!("{}: error: {e}", report.dir.display())])?;
        let frames = paths
            .into_iter()
            .map(|path| {
                let bytes = anim_core::load::read_input(&path, self.load.max_input, "file");
                let key = key(&path, &bytes.unwrap_or_default());
                FrameSource { path, key }
            })
            .collect();
        let spec = read_spec(&self.input);
        Ok(Built {
            frames,
            fps: report.fps.as_f64(),
            keys: spec.as_ref().map(SpecFile::key_times).unwrap_or_default(),
            warnings: text(report.warnings),
        })
    }
}

fn read_spec(path: &Path) -> Option<SpecFile> {
    let src = Source::read(path, Source::MAX_BYTES).ok()?;
    spec_file::parse(&src).ok()
}

/// The base scene file a spec names, if it names one.
fn spec_scene(path: &Path) -> Option<PathBuf> {
    match read_spec(path)?.scene {
        SceneSource::File(rel) => Some(path.parent().unwrap_or(Path::new("")).join(rel)),
        SceneSource::Inline(_) => None,
    }
}
