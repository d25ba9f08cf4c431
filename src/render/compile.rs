//! Compiles a scene description into the flat render scene that the integrator touches per
//! ray: primitives in one array, a BVH over the bounded ones, materials in f32 SIMD form.

use super::primitive::{Primitive, SurfaceHit};
use crate::accel::Bvh;
use crate::math::Ray;
use crate::scene::{Material, Scene};
use crate::shape::{Shape, ShapeHit, Sphere, SphereRay};
use glam::{Vec3A, Vec4};

#[derive(Clone, Debug)]
pub struct ShadeMaterial {
    pub ka: Vec3A,
    pub kd: Vec3A,
    pub ks: Vec3A,
    pub m: f32,
    pub reflectivity: f32,
    pub opacity: f32,
    pub ior: f32,
}

impl ShadeMaterial {
    fn from(m: &Material) -> Self {
        ShadeMaterial {
            ka: m.ka.into(),
            kd: m.kd.into(),
            ks: m.ks.into(),
            m: m.m,
            reflectivity: m.reflectivity.clamp(0.0, 1.0),
            opacity: m.opacity.clamp(0.0, 1.0),
            ior: m.ior,
        }
    }

    pub fn is_transparent(&self) -> bool {
        self.opacity < 1.0
    }
}

#[derive(Clone, Debug)]
pub struct PointLight {
    pub position: Vec3A,
    pub intensity: Vec3A,
}

/// `RenderScene::kind` of a primitive that is a packed world-space sphere.
const SPHERE: u32 = u32::MAX;
/// Spheres tested at once.
const LANES: usize = 4;

/// Primitives are numbered in the BVH's leaf order (so a leaf reads consecutive entries),
/// then the unbounded ones. World-space spheres, the common case, are packed into 16 bytes
/// and tested four at a time with no dispatch; everything else is a [`Primitive`].
#[derive(Clone, Debug)]
pub struct RenderScene {
    /// Per primitive: its material.
    material: Vec<u32>,
    /// Per primitive: [`SPHERE`], or its index in `objects`.
    kind: Vec<u32>,
    /// Per primitive: the packed sphere (`Sphere::packed`; NaN for other kinds, which no
    /// sphere test hits), then `LANES - 1` NaN entries so a leaf can always load four.
    spheres: Vec<Vec4>,
    objects: Vec<Primitive>,
    bvh: Bvh,
    /// The first primitive without finite bounds (planes); these are tested on every ray.
    unbounded: u32,
    pub materials: Vec<ShadeMaterial>,
    pub lights: Vec<PointLight>,
    pub ambient: Vec3A,
    pub background: Vec3A,
    /// Whether any material lets light through: if not, shadow rays stop at the first hit.
    pub any_transparent: bool,
    /// An upper bound of the radiance any ray can carry (per channel max), used to stop
    /// tracing rays whose weight can no longer change the 8-bit result.
    pub max_radiance: f32,
}

/// A primitive that could not be placed (degenerate after transformation).
#[derive(Clone, Debug)]
pub struct Dropped {
    pub instance: String,
    pub loc: Option<crate::diag::Loc>,
}

