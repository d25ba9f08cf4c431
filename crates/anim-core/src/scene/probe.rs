//! Never a silent blank image: before rendering, a coarse look through each job's camera
//! (32×18 primary rays for a 16:9 image, one shadow ray per light, a few mirror bounces) tells whether the
//! image would be all background or all black, and why.
//!
//! The probe lives in `scene` and uses only `shape`, `accel` and `math` (the layering forbids
//! `render` here), so it rebuilds the pinhole camera of `render::camera` (the same formula:
//! horizontal field of view, image plane at `(w/2)/tan(fov/2)` pixels) and intersects the
//! instances through its own hierarchy of their world bounds. It only has to be right about "nothing at all would show", so it
//! shades with Phong terms but without refraction. A quick look first sends a few of its rays
//! against every shape, without the hierarchy: when one of them surely shows something, that
//! is the probe's answer, and the hierarchy is never built.

use super::{load_file, Camera, Instance, Material, RenderJob, Scene};
use crate::accel::Bvh;
use crate::diag::{Diagnostic, Loc, Severity};
use crate::math::{reflect, spawn_ray, Aabb, Ray, Transform};
use crate::sdf::LoadOptions;
use crate::shape::{AaBox, Cone, Cylinder, Geometry, Plane, Shape, Sphere, Triangle};
use glam::{DVec3, Vec3, Vec3A};
use std::cell::Cell;
use std::path::Path;
use std::sync::Arc;

/// The probe's image width in rays (its height follows the image's aspect ratio: 18 for
/// 16:9): enough to see any object that covers a few percent of the image, at a cost far
/// below one real sample per pixel.
pub const PROBE_WIDTH: u32 = 32;

/// Shapes × primary rays beyond which the probe is skipped (about 35 000 shapes at 16:9). The
/// rays are cheap through the probe's hierarchy, but placing every shape (a copy of each, and
/// its bounds) is not: for a huge generated scene it would cost memory and time the render
/// needs, and the "nothing at all would show" question stays cheap to get wrong there.
const PROBE_BUDGET: usize = 20_000_000;

/// Mirror and see-through bounces the probe follows.
const PROBE_DEPTH: u32 = 4;

/// Below this a colour is black (8-bit output rounds it to 0).
const BLACK: f32 = 1.0 / 512.0;

/// Where the quick look ([`Probe::quick_content`]) sends its rays, as fractions of the
/// probe's rows and columns: spread over the image, off its centre lines (which, in a scene
/// of shapes on a grid, run along the gaps between them).
const QUICK_RAYS: [(f64, f64); 4] = [(0.45, 0.4), (0.3, 0.7), (0.7, 0.25), (0.2, 0.2)];

/// Shape tests the quick look may spend, per placed shape: about what placing the shapes
/// and building the hierarchy over them costs, so that a scene it cannot settle pays at most
/// twice.
const QUICK_TESTS_PER_SHAPE: usize = 16;

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
    pub reason: String,
}

/// A shape placed in the world, ready to intersect.
struct Placed<'s> {
    instance: &'s Instance,
    transform: &'s Transform,
    shape: Shape,
    material: &'s Material,
    /// Closed shapes have an inside a camera can be in.
    closed: bool,
}

/// A world-space hit.
struct Hit<'p, 's> {
    placed: &'p Placed<'s>,
    t: f32,
    point: Vec3A,
    /// Unit, facing the ray.
    normal: Vec3A,
    back_face: bool,
}

fn v(x: DVec3) -> Vec3A {
    Vec3A::from(x.as_vec3())
}

fn shape_of(g: &Geometry) -> Option<Shape> {
    match *g {
        Geometry::Sphere { center, radius } => {
            Sphere::new(v(center), radius as f32).map(Shape::Sphere)
        }
        Geometry::Box { p1, p2 } => AaBox::new(v(p1), v(p2)).map(Shape::Box),
        Geometry::Plane { point, normal } => Plane::new(v(point), v(normal)).map(Shape::Plane),
        Geometry::Triangle {
            vertices: [a, b, c],
        } => Triangle::new(v(a), v(b), v(c)).map(Shape::Triangle),
        Geometry::Cylinder { p1, p2, radius } => {
            Cylinder::new(v(p1), v(p2), radius as f32).map(Shape::Cylinder)
        }
        Geometry::Cone { base, tip, radius } => {
            Cone::new(v(base), v(tip), radius as f32).map(Shape::Cone)
        }
        Geometry::Mesh(ref m) => m.mesh().cloned().map(Shape::Mesh),
    }
}

