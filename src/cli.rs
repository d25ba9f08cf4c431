//! Command-line definitions (clap derive), resolved into configuration before any work starts.

use crate::app::{CheckConfig, GenerateConfig, PreviewConfig, RenderConfig};
use anim_bench::pov::PovSetting;
use anim_bench::{BenchConfig, Clock, PovMode, Preset, Setting};
use anim_core::limits;
use anim_core::render::RenderSettings;
use anim_core::sdf::{LoadOptions, MaterialField, MaterialLayout, TransformOrder};
use anim_core::shape::MeshCache;
use anim_pipeline::frames::{FrameOptions, Shard};
use clap::{Args, Parser, Subcommand, ValueEnum};
use std::path::{Path, PathBuf};

#[derive(Parser, Debug)]
#[command(
    name = "anim",
    version,
    about = "Keyframe spec → SDF frames → ray-traced images → MP4"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render SDF scene files, or every .sdf file in a directory (frames in parallel).
    Render(RenderArgs),
    /// Parse and validate scene files without rendering; print every warning and error.
    Check(CheckArgs),
    /// Turn a RON keyframe spec into one SDF scene file per frame.
    Generate(GenerateArgs),
    /// Measure render time against image error on built-in scenes.
    Bench(BenchArgs),
    /// Show a keyframe spec (or one scene) in the browser: every frame small at once, then at
    /// full quality, following every edit of its files.
    Preview(PreviewArgs),
}

#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// Make every warning an error.
    #[arg(long)]
    pub strict: bool,
    /// Meaning of the numbers after `m` in material lines, in order
    /// (reflectivity, opacity, transparency, ior, roughness), or `auto`: the layout that
    /// makes every material of the file plausible (one warning says which was taken).
    #[arg(long, value_name = "LIST", default_value = "auto", value_parser = parse_material_fields, value_delimiter = ',')]
    pub material_fields: Vec<Option<MaterialField>>,
    /// How a transform statement composes with earlier ones: `world` (M ← T·M), `local`
    /// (M ← M·T), or `auto`: world, unless the file's images would be blank that way and not
    /// with cameras turned the course framework's way (opposite to shapes) or in the other
    /// order (one warning says which).
    #[arg(long, value_enum, default_value = "auto")]
    pub transform_order: TransformOrderArg,
    /// Largest scene file read, e.g. 512M or 2G (bytes without a unit); larger files are
    /// refused unread.
    #[arg(long, value_name = "BYTES", default_value_t = limits::DEFAULT_MAX_INPUT, value_parser = parse_bytes)]
    pub max_input: u64,
    /// Read meshes and included files wherever a scene names them; by default only files
    /// inside the scene's folder or the current directory are read.
    #[arg(long)]
    pub allow_any_input: bool,
    /// Memory a scene, and each image, may take while it is made, e.g. 512M or 8G (default:
    /// half of what the process may use: the machine's memory, or less under `ulimit -v` or a
    /// cgroup limit). Bigger scenes and images are refused before they are built, with the
    /// memory they would need.
    #[arg(long, value_name = "BYTES", value_parser = parse_bytes)]
    pub max_memory: Option<u64>,
}

