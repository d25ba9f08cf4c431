//! Never a silent blank image: before rendering, a coarse look through each job's camera
//! (32×18 primary rays for a 16:9 image, one shadow ray per light, a few mirror bounces)
//! tells whether the image would be all background or all black, and why.
//!
//! The probe looks with the renderer's own camera (`render::camera`) and asks the renderer's
//! compiled scene (`render::compile`), so it sees what the render would: the same shapes,
//! placed the same way, camera-relative as the render places them. It only has to be right
//! about "nothing at all would show", so it shades with Phong terms but without refraction.

use super::load_file;
use crate::diag::{Diagnostic, Loc, Severity};
use crate::math::{reflect, Ray};
use crate::render::camera::PinholeCamera;
use crate::render::compile::{Occlusion, PrimId, RayHint, RenderScene, Scratch, SurfaceHit};
use crate::render::film::{tone_map_u8, HdrImage};
use crate::render::shading::ShadeMaterial;
use crate::render::Prepared;
use crate::scene::{Camera, RenderJob, Scene};
use crate::sdf::LoadOptions;
use glam::{Vec3, Vec3A};
use std::cell::RefCell;
use std::path::Path;
use std::sync::Arc;

/// The probe's image width in rays (its height follows the image's aspect ratio: 18 for
/// 16:9): enough to see any object that covers a few percent of the image, at a cost far
/// below one real sample per pixel.
pub const PROBE_WIDTH: u32 = 32;

/// Shapes × primary rays beyond which the probe is skipped (about 35 000 shapes at 16:9).
/// Placing every shape and building the hierarchy over them costs memory and time the
/// render needs, and the "nothing at all would show" question stays cheap to get wrong for a
/// huge generated scene.
const PROBE_BUDGET: usize = 20_000_000;

/// Mirror and see-through bounces the probe follows.
const PROBE_DEPTH: u32 = 4;

/// Invisible surfaces a probe ray steps through before it gives up.
const INVISIBLE_MAX: u32 = 16;

/// Below this a colour is black (8-bit output rounds it to 0).
const BLACK: f32 = 1.0 / 512.0;

/// What one probe ray sees.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Seen {
    /// Nothing: the background colour.
    Background,
    /// A surface that would be drawn black.
    Black,
    /// Something lit.
    Content,
}

/// Why an image would show nothing.
#[derive(Clone, Debug, PartialEq)]
pub struct Blank {
    /// Why, as a clause the author can act on ("the scene has no lights and no ambient light:
    /// every surface is black"); the warning quotes it after "would be blank:".
    pub reason: String,
}

/// A visible hit: the primitive, its surface, and whether the ray met the inside of a closed
/// shape.
struct Hit {
    prim: PrimId,
    surface: SurfaceHit,
    /// Unit normal, facing the ray.
    normal: Vec3A,
    inside: bool,
}

/// The material draws nothing: fully transparent and not refracting. (Its reflectivity does
/// not help: the shading model weighs the mirror term by the opacity, `docs/shading.md`.)
fn invisible(m: &ShadeMaterial) -> bool {
    m.opacity <= 0.0 && (m.ior - 1.0).abs() < 1e-6
}

/// A mirror that shows only what it reflects.
fn perfect_mirror(m: &ShadeMaterial) -> bool {
    m.reflectivity * m.opacity >= 0.999
}

/// A job's scene compiled as the render compiles it, and the probe's rays through its camera.
struct Probe<'p> {
    job: &'p RenderJob,
    /// The job's scene as the render places it (camera-relative).
    scene: &'p Scene,
    compiled: RenderScene,
    rays: Vec<Ray>,
    /// The probe's own scratch for its queries (its methods read, and only this changes).
    scratch: RefCell<Scratch>,
}

impl<'p> Probe<'p> {
    /// The probe of a prepared job; `None` for a camera the renderer refuses (it reports
    /// that itself).
    fn new(prepared: &'p Prepared) -> Option<Probe<'p>> {
        let job = prepared.job();
        let rays = primary_rays(prepared.camera(), job.width, job.height)?;
        Some(Probe {
            job,
            scene: prepared.scene(),
            compiled: prepared.compile(None),
            rays,
            scratch: RefCell::default(),
        })
    }

    fn material(&self, prim: PrimId) -> &ShadeMaterial {
        self.compiled.material(prim)
    }

    /// Every primitive's material.
    fn materials(&self) -> impl Iterator<Item = &ShadeMaterial> + '_ {
        (0..self.compiled.aggregate().len() as PrimId).map(|i| self.material(i))
    }

