//! Whitted-style shading: the local Phong model of docs/shading.md §2 with shadows (soft under
//! spherical lights, sampled at the point of the light the camera sample's pattern gives),
//! spot lights, mirror reflection and Fresnel refraction. Every question about a ray goes to
//! the compiled scene's facade (`super::compile::RenderScene`): closest hits, and for a
//! shadow ray how much of its light passes ([`RenderScene::transmittance`]) or what the
//! moving shapes alone do to it ([`RenderScene::moving_shadow`]), and what a point sees of a
//! spherical light as a whole ([`RenderScene::whole_light`]).

use super::camera::PinholeCamera;
use super::compile::{
    LightSight, MovingShadow, PrimId, RayHint, RenderScene, Scratch, ShadowRay, SurfaceHit,
    WholeLight, NO_HIT,
};
use super::shading::{LightDisc, PointLight, ShadeMaterial};
use crate::math::{reflect, Ray};
use glam::Vec3A;

/// A ray whose contribution to the pixel is below half an 8-bit step cannot change the
/// result: `c/(c+1)` has slope at most 1, so an HDR change `w·L_max` moves the output by at
/// most that much.
const NEGLIGIBLE: f32 = 0.5 / 255.0;

/// What one worker keeps between the rays it traces: the scratch its scene queries keep
/// (its ray counts among them), and how its camera samples are shaded. The caches only save
/// work, never change a value, so images do not depend on which worker traced which pixel.
pub struct TraceState {
    /// What the scene's queries keep between rays, and the rays traced so far.
    pub scratch: Scratch,
    /// A light's term whose share of the pixel, lit, is below this is added as lit without
    /// its shadow ray: 0 (every shadow ray traced) except for adaptive sampling's refining
    /// samples ([`TraceState::refining`]).
    shadow_cut: f32,
    /// Bit k: a shadow ray towards light k of the current camera sample's tree found it not
    /// fully visible (blocked, or through glass); [`CameraSample::not_clear`].
    not_clear: u32,
    /// Per light, the point of the unit square at which the current camera sample samples
    /// it if it is a sphere (set by the sampler, from the pixel's pattern); a light without
    /// one here is sampled at its centre.
    pub light_points: Vec<[f32; 2]>,
    /// Whether spherical lights are asked as a whole first ([`RenderScene::whole_light`]).
    whole_lights: bool,
    /// Whether the current camera sample's tree sampled a spherical light it saw only in
    /// part; [`CameraSample::penumbra`].
    penumbra: bool,
}

/// What adaptive sampling's first pass learned about a pixel, handed to the integrator for
/// the first samples it adds there (`sampler::pattern::PRIOR_SAMPLES`): the lights every
/// shadow ray of the centres around the pixel saw fully, taken as visible at the surface a
/// camera ray hits without a shadow ray.
#[derive(Clone, Debug, Default)]
pub struct PixelPrior {
    /// Bit k: light k is known to be fully visible.
    pub known_clear: u32,
    /// In a frame with motion, `known_clear` speaks for the shapes that hold still only: a
    /// sample still asks the moving shapes at its own instant. And it holds for camera hits
    /// near the first pass's hits around the pixel only (`KnownNear`).
    pub near: Option<KnownNear>,
}

impl PixelPrior {
    /// Nothing known: every shadow ray is traced.
    pub const NONE: PixelPrior = PixelPrior {
        known_clear: 0,
        near: None,
    };
}

/// Radiance along a camera ray and what the integrator found on its way.
#[derive(Clone, Copy, Debug)]
pub struct CameraSample {
    /// Radiance arriving along the ray.
    pub radiance: Vec3A,
    /// The primitive hit ([`NO_HIT`] for the background), which adaptive sampling compares
    /// between neighbouring pixels.
    pub prim: PrimId,
    /// How far along the ray the surface is (`None`: the background).
    pub t: Option<f32>,
    /// Bit k: some shadow ray of the sample's tree towards light k did not see it fully.
    pub not_clear: u32,
    /// The largest angle (radians, as the eye sees it) swept over the exposure by the moving
    /// shapes the sample's rays may have met at some instant, where it was measured
    /// ([`Integrator::camera_sample_swept`]); 0 otherwise.
    pub swept: f32,
    /// Whether, with spherical lights asked as a whole ([`TraceState::asking_whole_lights`]),
    /// a point of the sample's tree saw one in part (or could not be shown to see all or
    /// none of it): its radiance then depends on where the light is sampled.
    pub penumbra: bool,
}