/// The material draws nothing: fully transparent and not refracting. (Its reflectivity does
/// not help: the shading model weighs the mirror term by the opacity, `docs/shading.md`.)
fn invisible(m: &Material) -> bool {
    m.opacity <= 0.0 && (m.ior - 1.0).abs() < 1e-6
}

/// A mirror that shows only what it reflects.
fn perfect_mirror(m: &Material) -> bool {
    m.reflectivity * m.opacity >= 0.999
}

struct Probe<'s> {
    scene: &'s Scene,
    placed: Vec<Placed<'s>>,
    /// Over the placed shapes with finite bounds: without it every probe ray tests every
    /// shape, which on a scene of 10k spheres cost more than rendering it.
    bvh: Bvh,
    /// Placed shapes without finite bounds (planes), tested on every ray.
    unbounded: Vec<u32>,
    /// Whether `bvh` is built; until then every ray tests every shape (the quick look).
    indexed: bool,
    /// Set when the quick look met two shapes at the same distance (the hierarchy's order
    /// picks one of them, which it cannot know) or ran out of shape tests: its answer is
    /// then not used.
    unsure: Cell<bool>,
    /// Shape tests the quick look has left.
    tests_left: Cell<usize>,
}

/// World bounds of a placed shape (infinite for planes), widened by a relative margin so
/// that the f32 rounding of the object-space intersection never falls outside them.
fn world_bounds(shape: &Shape, xf: &Transform) -> Aabb {
    let local = shape.bounds();
    if !local.is_finite() {
        return local;
    }
    let b = Aabb::from_points(
        local
            .corners()
            .map(|c| v(xf.world_from_object.transform_point3(c.as_dvec3()))),
    );
    let margin = (b.extent() + b.min.abs().max(b.max.abs())) * 1e-5;
    Aabb::new(b.min - margin, b.max + margin)
}

impl<'s> Probe<'s> {
    /// The shapes placed, not yet indexed (see [`Probe::index`]).
    fn new(scene: &'s Scene) -> Self {
        let placed = scene
            .instances
            .iter()
            .filter_map(|instance| {
                let material = scene.materials.get(instance.material)?;
                let shape = shape_of(&instance.geometry)?;
                let closed = !matches!(
                    instance.geometry,
                    Geometry::Plane { .. } | Geometry::Triangle { .. } | Geometry::Mesh(_)
                );
                Some(Placed {
                    instance,
                    transform: scene.transform_of(instance),
                    shape,
                    material,
                    closed,
                })
            })
            .collect::<Vec<_>>();
        let tests = placed.len().saturating_mul(QUICK_TESTS_PER_SHAPE);
        Probe {
            scene,
            placed,
            bvh: Bvh::default(),
            unbounded: Vec::new(),
            indexed: false,
            unsure: Cell::new(false),
            tests_left: Cell::new(tests),
        }
    }

    /// Builds the hierarchy over the placed shapes' world bounds.
    fn index(&mut self) {
        let bounds: Vec<Aabb> = self
            .placed
            .iter()
            .map(|p| world_bounds(&p.shape, p.transform))
            .collect();
        let (bounded, unbounded): (Vec<u32>, Vec<u32>) =
            (0..self.placed.len() as u32).partition(|&i| bounds[i as usize].is_finite());
        self.bvh = Bvh::build(&bounds, bounded);
        self.unbounded = unbounded;
        self.indexed = true;
    }

    /// Whether one of a few rays ([`QUICK_RAYS`]) surely shows something, found by testing
    /// every shape on every ray, without a hierarchy: in a scene that shows something, most
    /// of the probe's time went into placing bounds and building the hierarchy for rays of
    /// which the first few already say so (grid10k: 36 M instructions). "Surely": every
    /// nearest hit on the way was the only one at its distance, which makes it the one the
    /// hierarchy finds, so the full probe would see the same on that ray. Meshes (whose own
    /// hierarchy picks among equally close triangles) are left to the full probe.
    fn quick_content(&self, rays: &[Ray]) -> bool {
        if self
            .placed
            .iter()
            .any(|p| matches!(p.shape, Shape::Mesh(_)))
        {
            return false;
        }
        let rows = rays.len() / PROBE_WIDTH as usize;
        QUICK_RAYS.iter().any(|&(fy, fx)| {
            let row = ((rows as f64 * fy) as usize).min(rows.saturating_sub(1));
            let col = ((f64::from(PROBE_WIDTH) * fx) as usize).min(PROBE_WIDTH as usize - 1);
            let Some(ray) = rays.get(row * PROBE_WIDTH as usize + col) else {
                return false;
            };
            self.unsure.set(false);
            let (seen, _) = self.trace(ray, 0);
            seen == Seen::Content && !self.unsure.get()
        })
    }

