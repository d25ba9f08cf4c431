//! Command-line definitions (clap derive), resolved into configuration before any work starts.

use crate::render::RenderSettings;
use crate::sdf::{LoadOptions, MaterialField, TransformOrder};
use clap::{Args, Parser, Subcommand, ValueEnum};
use std::path::PathBuf;

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
}

#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// Make every warning an error.
    #[arg(long)]
    pub strict: bool,
    /// Meaning of the numbers after `m` in material lines, in order
    /// (reflectivity, opacity, transparency, ior, roughness).
    #[arg(long, value_name = "LIST", default_value = "reflectivity,opacity,ior", value_parser = parse_material_fields, value_delimiter = ',')]
    pub material_fields: Vec<MaterialField>,
    /// How a transform statement composes with earlier ones: `world` (M ← T·M, the
    /// default) or `local` (M ← M·T).
    #[arg(long, value_enum, default_value = "world")]
    pub transform_order: TransformOrderArg,
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
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub spp: Option<u32>,
    /// Adaptive sampling: target error of each pixel that needs more than one sample, in
    /// 8-bit levels (default 2). Given explicitly, it also overrides a render statement's
    /// sample count.
    #[arg(long, value_name = "E", value_parser = parse_error_target, conflicts_with = "spp")]
    pub error: Option<f32>,
    /// Adaptive sampling: most samples one pixel may take (default 32).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4096), conflicts_with = "spp")]
    pub max_spp: Option<u32>,
    /// Worker threads (default: one per core). The output does not depend on it.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Override every render statement's image width.
    #[arg(long, value_name = "W", value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub width: Option<u32>,
    /// Override every render statement's image height.
    #[arg(long, value_name = "H", value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub height: Option<u32>,
    /// Maximum depth of reflected and refracted rays.
    #[arg(long, value_name = "N", default_value_t = 8)]
    pub max_depth: u32,
    /// Write .ppm files as ASCII (P3) instead of binary (P6).
    #[arg(long)]
    pub ppm_ascii: bool,
    /// Render frames even if their input and settings are unchanged since the last run.
    #[arg(long)]
    pub force: bool,
    /// Render only frames i (counting from 0 in natural order) with i mod N = K−1.
    #[arg(long, value_name = "K/N", value_parser = parse_shard)]
    pub shard: Option<Shard>,
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
}

#[derive(Args, Debug, Clone)]
pub struct BenchArgs {
    /// Write the results as a Markdown table to this file as well as to stdout.
    #[arg(long, value_name = "FILE")]
    pub markdown: Option<PathBuf>,
    /// Image width for the benchmark renders.
    #[arg(long, default_value_t = 1920)]
    pub width: u32,
    /// Image height for the benchmark renders.
    #[arg(long, default_value_t = 1080)]
    pub height: u32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TransformOrderArg {
    World,
    Local,
}

/// One shard of an animation: K of N, K counting from 1 (as Slurm array task ids do).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: u32,
    pub count: u32,
}

impl Shard {
    /// Whether frame `i` (counting from 0) belongs to this shard.
    pub fn contains(&self, i: usize) -> bool {
        i % self.count as usize == (self.index - 1) as usize
    }
}

fn parse_shard(s: &str) -> Result<Shard, String> {
    let (k, n) = s.split_once('/').ok_or("expected K/N, e.g. 2/3")?;
    let index: u32 = k
        .trim()
        .parse()
        .map_err(|_| format!("'{k}' is not a whole number"))?;
    let count: u32 = n
        .trim()
        .parse()
        .map_err(|_| format!("'{n}' is not a whole number"))?;
    if count == 0 || index == 0 || index > count {
        return Err(format!("K must be between 1 and N (got {index}/{count})"));
    }
    Ok(Shard { index, count })
}

fn parse_error_target(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(e) if e.is_finite() && e > 0.0 => Ok(e),
        _ => Err(format!("'{s}' is not a positive number of 8-bit levels")),
    }
}

pub fn parse_material_fields(s: &str) -> Result<MaterialField, String> {
    match s.trim() {
        "reflectivity" => Ok(MaterialField::Reflectivity),
        "opacity" => Ok(MaterialField::Opacity),
        "transparency" => Ok(MaterialField::Transparency),
        "ior" => Ok(MaterialField::Ior),
        "roughness" => Ok(MaterialField::Roughness),
        other => Err(format!(
            "unknown material field '{other}' (expected reflectivity, opacity, transparency, ior or roughness)"
        )),
    }
}

impl RenderArgs {
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
        }
    }
}

impl SceneArgs {
    pub fn load_options(&self) -> LoadOptions {
        LoadOptions {
            strict: self.strict,
            material_fields: self.material_fields.clone(),
            transform_order: match self.transform_order {
                TransformOrderArg::World => TransformOrder::World,
                TransformOrderArg::Local => TransformOrder::Local,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_partition_the_frames() {
        let shards: Vec<Shard> = (1..=3)
            .map(|k| parse_shard(&format!("{k}/3")).unwrap())
            .collect();
        for i in 0..10 {
            assert_eq!(shards.iter().filter(|s| s.contains(i)).count(), 1);
        }
        assert!(parse_shard("0/3").is_err());
        assert!(parse_shard("4/3").is_err());
        assert!(parse_shard("1/0").is_err());
    }
}
