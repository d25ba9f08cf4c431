//! `anim bench`: render time against image error, for anim and (when installed) POV-Ray.
//!
//! For every scene file of the bench folder a converged reference is rendered (uniform
//! sampling, cached by content), then each setting is rendered and timed and its 8-bit image
//! compared with the reference ([`metrics`]). POV-Ray's points ([`pov`]) are measured against
//! POV-Ray's own converged image, so each renderer is judged by how fast it approaches what it
//! would converge to. [`stress`] is the numerical stress table (`--stress`).
//!
//! The library takes a [`BenchConfig`] and returns values; it never prints. Lines describing
//! progress go to a callback, and [`write_outputs`] writes the CSV, Markdown and plots.

pub mod metrics;
mod plot;
pub mod pov;
pub mod rehit;
mod report;
pub mod stress;

pub use report::{markdown, write_outputs};

use anim_core::render::{self, film, RayCounts, RenderSettings};
use anim_core::scene::RenderJob;
use anim_core::sdf::LoadOptions;
use anim_core::util::Fnv64;
use cpu_time::ProcessTime;
use metrics::ErrorStats;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// How one anim image is sampled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Setting {
    /// The same number of samples in every pixel (a k×k grid when it is a square).
    Uniform(u32),
    /// Samples added per pixel until its estimated error falls below `error` (8-bit levels).
    Adaptive { error: f64 },
}

impl Setting {
    pub fn mode(&self) -> &'static str {
        match self {
            Setting::Uniform(_) => "uniform",
            Setting::Adaptive { .. } => "adaptive",
        }
    }

    pub fn label(&self) -> String {
        match self {
            Setting::Uniform(spp) => format!("{spp} spp"),
            Setting::Adaptive { error } => format!("error {error}"),
        }
    }
}

/// The one place a bench setting becomes renderer settings.
pub fn render_settings(
    setting: &Setting,
    width: u32,
    height: u32,
    max_depth: u32,
) -> RenderSettings {
    let base = RenderSettings {
        width: Some(width),
        height: Some(height),
        max_depth,
        ..RenderSettings::default()
    };
    match *setting {
        Setting::Uniform(spp) => RenderSettings {
            spp: Some(spp),
            ..base
        },
        Setting::Adaptive { error } => RenderSettings {
            error: Some(error as f32),
            ..base
        },
    }
}

/// How big a run is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preset {
    /// 640×360, every setting.
    Full,
    /// Small images and fewer settings: a couple of minutes on 2 cores.
    Quick,
    /// Tiny images, for the test suite.
    Tiny,
}

/// What POV-Ray points to add.
#[derive(Clone, Debug, PartialEq)]
pub enum PovMode {
    Off,
    /// With the converter scripts in this folder (`sdf2pov.py`, `povtonemap.py`).
    Tools(PathBuf),
}

#[derive(Clone, Debug, PartialEq)]
pub struct BenchConfig {
    /// Every `.sdf` file here is a bench scene, named by its file stem.
    pub scenes_dir: PathBuf,
    /// Only these scenes (by name); all when empty.
    pub only: Vec<String>,
    pub width: u32,
    pub height: u32,
    pub max_depth: u32,
    /// Samples per pixel of the converged reference (uniform).
    pub reference_spp: u32,
    pub settings: Vec<Setting>,
    pub pov: PovMode,
    /// POV-Ray anti-aliasing settings to time.
    pub pov_settings: Vec<pov::PovSetting>,
    /// Converged references are kept here between runs.
    pub cache_dir: PathBuf,
    /// Worker threads the renders run on (reported, and given to POV-Ray as `+WT`).
    pub threads: usize,
}

