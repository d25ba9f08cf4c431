//! A shot: frames rendered one after another from one camera that holds still, each traced
//! only where it may differ from the frame before (Jevans 1992, "Object space temporal
//! coherence for ray tracing", with the later frames known in advance).
//!
//! What one frame changes from the one before ([`changes`]) is the boxes where a shape
//! changed (its bounds in both frames, camera-relative as rendered, swept over the exposure
//! where it moves), the materials whose shading changed, whether a light or the ambient
//! light changed, and whether the background did; a change of the camera, the image's size
//! or sampling, or of anything every pixel reads (the bound shading stops rays by, which
//! materials let light through, how the moving shapes are asked) changes everything, and
//! starts a new shot. A frame is traced watching every ray against what the shot's later
//! frames change (`super::footprint`); the next frame traces again only the pixels whose
//! footprint it reaches, and the pixels adaptive sampling decides from those
//! (`super::sampler`), and takes the others from the frame before. Every pixel is what a
//! render of the frame alone gives, to the bit: a pixel whose rays meet nothing that
//! changed asks the same questions and gets the same answers.

use super::footprint::{Ahead, Changed};
use super::geometry::placed_bounds;
use super::policy::{MOVING_BLOCKS_MAX, RETRACED_SHARE_MAX};
use super::sampler::{self, Kept};
use super::shading::max_radiance;
use super::{rebased, trace_frame, Prepared, RenderSettings, Rendered};
use crate::render::camera::CameraError;
use crate::scene::{Instance, RenderJob, Scene};
use std::sync::Arc;

/// The frames of a shot rendered so far, and what the later ones change.
pub struct Shot {
    /// `later[k]`: what frame `k + 1` of the shot changes from frame `k`.
    later: Vec<Changed>,
    /// The number of the next frame to render.
    next: u32,
    /// What the last frame rendered keeps for the next, with its job and settings.
    kept: Option<(Kept, RenderJob, RenderSettings)>,
    /// How many of the next frames are rendered as alone, and how many the next time a
    /// frame traces again more than `policy::RETRACED_SHARE_MAX` of its pixels (doubling
    /// while frames do, one again when a frame does not).
    alone: (u32, u32),
}

/// One frame of a shot, rendered.
pub struct ShotFrame {
    /// The frame, as a render of it alone gives it.
    pub rendered: Rendered,
    /// Pixels traced again (every pixel of the shot's first frame).
    pub retraced: u64,
    /// Whether the frame was traced from the frame before (not the shot's first, nor one
    /// traced in full because it did not follow as told).
    pub follows: bool,
}

impl Shot {
    /// A shot whose frame `k + 1` changes what `later[k]` says from frame `k`.
    pub fn new(later: Vec<Changed>) -> Shot {
        Shot {
            later,
            next: 0,
            kept: None,
            alone: (0, 1),
        }
    }

    /// Renders the shot's next frame (`prepared`: its job made ready), tracing again only
    /// what may differ from the frame before. `on_pixels(n)` is called as each band of `n`
    /// pixels is done. A frame that does not change from the one before what the shot was
    /// told it changes (its file was edited since, say) is traced in full, and so is every
    /// frame after a failed one.
    ///
    /// Where a frame traced again nearly all its pixels, watching its rays cost more than it
    /// saved, and the next frames are likely to do the same: they are rendered as alone,
    /// without watching, and the one after them starts over, watching
    /// (`policy::RETRACED_SHARE_MAX`). One frame the first time, twice as many each time
    /// the frame that starts over does the same again: a shot whose every frame changes
    /// nearly everything pays for watching a few frames only, one that changed much for a
    /// moment soon traces only what changed again.
    pub fn render(
        &mut self,
        prepared: &Prepared,
        settings: &RenderSettings,
        on_pixels: &(dyn Fn(u64) + Sync),
    ) -> Result<ShotFrame, CameraError> {
        let at = self.next;
        self.next += 1;
        if self.alone.0 > 0 {
            self.alone.0 -= 1;
            self.kept = None;
            let rendered = super::render_prepared(prepared, settings, on_pixels)?;
            let retraced = rendered.image.pixels.len() as u64;
            return Ok(ShotFrame {
                rendered,
                retraced,
                follows: false,
            });
        }
        let job = prepared.job();
        let kept = self.kept.take().and_then(|(kept, before, was)| {
            let told = at.checked_sub(1).and_then(|k| self.later.get(k as usize));
            let follows = was == *settings
                && told.is_some()
                && changes(&before, job, settings).as_ref() == told;
            follows.then_some(kept)
        });
        let follows = kept.is_some();
        let later = self.later.get(at as usize..).unwrap_or(&[]);
        let materials = prepared.scene().materials.len();
        let ahead = Ahead::new(at + 1, later, materials);
        let ahead = (!ahead.is_empty()).then(|| Arc::new(ahead));
        let (rendered, (kept, retraced)) =
            trace_frame(prepared, settings, ahead, |frame, sampling| {
                let (sampled, kept, retraced) =
                    sampler::render_again(frame, sampling, at, kept, on_pixels);
                (sampled, (kept, retraced))
            })?;
        self.kept = Some((kept, job.clone(), settings.clone()));
        let pixels = rendered.image.pixels.len() as f64;
        if follows {
            self.alone = if retraced as f64 > RETRACED_SHARE_MAX * pixels {
                (self.alone.1, self.alone.1.saturating_mul(2))
            } else {
                (0, 1)
            };
        }
        Ok(ShotFrame {
            rendered,
            retraced,
            follows,
        })
    }
}