    /// The nearest hit with a shape that draws something, every shape tested in turn (see
    /// [`Probe::quick_content`]).
    fn nearest_of_all(&self, ray: &Ray, t_max: f32) -> Option<Hit<'_, 's>> {
        let left = self.tests_left.get();
        if left < self.placed.len() {
            self.unsure.set(true);
            return None;
        }
        self.tests_left.set(left - self.placed.len());
        let mut best: Option<Hit> = None;
        for i in 0..self.placed.len() as u32 {
            // A hit at the kept distance is found too, to be told apart.
            let limit = best.as_ref().map_or(t_max, |b| b.t.next_up());
            if let Some(h) = self.hit_of(i, ray, limit) {
                if best.as_ref().is_some_and(|b| b.t == h.t) {
                    self.unsure.set(true);
                } else {
                    best = Some(h);
                }
            }
        }
        best
    }

    /// The hit of placed shape `i` if it draws something and is met before `t_max`.
    fn hit_of(&self, i: u32, ray: &Ray, t_max: f32) -> Option<Hit<'_, 's>> {
        let p = &self.placed[i as usize];
        if invisible(p.material) {
            return None;
        }
        let xf = p.transform;
        let origin = xf.object_from_world.transform_point3(ray.origin.as_dvec3());
        let dir = xf.object_from_world.transform_vector3(ray.dir.as_dvec3());
        let h = p.shape.intersect(&Ray::new(v(origin), v(dir)), t_max)?;
        let n = (xf.normal_matrix() * h.normal.as_dvec3()).normalize_or_zero();
        let mut normal = v(n);
        let back_face = normal.dot(ray.dir) > 0.0;
        if back_face {
            normal = -normal;
        }
        Some(Hit {
            placed: p,
            t: h.t,
            point: ray.at(h.t),
            normal,
            back_face,
        })
    }

    /// The nearest hit with a shape that draws something.
    fn nearest(&self, ray: &Ray, t_max: f32) -> Option<Hit<'_, 's>> {
        if !self.indexed {
            return self.nearest_of_all(ray, t_max);
        }
        let mut best: Option<Hit> = None;
        for &i in &self.unbounded {
            let limit = best.as_ref().map_or(t_max, |b| b.t);
            if let Some(h) = self.hit_of(i, ray, limit) {
                best = Some(h);
            }
        }
        let limit = best.as_ref().map_or(t_max, |b| b.t);
        self.bvh.closest(ray, limit, |i, t_max| {
            let h = self.hit_of(i, ray, t_max)?;
            let t = h.t;
            best = Some(h);
            Some(t)
        });
        best
    }

    /// Ambient and direct light at a hit (shadows from opaque shapes included).
    fn direct(&self, hit: &Hit, view: Vec3A) -> Vec3 {
        let m = hit.placed.material;
        let mut c = self.scene.ambient * m.ka;
        for light in &self.scene.lights {
            let to_light = v(light.position) - hit.point;
            let dist = to_light.length();
            if dist <= 0.0 || light.intensity.max_element() <= 0.0 {
                continue;
            }
            let l = to_light / dist;
            let cos = hit.normal.dot(l);
            if cos <= 0.0 {
                continue;
            }
            let shadow = spawn_ray(hit.point, hit.normal, l);
            let blocked = self
                .nearest(&shadow, dist)
                .is_some_and(|b| b.placed.material.opacity >= 1.0);
            if blocked {
                continue;
            }
            let r = reflect(-l, hit.normal);
            let spec = r.dot(-view).max(0.0).powf(m.m.max(1.0));
            c += light.intensity * (m.kd * cos + m.ks * spec);
        }
        c
    }

    fn trace(&self, ray: &Ray, depth: u32) -> (Seen, Option<bool>) {
        let Some(hit) = self.nearest(ray, f32::INFINITY) else {
            return (Seen::Background, None);
        };
        let m = hit.placed.material;
        let back = Some(hit.back_face && hit.placed.closed);
        let view = ray.dir.normalize_or_zero();
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
            let (s, _) = self.trace(&spawn_ray(hit.point, hit.normal, dir), depth + 1);
            seen = combine(seen, s);
        }
        if m.opacity < 1.0 {
            let (s, _) = self.trace(&spawn_ray(hit.point, hit.normal, view), depth + 1);
            seen = combine(seen, s);
        }
        (seen, back)
    }
}