impl BenchConfig {
    pub fn preset(preset: Preset) -> BenchConfig {
        let (width, height, uniform, errors, pov_settings): (u32, u32, &[u32], &[f64], _) =
            match preset {
                Preset::Full => (
                    640,
                    360,
                    &[1, 4, 9, 16, 64],
                    &[8.0, 4.0, 2.0, 1.0, 0.5],
                    pov::standard_settings(),
                ),
                // 96×54 keeps a cold run (no cached references) under two minutes on two
                // cores: POV-Ray's converged +A0.0 +AM2 +R5 takes ~1 ms a pixel per pass.
                Preset::Quick => (
                    96,
                    54,
                    &[1, 4, 16, 64],
                    &[4.0, 2.0, 1.0],
                    pov::quick_settings(),
                ),
                Preset::Tiny => (48, 27, &[1, 4, 64], &[2.0], pov::quick_settings()),
            };
        let mut settings: Vec<Setting> = uniform.iter().map(|&s| Setting::Uniform(s)).collect();
        settings.extend(errors.iter().map(|&error| Setting::Adaptive { error }));
        BenchConfig {
            scenes_dir: PathBuf::from("scenes/bench"),
            only: Vec::new(),
            width,
            height,
            max_depth: RenderSettings::default().max_depth,
            reference_spp: 1024,
            settings,
            pov: PovMode::Tools(PathBuf::from("../shared/tools")),
            pov_settings,
            cache_dir: PathBuf::from("target/anim-bench-cache"),
            threads: rayon::current_num_threads(),
        }
    }
}

/// Which program made a row.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Renderer {
    Anim,
    PovRay,
}

impl Renderer {
    pub fn name(&self) -> &'static str {
        match self {
            Renderer::Anim => "anim",
            Renderer::PovRay => "povray",
        }
    }
}

/// One measured point: a scene rendered by one renderer at one setting.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub scene: String,
    pub renderer: Renderer,
    /// Sampling mode: a line in the plot.
    pub mode: String,
    pub setting: String,
    pub width: u32,
    pub height: u32,
    /// CPU time of the process (anim: around the render call; POV-Ray: the child process).
    pub cpu_s: f64,
    pub wall_s: f64,
    /// Rays traced, when the renderer says.
    pub rays: Option<u64>,
    /// Mean samples per pixel, when the renderer says.
    pub mean_spp: Option<f64>,
    pub error: ErrorStats,
}

/// How a scene's reference was obtained.
#[derive(Clone, Debug, PartialEq)]
pub struct Reference {
    pub renderer: Renderer,
    pub setting: String,
    /// Wall seconds it took to make; `None` when it came from the cache.
    pub wall_s: Option<f64>,
    pub path: PathBuf,
}

#[derive(Clone, Debug, PartialEq)]
pub struct SceneResult {
    pub name: String,
    pub file: PathBuf,
    pub references: Vec<Reference>,
}

/// Everything a bench run measured.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchReport {
    pub width: u32,
    pub height: u32,
    pub threads: usize,
    pub reference_spp: u32,
    pub scenes: Vec<SceneResult>,
    pub rows: Vec<Row>,
    /// Things a reader must know: skipped renderers or settings, and why.
    pub notes: Vec<String>,
    /// Per scene and adaptive setting: the per-pixel error estimate against the error
    /// measured against the reference (`calibration.tsv`).
    pub calibration: Vec<(String, String, Vec<metrics::CalibrationBin>)>,
}

/// A bench scene: its name, file, bytes (for the cache key) and first render job.
pub struct BenchScene {
    pub name: String,
    pub file: PathBuf,
    pub bytes: Vec<u8>,
    pub job: RenderJob,
}

/// Loads every `.sdf` file of `dir` (by name order), or only those named in `only`.
pub fn load_scenes(dir: &Path, only: &[String]) -> Result<Vec<BenchScene>, String> {
    let entries = std::fs::read_dir(dir)
        .map_err(|e| format!("cannot read the bench scenes folder {}: {e}", dir.display()))?;
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "sdf"))
        .collect();
    files.sort();
    let name_of = |p: &Path| {
        p.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    for wanted in only {
        if !files.iter().any(|f| &name_of(f) == wanted) {
            return Err(format!("no scene '{wanted}.sdf' in {}", dir.display()));
        }
    }
    let mut scenes = Vec::new();
    for file in files {
        let name = name_of(&file);
        if !only.is_empty() && !only.contains(&name) {
            continue;
        }
        let bytes =
            std::fs::read(&file).map_err(|e| format!("cannot read {}: {e}", file.display()))?;
        let loaded = anim_core::load::load_str(
            &String::from_utf8_lossy(&bytes),
            &file,
            &LoadOptions::default(),
        )
        .map_err(|d| {
            d.iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join("\n")
        })?;
        let job = loaded
            .jobs
            .into_iter()
            .next()
            .ok_or_else(|| format!("{} has no render statement", file.display()))?;
        scenes.push(BenchScene {
            name,
            file,
            bytes,
            job,
        });
    }
    if scenes.is_empty() {
        return Err(format!("no .sdf scenes in {}", dir.display()));
    }
    Ok(scenes)
}

