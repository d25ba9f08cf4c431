//! `anim bench`: run time against image error. Speed is measured on the assignment's example
//! scene at the requested resolution; error (RMSE of 8-bit values) against a 256-sample
//! reference at a quarter of that size (so the reference stays cheap), on the assignment
//! scene and on the showcase.

use crate::cli::BenchArgs;
use crate::render::{self, film, HdrImage, RenderSettings};
use crate::scene;
use crate::scene::RenderJob;
use crate::sdf::LoadOptions;
use std::fmt::Write as _;
use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

/// The assignment's first example (SPEC.md §3).
pub const ASSIGNMENT_SCENE: &str = include_str!("../scenes/assignment.sdf");
/// Mirrors, glass and every primitive: where anti-aliasing and recursion cost something.
pub const SHOWCASE_SCENE: &str = include_str!("../scenes/showcase.sdf");

fn job_for(text: &str) -> Result<RenderJob, String> {
    let loaded = scene::load_str(
        text,
        Path::new("scenes/assignment.sdf"),
        &LoadOptions::default(),
    )
    .map_err(|d| {
        d.iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join("\n")
    })?;
    loaded
        .jobs
        .into_iter()
        .next()
        .ok_or_else(|| "the scene has no render statement".into())
}

fn render_timed(
    job: &RenderJob,
    width: u32,
    height: u32,
    spp: u32,
) -> Result<(HdrImage, f64, u64), String> {
    let settings = RenderSettings {
        spp: Some(spp),
        width: Some(width),
        height: Some(height),
        ..RenderSettings::default()
    };
    let start = Instant::now();
    let r = render::render_job(job, &settings, &|_| {}).map_err(|e| format!("{e:?}"))?;
    Ok((r.image, start.elapsed().as_secs_f64(), r.rays.total()))
}

/// Root-mean-square difference of the 8-bit images, in 8-bit steps.
pub fn rmse_u8(a: &HdrImage, b: &HdrImage) -> f64 {
    let (x, y) = (film::to_rgb8(a), film::to_rgb8(b));
    let sum: f64 = x
        .iter()
        .zip(&y)
        .map(|(&p, &q)| (p as f64 - q as f64).powi(2))
        .sum();
    (sum / x.len().max(1) as f64).sqrt()
}

pub fn run(args: &BenchArgs) -> ExitCode {
    match run_inner(args) {
        Ok(table) => {
            print!("{table}");
            if let Some(path) = &args.markdown {
                if let Err(e) = crate::util::write_atomically(path, |w| {
                    std::io::Write::write_all(w, table.as_bytes())
                }) {
                    eprintln!("error: cannot write {}: {e}", path.display());
                    return ExitCode::FAILURE;
                }
            }
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run_inner(args: &BenchArgs) -> Result<String, String> {
    let job = job_for(ASSIGNMENT_SCENE)?;
    let threads = rayon::current_num_threads();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "## Speed: assignment example, {}×{}, {threads} threads\n",
        args.width, args.height
    );
    let _ = writeln!(out, "| spp | render s | Mrays/s |\n|---:|---:|---:|");
    for spp in [1, 4, 16] {
        let (_, secs, rays) = render_timed(&job, args.width, args.height, spp)?;
        let _ = writeln!(
            out,
            "| {spp} | {secs:.3} | {:.1} |",
            rays as f64 / secs / 1e6
        );
    }
    let (w, h) = ((args.width / 4).max(1), (args.height / 4).max(1));
    for (name, text) in [
        ("assignment", ASSIGNMENT_SCENE),
        ("showcase", SHOWCASE_SCENE),
    ] {
        let job = job_for(text)?;
        let (reference, ref_secs, _) = render_timed(&job, w, h, 256)?;
        let _ = writeln!(
            out,
            "\n## Time against error: {name}, {w}×{h}, RMSE in 8-bit steps against 256 spp ({ref_secs:.2} s)\n"
        );
        let _ = writeln!(out, "| spp | render s | RMSE |\n|---:|---:|---:|");
        for spp in [1, 4, 9, 16, 64] {
            let (img, secs, _) = render_timed(&job, w, h, spp)?;
            let _ = writeln!(
                out,
                "| {spp} | {secs:.3} | {:.3} |",
                rmse_u8(&img, &reference)
            );
        }
    }
    Ok(out)
}