/// Where a camera hit of a frame with motion must lie for the lights the first pass's
/// centres around its pixel saw fully to count as visible from it: a hit nearer or farther
/// than all of theirs, on a shape that has moved there or seen past an edge the moving
/// camera uncovers, may see the lights past shapes theirs did not; and under a moving camera
/// a sample's hit may lie pixels away from those centres, across a shadow's edge.
#[derive(Clone, Debug)]
pub struct KnownNear {
    /// The least and greatest distance from the first pass's eye (the camera at the middle
    /// of the exposure) of the centres' hits.
    pub depth: (f32, f32),
    /// Under a moving camera: that eye's view, and the window of image positions (left, top,
    /// right, bottom) spanned by the centres, in which the hit must be seen from it.
    pub seen_from: Option<(PinholeCamera, [f32; 4])>,
}

impl KnownNear {
    /// Whether `point`, a camera ray's hit `t` along it, lies among the centres' hits.
    #[inline]
    fn holds(&self, point: Vec3A, t: f32) -> bool {
        let (lo, hi) = self.depth;
        let Some((view, [left, top, right, bottom])) = &self.seen_from else {
            return t >= lo && t <= hi;
        };
        let dist = view.eye().distance(point);
        dist >= lo
            && dist <= hi
            && view
                .project(point)
                .is_some_and(|(x, y)| x >= *left && x <= *right && y >= *top && y <= *bottom)
    }
}

impl Default for TraceState {
    fn default() -> Self {
        TraceState {
            scratch: Scratch::default(),
            shadow_cut: 0.0,
            not_clear: 0,
            light_points: Vec::new(),
            whole_lights: false,
            penumbra: false,
        }
    }
}

impl TraceState {
    /// For the samples adaptive sampling adds to a pixel. More than half of their shadow
    /// rays (most of them from deep inside glass and mirror trees, or for highlights of
    /// exponent 300 and more far from their peak) decide a term that could not move the
    /// pixel by half an 8-bit step even fully lit, the bound below which reflected and
    /// refracted rays are not traced either (`NEGLIGIBLE`). Such a term is counted lit:
    /// right for most of them, and off by less than that bound where it is not. Uniform
    /// sampling and adaptive sampling's first pass trace them all, so their images do not
    /// change.
    pub fn refining() -> Self {
        TraceState {
            shadow_cut: NEGLIGIBLE,
            ..TraceState::default()
        }
    }

    /// For adaptive sampling's first pass: a spherical light is first asked as a whole
    /// ([`RenderScene::whole_light`]), and its one shadow ray, where that proves nothing, goes
    /// to its centre ([`CameraSample::penumbra`] says so).
    pub fn asking_whole_lights() -> Self {
        TraceState {
            whole_lights: true,
            ..TraceState::default()
        }
    }
}

/// What a camera sample finds of a spherical light before the glass walk
/// (`Integrator::sphere_sight`).
enum SphereSight {
    /// All of it lights the point, without a shadow ray.
    Lit,
    /// None of it does.
    Hidden,
    /// The shadow ray to trace.
    Ray(ShadowRay),
}

/// The lights taken as visible at a camera hit without a shadow ray ([`PixelPrior`]).
#[derive(Clone, Copy, Debug)]
struct KnownLit {
    lights: u32,
    /// In a frame with motion (the prior knows only of what holds still): the moving shapes
    /// are still asked, about shadow rays leaving this primitive (the camera hit's).
    ask_moving: Option<PrimId>,
}

impl KnownLit {
    const NONE: KnownLit = KnownLit {
        lights: 0,
        ask_moving: None,
    };
}