fn combine(a: Seen, b: Seen) -> Seen {
    match (a, b) {
        (Seen::Content, _) | (_, Seen::Content) => Seen::Content,
        (Seen::Background, _) | (_, Seen::Background) => Seen::Background,
        _ => Seen::Black,
    }
}

/// The probe's primary rays, as `render::camera` makes them for an image of `width` ×
/// `height`; `None` for a camera the renderer would refuse (reported elsewhere).
fn primary_rays(cam: &Camera, width: u32, height: u32) -> Option<Vec<Ray>> {
    let d = cam.dir.try_normalize()?;
    let r = d.cross(cam.up).try_normalize()?;
    let u = r.cross(d);
    // The image's own aspect ratio (the vertical field of view follows from it), on a grid
    // of PROBE_WIDTH columns.
    let aspect = f64::from(height.max(1)) / f64::from(width.max(1));
    let rows = ((f64::from(PROBE_WIDTH) * aspect).round() as u32).clamp(2, 2 * PROBE_WIDTH);
    let (w, h) = (f64::from(PROBE_WIDTH), f64::from(PROBE_WIDTH) * aspect);
    let dist = (w / 2.0) / (cam.fov_x_deg.to_radians() / 2.0).tan();
    let mut rays = Vec::new();
    // The outer rays go through the centres of the image's outer pixels: what lies beyond
    // them is never drawn.
    let (ex, ey) = (
        0.5 * w / f64::from(width.max(1)),
        0.5 * h / f64::from(height.max(1)),
    );
    for y in 0..rows {
        for x in 0..PROBE_WIDTH {
            let px = ex + f64::from(x) * (w - 2.0 * ex) / f64::from(PROBE_WIDTH - 1);
            let py = ey + f64::from(y) * (h - 2.0 * ey) / f64::from(rows - 1);
            let dir = d * dist + r * (px - w / 2.0) + u * (h / 2.0 - py);
            rays.push(Ray::new(v(cam.eye), v(dir.normalize())));
        }
    }
    Some(rays)
}

/// Whether the image of `job` would be blank, and why. `None` when something would show (or
/// the camera is one the renderer refuses, which it reports itself).
pub fn blank_image(job: &RenderJob) -> Option<Blank> {
    let scene = &job.scene;
    let blank = |reason: String| Some(Blank { reason });
    if scene.shape_count() == 0 {
        return blank("the scene has no shapes at all: the image is only the background".into());
    }
    if scene.has_prototypes() {
        // Composites drawn in many places: too many shapes to probe one by one.
        return None;
    }
    let rays = primary_rays(&job.camera, job.width, job.height)?;
    // Counted before the shapes are placed, so that a huge scene costs no memory here; the
    // count stops as soon as it is over the budget.
    let most = PROBE_BUDGET / rays.len().max(1);
    let over = scene
        .instances
        .iter()
        .filter(|i| scene.materials.get(i.material).is_some() && shape_of(&i.geometry).is_some())
        .nth(most)
        .is_some();
    if over {
        // Scenes this big are generated, and their images are rarely empty: the probe
        // stays cheap rather than exhaustive (the reasons above still apply).
        return None;
    }
    let mut probe = Probe::new(scene);
    if probe.quick_content(&rays) {
        return None;
    }
    probe.index();
    let mut seen = Vec::with_capacity(rays.len());
    for ray in &rays {
        seen.push(probe.trace(ray, 0));
    }
    if seen.iter().any(|(s, _)| *s == Seen::Content) {
        return None;
    }
    // Why: the reasons an author can act on, the most basic first.
    let visible: Vec<&Placed> = probe
        .placed
        .iter()
        .filter(|p| !invisible(p.material))
        .collect();
    let hits_any_geometry = rays.iter().any(|ray| {
        probe.placed.iter().any(|p| {
            let xf = p.transform;
            let o = xf.object_from_world.transform_point3(ray.origin.as_dvec3());
            let d = xf.object_from_world.transform_vector3(ray.dir.as_dvec3());
            p.shape
                .intersect(&Ray::new(v(o), v(d)), f32::INFINITY)
                .is_some()
        })
    });
    if hits_any_geometry && visible.is_empty() {
        let names = material_names(probe.placed.iter().map(|p| p.material));
        return blank(format!(
            "every material the camera could see is invisible (opacity 0, ior 1): {names}"
        ));
    }
    if !hits_any_geometry {
        let eye = job.camera.eye;
        let dir = job.camera.dir;
        let behind = probe.placed.iter().all(|p| {
            let b = p.shape.bounds();
            if !b.min.is_finite() || !b.max.is_finite() {
                return false;
            }
            let center = p.transform.point(((b.min + b.max) * 0.5).as_dvec3());
            (center - eye).dot(dir) < 0.0
        });
        return blank(if behind {
            format!(
                "every shape is behind camera `{}`: it looks along {} {} {}",
                job.camera.name, dir.x, dir.y, dir.z
            )
        } else {
            format!(
                "no shape is in the view of camera `{}` (all lie outside its field of view)",
                job.camera.name
            )
        });
    }
    if seen.iter().all(|(_, back)| *back == Some(true)) {
        let name = probe
            .nearest(&rays[rays.len() / 2], f32::INFINITY)
            .map_or(String::new(), |h| {
                format!(" `{}`", scene.instance_name(h.placed.instance))
            });
        return blank(format!(
            "the camera is inside an object{name}: every ray meets its inside, which no light reaches"
        ));
    }
    if visible.iter().all(|p| perfect_mirror(p.material)) {
        return blank(
            "every visible material is a perfect mirror (reflectivity 1) of an empty world: \
             the mirrors show only each other and the background"
                .into(),
        );
    }
    let lit = scene.lights.iter().any(|l| l.intensity.max_element() > 0.0);
    if !lit && scene.ambient.max_element() <= 0.0 {
        return blank(
            "the scene has no lights and no ambient light: every surface is black".into(),
        );
    }
    if !lit && visible.iter().all(|p| p.material.ka.max_element() <= 0.0) {
        return blank(
            "the scene has no lights, and the ambient light meets materials with Ka 0: every surface is black"
                .into(),
        );
    }
    blank("no light reaches the surfaces the camera sees: every one is in shadow or faces away from the lights".into())
}

