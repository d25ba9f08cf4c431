//! `anim bench`: render time against image error, for anim and (when installed) POV-Ray.
//!
//! For every scene file of the bench folder a converged reference is rendered (uniform
//! sampling, cached by content), then each setting is rendered and timed and its 8-bit image
//! compared with the reference ([`metrics`]). POV-Ray's points ([`pov`]) are measured against
//! POV-Ray's own converged image, so each renderer is judged by how fast it approaches what it
//! would converge to. Each run may be timed several times, all runs of a scene in turn, and
//! anim either around its render call or as a whole `anim render` process, as POV-Ray is
//! ([`Clock`]). [`stress`] is the numerical stress table (`--stress`).
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
use std::process::Command;
use std::time::Instant;

/// How one anim image is sampled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Setting {
    /// The same number of samples in every pixel (a k×k grid when it is a square).
    Uniform(u32),
    /// Samples added per pixel until its estimated error falls below `error` (8-bit levels).
    Adaptive { error: f32 },
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

impl Setting {
    /// The options of `anim render` that ask for this setting: the command-line twin of
    /// [`render_settings`], held to it by the image check of [`Clock::Process`].
    fn render_flags(&self) -> [String; 2] {
        match self {
            Setting::Uniform(spp) => ["--spp".into(), spp.to_string()],
            Setting::Adaptive { error } => ["--error".into(), error.to_string()],
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
            error: Some(error),
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

/// How anim's time is taken.
#[derive(Clone, Debug, PartialEq)]
pub enum Clock {
    /// The CPU time of this process around the render call: tracing alone, without reading
    /// the file, building the scene or writing the image.
    RenderCall,
    /// The whole `anim render` process of this executable (reading, building, tracing,
    /// writing the image) under GNU time, as POV-Ray is timed: both renderers on one footing.
    /// Its image must be the one measured in this process.
    Process(PathBuf),
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
    /// Worker threads the renders run on (reported, given to POV-Ray as `+WT` and to a timed
    /// `anim render` process as `--threads`).
    pub threads: usize,
    /// Every run is timed this many times, all runs of a scene in turn (A B C A B C) so that
    /// each sees the same load, and each keeps the median of its turns.
    pub turns: usize,
    pub clock: Clock,
}

impl BenchConfig {
    pub fn preset(preset: Preset) -> BenchConfig {
        let (width, height, uniform, errors, pov_settings): (u32, u32, &[u32], &[f32], _) =
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
            turns: 1,
            clock: Clock::RenderCall,
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
    /// How many times each run was timed (its times are the median).
    pub turns: usize,
    /// Whether anim was timed as a whole process ([`Clock::Process`]).
    pub whole_process: bool,
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
    /// Render lines in the file: an `anim render` process renders them all.
    pub render_lines: usize,
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
        let render_lines = loaded.jobs.len();
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
            render_lines,
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

/// What one timed run cost: CPU seconds (every thread) and wall seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timing {
    pub cpu_s: f64,
    pub wall_s: f64,
}

/// The median of the turns of one run, CPU and wall time each (the lower middle of an even
/// count, so that it is a time that was measured).
pub fn median(turns: &[Timing]) -> Timing {
    let middle = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v.get(v.len().saturating_sub(1) / 2)
            .copied()
            .unwrap_or(f64::NAN)
    };
    Timing {
        cpu_s: middle(turns.iter().map(|t| t.cpu_s).collect()),
        wall_s: middle(turns.iter().map(|t| t.wall_s).collect()),
    }
}

/// GNU time, which reports a child process's CPU time (the standard library does not).
const TIME: &str = "/usr/bin/time";

/// The end of a failed program's messages, where the reason is.
fn last_lines(text: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(8)..].join(" | ")
}

/// Runs `cmd` to its end; its standard error, or why it failed.
fn run_child(cmd: &mut Command) -> Result<String, String> {
    let out = cmd
        .output()
        .map_err(|e| format!("cannot run {cmd:?}: {e}"))?;
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    if !out.status.success() {
        return Err(format!(
            "{:?} failed ({}): {}",
            cmd.get_program(),
            out.status,
            last_lines(&stderr)
        ));
    }
    Ok(stderr)
}

/// Runs `cmd` under GNU time, which writes its report to `report`: the child's standard error
/// and its cost, the CPU time being the whole process's (user + system).
fn timed_process(cmd: &Command, report: &Path) -> Result<(String, Timing), String> {
    let wall = Instant::now();
    let stderr = run_child(
        Command::new(TIME)
            .arg("-o")
            .arg(report)
            .args(["-f", "%U+%S"])
            .arg(cmd.get_program())
            .args(cmd.get_args()),
    )?;
    let wall_s = wall.elapsed().as_secs_f64();
    Ok((
        stderr,
        Timing {
            cpu_s: read_time(report)?,
            wall_s,
        },
    ))
}

/// Reads GNU time's `%U+%S` report (user + system seconds of the child).
fn read_time(path: &Path) -> Result<f64, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    let line = text
        .lines()
        .rev()
        .find(|l| l.contains('+'))
        .ok_or_else(|| format!("no time in {}", path.display()))?;
    let (u, s) = line.trim().split_once('+').unwrap_or((line, "0"));
    let parse = |x: &str| {
        x.trim()
            .parse::<f64>()
            .map_err(|_| format!("bad time '{line}' in {}", path.display()))
    };
    Ok(parse(u)? + parse(s)?)
}

/// A folder for one scene's intermediate files, in the cache folder, removed when dropped.
struct WorkDir(PathBuf);

impl WorkDir {
    fn new(config: &BenchConfig, what: &str, scene: &BenchScene) -> Result<WorkDir, String> {
        let dir =
            config
                .cache_dir
                .join(format!("{what}-work-{}-{}", std::process::id(), scene.name));
        std::fs::create_dir_all(&dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        Ok(WorkDir(dir))
    }
}

impl Drop for WorkDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Times `anim render` of `scene` at `setting` as a whole process of `exe`, its image written
/// into `work`. With `measured` (the image this process rendered at the setting), the
/// process's image must be the same, so that the work timed is the work measured; lossy
/// formats (JPEG) cannot be compared and are not.
fn time_anim_process(
    exe: &Path,
    scene: &BenchScene,
    setting: &Setting,
    config: &BenchConfig,
    work: &Path,
    measured: Option<&[u8]>,
) -> Result<Timing, String> {
    if scene.render_lines != 1 {
        return Err(format!(
            "{} has {} render lines; a timed `anim render` process renders them all, so \
             whole-process timing takes scenes of one",
            scene.file.display(),
            scene.render_lines
        ));
    }
    let mut cmd = Command::new(exe);
    cmd.arg("render")
        .arg(&scene.file)
        .arg("--out")
        .arg(work)
        .args(["--width", &config.width.to_string()])
        .args(["--height", &config.height.to_string()])
        .args(["--max-depth", &config.max_depth.to_string()])
        .args(["--threads", &config.threads.max(1).to_string()])
        .args(setting.render_flags())
        .arg("--quiet");
    let (_, timing) = timed_process(&cmd, &work.join("time.txt"))?;
    let image = work.join(scene.job.output.file_name().unwrap_or_default());
    let lossy = image
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("jpg") || e.eq_ignore_ascii_case("jpeg"));
    if let (Some(measured), false) = (measured, lossy) {
        if read_rgb8(&image, config.width, config.height).as_deref() != Some(measured) {
            return Err(format!(
                "{}: the timed `anim render` process ({}) drew another image than the \
                 measured render: {cmd:?}",
                scene.name,
                setting.label()
            ));
        }
    }
    Ok(timing)
}

/// Runs the time-against-error benchmark.
pub fn run(config: &BenchConfig, progress: &mut dyn FnMut(&str)) -> Result<BenchReport, String> {
    let scenes = load_scenes(&config.scenes_dir, &config.only)?;
    if matches!(config.clock, Clock::Process(_)) && !Path::new(TIME).is_file() {
        return Err(format!(
            "timing whole processes needs GNU time at {TIME} (Debian: apt-get install time)"
        ));
    }
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
        turns: config.turns.max(1),
        whole_process: matches!(config.clock, Clock::Process(_)),
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
        let pov = pov_tools.as_ref().and_then(|tools| {
            pov::Session::start(tools, scene, config, progress)
                .map_err(|e| pov_failed(&mut report, scene, &e, progress))
                .ok()
        });
        if let Some(session) = &pov {
            result.references.push(session.reference.clone());
        }
        scene_rows(scene, &reference, pov, config, &mut report, progress)?;
        report.scenes.push(result);
    }
    Ok(report)
}