/// Where a ray meets a surface, as shading reads it: the ray, the primitive and its hit.
#[derive(Clone, Copy)]
struct SurfacePoint<'a> {
    ray: &'a Ray,
    prim: PrimId,
    hit: &'a SurfaceHit,
}

/// What shading carries down a ray's tree besides the point: the number of bounces so far,
/// the ray's share of the pixel (for `NEGLIGIBLE` and `TraceState::shadow_cut`), and the
/// lights taken as visible without a shadow ray (at camera hits only).
#[derive(Clone, Copy)]
struct ShadeContext {
    depth: u32,
    weight: f32,
    known: KnownLit,
}

/// The Whitted integrator over a compiled scene (docs/shading.md).
pub struct Integrator<'a> {
    /// What rays meet, and how it is shaded.
    pub scene: &'a RenderScene,
    /// Most reflected or refracted bounces of a camera ray.
    pub max_depth: u32,
}

/// Fresnel reflectance of an unpolarised ray meeting a dielectric boundary, for the ratio
/// `eta = η_incident / η_transmitted` and `cos_i` the cosine of the angle of incidence.
/// Returns `(F, cos_t)`; `F = 1` under total internal reflection.
pub fn fresnel(cos_i: f32, eta: f32) -> (f32, f32) {
    let sin_t2 = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin_t2 >= 1.0 {
        return (1.0, 0.0);
    }
    let cos_t = (1.0 - sin_t2).sqrt();
    let r_s = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_p = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    (0.5 * (r_s * r_s + r_p * r_p), cos_t)
}