#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    /// SDF files, or directories whose .sdf files are rendered as animation frames.
    #[arg(required = true, value_name = "FILE|DIR")]
    pub inputs: Vec<PathBuf>,
    /// Write images into DIR instead of beside each scene file.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Uniform sampling, N samples per pixel (k² gives a k×k stratified grid; 1 = one ray
    /// through the pixel centre). Overrides the render statement's own count. Without it,
    /// sampling is adaptive unless the render statement gives a count.
    #[arg(long, value_name = "N", value_parser = parse_samples)]
    pub spp: Option<u32>,
    /// Adaptive sampling: target error of each pixel that needs more than one sample, in
    /// 8-bit levels (default 2); a pixel blurred by the lens or in a soft shadow is held to a
    /// quarter of it. Given explicitly, it also overrides a render statement's sample count.
    #[arg(long, value_name = "E", value_parser = parse_error_target, conflicts_with = "spp")]
    pub error: Option<f32>,
    /// Adaptive sampling: most samples one pixel may take (default 32); a pixel blurred by
    /// the lens or in a soft shadow may take 4 times as many.
    #[arg(long, value_name = "N", value_parser = parse_samples, conflicts_with = "spp")]
    pub max_spp: Option<u32>,
    /// Worker threads (default: one per core). The output does not depend on it.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Override every render statement's image width.
    #[arg(long, value_name = "W", value_parser = parse_image_side)]
    pub width: Option<u32>,
    /// Override every render statement's image height.
    #[arg(long, value_name = "H", value_parser = parse_image_side)]
    pub height: Option<u32>,
    /// Maximum depth of reflected and refracted rays (at most 10000).
    #[arg(long, value_name = "N", default_value_t = limits::DEFAULT_MAX_DEPTH, value_parser = parse_max_depth)]
    pub max_depth: u32,
    /// Write .ppm files as ASCII (P3) instead of binary (P6).
    #[arg(long)]
    pub ppm_ascii: bool,
    /// Also write each image's linear radiance, before tone mapping, beside it as a PFM file
    /// (NAME.pfm: little-endian 32-bit floats, bottom row first).
    #[arg(long)]
    pub hdr: bool,
    /// Bits per channel: 8 or 16 for PNG (16: tone-mapped like the 8-bit image, or linear with
    /// --linear), 16 (half, the default) or 32 (float) for OpenEXR (.exr); other formats hold
    /// 8.
    #[arg(long, value_name = "BITS", value_parser = parse_depth)]
    pub depth: Option<u8>,
    /// Write linear radiance (clipped to [0, 1], marked by a gAMA chunk of 1.0) rather than the
    /// tone map's values: 16-bit PNG only; OpenEXR is always linear.
    #[arg(long)]
    pub linear: bool,
    /// Add an alpha channel: each pixel's coverage by geometry (a camera sample that hits
    /// nothing is transparent), without the background colour. Straight in PNG and TGA,
    /// premultiplied in OpenEXR.
    #[arg(long)]
    pub alpha: bool,
    /// Write images where render lines say even outside the scene's folder (or --out):
    /// absolute paths and paths climbing out with `..`.
    #[arg(long)]
    pub allow_any_output: bool,
    /// Render frames even if their input and settings are unchanged since the last run.
    #[arg(long)]
    pub force: bool,
    /// Render only the K-th of N contiguous runs of frames (in natural order, as even as can
    /// be): frames i of n (counting from 0) with ⌊i·N/n⌋ = K−1.
    #[arg(long, value_name = "K/N", value_parser = parse_shard)]
    pub shard: Option<Shard>,
    /// Render only frames A to B of a directory, both included, counting from 0 in natural
    /// order (for generated frames, the numbers in their names): `10..19`, `10..` (to the
    /// end), `..19`, or one frame `12`.
    #[arg(long, value_name = "A..B", value_parser = parse_frame_range)]
    pub frames: Option<(usize, usize)>,
    /// Render every frame of a directory in full. By default, the frames of a shot (in order,
    /// from a camera that holds still) trace again only the pixels whose rays may meet what
    /// changed since the frame before; the images are the same either way.
    #[arg(long)]
    pub no_incremental: bool,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
    #[command(flatten)]
    pub scene: SceneArgs,
}

#[derive(Args, Debug, Clone)]
pub struct CheckArgs {
    /// SDF files or directories (searched recursively for .sdf and .txt files).
    #[arg(required = true, value_name = "FILE|DIR")]
    pub inputs: Vec<PathBuf>,
    /// Print only errors and the summary.
    #[arg(short, long)]
    pub quiet: bool,
    /// Print a table: for each file, whether it renders, renders blank (and why) or is
    /// rejected (and why).
    #[arg(long)]
    pub summary: bool,
    #[command(flatten)]
    pub scene: SceneArgs,
}