    /// The nearest hit along `ray` with a surface that draws something: invisible ones are
    /// stepped through.
    fn nearest(&self, ray: &Ray, t_max: f32) -> Option<Hit> {
        let mut ray = *ray;
        let mut left = t_max;
        for _ in 0..INVISIBLE_MAX {
            let (prim, surface) = self.compiled.intersect(
                &ray,
                left,
                RayHint::Secondary,
                &mut self.scratch.borrow_mut(),
            )?;
            if !invisible(self.material(prim)) {
                let inside = surface.normal.dot(ray.dir) > 0.0;
                let normal = if inside {
                    -surface.normal
                } else {
                    surface.normal
                };
                let closed = self.compiled.aggregate().is_closed(prim);
                return Some(Hit {
                    prim,
                    surface,
                    normal,
                    inside: inside && closed,
                });
            }
            left -= surface.t;
            ray = surface.spawn_ray(ray.dir);
        }
        None
    }

    /// Ambient and direct light at a hit (shadows from opaque shapes included).
    fn direct(&self, hit: &Hit, view: Vec3A) -> Vec3A {
        let m = self.material(hit.prim);
        let shading = self.compiled.shading();
        let mut c = shading.ambient * m.ka;
        for (k, light) in shading.lights.iter().enumerate() {
            let to_light = light.position - hit.surface.point;
            let dist = to_light.length();
            if dist <= 0.0 || light.intensity.max_element() <= 0.0 {
                continue;
            }
            let l = to_light / dist;
            let cos = hit.normal.dot(l);
            if cos <= 0.0 {
                continue;
            }
            let shadow = hit.surface.spawn_ray(l);
            let hint = RayHint::Shadow(k);
            let blocked =
                self.compiled
                    .occlusion(&shadow, dist, hint, &mut self.scratch.borrow_mut());
            if matches!(blocked, Occlusion::Blocked(_)) {
                continue;
            }
            let r = reflect(-l, hit.normal);
            let spec = r.dot(-view).max(0.0).powf(m.m.max(1.0));
            c += light.intensity * (m.kd * cos + m.ks * spec);
        }
        c
    }

    /// What a ray sees, and whether it met the inside of a closed shape first.
    fn trace(&self, ray: &Ray, depth: u32) -> (Seen, Option<bool>) {
        let Some(hit) = self.nearest(ray, f32::INFINITY) else {
            return (Seen::Background, None);
        };
        let m = self.material(hit.prim);
        let back = Some(hit.inside);
        let view = ray.dir;
        let local = self.direct(&hit, view) * (1.0 - m.reflectivity) * m.opacity;
        if local.max_element() > BLACK {
            return (Seen::Content, back);
        }
        if depth >= PROBE_DEPTH {
            return (Seen::Black, back);
        }
        let mut seen = Seen::Black;
        if m.reflectivity * m.opacity > 0.0 {
            let dir = reflect(view, hit.normal);
            let (s, _) = self.trace(&hit.surface.spawn_ray(dir), depth + 1);
            seen = combine(seen, s);
        }
        if m.opacity < 1.0 {
            let (s, _) = self.trace(&hit.surface.spawn_ray(view), depth + 1);
            seen = combine(seen, s);
        }
        (seen, back)
    }

    /// Why nothing shows, given what every ray saw: the reasons an author can act on, the
    /// most basic first.
    fn why(&self, seen: &[(Seen, Option<bool>)]) -> String {
        let camera = &self.job.camera;
        let any_hit = self.rays.iter().any(|ray| {
            let scene = &self.compiled;
            scene
                .intersect(
                    ray,
                    f32::INFINITY,
                    RayHint::Secondary,
                    &mut self.scratch.borrow_mut(),
                )
                .is_some()
        });
        if !any_hit {
            return if self.all_behind() {
                let d = camera.dir;
                format!(
                    "every shape is behind camera `{}`: it looks along {} {} {}",
                    camera.name, d.x, d.y, d.z
                )
            } else {
                format!(
                    "no shape is in the view of camera `{}` (all lie outside its field of view)",
                    camera.name
                )
            };
        }
        if self.materials().all(invisible) {
            let names = self.material_names();
            return format!(
                "every material the camera could see is invisible (opacity 0, ior 1): {names}"
            );
        }
        if seen.iter().all(|(_, back)| *back == Some(true)) {
            return self.inside_reason();
        }
        self.unlit_reason()
    }