/// Whether the samples of `job` draw points of a lens or of a spherical light: such frames
/// are rendered in full, each alone (see `sampler::render_again`).
fn draws(job: &RenderJob) -> bool {
    job.camera.lens.is_some() || job.scene.lights.iter().any(|l| l.radius > 0.0)
}

/// What job `b` changes from job `a`, rendered with `settings`, when `b` can follow `a` in a
/// shot; `None` when it changes everything (the camera, the image, its sampling, or what
/// every pixel reads).
pub fn changes(a: &RenderJob, b: &RenderJob, settings: &RenderSettings) -> Option<Changed> {
    let same_camera = a.camera.eye == b.camera.eye
        && a.camera.dir == b.camera.dir
        && a.camera.up == b.camera.up
        && a.camera.fov_x_deg == b.camera.fov_x_deg
        && a.camera.lens == b.camera.lens;
    let same_image =
        settings.resolve(a) == settings.resolve(b) && settings.sampling(a) == settings.sampling(b);
    if !same_camera || !same_image || !same_frame(&a.scene, &b.scene) || draws(a) || draws(b) {
        return None;
    }
    let (sa, sb) = (&a.scene, &b.scene);
    // The bound on radiance decides, where a ray meets a mirror or glass, whether the rays
    // it spawns are worth tracing: a new bound changes what those surfaces shade.
    let new_bound = max_radiance(sa).to_bits() != max_radiance(sb).to_bits();
    let spawns = |m: &crate::scene::Material| m.reflectivity > 0.0 || m.opacity < 1.0;
    let mut changed = Changed {
        materials: (0..sa.materials.len())
            .filter(|&m| {
                let (x, y) = (&sa.materials[m], &sb.materials[m]);
                x != y || (new_bound && (spawns(x) || spawns(y)))
            })
            .collect(),
        shading: sa.lights != sb.lights || sa.ambient != sb.ambient,
        background: sa.background != sb.background,
        boxes: Vec::new(),
    };
    let moved = moved_instances(sa, sb);
    if !moved.is_empty() {
        let (ra, rb) = (rebased(a), rebased(b));
        let (ra, rb) = (
            ra.as_ref().map_or(sa, |r| &r.0),
            rb.as_ref().map_or(sb, |r| &r.0),
        );
        for i in moved {
            changed.boxes.extend(placed_bounds(ra, i));
            changed.boxes.extend(placed_bounds(rb, i));
        }
    }
    Some(changed)
}

/// Whether scenes `a` and `b` agree on what every pixel reads, so that one can follow the
/// other in a shot: as many materials, lights and shapes, no composites kept once, the same
/// opacities (which decide how shadow rays are asked), no moving camera or light, and the
/// moving shapes asked alike.
fn same_frame(a: &Scene, b: &Scene) -> bool {
    let counts = a.materials.len() == b.materials.len()
        && a.lights.len() == b.lights.len()
        && a.instances.len() == b.instances.len();
    if !counts {
        return false;
    }
    let opacities = a
        .materials
        .iter()
        .zip(&b.materials)
        .all(|(m, n)| m.opacity == n.opacity);
    let composites = !a.has_prototypes() && !b.has_prototypes() && a.instanced == b.instanced;
    opacities && composites && same_motion(a, b)
}