#[derive(Args, Debug, Clone)]
pub struct GenerateArgs {
    /// The RON keyframe spec.
    pub spec: PathBuf,
    /// Output directory for the frame files (default: as the spec says, beside the spec).
    #[arg(short = 'o', long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
    /// Print the frame directory, alone, on stdout (the summary goes to stderr): for scripts
    /// that render what the spec generated, wherever its `frames_dir` puts it.
    #[arg(long)]
    pub print_dir: bool,
    /// Write each frame file whole, as a scene of its own, rather than including the part of
    /// the scene that no frame changes from static.sdfi in the frame directory.
    #[arg(long)]
    pub standalone: bool,
    /// Write only frames A to B, both included (`10..19`, `10..`, `..19` or `12`); every frame
    /// is still made and the static part is the whole animation's, so the frames written
    /// match those of a full run.
    #[arg(long, value_name = "A..B", value_parser = parse_frame_range)]
    pub frames: Option<(usize, usize)>,
}

#[derive(Args, Debug, Clone)]
pub struct PreviewArgs {
    /// The RON keyframe spec, or one SDF scene file.
    #[arg(value_name = "SPEC.ron|SCENE.sdf")]
    pub input: PathBuf,
    /// The port to listen on (default: a free one, printed at start).
    #[arg(long, default_value_t = 0)]
    pub port: u16,
    /// The address to listen on. Anything but 127.0.0.1 lets other machines see the preview.
    #[arg(long, value_name = "IP", default_value = "127.0.0.1")]
    pub host: std::net::IpAddr,
    /// Open the page in the system's browser.
    #[arg(long)]
    pub open: bool,
    /// Render every frame at full quality, encode them into this MP4 with ffmpeg and stop
    /// (no server). Checked first: its folder must exist, and it must not be a file the
    /// preview reads (the spec, its scene, includes, meshes).
    #[arg(long, value_name = "OUT.mp4")]
    pub export: Option<PathBuf>,
    /// Worker threads (default: one per core).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    #[command(flatten)]
    pub scene: SceneArgs,
}

#[derive(Args, Debug, Clone)]
pub struct BenchArgs {
    /// Write bench.csv, bench.md, calibration.tsv, one time-vs-error-SCENE.png per scene and one estimate-vs-error-SCENE.png per adaptively rendered scene here
    /// (stress.csv and stress.md with --stress).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Small images and fewer settings (a couple of minutes on 2 cores).
    #[arg(long)]
    pub quick: bool,
    /// Tiny images and the quick settings, for the test suite (overrides --quick).
    #[arg(long, hide = true)]
    pub tiny: bool,
    /// Instead of time against error: render the scenes scaled by 1e-4…1e5 and moved by
    /// 1e3…1e6 and compare each with the unchanged render.
    #[arg(long)]
    pub stress: bool,
    /// The bench scenes: every .sdf file in DIR [default: scenes/bench in the repository].
    #[arg(long, value_name = "DIR")]
    pub scenes: Option<PathBuf>,
    /// Only this scene (file stem; repeat for several).
    #[arg(long = "scene", value_name = "NAME")]
    pub only: Vec<String>,
    /// Converged reference images are cached here, keyed by scene content, size and version
    /// [default: target/anim-bench-cache in the repository].
    #[arg(long, value_name = "DIR")]
    pub cache: Option<PathBuf>,
    /// Folder with sdf2pov.py and povtonemap.py for POV-Ray's points
    /// [default: ../shared/tools from the repository].
    #[arg(long, value_name = "DIR")]
    pub pov_tools: Option<PathBuf>,
    /// Leave POV-Ray out even when it is installed.
    #[arg(long)]
    pub no_pov: bool,
    /// Image width (default 640; --quick 96).
    #[arg(long, value_name = "W", value_parser = parse_image_side)]
    pub width: Option<u32>,
    /// Image height (default 360; --quick 54).
    #[arg(long, value_name = "H", value_parser = parse_image_side)]
    pub height: Option<u32>,
    /// Samples per pixel of the converged anim reference.
    #[arg(long, value_name = "N", default_value_t = 1024, value_parser = parse_reference_samples)]
    pub reference_spp: u32,
    /// Uniform settings to measure, in samples per pixel (e.g. `--spp 1,16`). With --spp or
    /// --error, the settings measured are those given instead of the preset's.
    #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = parse_samples)]
    pub spp: Vec<u32>,
    /// Adaptive settings to measure, as error targets in 8-bit levels (e.g. `--error 2,3,4`).
    #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = parse_error_target)]
    pub error: Vec<f32>,
    /// A POV-Ray setting to time instead of the preset's (repeat for several): command-line
    /// flags, e.g. `--pov-setting "+A0.1 +AM2 +R3"`, and for scenes with spherical lights or a
    /// lens, how POV-Ray samples its area lights and focal blur: `area=N` (N×N grid, default 9),
    /// `adaptive=N` (area light's adaptive level; default off), `blur=N` (blur_samples, default
    /// 32), `confidence=X` (0.9), `variance=X` (1/128), e.g. `--pov-setting "-A area=9 adaptive=1"`.
    #[arg(long = "pov-setting", value_name = "FLAGS", value_parser = PovSetting::parse, allow_hyphen_values = true)]
    pub pov_settings: Vec<PovSetting>,
    /// Time every run N times, all runs of a scene in turn (A B A B), and keep each run's
    /// median.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100))]
    pub turns: u32,
    /// Time anim as a whole `anim render` process (reading, building, tracing, writing; GNU
    /// time), as POV-Ray is timed, instead of around its render call.
    #[arg(long)]
    pub whole_process: bool,
    /// Worker threads (default: one per core).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
}