impl RenderScene {
    pub fn compile(scene: &Scene) -> (RenderScene, Vec<Dropped>) {
        let n = scene.instances.len();
        let mut material = Vec::with_capacity(n);
        let mut kind = Vec::with_capacity(n);
        let mut spheres = Vec::with_capacity(n + LANES - 1);
        let mut bounds = Vec::with_capacity(n);
        let mut objects = Vec::new();
        let mut dropped = Vec::new();
        for inst in scene.instances.iter() {
            match Primitive::new(
                &inst.geometry,
                scene.transform_of(inst),
                inst.material as u32,
            ) {
                Ok(p) => {
                    bounds.push(p.bounds);
                    material.push(p.material);
                    if let Some(s) = p.world_sphere() {
                        spheres.push(s.packed());
                        kind.push(SPHERE);
                    } else {
                        spheres.push(Vec4::NAN);
                        kind.push(objects.len() as u32);
                        objects.push(p);
                    }
                }
                Err(_) => dropped.push(Dropped {
                    instance: scene.instance_name(inst),
                    loc: scene.instance_loc(inst),
                }),
            }
        }
        let (bounded, unbounded): (Vec<u32>, Vec<u32>) =
            (0..material.len() as u32).partition(|&i| bounds[i as usize].is_finite());
        let mut bvh = Bvh::build(&bounds, bounded);
        drop(bounds);
        let mut order = bvh.renumber_in_leaf_order();
        let first_unbounded = order.len() as u32;
        order.extend(unbounded);
        let permute = |v: &[u32]| order.iter().map(|&i| v[i as usize]).collect::<Vec<u32>>();
        let (material, kind) = (permute(&material), permute(&kind));
        let mut spheres: Vec<Vec4> = order.iter().map(|&i| spheres[i as usize]).collect();
        spheres.resize(order.len() + LANES - 1, Vec4::NAN);
        drop(order);
        let materials: Vec<ShadeMaterial> =
            scene.materials.iter().map(ShadeMaterial::from).collect();
        let lights: Vec<PointLight> = scene
            .lights
            .iter()
            .map(|l| PointLight {
                position: l.position.as_vec3().into(),
                intensity: l.intensity.into(),
            })
            .collect();
        let ambient: Vec3A = scene.ambient.into();
        let background: Vec3A = scene.background.into();
        let mut used = vec![false; materials.len()];
        for &m in &material {
            if let Some(u) = used.get_mut(m as usize) {
                *u = true;
            }
        }
        let any_transparent = materials
            .iter()
            .zip(&used)
            .any(|(m, &used)| m.is_transparent() && used);
        // Every shaded colour is a convex combination of local colours and the background
        // (the weights in docs/shading.md §3 sum to 1), so the largest local colour bounds them all.
        let total_light: Vec3A = lights.iter().map(|l| l.intensity.max(Vec3A::ZERO)).sum();
        let max_local = materials
            .iter()
            .map(|m| {
                (m.ka * ambient + total_light * (m.kd.max(Vec3A::ZERO) + m.ks.max(Vec3A::ZERO)))
                    .max_element()
            })
            .fold(0.0f32, f32::max);
        let max_radiance = max_local.max(background.max_element());
        let scene = RenderScene {
            material,
            kind,
            spheres,
            objects,
            bvh,
            unbounded: first_unbounded,
            materials,
            lights,
            ambient,
            background,
            any_transparent,
            max_radiance,
        };
        (scene, dropped)
    }

    /// Number of primitives.
    pub fn len(&self) -> usize {
        self.material.len()
    }

    pub fn is_empty(&self) -> bool {
        self.material.is_empty()
    }

    /// The material of primitive `i`.
    #[inline(always)]
    pub fn material_of(&self, i: u32) -> u32 {
        self.material[i as usize]
    }

    /// The object-space shape of primitive `i`, or `None` for a packed world-space sphere
    /// (for tools that report by kind of shape).
    pub fn object_shape(&self, i: u32) -> Option<&Shape> {
        match self.kind[i as usize] {
            SPHERE => None,
            k => Some(&self.objects[k as usize].shape),
        }
    }

    #[inline]
    fn sphere(&self, i: usize) -> Sphere {
        let s = self.spheres[i];
        Sphere {
            center: s.truncate().into(),
            radius: s.w,
        }
    }

    /// The four packed spheres from primitive `i` on.
    #[inline(always)]
    fn four_spheres(&self, i: usize) -> [Vec4; LANES] {
        let s = &self.spheres[i..i + LANES];
        [s[0], s[1], s[2], s[3]]
    }

    /// Distance to primitive `i` along the ray, if it is hit with `0 < t < t_max`.
    #[inline(always)]
    pub fn hit(&self, i: u32, ray: &Ray, t_max: f32) -> Option<f32> {
        match self.kind[i as usize] {
            SPHERE => self.sphere(i as usize).intersect(ray, t_max).map(|h| h.t),
            k => self.objects[k as usize].hit(ray, t_max).map(|h| h.t),
        }
    }

    /// Primitive `i`'s hit with `0 < t < t_max`, in world space.
    #[inline]
    pub fn intersect(&self, i: u32, ray: &Ray, t_max: f32) -> Option<SurfaceHit> {
        match self.kind[i as usize] {
            SPHERE => self
                .sphere(i as usize)
                .intersect(ray, t_max)
                .map(|h| sphere_surface(&h)),
            k => self.objects[k as usize].intersect(ray, t_max),
        }
    }

