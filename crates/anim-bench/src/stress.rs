//! `anim bench --stress`: the bench scenes scaled and moved far from the origin as a whole
//! (geometry, lights and camera together), rendered and compared with the unchanged render.
//! An exact renderer would draw the same image every time: light has no fall-off with
//! distance, so only floating-point precision can change a pixel.
//!
//! The change is applied to the loaded scene description, exactly as a transform on a root
//! composite plus the same transform on every camera and light would be: each instance's
//! world transform is premultiplied (so composite and shape transforms are kept), light
//! positions and the camera's eye, direction and up are mapped. The renderer then compiles it
//! to f32 as it does any scene, so every numerical path of a real file is exercised.

use super::rehit::{self, RehitCount};
use super::report::write_text;
use super::{load_scenes, render_measured, BenchConfig, BenchScene};
use anim_core::math::Transform;
use anim_core::render::RenderSettings;
use anim_core::scene::RenderJob;
use anim_core::shape::Shape;
use glam::DVec3;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One change of the whole scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Change {
    /// Uniform scale about the origin.
    Scale(f64),
    /// Translation by `(d, d, d)`.
    Translate(f64),
}

impl Change {
    pub fn label(&self) -> String {
        match self {
            Change::Scale(s) => format!("scale {s:e}"),
            Change::Translate(d) => format!("translate {d:e} (x, y, z)"),
        }
    }

    fn transform(&self) -> Transform {
        match *self {
            Change::Scale(s) => Transform::scale(DVec3::splat(s)).unwrap_or(Transform::IDENTITY),
            Change::Translate(d) => Transform::translate(DVec3::splat(d)),
        }
    }
}

/// The changes of the issue: five scales and three translations.
pub const CHANGES: [Change; 8] = [
    Change::Scale(1e-4),
    Change::Scale(1e-2),
    Change::Scale(1e2),
    Change::Scale(1e4),
    Change::Scale(1e5),
    Change::Translate(1e3),
    Change::Translate(1e5),
    Change::Translate(1e6),
];

/// `job` with the whole scene, camera and lights mapped by `t`.
pub fn transform_job(job: &RenderJob, t: &Transform) -> RenderJob {
    let mut out = job.clone();
    out.scene.transform_all(t);
    for light in &mut out.scene.lights {
        light.position = t.point(light.position);
    }
    out.camera.eye = t.point(job.camera.eye);
    out.camera.dir = t.vector(job.camera.dir);
    out.camera.up = t.vector(job.camera.up);
    out
}

#[derive(Clone, Debug, PartialEq)]
pub struct StressRow {
    pub scene: String,
    pub change: String,
    /// Pixels whose every channel is within 1 level of the unchanged render.
    pub pct_within_1lsb: f64,
    /// Pixels of the HDR buffer with a NaN or infinite channel.
    pub nonfinite: usize,
    /// Shapes left out because they became degenerate in f32.
    pub dropped: usize,
    pub cpu_s: f64,
    /// Rays spawned from surface hits and those that re-hit their own surface (`rehit`).
    pub spawned: u64,
    pub rehits: u64,
}