impl Integrator<'_> {
    /// Radiance arriving along a reflected or refracted `ray` (unit direction). `weight` is
    /// the ray's share of the pixel, `depth` the number of bounces so far.
    #[inline]
    pub fn trace(&self, ray: &Ray, depth: u32, weight: f32, st: &mut TraceState) -> Vec3A {
        let hit = self
            .scene
            .intersect(ray, f32::INFINITY, RayHint::Secondary, &mut st.scratch);
        match hit {
            Some((prim, hit)) => {
                let at = SurfacePoint {
                    ray,
                    prim,
                    hit: &hit,
                };
                let known = KnownLit::NONE;
                self.shade(
                    &at,
                    ShadeContext {
                        depth,
                        weight,
                        known,
                    },
                    st,
                )
            }
            None => self.scene.shading().background,
        }
    }

    /// Radiance along a camera ray, with what the sampler knows of its pixel (`prior`).
    #[inline(always)]
    pub fn camera_sample(
        &self,
        ray: &Ray,
        prior: &PixelPrior,
        st: &mut TraceState,
    ) -> CameraSample {
        let hit = self
            .scene
            .intersect(ray, f32::INFINITY, RayHint::Camera, &mut st.scratch);
        self.shade_camera_hit(ray, hit.as_ref(), prior, st)
    }

    /// [`Integrator::camera_sample`] of a camera ray that leaves a thin lens, not the eye the
    /// scene was compiled for (docs/shading.md §1.1).
    #[inline(never)]
    pub fn lens_sample(&self, ray: &Ray, prior: &PixelPrior, st: &mut TraceState) -> CameraSample {
        let hit = self
            .scene
            .intersect(ray, f32::INFINITY, RayHint::Secondary, &mut st.scratch);
        self.shade_camera_hit(ray, hit.as_ref(), prior, st)
    }

    /// [`Integrator::camera_sample`] that also measures [`CameraSample::swept`]: adaptive
    /// sampling's first pass asks it of each pixel centre in a frame with motion.
    pub fn camera_sample_swept(
        &self,
        ray: &Ray,
        prior: &PixelPrior,
        st: &mut TraceState,
    ) -> CameraSample {
        st.scratch.measure_sweep();
        let sample = self.camera_sample(ray, prior, st);
        CameraSample {
            swept: st.scratch.take_sweep(),
            ..sample
        }
    }

    /// [`Integrator::camera_sample`] of a camera ray whose closest hit (`hit`) is known.
    #[inline]
    pub fn shade_camera_hit(
        &self,
        ray: &Ray,
        hit: Option<&(PrimId, SurfaceHit)>,
        prior: &PixelPrior,
        st: &mut TraceState,
    ) -> CameraSample {
        st.not_clear = 0;
        st.penumbra = false;
        let Some((prim, hit)) = hit else {
            return CameraSample {
                radiance: self.scene.shading().background,
                prim: NO_HIT,
                t: None,
                not_clear: 0,
                swept: 0.0,
                penumbra: false,
            };
        };
        let known = self.known_at(prior, *prim, hit);
        let at = SurfacePoint {
            ray,
            prim: *prim,
            hit,
        };
        let context = ShadeContext {
            depth: 0,
            weight: 1.0,
            known,
        };
        CameraSample {
            radiance: self.shade(&at, context, st),
            prim: *prim,
            t: Some(hit.t),
            not_clear: st.not_clear,
            swept: 0.0,
            penumbra: st.penumbra,
        }
    }

    /// What `prior` says of the lights at camera hit `hit` on primitive `prim`: its known
    /// lights where the hit lies among the first pass's (`KnownNear`), none elsewhere.
    #[inline]
    fn known_at(&self, prior: &PixelPrior, prim: PrimId, hit: &SurfaceHit) -> KnownLit {
        match &prior.near {
            None => KnownLit {
                lights: prior.known_clear,
                ask_moving: None,
            },
            Some(near) if near.holds(hit.point, hit.t) => KnownLit {
                lights: prior.known_clear,
                ask_moving: Some(prim),
            },
            Some(_) => KnownLit::NONE,
        }
    }

    /// Radiance leaving the surface point `at` back along its ray.
    #[inline]
    fn shade(&self, at: &SurfacePoint, context: ShadeContext, st: &mut TraceState) -> Vec3A {
        let (ray, hit) = (at.ray, at.hit);
        let ShadeContext { depth, weight, .. } = context;
        let shading = self.scene.shading();
        let mat = self.scene.material(at.prim);
        let entering = hit.normal.dot(ray.dir) < 0.0;
        // Shading normal faces the incoming ray; the geometric one decides inside/outside.
        let n = if entering { hit.normal } else { -hit.normal };
        let (rho, alpha) = (mat.reflectivity, mat.opacity);
        if rho == 0.0 && alpha == 1.0 {
            return self.local(mat, at, n, context, st);
        }

        // c = α·((1−ρ)·c_local + ρ·c_r) + (1−α)·(F·c_r + (1−F)·c_t)
        let mut fresnel_f = 1.0;
        let mut refracted = None;
        if alpha < 1.0 {
            let eta = if entering { 1.0 / mat.ior } else { mat.ior };
            let cos_i = -ray.dir.dot(n);
            let (f, cos_t) = fresnel(cos_i, eta);
            fresnel_f = f;
            if f < 1.0 {
                refracted = Some((ray.dir * eta + n * (eta * cos_i - cos_t)).normalize());
            }
        }
        let w_reflect = alpha * rho + (1.0 - alpha) * fresnel_f;
        let w_refract = (1.0 - alpha) * (1.0 - fresnel_f);
        // A perfect mirror or clear glass shows none of its local colour: its shadow rays
        // would be multiplied by zero.
        let w_local = alpha * (1.0 - rho);
        let mut c = if w_local == 0.0 {
            Vec3A::ZERO
        } else {
            let local = ShadeContext {
                weight: weight * w_local,
                ..context
            };
            self.local(mat, at, n, local, st) * w_local
        };
        let can_recurse = depth < self.max_depth;
        let worth =
            |w: f32| can_recurse && w > 0.0 && weight * w * shading.max_radiance >= NEGLIGIBLE;
        if worth(w_reflect) {
            let dir = reflect(ray.dir, n);
            st.scratch.counts.reflected += 1;
            let r = hit.spawn_ray(dir).at_time(ray.time);
            c += self.trace(&r, depth + 1, weight * w_reflect, st) * w_reflect;
        }
        if let Some(dir) = refracted.filter(|_| worth(w_refract)) {
            st.scratch.counts.refracted += 1;
            let r = hit.spawn_ray(dir).at_time(ray.time);
            c += self.trace(&r, depth + 1, weight * w_refract, st) * w_refract;
        }
        c
    }

    /// `Ka·I_ambient + Σ vis·I·(Kd·max(N·L,0) + Ks·max(R·V,0)^m)`, specular only where N·L > 0,
    /// at `at` with shading normal `n`, seen back along its ray. Lights and shadowing geometry
    /// are taken at the ray's instant of the exposure; `context.weight` is the result's share
    /// of the pixel (for `TraceState::shadow_cut`), and `context.known` the lights taken as
    /// visible here without a shadow ray.
    #[inline]
    fn local(
        &self,
        mat: &ShadeMaterial,
        at: &SurfacePoint,
        n: Vec3A,
        context: ShadeContext,
        st: &mut TraceState,
    ) -> Vec3A {
        let (hit, v, time) = (at.hit, -at.ray.dir, at.ray.time);
        let ShadeContext { weight, known, .. } = context;
        let shading = self.scene.shading();
        let mut c = mat.ka * shading.ambient;
        // `ks·spec` is exactly zero without a specular colour (spec is at most 1 for m ≥ 0).
        let specular = mat.ks != Vec3A::ZERO || mat.m < 0.0 || mat.m.is_nan();
        for (k, light) in shading.lights.iter().enumerate() {
            let centre = shading.light_position(k, light, time);
            let to_light = centre - hit.point;
            let dist = to_light.length();
            if dist == 0.0 {
                continue;
            }
            let l = to_light / dist;
            let n_dot_l = n.dot(l);
            if n_dot_l <= 0.0 {
                continue;
            }
            // A spot sends its intensity scaled by the direction to the point.
            let intensity = match &light.spot {
                None => light.intensity,
                Some(spot) => match spot.factor(-l) {
                    f if f > 0.0 => light.intensity * f,
                    _ => continue,
                },
            };
            let spec = if specular {
                let r_dot_v = reflect(-l, n).dot(v);
                // powf(0, m) is 0 for every positive m: no call for the unlit half.
                if r_dot_v > 0.0 || mat.m <= 0.0 {
                    r_dot_v.max(0.0).powf(mat.m)
                } else {
                    0.0
                }
            } else {
                0.0
            };
            let unshadowed = mat.kd * n_dot_l + mat.ks * spec;
            // Nothing to shadow (glass has no diffuse term, so only its highlights count):
            // adding zero changes no value, so the shadow ray is not traced.
            if unshadowed == Vec3A::ZERO {
                continue;
            }
            let lit = intensity * unshadowed;
            // One call of the glass walk for both kinds of light, as the point light had it.
            let shadow = if light.radius == 0.0 {
                let shadow = || ShadowRay::new(hit, l, dist, time, k);
                if self.taken_as_lit(lit, weight, known, k, shadow, st) {
                    c += lit;
                    continue;
                }
                shadow()
            } else {
                let sight = LightSight {
                    hit,
                    leaving: at.prim,
                    normal: n,
                    light: k,
                    centre,
                    radius: light.radius,
                    time,
                };
                match self.sphere_sight(&sight, l, light, (lit, weight, known), st) {
                    SphereSight::Lit => {
                        c += lit;
                        continue;
                    }
                    SphereSight::Hidden => {
                        st.not_clear |= 1 << k.min(31);
                        continue;
                    }
                    SphereSight::Ray(shadow) => shadow,
                }
            };
            st.scratch.counts.shadow += 1;
            let vis = self.scene.transmittance(&shadow, &mut st.scratch);
            if vis < 1.0 {
                st.not_clear |= 1 << k.min(31);
            }
            if vis == 0.0 {
                continue;
            }
            c += intensity * vis * unshadowed;
        }
        c
    }

    /// What one camera sample finds of spherical light `light` (number `sight.light`, seen
    /// from `sight.hit` along unit `l` to its centre): the shadow ray towards the point of
    /// the light the sample draws (docs/shading.md §2.1), or `Lit` where `taken_as_lit` (given
    /// `lit`, `weight` and `known`) needs none. Asking as a whole first
    /// ([`TraceState::asking_whole_lights`]), a light all visible or all hidden takes no ray,
    /// and one in part sends its ray to the centre, noted as a penumbra (and as not clear).
    /// Not inlined: scenes without spherical lights keep the point-light path of `local` as
    /// small as it was.
    #[inline(never)]
    fn sphere_sight(
        &self,
        sight: &LightSight,
        l: Vec3A,
        light: &PointLight,
        (lit, weight, known): (Vec3A, f32, KnownLit),
        st: &mut TraceState,
    ) -> SphereSight {
        let (k, centre) = (sight.light, sight.centre);
        let sampled = self.light_point(k, light, centre, l, st);
        let shadow = || self.towards(sight.hit, sampled, sight.time, k);
        if self.taken_as_lit(lit, weight, known, k, shadow, st) {
            return SphereSight::Lit;
        }
        let aim = if st.whole_lights {
            match self.scene.whole_light(sight, &mut st.scratch) {
                WholeLight::Visible => return SphereSight::Lit,
                WholeLight::Hidden => return SphereSight::Hidden,
                WholeLight::Partial => {
                    st.penumbra = true;
                    st.not_clear |= 1 << k.min(31);
                    centre
                }
            }
        } else {
            sampled
        };
        let ray = self.towards(sight.hit, aim, sight.time, k);
        // A point of the light below the surface's horizon is hidden by the surface itself.
        if ray.ray.dir.dot(sight.normal).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return SphereSight::Hidden;
        }
        SphereSight::Ray(ray)
    }

    /// Whether light `k` is taken as visible without a shadow ray: its share `lit` (times the
    /// pixel share `weight`) is below the shadow cut, or it is `known` clear of what holds
    /// still and no moving shape, asked at the sample's instant along `shadow()`, may block it.
    #[inline]
    fn taken_as_lit(
        &self,
        lit: Vec3A,
        weight: f32,
        known: KnownLit,
        k: usize,
        shadow: impl Fn() -> ShadowRay,
        st: &mut TraceState,
    ) -> bool {
        lit.max_element() * weight < st.shadow_cut
            || ((known.lights >> k.min(31)) & 1 != 0
                && !known.ask_moving.is_some_and(|leaving| {
                    let moving = self
                        .scene
                        .moving_shadow(&shadow(), leaving, &mut st.scratch);
                    moving != MovingShadow::Clear
                }))
    }

    /// Where the current camera sample samples spherical light `k` (centre `centre`, seen
    /// along unit `l`): the point of its disc that the sample's point of the unit square
    /// maps to, or the centre when the sampler gave none.
    #[inline]
    fn light_point(
        &self,
        k: usize,
        light: &PointLight,
        centre: Vec3A,
        l: Vec3A,
        st: &TraceState,
    ) -> Vec3A {
        match st.light_points.get(k) {
            Some(&uv) => LightDisc::new(centre, light.radius, l).sample(uv),
            None => centre,
        }
    }

    /// The shadow ray from `hit` towards point `to` of light `k`, at instant `time`.
    #[inline]
    fn towards(&self, hit: &SurfaceHit, to: Vec3A, time: f32, k: usize) -> ShadowRay {
        let d = to - hit.point;
        let dist = d.length();
        ShadowRay::new(hit, d / dist, dist, time, k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A grey floor under an opaque ball, one light straight above: the point of the floor
    /// below the ball is in its shadow. Traced straight down from between the two.
    fn shadowed_floor(kd: f32) -> (f32, f32, f32, u64) {
        use crate::scene::{Geometry, Instance, Light, Material, Scene};
        use glam::{DVec3, Vec3};
        let scene = Scene {
            materials: vec![Material::phong(
                "grey",
                Vec3::splat(0.1),
                Vec3::splat(kd),
                Vec3::ZERO,
                1.0,
            )],
            instances: vec![
                Instance::new(
                    Geometry::Box {
                        p1: DVec3::new(-10.0, -1.0, -10.0),
                        p2: DVec3::new(10.0, 0.0, 10.0),
                    },
                    0,
                ),
                Instance::new(
                    Geometry::Sphere {
                        center: DVec3::new(0.0, 2.0, 0.0),
                        radius: 0.5,
                    },
                    0,
                ),
            ]
            .into(),
            lights: vec![Light {
                name: "top".into(),
                position: DVec3::new(0.0, 5.0, 0.0),
                intensity: Vec3::ONE,
                radius: 0.0,
                spot: None,
            }],
            ambient: Vec3::splat(0.2),
            ..Scene::default()
        };
        let (scene, _) = RenderScene::compile(&scene, None);
        let integrator = Integrator {
            scene: &scene,
            max_depth: 4,
        };
        let ray = Ray::new(Vec3A::new(0.0, 1.0, 0.0), Vec3A::new(0.0, -1.0, 0.0));
        let mut exact = TraceState::default();
        let mut refining = TraceState::refining();
        let mut known = TraceState::refining();
        let lit = PixelPrior {
            known_clear: 1,
            near: None,
        };
        let none = &PixelPrior::NONE;
        let shadowed = integrator.camera_sample(&ray, none, &mut exact).radiance.x;
        let refined = integrator
            .camera_sample(&ray, none, &mut refining)
            .radiance
            .x;
        let assumed = integrator.camera_sample(&ray, &lit, &mut known).radiance.x;
        (shadowed, refined, assumed, refining.scratch.counts.shadow)
    }

    #[test]
    fn refining_samples_skip_shadow_rays_only_for_negligible_or_known_clear_lights() {
        let ambient = 0.1 * 0.2;
        // A term that matters: the refining sample traces its shadow ray and agrees; a light
        // known clear around the pixel is taken as lit at the camera hit (N·L = 1).
        let (shadowed, refined, assumed, rays) = shadowed_floor(0.5);
        assert!((shadowed - ambient).abs() < 1e-6, "{shadowed}");
        assert_eq!((refined, rays), (shadowed, 1));
        assert!((assumed - (ambient + 0.5)).abs() < 1e-6, "{assumed}");
        // A term below NEGLIGIBLE even fully lit is added lit, without a shadow ray.
        let kd = 0.5 * NEGLIGIBLE;
        let (shadowed, refined, _, rays) = shadowed_floor(kd);
        assert!((shadowed - ambient).abs() < 1e-6, "{shadowed}");
        assert_eq!(rays, 0);
        assert!((refined - (ambient + kd)).abs() < 1e-6, "{refined}");
    }

    #[test]
    fn fresnel_at_normal_incidence() {
        for ior in [1.0f32, 1.33, 1.5, 2.4] {
            let (f, cos_t) = fresnel(1.0, 1.0 / ior);
            let expected = ((ior - 1.0) / (ior + 1.0)).powi(2);
            assert!((f - expected).abs() < 1e-6, "ior {ior}: {f} vs {expected}");
            assert!((cos_t - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn total_internal_reflection_beyond_the_critical_angle() {
        let ior = 1.5f32;
        let critical = (1.0 / ior).asin();
        let just_inside = (critical - 0.01).cos();
        let beyond = (critical + 0.01).cos();
        assert!(fresnel(just_inside, ior).0 < 1.0);
        assert_eq!(fresnel(beyond, ior).0, 1.0);
    }

    #[test]
    fn fresnel_is_symmetric_and_rises_to_one_at_grazing() {
        let (f_out, _) = fresnel(0.0001, 1.0 / 1.5);
        assert!(f_out > 0.99);
        // Same pair of angles from either side gives the same reflectance.
        let cos_i = 0.8f32;
        let (f1, cos_t) = fresnel(cos_i, 1.0 / 1.5);
        let (f2, _) = fresnel(cos_t, 1.5);
        assert!((f1 - f2).abs() < 1e-5);
    }
}