/// The nearest folder from the current one up that holds `.git` (a folder, or a file in a
/// worktree); the current folder (as `.`) outside a repository.
fn repository_root() -> PathBuf {
    std::env::current_dir()
        .ok()
        .and_then(|cwd| {
            cwd.ancestors()
                .find(|d| d.join(".git").exists())
                .map(Path::to_path_buf)
        })
        .unwrap_or_else(|| PathBuf::from("."))
}

impl BenchArgs {
    /// The benchmark's configuration, for a pool of `--threads` workers (default: one per
    /// core, as the command layer's pool has).
    pub fn config(&self) -> BenchConfig {
        let threads = self.threads.map_or_else(
            || std::thread::available_parallelism().map_or(1, |n| n.get()),
            |n| n as usize,
        );
        let preset = if self.tiny {
            Preset::Tiny
        } else if self.quick {
            Preset::Quick
        } else {
            Preset::Full
        };
        let mut c = BenchConfig::preset(preset);
        // The defaults are paths in the repository, wherever in it the command runs.
        let root = repository_root();
        let or_default = |given: &Option<PathBuf>, default: &Path| {
            given.clone().unwrap_or_else(|| root.join(default))
        };
        c.scenes_dir = or_default(&self.scenes, &c.scenes_dir);
        c.cache_dir = or_default(&self.cache, &c.cache_dir);
        c.only = self.only.clone();
        c.pov = match (&c.pov, self.no_pov) {
            (_, true) => PovMode::Off,
            (PovMode::Tools(default), false) => {
                PovMode::Tools(or_default(&self.pov_tools, default))
            }
            (PovMode::Off, false) => PovMode::Off,
        };
        c.width = self.width.unwrap_or(c.width);
        c.height = self.height.unwrap_or(c.height);
        c.reference_spp = self.reference_spp;
        c.threads = threads;
        if !self.spp.is_empty() || !self.error.is_empty() {
            let uniform = self.spp.iter().map(|&spp| Setting::Uniform(spp));
            let adaptive = self.error.iter().map(|&error| Setting::Adaptive { error });
            c.settings = uniform.chain(adaptive).collect();
        }
        if !self.pov_settings.is_empty() {
            c.pov_settings = self.pov_settings.clone();
        }
        c.turns = self.turns as usize;
        if self.whole_process {
            // This very executable renders: the build measured is the build timed. Without a
            // path to it (no /proc), the `anim` on PATH, which the image check holds to this
            // one's images.
            let exe = std::env::current_exe().unwrap_or_else(|_| PathBuf::from("anim"));
            c.clock = Clock::Process(exe);
        }
        c
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TransformOrderArg {
    Auto,
    World,
    Local,
}

fn parse_error_target(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(e) if e.is_finite() && e > 0.0 => Ok(e),
        _ => Err(format!("'{s}' is not a positive number of 8-bit levels")),
    }
}

/// One entry of `--material-fields`; `None` is `auto`, which the loader reads as an empty
/// list (infer the layout per file).
pub fn parse_material_fields(s: &str) -> Result<Option<MaterialField>, String> {
    match s.trim() {
        "auto" => Ok(None),
        "reflectivity" => Ok(Some(MaterialField::Reflectivity)),
        "opacity" => Ok(Some(MaterialField::Opacity)),
        "transparency" => Ok(Some(MaterialField::Transparency)),
        "ior" => Ok(Some(MaterialField::Ior)),
        "roughness" => Ok(Some(MaterialField::Roughness)),
        other => Err(format!(
            "unknown material field '{other}' (expected auto, or a list from reflectivity, opacity, transparency, ior and roughness)"
        )),
    }
}

fn parse_shard(s: &str) -> Result<Shard, String> {
    s.parse()
}

/// `A..B` (both included), `A..`, `..B` or `N`: the first and last frame, counting from 0.
pub fn parse_frame_range(s: &str) -> Result<(usize, usize), String> {
    let number = |t: &str| {
        t.trim()
            .parse::<usize>()
            .map_err(|_| format!("'{t}' is not a frame number (frames count from 0)"))
    };
    let (first, last) = match s.split_once("..") {
        Some((a, b)) => (
            if a.trim().is_empty() { 0 } else { number(a)? },
            if b.trim().is_empty() {
                usize::MAX
            } else {
                number(b)?
            },
        ),
        None => (number(s)?, number(s)?),
    };
    if first > last {
        return Err(format!(
            "the range {s} is empty: write the first frame, then the last (A..B, both included)"
        ));
    }
    Ok((first, last))
}

/// A whole number within `range` (one of the value rules of `limits`).
fn whole_in(s: &str, range: std::ops::RangeInclusive<u32>) -> Result<u32, String> {
    let n: u32 = s
        .trim()
        .parse()
        .map_err(|_| format!("'{s}' is not a whole number"))?;
    if range.contains(&n) {
        Ok(n)
    } else {
        Err(format!("{n} is not in {}..={}", range.start(), range.end()))
    }
}

fn parse_samples(s: &str) -> Result<u32, String> {
    whole_in(s, limits::SAMPLES)
}

/// A converged reference takes at least 1024 samples, and no more than any render may.
fn parse_reference_samples(s: &str) -> Result<u32, String> {
    whole_in(s, 1024..=*limits::SAMPLES.end())
}

fn parse_image_side(s: &str) -> Result<u32, String> {
    whole_in(s, limits::IMAGE_SIDE)
}

fn parse_depth(s: &str) -> Result<u8, String> {
    match s.trim() {
        "8" => Ok(8),
        "16" => Ok(16),
        "32" => Ok(32),
        _ => Err(format!("'{s}' is not a channel depth: 8, 16 or 32")),
    }
}

fn parse_max_depth(s: &str) -> Result<u32, String> {
    whole_in(s, 0..=limits::MAX_DEPTH)
}

/// A byte count with an optional binary suffix: `4096`, `512K`, `512M`, `8G` (also `8GiB`),
/// up to `16E`, which stands for the largest count there is (one byte short of 16 EiB).
fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let digits = t.find(|c: char| !c.is_ascii_digit()).unwrap_or(t.len());
    let (number, unit) = t.split_at(digits);
    let n: u64 = number
        .parse()
        .map_err(|_| format!("'{s}' is not a size such as 512M or 8G"))?;
    let shift = match unit.trim().to_ascii_uppercase().as_str() {
        "" | "B" => 0,
        "K" | "KB" | "KIB" => 10,
        "M" | "MB" | "MIB" => 20,
        "G" | "GB" | "GIB" => 30,
        "T" | "TB" | "TIB" => 40,
        "P" | "PB" | "PIB" => 50,
        "E" | "EB" | "EIB" => 60,
        _ => return Err(format!("'{s}' is not a size such as 512M or 8G")),
    };
    let bytes = u128::from(n) << shift;
    match bytes {
        0 => Err(format!("'{s}' is not a size between 1 byte and 16 EiB")),
        b if b == 1u128 << 64 => Ok(u64::MAX),
        b => u64::try_from(b).map_err(|_| format!("'{s}' is not a size between 1 byte and 16 EiB")),
    }
}