impl StressRow {
    pub fn rehits_per_million(&self) -> f64 {
        1e6 * self.rehits as f64 / self.spawned.max(1) as f64
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct StressReport {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub rows: Vec<StressRow>,
    /// Spawned rays and re-hits per primitive kind over every row.
    pub kinds: RehitCount,
}

/// Samples per pixel of the stress renders: one ray through each pixel centre, so a pixel
/// difference is one ray's difference, not averaged away.
pub const STRESS_SPP: u32 = 1;

fn nonfinite(hdr: &anim_core::render::HdrImage) -> usize {
    hdr.pixels.iter().filter(|p| !p.is_finite()).count()
}

fn within_1lsb(a: &[u8], b: &[u8]) -> f64 {
    let pixels = a.len() / 3;
    let close = a
        .chunks_exact(3)
        .zip(b.chunks_exact(3))
        .filter(|(p, q)| p.iter().zip(q.iter()).all(|(x, y)| x.abs_diff(*y) <= 1))
        .count();
    100.0 * close as f64 / pixels.max(1) as f64
}

/// Name of the built-in scene of every primitive kind scaled non-uniformly.
pub const ANISOTROPIC: &str = "anisotropic";
const ANISOTROPIC_SDF: &str = include_str!("anisotropic.sdf");

fn anisotropic_scene() -> Result<BenchScene, String> {
    let file = PathBuf::from("anisotropic.sdf (built in)");
    let job = anim_core::load::load_str(
        ANISOTROPIC_SDF,
        &file,
        &anim_core::sdf::LoadOptions::default(),
    )
    .map_err(|d| format!("the built-in stress scene does not load: {d:?}"))?
    .jobs
    .remove(0);
    Ok(BenchScene {
        name: ANISOTROPIC.into(),
        file,
        bytes: ANISOTROPIC_SDF.as_bytes().to_vec(),
        job,
        render_lines: 1,
    })
}

/// The bench scenes plus the built-in anisotropic one (all, or those named in `only`).
fn stress_scenes(config: &BenchConfig) -> Result<Vec<BenchScene>, String> {
    let from_files: Vec<String> = config
        .only
        .iter()
        .filter(|n| n.as_str() != ANISOTROPIC)
        .cloned()
        .collect();
    let mut scenes = if config.only.is_empty() || !from_files.is_empty() {
        load_scenes(&config.scenes_dir, &from_files)?
    } else {
        Vec::new()
    };
    if config.only.is_empty() || config.only.iter().any(|n| n == ANISOTROPIC) {
        scenes.push(anisotropic_scene()?);
    }
    Ok(scenes)
}

/// Re-hits of `job` rendered as the renderer renders it: camera-relative.
fn count_rehits(job: &RenderJob, settings: &RenderSettings) -> Result<RehitCount, String> {
    let (width, height, _) = settings.resolve(job);
    let relative = transform_job(job, &Transform::translate(-job.camera.eye));
    rehit::count(&relative, width, height, settings.max_depth)
}

pub fn run(config: &BenchConfig, progress: &mut dyn FnMut(&str)) -> Result<StressReport, String> {
    let scenes = stress_scenes(config)?;
    let mut kinds = RehitCount::default();
    let settings = RenderSettings {
        spp: Some(STRESS_SPP),
        width: Some(config.width),
        height: Some(config.height),
        max_depth: config.max_depth,
        ..RenderSettings::default()
    };
    let mut rows = Vec::new();
    for scene in &scenes {
        let base = render_measured(&scene.job, &settings)?;
        let base_rehits = count_rehits(&scene.job, &settings)?;
        kinds.add(&base_rehits);
        rows.push(StressRow {
            scene: scene.name.clone(),
            change: "none".into(),
            pct_within_1lsb: 100.0,
            nonfinite: nonfinite(&base.hdr),
            dropped: base.dropped,
            cpu_s: base.cpu_s,
            spawned: base_rehits.spawned(),
            rehits: base_rehits.rehits(),
        });
        for change in CHANGES {
            let job = transform_job(&scene.job, &change.transform());
            let t = render_measured(&job, &settings)?;
            let rehits = count_rehits(&job, &settings)?;
            kinds.add(&rehits);
            let row = StressRow {
                scene: scene.name.clone(),
                change: change.label(),
                pct_within_1lsb: within_1lsb(&t.rgb, &base.rgb),
                nonfinite: nonfinite(&t.hdr),
                dropped: t.dropped,
                cpu_s: t.cpu_s,
                spawned: rehits.spawned(),
                rehits: rehits.rehits(),
            };
            progress(&format!(
                "{}: {} — {:.2} % within 1 LSB, {} non-finite, {} dropped, {} re-hits in {} spawned rays",
                row.scene, row.change, row.pct_within_1lsb, row.nonfinite, row.dropped, row.rehits, row.spawned
            ));
            rows.push(row);
        }
    }
    Ok(StressReport {
        width: config.width,
        height: config.height,
        spp: STRESS_SPP,
        rows,
        kinds,
    })
}

pub const CSV_HEADER: &str =
    "scene,change,pct_within_1lsb,nonfinite_pixels,dropped_shapes,cpu_s,spawned_rays,rehits";

pub fn csv(report: &StressReport) -> String {
    let mut out = format!("{CSV_HEADER}\n");
    for r in &report.rows {
        let _ = writeln!(
            out,
            "{},{},{:.4},{},{},{:.6},{},{}",
            r.scene,
            r.change,
            r.pct_within_1lsb,
            r.nonfinite,
            r.dropped,
            r.cpu_s,
            r.spawned,
            r.rehits
        );
    }
    out
}

pub fn markdown(report: &StressReport) -> String {
    let mut out = format!(
        "# anim bench --stress: the whole scene scaled and moved\n\n{}×{}, {} spp. Each render is compared with the unchanged scene's (8-bit, after tone mapping). Non-finite: pixels of the HDR buffer with a NaN or infinite channel. Dropped: shapes degenerate in f32 once transformed, left out. Spawned: rays leaving a surface hit of a walk over the pixel centres (shadow, mirror, refracted and two random directions per hit, to the depth limit); re-hits: those meeting the primitive they left where exact arithmetic cannot (again, after leaving a flat or convex shape outwards; entering it, after leaving inwards), per million spawned.\n\n| scene | change | % within 1 LSB | non-finite | dropped | spawned | re-hits per M | CPU s |\n|---|---|---:|---:|---:|---:|---:|---:|\n",
        report.width, report.height, report.spp
    );
    for r in &report.rows {
        let _ = writeln!(
            out,
            "| {} | {} | {:.2} | {} | {} | {} | {:.2} | {:.3} |",
            r.scene,
            r.change,
            r.pct_within_1lsb,
            r.nonfinite,
            r.dropped,
            r.spawned,
            r.rehits_per_million(),
            r.cpu_s
        );
    }
    out.push_str("\nSpawned rays and re-hits per primitive kind, all rows together:\n\n| primitive | spawned | re-hits |\n|---|---:|---:|\n");
    for (name, (spawned, rehits)) in Shape::KINDS.iter().zip(report.kinds.by_kind.iter()) {
        let _ = writeln!(out, "| {name} | {spawned} | {rehits} |");
    }
    out
}

/// Writes `stress.csv` and `stress.md` into `dir`.
pub fn write_outputs(report: &StressReport, dir: &Path) -> Result<Vec<PathBuf>, String> {
    let mut written = Vec::new();
    for (name, text) in [("stress.csv", csv(report)), ("stress.md", markdown(report))] {
        let path = dir.join(name);
        write_text(&path, &text)?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;
    use anim_core::load::load_str;
    use anim_core::sdf::LoadOptions;

    #[test]
    fn within_1lsb_counts_pixels() {
        let a = [0, 0, 0, 10, 10, 10];
        let b = [1, 1, 1, 10, 12, 10];
        assert_eq!(within_1lsb(&a, &b), 50.0);
    }

    #[test]
    fn whole_scene_transform_keeps_the_picture() {
        let text = "define material m 0.2 0.2 0.2 0.6 0.6 0.6 0.2 0.2 0.2 10\n\
            define shape sphere s 0 0 -5 1 m\n\
            define light l 3 3 0 1 1 1 1\n\
            define camera c 60\n\
            render c x.png 24 16\n";
        let job = load_str(text, Path::new("t.sdf"), &LoadOptions::default())
            .unwrap()
            .jobs
            .remove(0);
        let moved = transform_job(&job, &Change::Translate(10.0).transform());
        assert_eq!(moved.camera.eye, DVec3::splat(10.0));
        assert_eq!(moved.scene.lights[0].position, DVec3::new(13.0, 13.0, 10.0));
        let settings = RenderSettings {
            spp: Some(1),
            ..RenderSettings::default()
        };
        let a = render_measured(&job, &settings).unwrap();
        let b = render_measured(&moved, &settings).unwrap();
        assert_eq!(within_1lsb(&a.rgb, &b.rgb), 100.0);
        assert_eq!(nonfinite(&b.hdr), 0);
    }
}