    /// Whether every shape (all bounded) lies behind the eye, by its bounds' centre.
    fn all_behind(&self) -> bool {
        let geometry = self.compiled.aggregate();
        let dir = self.job.camera.dir.as_vec3();
        geometry.bounded() == geometry.len()
            && (0..geometry.len()).all(|i| {
                let b = geometry.bound(i);
                Vec3A::from(dir).dot((b.min + b.max) * 0.5) < 0.0
            })
    }

    /// The camera is inside an object: which one, as the middle ray meets it.
    fn inside_reason(&self) -> String {
        let name = self.middle_object_name();
        format!(
            "the camera is inside an object{name}: every ray meets its inside, which no light reaches"
        )
    }

    /// ` `name`` of the object the middle ray meets first, or nothing.
    fn middle_object_name(&self) -> String {
        let middle = &self.rays[self.rays.len() / 2];
        let geometry = self.compiled.aggregate();
        self.nearest(middle, f32::INFINITY)
            .and_then(|h| geometry.source(h.prim))
            .and_then(|k| self.scene.instances.get(k as usize))
            .map_or(String::new(), |inst| {
                format!(" `{}`", self.scene.instance_name(inst))
            })
    }

    /// Something shows, but nothing lit: mirrors of nothing, no light, or all in shadow.
    fn unlit_reason(&self) -> String {
        let shading = self.compiled.shading();
        if self
            .materials()
            .filter(|m| !invisible(m))
            .all(perfect_mirror)
        {
            return "every visible material is a perfect mirror (reflectivity 1) of an empty world: \
                    the mirrors show only each other and the background"
                .into();
        }
        let lit = shading
            .lights
            .iter()
            .any(|l| l.intensity.max_element() > 0.0);
        if !lit && shading.ambient.max_element() <= 0.0 {
            return "the scene has no lights and no ambient light: every surface is black".into();
        }
        let visible_ka = self
            .materials()
            .filter(|m| !invisible(m))
            .any(|m| m.ka.max_element() > 0.0);
        if !lit && !visible_ka {
            return "the scene has no lights, and the ambient light meets materials with Ka 0: every surface is black"
                .into();
        }
        "no light reaches the surfaces the camera sees: every one is in shadow or faces away from the lights".into()
    }