/// The cache key of `parts` (a file's bytes, a renderer's version, its settings): std's
/// hasher may change between Rust releases, and the key only has to tell versions apart.
pub fn cache_key(parts: &[&[u8]]) -> u64 {
    let mut h = Fnv64::default();
    for part in parts {
        h.write_part(part);
    }
    h.finish()
}

/// An anim render's result with its cost.
pub struct Timed {
    pub rgb: Vec<u8>,
    pub hdr: render::HdrImage,
    /// Adaptive sampling's per-pixel error estimates (`Rendered::error_estimates`).
    pub error_estimates: Vec<f32>,
    pub rays: RayCounts,
    pub dropped: usize,
    pub cpu_s: f64,
    pub wall_s: f64,
}

/// Renders `job` and measures it: process CPU time (`cpu-time`'s `ProcessTime`, that is
/// `clock_gettime(CLOCK_PROCESS_CPUTIME_ID)`, all threads together) and wall time around the
/// render call alone; tone mapping is not counted.
pub fn render_measured(job: &RenderJob, settings: &RenderSettings) -> Result<Timed, String> {
    let cpu = ProcessTime::try_now().map_err(|e| format!("cannot read the CPU clock: {e}"))?;
    let wall = Instant::now();
    let r = render::render_job(job, settings, &|_| {})
        .map_err(|e| format!("camera '{}': {e:?}", job.camera.name))?;
    let wall_s = wall.elapsed().as_secs_f64();
    let cpu_s = cpu
        .try_elapsed()
        .map_err(|e| format!("cannot read the CPU clock: {e}"))?
        .as_secs_f64();
    Ok(Timed {
        rgb: film::to_rgb8(&r.image),
        hdr: r.image,
        error_estimates: r.error_estimates,
        rays: r.rays,
        dropped: r.dropped.len(),
        cpu_s,
        wall_s,
    })
}