/// Notes that POV-Ray could not measure `scene`: one scene POV-Ray cannot take (a converter
/// limit) should not lose the rest.
fn pov_failed(
    report: &mut BenchReport,
    scene: &BenchScene,
    e: &str,
    progress: &mut dyn FnMut(&str),
) {
    progress(&format!("{}: POV-Ray failed: {e}", scene.name));
    report
        .notes
        .push(format!("POV-Ray: no rows for {}: {e}", scene.name));
}

/// Measures anim at `setting` in this process: its row (error against `reference`, rays,
/// samples; times of this one render), its calibration, and its image.
fn measure_anim(
    scene: &BenchScene,
    setting: &Setting,
    reference: &[u8],
    config: &BenchConfig,
    report: &mut BenchReport,
    progress: &mut dyn FnMut(&str),
) -> Result<(Row, Vec<u8>), String> {
    let settings = render_settings(setting, config.width, config.height, config.max_depth);
    let t = render_measured(&scene.job, &settings)?;
    let pixels = f64::from(config.width) * f64::from(config.height);
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
        error: metrics::compare_rgb8(&t.rgb, reference),
    };
    if !t.error_estimates.is_empty() {
        let bins = metrics::calibration(&t.rgb, reference, &t.error_estimates);
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
    Ok((row, t.rgb))
}