    /// The names of the materials the scene's shapes draw with, each once, in the order of
    /// the shapes.
    fn material_names(&self) -> String {
        let mut names: Vec<&str> = Vec::new();
        for inst in self.scene.instances.iter() {
            let Some(m) = self.scene.materials.get(inst.material) else {
                continue;
            };
            if !names.contains(&m.name.as_str()) {
                names.push(&m.name);
            }
        }
        names
            .iter()
            .map(|n| format!("`{n}`"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

fn combine(a: Seen, b: Seen) -> Seen {
    match (a, b) {
        (Seen::Content, _) | (_, Seen::Content) => Seen::Content,
        (Seen::Background, _) | (_, Seen::Background) => Seen::Background,
        _ => Seen::Black,
    }
}

/// The probe's primary rays through `camera` for an image of `width` × `height`, on a grid of
/// [`PROBE_WIDTH`] columns and rows in the image's aspect ratio. The outer rays go through the
/// centres of the image's outer pixels: what lies beyond them is never drawn. `None` for a
/// camera the renderer refuses.
fn primary_rays(camera: &Camera, width: u32, height: u32) -> Option<Vec<Ray>> {
    let (width, height) = (width.max(1), height.max(1));
    let camera = PinholeCamera::new(camera, width, height).ok()?;
    let rows = probe_rows(width, height);
    let along = |i: u32, n: u32, size: u32| {
        (0.5 + f64::from(i) * f64::from(size - 1) / f64::from(n - 1)) as f32
    };
    let mut rays = Vec::with_capacity((rows * PROBE_WIDTH) as usize);
    for y in 0..rows {
        for x in 0..PROBE_WIDTH {
            rays.push(camera.ray(along(x, PROBE_WIDTH, width), along(y, rows, height)));
        }
    }
    Some(rays)
}

/// Rows of the probe's grid of rays for an image of `width` × `height`.
fn probe_rows(width: u32, height: u32) -> u32 {
    let aspect = f64::from(height.max(1)) / f64::from(width.max(1));
    ((f64::from(PROBE_WIDTH) * aspect).round() as u32).clamp(2, 2 * PROBE_WIDTH)
}

/// Whether the image of `job` would be blank, and why. `None` when something would show (or
/// the camera is one the renderer refuses, which it reports itself).
pub fn blank_image(job: &RenderJob) -> Option<Blank> {
    match judged_without_a_look(job) {
        Some(answer) => answer,
        None => look(&Prepared::new(job)),
    }
}

/// [`blank_image`] of a job prepared for rendering (its geometry is not built again).
pub fn blank_image_of(prepared: &Prepared) -> Option<Blank> {
    match judged_without_a_look(prepared.job()) {
        Some(answer) => answer,
        None => look(prepared),
    }
}

/// What can be said of `job`'s image before its geometry is built, if anything.
fn judged_without_a_look(job: &RenderJob) -> Option<Option<Blank>> {
    let scene = &job.scene;
    if scene.shape_count() == 0 {
        let reason = "the scene has no shapes at all: the image is only the background";
        return Some(Some(Blank {
            reason: reason.into(),
        }));
    }
    // Composites drawn in many places: too many shapes to probe one by one. And a scene
    // this big is generated, and its images are rarely empty: the probe stays cheap rather
    // than exhaustive (counted before anything is placed, so it costs no memory).
    let rays = (PROBE_WIDTH * probe_rows(job.width, job.height)) as usize;
    (scene.has_prototypes() || scene.instances.len() > PROBE_BUDGET / rays).then_some(None)
}

/// The probe's look through the camera of a prepared job.
fn look(prepared: &Prepared) -> Option<Blank> {
    let probe = Probe::new(prepared)?;
    let seen: Vec<(Seen, Option<bool>)> = probe.rays.iter().map(|r| probe.trace(r, 0)).collect();
    if seen.iter().any(|(s, _)| *s == Seen::Content) {
        return None;
    }
    Some(Blank {
        reason: probe.why(&seen),
    })
}

/// One warning per job whose image would be blank, at its render line (or the file's first
/// line for the image of a file without one). Meant to be added to a loaded file's
/// diagnostics.
pub fn blank_image_warnings(jobs: &[RenderJob], path: &Path) -> Vec<Diagnostic> {
    jobs.iter()
        .filter_map(|job| Some(blank_warning(job, &blank_image(job)?, path)))
        .collect()
}

/// The warning that `job`'s image would be blank, for `blank`'s reason.
pub fn blank_warning(job: &RenderJob, blank: &Blank, path: &Path) -> Diagnostic {
    let what = format!("would be blank: {}", blank.reason);
    image_warning(job, &what, path)
}

/// A warning about `job`'s image (`the image `NAME` WHAT`), at its render line, or the
/// file's first line for the image of a file without one.
fn image_warning(job: &RenderJob, what: &str, path: &Path) -> Diagnostic {
    let loc = job.loc.clone().unwrap_or_else(|| Loc {
        file: Arc::from(path),
        line: 1,
        col: 1,
    });
    let message = format!("the image `{}` {what}", job.output.display());
    Diagnostic::new(Severity::Warning, loc, message)
}

/// Share of an image's pixels that one colour may cover before a person sees nothing in it.
pub const ONE_COLOUR_SHARE: f64 = 0.99;

/// The share of `image`'s pixels (as the 8-bit file holds them) that its most common colour
/// covers, when that is at least [`ONE_COLOUR_SHARE`]. Such a colour is one of nine pixels
/// spread over the image (corners, edge middles, centre): no more than 1 % of the pixels can
/// hide it from all nine, so one pass comparing with those nine finds it.
pub fn one_colour_share(image: &HdrImage) -> Option<f64> {
    let (w, h) = (image.width as usize, image.height as usize);
    let rgb = |p: Vec3| [tone_map_u8(p.x), tone_map_u8(p.y), tone_map_u8(p.z)];
    let mut candidates: Vec<[u8; 3]> = Vec::with_capacity(9);
    for y in [0, h / 2, h.saturating_sub(1)] {
        for x in [0, w / 2, w.saturating_sub(1)] {
            let c = rgb(*image.pixels.get(y * w + x)?);
            if !candidates.contains(&c) {
                candidates.push(c);
            }
        }
    }
    let mut counts = vec![0usize; candidates.len()];
    for &p in &image.pixels {
        let c = rgb(p);
        if let Some(k) = candidates.iter().position(|&d| d == c) {
            counts[k] += 1;
        }
    }
    let share = *counts.iter().max()? as f64 / image.pixels.len() as f64;
    (share >= ONE_COLOUR_SHARE).then_some(share)
}

/// Why the rendered `image` of a prepared job is one colour over nearly all of it, when it
/// is and the probe did not find it blank already (its warning says why then).
pub fn one_colour(prepared: &Prepared, image: &HdrImage) -> Option<(f64, String)> {
    let share = one_colour_share(image)?;
    let camera = &prepared.job().camera;
    if camera.fov_x_deg < NARROW_FOV_DEG {
        let reason = format!(
            "camera `{}` has a field of view of {}°, under {NARROW_FOV_DEG}° (radians? {} rad is {:.1}°)",
            camera.name,
            camera.fov_x_deg,
            camera.fov_x_deg,
            camera.fov_x_deg.to_degrees()
        );
        return Some((share, reason));
    }
    let probe = Probe::new(prepared)?;
    let hits: Vec<Option<Hit>> = probe
        .rays
        .iter()
        .map(|r| probe.nearest(r, f32::INFINITY))
        .collect();
    let covered = hits.iter().filter(|h| h.is_some()).count() as f64 / hits.len().max(1) as f64;
    let reason = if !hits.is_empty() && hits.iter().all(|h| h.as_ref().is_some_and(|h| h.inside)) {
        let name = probe.middle_object_name();
        format!("the camera is inside an object{name}, whose inside fills the view")
    } else if covered < 0.02 {
        format!(
            "the shapes in the view of camera `{}` cover almost none of it: they are small or far away",
            camera.name
        )
    } else if covered > 0.98 {
        format!("one surface fills the view of camera `{}`", camera.name)
    } else {
        "the shapes in view are drawn in the background's colour (unlit, or mirrors that show nothing)"
            .to_string()
    };
    Some((share, reason))
}

/// A field of view under this many degrees shows almost nothing of a scene.
const NARROW_FOV_DEG: f64 = 2.0;

/// The warning that `job`'s rendered image is one colour over `share` of its pixels.
pub fn one_colour_warning(job: &RenderJob, share: f64, reason: &str, path: &Path) -> Diagnostic {
    let what = format!(
        "is one colour over {:.1} % of its pixels: {reason}",
        share * 100.0
    );
    image_warning(job, &what, path)
}

/// How a file fares, for `anim check --summary`.
#[derive(Clone, Debug, PartialEq)]
pub enum Classification {
    /// Every image shows something.
    Renders,
    /// Some image would be blank; the reason is given (as a warning when loading).
    BlankExplained(String),
    /// The file is not rendered; the first error.
    Rejected(String),
}

/// Loads `path` and probes each of its images.
pub fn classify(path: &Path, opts: &LoadOptions) -> Classification {
    match load_file(path, opts) {
        Err(diagnostics) => {
            let first = diagnostics
                .iter()
                .find(|d| d.is_error())
                .map_or_else(|| "rejected".to_string(), |d| d.to_string());
            Classification::Rejected(first.lines().next().unwrap_or_default().to_string())
        }
        Ok(loaded) => match loaded.jobs.iter().find_map(blank_image) {
            Some(b) => Classification::BlankExplained(b.reason),
            None => Classification::Renders,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_share_of_the_most_common_colour_is_counted_exactly() {
        // 100 × 10 pixels of background with `n` lit ones in the middle row.
        let image = |n: usize| {
            let mut pixels = vec![Vec3::ZERO; 1000];
            for p in &mut pixels[500..500 + n] {
                *p = Vec3::ONE;
            }
            HdrImage {
                width: 100,
                height: 10,
                pixels,
            }
        };
        assert_eq!(one_colour_share(&image(0)), Some(1.0));
        assert_eq!(one_colour_share(&image(10)), Some(0.99));
        assert_eq!(one_colour_share(&image(11)), None);
    }
    use crate::load::load_str;

    fn probe(text: &str) -> Option<String> {
        // The materials here mean the standard layout, whatever inference would make of them.
        let opts = LoadOptions {
            material_fields: crate::sdf::MaterialLayout::standard(),
            ..LoadOptions::default()
        };
        let loaded =
            load_str(text, Path::new("probe.sdf"), &opts).unwrap_or_else(|d| panic!("{d:?}"));
        loaded.jobs.iter().find_map(blank_image).map(|b| b.reason)
    }

    const MAT: &str = "define material red 0.2 0 0 1 0 0 0.5 0.5 0.5 20\n";
    const CAM: &str = "define camera eye 60 0 0 0 0 0 -1 0 1 0\nrender eye out.png 64 36\n";

    #[test]
    fn a_lit_sphere_is_not_blank() {
        let text =
            format!("{MAT}define shape sphere s 0 0 -5 1 red\ndefine light l 0 5 0 1 1 1 1\n{CAM}");
        assert_eq!(probe(&text), None);
    }

    #[test]
    fn no_lights_and_no_ambient() {
        let text = format!("{MAT}define shape sphere s 0 0 -5 1 red\n{CAM}");
        assert!(probe(&text).unwrap().contains("no lights and no ambient"));
    }

    #[test]
    fn one_small_sphere_among_many_behind_the_camera_is_seen() {
        // Through the hierarchy: 2000 shapes behind the eye, one in front near the image's
        // corner; the probe must find that one, and say "behind" once it is moved back too.
        let mut text = format!("{MAT}define light l 0 5 0 1 1 1 1\n");
        for k in 0..2000 {
            let (x, y) = ((k % 50) as f64 - 25.0, (k / 50) as f64 - 20.0);
            text += &format!("define shape sphere b{k} {x} {y} 10 0.3 red\n");
        }
        let front = |z: f64| format!("define shape sphere f -2.5 1.2 {z} 0.4 red\n");
        assert_eq!(probe(&format!("{text}{}{CAM}", front(-6.0))), None);
        let reason = probe(&format!("{text}{}{CAM}", front(6.0))).unwrap();
        assert!(reason.contains("behind"), "{reason}");
    }

    #[test]
    fn every_shape_behind_the_camera() {
        let text =
            format!("{MAT}define shape sphere s 0 0 5 1 red\ndefine light l 0 5 0 1 1 1 1\n{CAM}");
        assert!(probe(&text).unwrap().contains("behind"));
    }

    #[test]
    fn camera_inside_a_sphere() {
        let text = format!(
            "{MAT}define shape sphere s 0 0 0 10 red\ndefine light l 0 50 0 1 1 1 1\n{CAM}"
        );
        assert!(probe(&text).unwrap().contains("inside"));
    }

    #[test]
    fn invisible_materials() {
        let text = "define material glass 0 0 0 0 0 0 0 0 0 10 0 0 1\n\
                    define shape sphere s 0 0 -5 1 glass\ndefine light l 0 5 0 1 1 1 1\n"
            .to_string()
            + CAM;
        assert!(probe(&text).unwrap().contains("invisible"));
    }

    #[test]
    fn a_lone_perfect_mirror() {
        let text = "define material m 0 0 0 0 0 0 0 0 0 10 1 1 1\n\
                    define shape sphere s 0 0 -5 1 m\ndefine light l 0 5 0 1 1 1 1\n"
            .to_string()
            + CAM;
        assert!(probe(&text).unwrap().contains("mirror"));
    }

    #[test]
    fn a_cone_off_axis_is_seen() {
        let text = "define material violet 0.3 0.0 0.6 0.5 0.0 0.8 0.1 0.0 0.3 1.0\n\
                    define shape cone c 2.0 4.0 -10 4.0 7.0 -5 2 violet\n\
                    define light spot 0 0 0 0.3 0.3 0.3 0.9 0.9 0.9\n\
                    define camera eye 45.0\nrender eye out.ppm 1000 800\n";
        assert_eq!(probe(text), None);
    }

    #[test]
    fn no_shapes() {
        let text = format!("{MAT}define light l 0 5 0 1 1 1 1\n{CAM}");
        assert!(probe(&text).unwrap().contains("no shapes"));
    }
}