impl RenderArgs {
    /// What the command line asks `anim render` to do.
    pub fn config(&self) -> RenderConfig {
        RenderConfig {
            inputs: self.inputs.clone(),
            settings: self.settings(),
            load: self.scene.load_options(),
            frames: FrameOptions {
                force: self.force,
                shard: self.shard,
                range: self.frames,
                no_incremental: self.no_incremental,
            },
            quiet: self.quiet,
        }
    }

    /// The settings that decide what the images look like and where they go.
    pub fn settings(&self) -> RenderSettings {
        RenderSettings {
            spp: self.spp,
            error: self.error,
            max_spp: self.max_spp,
            width: self.width,
            height: self.height,
            max_depth: self.max_depth,
            ppm_ascii: self.ppm_ascii,
            out_dir: self.out.clone(),
            allow_any_output: self.allow_any_output,
            max_memory: self.scene.max_memory(),
            hdr: self.hdr,
            depth: self.depth,
            linear: self.linear,
            alpha: self.alpha,
        }
    }
}

impl GenerateArgs {
    /// What the command line asks `anim generate` to do.
    pub fn config(&self) -> GenerateConfig {
        GenerateConfig {
            spec: self.spec.clone(),
            out: self.out.clone(),
            standalone: self.standalone,
            frames: self.frames,
        }
    }
}