/// Writes 8-bit RGB as binary PPM (the cache's format: no encoder, exact bytes).
fn write_ppm(path: &Path, rgb: &[u8], width: u32, height: u32) -> Result<(), String> {
    anim_core::util::write_atomically(path, |w| {
        use std::io::Write;
        write!(w, "P6\n{width} {height}\n255\n")?;
        w.write_all(rgb)
    })
    .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// Reads an image file (PPM or PNG) as 8-bit RGB; `None` if absent, unreadable or of
/// another size.
fn read_rgb8(path: &Path, width: u32, height: u32) -> Option<Vec<u8>> {
    let img = image::open(path).ok()?.into_rgb8();
    (img.width() == width && img.height() == height).then(|| img.into_raw())
}

/// The converged anim reference of a scene, from the cache or rendered (and cached).
fn anim_reference(
    scene: &BenchScene,
    config: &BenchConfig,
    progress: &mut dyn FnMut(&str),
) -> Result<(Vec<u8>, Reference), String> {
    let setting = Setting::Uniform(config.reference_spp);
    let key = cache_key(&[
        &scene.bytes,
        &config.width.to_le_bytes(),
        &config.height.to_le_bytes(),
        &config.reference_spp.to_le_bytes(),
        &config.max_depth.to_le_bytes(),
        env!("CARGO_PKG_VERSION").as_bytes(),
    ]);
    let path = config
        .cache_dir
        .join(format!("{}-anim-{key:016x}.ppm", scene.name));
    let mut reference = Reference {
        renderer: Renderer::Anim,
        setting: setting.label(),
        wall_s: None,
        path: path.clone(),
    };
    if let Some(rgb) = read_rgb8(&path, config.width, config.height) {
        progress(&format!(
            "{}: anim reference from cache {}",
            scene.name,
            path.display()
        ));
        return Ok((rgb, reference));
    }
    progress(&format!(
        "{}: rendering the anim reference ({}, {}×{})",
        scene.name,
        setting.label(),
        config.width,
        config.height
    ));
    let settings = render_settings(&setting, config.width, config.height, config.max_depth);
    let t = render_measured(&scene.job, &settings)?;
    write_ppm(&path, &t.rgb, config.width, config.height)?;
    reference.wall_s = Some(t.wall_s);
    Ok((t.rgb, reference))
}

/// Runs the time-against-error benchmark.
pub fn run(config: &BenchConfig, progress: &mut dyn FnMut(&str)) -> Result<BenchReport, String> {
    let scenes = load_scenes(&config.scenes_dir, &config.only)?;
    let mut notes = Vec::new();
    let pov_tools = match &config.pov {
        PovMode::Off => {
            notes.push("POV-Ray: not run (--no-pov).".into());
            None
        }
        PovMode::Tools(dir) => match pov::Tools::find(dir) {
            Ok(tools) => Some(tools),
            Err(why) => {
                notes.push(format!("POV-Ray: skipped, {why}."));
                progress(&format!("POV-Ray rows skipped: {why}"));
                None
            }
        },
    };
    let mut report = BenchReport {
        width: config.width,
        height: config.height,
        threads: config.threads,
        reference_spp: config.reference_spp,
        scenes: Vec::new(),
        rows: Vec::new(),
        notes,
        calibration: Vec::new(),
    };
    for scene in &scenes {
        let (reference, anim_ref) = anim_reference(scene, config, progress)?;
        let mut result = SceneResult {
            name: scene.name.clone(),
            file: scene.file.clone(),
            references: vec![anim_ref],
        };
        for setting in &config.settings {
            let settings = render_settings(setting, config.width, config.height, config.max_depth);
            let t = render_measured(&scene.job, &settings)?;
            let pixels = (config.width as f64) * (config.height as f64);
            let row = Row {
                scene: scene.name.clone(),
                renderer: Renderer::Anim,
                mode: setting.mode().to_string(),
                setting: setting.label(),
                width: config.width,
                height: config.height,
                cpu_s: t.cpu_s,
                wall_s: t.wall_s,
                rays: Some(t.rays.total()),
                mean_spp: Some(t.rays.primary as f64 / pixels),
                error: metrics::compare_rgb8(&t.rgb, &reference),
            };
            progress(&row_line(&row));
            if !t.error_estimates.is_empty() {
                let bins = metrics::calibration(&t.rgb, &reference, &t.error_estimates);
                progress(&format!(
                    "{}: {} estimated against measured error per pixel: {}",
                    scene.name,
                    setting.label(),
                    metrics::calibration_line(&bins)
                ));
                report
                    .calibration
                    .push((scene.name.clone(), setting.label(), bins));
            }
            report.rows.push(row);
        }
        if let Some(tools) = &pov_tools {
            match pov::measure_scene(tools, scene, config, progress) {
                Ok((pov_ref, rows)) => {
                    result.references.push(pov_ref);
                    report.rows.extend(rows);
                }
                // One scene POV-Ray cannot take (a converter limit) should not lose the rest.
                Err(e) => {
                    progress(&format!("{}: POV-Ray failed: {e}", scene.name));
                    report
                        .notes
                        .push(format!("POV-Ray: no rows for {}: {e}", scene.name));
                }
            }
        }
        report.scenes.push(result);
    }
    Ok(report)
}

/// One progress line for a measured row.
pub fn row_line(row: &Row) -> String {
    let mut s = format!(
        "{}: {} {} — {:.3} CPU s, {:.3} s, RMSE {:.3}",
        row.scene,
        row.renderer.name(),
        row.setting,
        row.cpu_s,
        row.wall_s,
        row.error.rmse
    );
    if let Some(spp) = row.mean_spp {
        let _ = write!(s, ", {spp:.2} spp");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_settings_map_to_sample_counts() {
        let s = render_settings(&Setting::Uniform(9), 64, 32, 5);
        assert_eq!(s.spp, Some(9));
        assert_eq!((s.width, s.height, s.max_depth), (Some(64), Some(32), 5));
    }

    #[test]
    fn adaptive_settings_map_to_an_error_target() {
        let s = render_settings(&Setting::Adaptive { error: 1.0 }, 8, 8, 8);
        assert_eq!((s.spp, s.error), (None, Some(1.0)));
    }

    #[test]
    fn cache_keys_separate_parts_and_are_stable() {
        assert_ne!(cache_key(&[b"ab", b"c"]), cache_key(&[b"a", b"bc"]));
        assert_eq!(cache_key(&[b"x"]), cache_key(&[b"x"]));
        assert_ne!(cache_key(&[b"x"]), cache_key(&[b"y"]));
    }
}