/// One turn of anim at `setting`, by the configured clock. In the first turn `measured` is
/// the row just measured in this process and its image: its render is that turn's time around
/// the render call, and the image a timed process must draw.
fn time_anim(
    scene: &BenchScene,
    setting: &Setting,
    config: &BenchConfig,
    work: Option<&WorkDir>,
    measured: Option<(&Row, &[u8])>,
) -> Result<Timing, String> {
    if let (Clock::Process(exe), Some(work)) = (&config.clock, work) {
        let image = measured.map(|(_, rgb)| rgb);
        return time_anim_process(exe, scene, setting, config, &work.0, image);
    }
    if let Some((row, _)) = measured {
        return Ok(Timing {
            cpu_s: row.cpu_s,
            wall_s: row.wall_s,
        });
    }
    let settings = render_settings(setting, config.width, config.height, config.max_depth);
    let t = render_measured(&scene.job, &settings)?;
    Ok(Timing {
        cpu_s: t.cpu_s,
        wall_s: t.wall_s,
    })
}

/// One scene's rows: every anim setting and, with a POV-Ray session, every POV-Ray setting,
/// timed `config.turns` times. Each turn runs all of them once, in order, so that every run
/// sees the same load; a row keeps the median of its turns. The first turn also measures
/// anim's rows (error, rays, calibration) in this process.
fn scene_rows(
    scene: &BenchScene,
    reference: &[u8],
    mut pov: Option<pov::Session>,
    config: &BenchConfig,
    report: &mut BenchReport,
    progress: &mut dyn FnMut(&str),
) -> Result<(), String> {
    let turns = config.turns.max(1);
    let work = match &config.clock {
        Clock::Process(_) => Some(WorkDir::new(config, "anim", scene)?),
        Clock::RenderCall => None,
    };
    let mut rows: Vec<Row> = Vec::new();
    let mut times: Vec<Vec<Timing>> = vec![Vec::new(); config.settings.len()];
    let mut pov_times: Vec<Vec<Timing>> = vec![Vec::new(); config.pov_settings.len()];
    let mut pov_spp = vec![1.0; config.pov_settings.len()];
    for turn in 0..turns {
        if turns > 1 {
            progress(&format!("{}: turn {} of {turns}", scene.name, turn + 1));
        }
        for (i, setting) in config.settings.iter().enumerate() {
            let timing = if turn == 0 {
                let (row, rgb) = measure_anim(scene, setting, reference, config, report, progress)?;
                let timing = time_anim(scene, setting, config, work.as_ref(), Some((&row, &rgb)))?;
                rows.push(row);
                timing
            } else {
                time_anim(scene, setting, config, work.as_ref(), None)?
            };
            times[i].push(timing);
        }
        if let Some(session) = &pov {
            match session.time_all() {
                Ok(timed) => {
                    for (j, (timing, spp)) in timed.into_iter().enumerate() {
                        pov_times[j].push(timing);
                        pov_spp[j] = spp;
                    }
                }
                Err(e) => {
                    pov_failed(report, scene, &e, progress);
                    pov = None;
                }
            }
        }
    }
    for (mut row, turns) in rows.into_iter().zip(&times) {
        let m = median(turns);
        (row.cpu_s, row.wall_s) = (m.cpu_s, m.wall_s);
        progress(&row_line(&row));
        report.rows.push(row);
    }
    if let Some(session) = &pov {
        let timed = pov_times.iter().map(|t| median(t)).zip(pov_spp);
        match session.rows(timed) {
            Ok(rows) => {
                for row in &rows {
                    progress(&row_line(row));
                }
                report.rows.extend(rows);
            }
            Err(e) => pov_failed(report, scene, &e, progress),
        }
    }
    Ok(())
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
    fn a_setting_asks_anim_render_for_what_it_asks_the_renderer() {
        assert_eq!(Setting::Uniform(16).render_flags(), ["--spp", "16"]);
        let adaptive = Setting::Adaptive { error: 0.5 };
        assert_eq!(adaptive.render_flags(), ["--error", "0.5"]);
        assert_eq!(render_settings(&adaptive, 8, 8, 8).error, Some(0.5));
    }

    #[test]
    fn the_median_of_turns_is_a_time_one_turn_took() {
        let t = |cpu_s, wall_s| Timing { cpu_s, wall_s };
        let odd = [t(3.0, 0.1), t(1.0, 0.3), t(2.0, 0.2)];
        assert_eq!(median(&odd), t(2.0, 0.2));
        // CPU and wall are taken apart; of an even count, the lower middle.
        assert_eq!(median(&[t(4.0, 0.1), t(1.0, 0.4)]), t(1.0, 0.1));
        assert_eq!(median(&[t(5.0, 0.5)]), t(5.0, 0.5));
    }

    #[test]
    fn gnu_times_report_is_user_plus_system() {
        let dir = tempfile::tempdir().unwrap();
        let report = dir.path().join("time.txt");
        // A failing child makes GNU time write a line of its own before the figures.
        std::fs::write(
            &report,
            "Command exited with non-zero status 1\n0.52+0.25\n",
        )
        .unwrap();
        assert!((read_time(&report).unwrap() - 0.77).abs() < 1e-12);
        std::fs::write(&report, "no figures\n").unwrap();
        assert!(read_time(&report).is_err());
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