fn material_names<'m>(materials: impl Iterator<Item = &'m Material>) -> String {
    let mut names: Vec<&str> = Vec::new();
    for m in materials {
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

/// One warning per job whose image would be blank, at its render line (or the file's first
/// line for the image of a file without one). Meant to be added to a loaded file's
/// diagnostics (`scene::load`).
pub fn blank_image_warnings(jobs: &[RenderJob], path: &Path) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for job in jobs {
        let Some(b) = blank_image(job) else { continue };
        let loc = job.loc.clone().unwrap_or_else(|| Loc {
            file: Arc::from(path),
            line: 1,
            col: 1,
        });
        let message = format!(
            "the image `{}` would be blank: {}",
            job.output.display(),
            b.reason
        );
        out.push(Diagnostic::new(Severity::Warning, loc, message));
    }
    out
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
    use crate::scene::load_str;

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

    fn quick(text: &str) -> bool {
        let opts = LoadOptions {
            material_fields: crate::sdf::MaterialLayout::standard(),
            ..LoadOptions::default()
        };
        let loaded = load_str(text, Path::new("probe.sdf"), &opts).unwrap();
        let job = &loaded.jobs[0];
        let rays = primary_rays(&job.camera, job.width, job.height).unwrap();
        Probe::new(&job.scene).quick_content(&rays)
    }

    /// The quick look answers for a lit sphere filling the view, and not where two shapes
    /// meet its rays at the same distance: which of them the full probe sees is its
    /// hierarchy's choice (here the black one would not show).
    #[test]
    fn quick_look_is_sure_or_silent() {
        let lit = format!("{MAT}define light l 0 5 0 1 1 1 1\n");
        let big = "define shape sphere s 0 0 -5 3 red\n";
        assert!(quick(&format!("{lit}{big}{CAM}")));
        let black = "define material black 0 0 0 0 0 0 0 0 0 20\n\
                     define shape sphere t 0 0 -5 3 black\n";
        assert!(!quick(&format!("{lit}{big}{black}{CAM}")));
        assert_eq!(probe(&format!("{lit}{big}{CAM}")), None);
    }

    #[test]
    fn no_shapes() {
        let text = format!("{MAT}define light l 0 5 0 1 1 1 1\n{CAM}");
        assert!(probe(&text).unwrap().contains("no shapes"));
    }
}