    /// Nearest surface along the ray with `t < t_max`.
    #[inline]
    pub fn closest(&self, ray: &Ray, t_max: f32) -> Option<(u32, SurfaceHit)> {
        // The winner's object-space hit, kept for its surface (spheres recompute theirs).
        let mut best: Option<(u32, f32, Option<ShapeHit>)> = None;
        let mut t_best = t_max;
        for i in self.unbounded..self.len() as u32 {
            if let Some(h) = self.shape_hit(i, ray, t_best) {
                t_best = h.t;
                best = Some((i, h.t, Some(h)));
            }
        }
        let lanes = SphereRay::new(ray);
        // Primitives in the order the hierarchy offers them, a strictly closer hit replacing
        // the kept one: of equally close hits the first offered wins.
        self.bvh.closest_leaves(ray, t_best, |leaf, t_max| {
            self.closest_in_leaf(&lanes, ray, leaf, t_max, &mut best)
        });
        let (i, t, hit) = best?;
        let surface = match (self.kind[i as usize], hit) {
            (SPHERE, _) => sphere_surface(&self.sphere(i as usize).hit_at(ray, t)),
            (o, Some(h)) => self.objects[o as usize].surface(&h),
            (_, None) => unreachable!("objects keep their hit"),
        };
        Some((i, surface))
    }

    /// Tests one leaf's primitives in their order (see `closest`); returns the new `t_max`.
    #[inline(always)]
    fn closest_in_leaf(
        &self,
        lanes: &SphereRay,
        ray: &Ray,
        leaf: &[u32],
        mut t_max: f32,
        best: &mut Option<(u32, f32, Option<ShapeHit>)>,
    ) -> f32 {
        let first = leaf[0] as usize;
        for start in (first..first + leaf.len()).step_by(LANES) {
            // Tested when the first sphere comes up, so leaves of other kinds skip it.
            let mut four = None;
            for k in 0..(first + leaf.len() - start).min(LANES) {
                let i = start + k;
                match self.kind[i] {
                    SPHERE => {
                        let (mask, t) = *four
                            .get_or_insert_with(|| lanes.hit4(self.four_spheres(start), t_max));
                        if mask & (1 << k) != 0 && t[k] < t_max {
                            t_max = t[k];
                            *best = Some((i as u32, t_max, None));
                        }
                    }
                    o => {
                        if let Some(h) = self.objects[o as usize].hit(ray, t_max) {
                            t_max = h.t;
                            *best = Some((i as u32, t_max, Some(h)));
                        }
                    }
                }
            }
        }
        t_max
    }

    #[inline]
    fn shape_hit(&self, i: u32, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        match self.kind[i as usize] {
            SPHERE => self.sphere(i as usize).intersect(ray, t_max),
            k => self.objects[k as usize].hit(ray, t_max),
        }
    }

    /// Whether anything lies on the ray before `t_max`.
    #[inline]
    pub fn occluded(&self, ray: &Ray, t_max: f32) -> bool {
        if (self.unbounded..self.len() as u32).any(|i| self.hit(i, ray, t_max).is_some()) {
            return true;
        }
        let lanes = SphereRay::new(ray);
        self.bvh.any_leaves(ray, t_max, |leaf| {
            let first = leaf[0] as usize;
            (first..first + leaf.len()).step_by(LANES).any(|start| {
                let live = (first + leaf.len() - start).min(LANES);
                let kinds = &self.kind[start..start + live];
                // Other kinds hold NaN, which no sphere test hits.
                (kinds.contains(&SPHERE)
                    && lanes.hit4(self.four_spheres(start), t_max).0 & ((1 << live) - 1) != 0)
                    || kinds
                        .iter()
                        .any(|&k| k != SPHERE && self.objects[k as usize].hit(ray, t_max).is_some())
            })
        })
    }

    /// Offers every primitive the ray may meet before `t_max` to `stop`, in no particular
    /// order, until it returns true (then true).
    #[inline]
    pub fn any_candidate(&self, ray: &Ray, t_max: f32, mut stop: impl FnMut(u32) -> bool) -> bool {
        (self.unbounded..self.len() as u32).any(&mut stop) || self.bvh.any(ray, t_max, stop)
    }

    /// Bytes the scene's geometry holds (primitives and hierarchy, not materials or lights).
    pub fn geometry_bytes(&self) -> usize {
        self.material.capacity() * 4
            + self.kind.capacity() * 4
            + self.spheres.capacity() * std::mem::size_of::<Vec4>()
            + self.objects.capacity() * std::mem::size_of::<Primitive>()
            + self.bvh.memory_bytes()
    }
}

/// What `Primitive::surface` makes of a world-space hit: the normal renormalised.
#[inline]
fn sphere_surface(h: &ShapeHit) -> SurfaceHit {
    SurfaceHit::on_face(h.t, h.point, h.normal.normalize_or_zero())
}