/// Whether the motion of `a` and `b` lets one follow the other: neither moves its camera or
/// a light, both move shapes or neither, and the moving shapes are asked alike
/// (`policy::MOVING_BLOCKS_MAX`); which shapes move and how is the shapes' own change.
fn same_motion(a: &Scene, b: &Scene) -> bool {
    let (ma, mb) = (a.motion.as_deref(), b.motion.as_deref());
    let still_view = |m: Option<&crate::scene::motion::Motion>| {
        m.is_none_or(|m| m.camera.is_none() && m.lights.iter().all(Option::is_none))
    };
    let asked = |s: &Scene| {
        let moving = s.motion.as_ref().map_or(0, |m| {
            s.instances
                .iter()
                .filter(|i| m.moves_slot(i.transform))
                .count()
        });
        moving <= MOVING_BLOCKS_MAX
    };
    let after = |m: Option<&crate::scene::motion::Motion>| m.map(|m| m.after);
    ma.is_some() == mb.is_some()
        && still_view(ma)
        && still_view(mb)
        && asked(a) == asked(b)
        && after(ma) == after(mb)
}

/// The instances of `a` (and `b`, as many) that are not the same shape, material and
/// placement in both, over the exposure where one moves.
fn moved_instances(a: &Scene, b: &Scene) -> Vec<usize> {
    let same_slot: Vec<bool> = (0..a.transforms.len().max(b.transforms.len()))
        .map(|k| a.transforms.get(k) == b.transforms.get(k))
        .collect();
    a.instances
        .iter()
        .zip(b.instances.iter())
        .enumerate()
        .filter(|(_, (ia, ib))| {
            let same_index = ia.transform == ib.transform
                && same_slot
                    .get(ia.transform as usize)
                    .copied()
                    .unwrap_or(true);
            let placed = same_index || a.transform_of(ia) == b.transform_of(ib);
            let moves = same_slot_motion(a, ia.transform, b, ib.transform);
            !(same_shape(ia, ib) && placed && moves)
        })
        .map(|(i, _)| i)
        .collect()
}

/// Whether slot `ka` of `a` and slot `kb` of `b` move alike over the exposure: the same
/// motion of the slot and of every moving slot above it.
fn same_slot_motion(a: &Scene, ka: u32, b: &Scene, kb: u32) -> bool {
    fn slot(s: &Scene, k: Option<u32>) -> Option<&crate::scene::motion::SlotMotion> {
        let m = s.motion.as_ref()?;
        m.slots.get(k? as usize)?.as_ref()
    }
    let (mut ka, mut kb) = (Some(ka), Some(kb));
    // Bounded by the slot count, as `Motion::slot_matrix` walks it.
    for _ in 0..=a.transforms.len().max(b.transforms.len()) {
        match (slot(a, ka), slot(b, kb)) {
            (None, None) => return true,
            (Some(x), Some(y)) if x == y => (ka, kb) = (x.parent, y.parent),
            _ => return false,
        }
    }
    false
}