impl PreviewArgs {
    /// What the command line asks `anim preview` to do.
    pub fn config(&self) -> PreviewConfig {
        PreviewConfig {
            input: self.input.clone(),
            addr: std::net::SocketAddr::new(self.host, self.port),
            open: self.open,
            export: self.export.clone(),
            load: self.scene.load_options(),
            settings: RenderSettings {
                max_memory: self.scene.max_memory(),
                ..RenderSettings::default()
            },
        }
    }
}

impl CheckArgs {
    /// What the command line asks `anim check` to do.
    pub fn config(&self) -> CheckConfig {
        CheckConfig {
            inputs: self.inputs.clone(),
            load: self.scene.load_options(),
            quiet: self.quiet,
            summary: self.summary,
        }
    }
}

impl SceneArgs {
    pub fn load_options(&self) -> LoadOptions {
        LoadOptions {
            strict: self.strict,
            // `auto` anywhere in the list means the whole list is inferred.
            material_fields: if self.material_fields.contains(&None) {
                MaterialLayout::Auto
            } else {
                MaterialLayout::Fields(self.material_fields.iter().flatten().copied().collect())
            },
            transform_order: match self.transform_order {
                TransformOrderArg::Auto | TransformOrderArg::World => TransformOrder::World,
                TransformOrderArg::Local => TransformOrder::Local,
            },
            infer_transform_order: self.transform_order == TransformOrderArg::Auto,
            max_input: self.max_input,
            allow_any_input: self.allow_any_input,
            max_memory: self.max_memory(),
            // One cache of each for the whole command: every frame it renders shares the
            // meshes and the included files.
            meshes: MeshCache::default(),
            includes: Default::default(),
        }
    }

    /// `--max-memory`, else the machine's default budget.
    pub fn max_memory(&self) -> u64 {
        self.max_memory
            .unwrap_or_else(limits::default_memory_budget)
    }
}