/// Whether two instances draw the same shape with the same material: equal statements, and
/// for a mesh the same loaded mesh (a file edited between two frames is loaded again).
fn same_shape(a: &Instance, b: &Instance) -> bool {
    use crate::shape::Geometry;
    let mesh = match (&a.geometry, &b.geometry) {
        (Geometry::Mesh(m), Geometry::Mesh(n)) => match (m.mesh(), n.mesh()) {
            (Some(x), Some(y)) => Arc::ptr_eq(x, y),
            (x, y) => x.is_none() && y.is_none(),
        },
        _ => true,
    };
    a.geometry == b.geometry && a.material == b.material && mesh
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{render_job, HdrImage};
    use crate::scene::{Camera, Geometry, Light, Material};
    use glam::{DVec3, Vec3};

    fn sphere(c: [f64; 3], r: f64, material: usize) -> Instance {
        Instance::new(
            Geometry::Sphere {
                center: DVec3::from(c),
                radius: r,
            },
            material,
        )
    }

    /// A floor, a wall, a glass ball, a mirror ball and a red ball at `x` (which casts its
    /// shadow on the floor and is seen in the mirror and through the glass), two lights.
    fn frame(x: f64, red: f32, background: f32) -> RenderJob {
        let mut glass = Material::phong("glass", Vec3::ZERO, Vec3::ZERO, Vec3::splat(0.9), 200.0);
        (glass.opacity, glass.ior) = (0.0, 1.5);
        let mut mirror = Material::phong("mirror", Vec3::ZERO, Vec3::splat(0.05), Vec3::ONE, 300.0);
        mirror.reflectivity = 0.9;
        let grey = Material::phong("grey", Vec3::splat(0.1), Vec3::splat(0.6), Vec3::ZERO, 1.0);
        let red = Material::phong(
            "red",
            Vec3::splat(0.1),
            Vec3::new(red, 0.1, 0.1),
            Vec3::splat(0.5),
            20.0,
        );
        let slab = |p1: [f64; 3], p2: [f64; 3]| {
            Instance::new(
                Geometry::Box {
                    p1: DVec3::from(p1),
                    p2: DVec3::from(p2),
                },
                2,
            )
        };
        let scene = Scene {
            materials: vec![glass, mirror, grey, red],
            instances: vec![
                slab([-20.0, -2.0, -30.0], [20.0, -1.0, 0.0]),
                slab([-20.0, -1.0, -12.0], [20.0, 8.0, -11.0]),
                sphere([-1.5, 0.0, -4.0], 0.8, 0),
                sphere([2.0, 0.2, -7.0], 1.2, 1),
                sphere([x, -0.4, -6.0], 0.6, 3),
            ]
            .into(),
            lights: vec![
                Light::point("a", DVec3::new(4.0, 9.0, 2.0), Vec3::splat(0.9)),
                Light::point("b", DVec3::new(-6.0, 5.0, -1.0), Vec3::new(0.3, 0.3, 0.5)),
            ],
            ambient: Vec3::splat(0.3),
            background: Vec3::splat(background),
            ..Scene::default()
        };
        RenderJob {
            scene,
            camera: Camera {
                eye: DVec3::new(0.3, 1.0, 4.0),
                ..Camera::default_with_fov("eye", 60.0)
            },
            output: "x.png".into(),
            width: 64,
            height: 40,
            samples: None,
            loc: None,
        }
    }

    fn bits(image: &HdrImage) -> Vec<[u32; 3]> {
        image
            .pixels
            .iter()
            .map(|p| p.to_array().map(f32::to_bits))
            .collect()
    }

    /// Renders `jobs` as a shot and alone; each frame's pixels must agree to the bit. Returns
    /// the pixels each frame of the shot traced again, and whether it was traced from the
    /// frame before.
    fn shot_against_alone(jobs: &[RenderJob], settings: &RenderSettings) -> Vec<(u64, bool)> {
        let later: Vec<Changed> = jobs
            .windows(2)
            .map(|w| changes(&w[0], &w[1], settings).expect("a still camera"))
            .collect();
        let mut shot = Shot::new(later);
        let mut retraced = Vec::new();
        for (k, job) in jobs.iter().enumerate() {
            let alone = render_job(job, settings, &|_| {}).unwrap().image;
            let prepared = Prepared::new(job);
            let again = shot.render(&prepared, settings, &|_| {}).unwrap();
            assert!(
                bits(&again.rendered.image) == bits(&alone),
                "frame {k} differs"
            );
            retraced.push((again.retraced, again.follows));
        }
        retraced
    }

    #[test]
    fn a_shot_s_frames_are_the_frames_rendered_alone_and_trace_only_what_changed() {
        let jobs = [
            frame(-1.0, 0.8, 0.1),
            frame(-0.8, 0.8, 0.1),
            frame(-0.8, 0.8, 0.1),
            frame(-0.6, 0.8, 0.1),
            frame(-0.6, 0.5, 0.1),
            frame(-0.6, 0.5, 0.2),
        ];
        let pixels = 64 * 40;
        for settings in [
            RenderSettings::default(),
            RenderSettings {
                spp: Some(4),
                ..RenderSettings::default()
            },
        ] {
            let retraced: Vec<u64> = shot_against_alone(&jobs, &settings)
                .into_iter()
                .map(|(n, _)| n)
                .collect();
            assert_eq!(retraced[0], pixels);
            // The ball moved: some pixels, not all; a frame like the one before: none.
            assert!(retraced[1] > 0 && retraced[1] < pixels / 2, "{retraced:?}");
            assert_eq!(retraced[2], 0, "{retraced:?}");
            assert!(retraced[4] > 0 && retraced[4] < pixels / 2, "{retraced:?}");
        }
    }

    /// The ambient light changes every frame: every pixel that sees a surface reads it, so a
    /// frame traced from the one before traces nearly all of them again, and the frame after
    /// it is rendered as alone; the one after that starts over, and when it does the same,
    /// two frames are rendered alone.
    #[test]
    fn frames_that_trace_nearly_everything_again_are_followed_by_frames_alone() {
        let jobs: Vec<RenderJob> = (0..9)
            .map(|k| {
                let mut job = frame(-1.0, 0.8, 0.1);
                job.scene.ambient = Vec3::splat(0.2 + 0.02 * k as f32);
                job
            })
            .collect();
        let frames = shot_against_alone(&jobs, &RenderSettings::default());
        let follows: Vec<bool> = frames.iter().map(|&(_, f)| f).collect();
        let expected = [false, true, false, false, true, false, false, false, true];
        assert_eq!(follows, expected, "{frames:?}");
        let pixels = 64 * 40;
        assert!(
            frames[1].0 as f64 > RETRACED_SHARE_MAX * pixels as f64,
            "{frames:?}"
        );
    }

    /// Frames whose samples draw points of a lens or of a spherical light are not followed in
    /// a shot (adaptive sampling asks such a light as a whole, a cone no footprint holds):
    /// each starts its own, and a shot renders it as it renders alone.
    #[test]
    fn frames_that_draw_lens_or_light_points_start_their_own_shot() {
        let lens = |job: &mut RenderJob| {
            job.camera.lens = Some(crate::scene::Lens {
                aperture: 0.15,
                focus: 9.0,
            })
        };
        let soft = |job: &mut RenderJob| job.scene.lights[0].radius = 0.8;
        let settings = RenderSettings::default();
        for draw in [lens, soft] {
            let (mut a, mut b) = (frame(-1.0, 0.8, 0.1), frame(-0.8, 0.8, 0.1));
            draw(&mut a);
            draw(&mut b);
            assert!(changes(&a, &a, &settings).is_none());
            assert!(changes(&a, &b, &settings).is_none());
            for spp in [None, Some(4)] {
                let settings = RenderSettings {
                    spp,
                    ..RenderSettings::default()
                };
                let alone = render_job(&b, &settings, &|_| {}).unwrap().image;
                let mut shot = Shot::new(Vec::new());
                let again = shot.render(&Prepared::new(&b), &settings, &|_| {});
                assert!(bits(&again.unwrap().rendered.image) == bits(&alone));
            }
        }
    }

    #[test]
    fn what_every_pixel_reads_starts_a_new_shot() {
        let settings = RenderSettings::default();
        let a = frame(-1.0, 0.8, 0.1);
        let mut turned = a.clone();
        turned.camera.eye.x += 0.1;
        assert!(changes(&a, &turned, &settings).is_none());
        let mut clear = a.clone();
        clear.scene.materials[3].opacity = 0.5;
        assert!(changes(&a, &clear, &settings).is_none());
        // A light made brighter raises the bound on radiance, which the mirror and the glass
        // (materials 0 and 1) read.
        let mut brighter = a.clone();
        brighter.scene.lights[0].intensity *= 2.0;
        let c = changes(&a, &brighter, &settings).unwrap();
        assert!(
            c.shading && c.boxes.is_empty() && c.materials == [0, 1],
            "{c:?}"
        );
        let mut moved = a.clone();
        moved.scene.lights[1].position.y += 1.0;
        let c = changes(&a, &moved, &settings).unwrap();
        assert!(
            c.shading && c.boxes.is_empty() && c.materials.is_empty(),
            "{c:?}"
        );
        assert!(changes(&a, &a, &settings).unwrap().is_empty());
    }
}
