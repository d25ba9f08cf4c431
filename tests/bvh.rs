//! Differential test of the wide BVH against brute force over real primitives: random scenes
//! of spheres, boxes and triangles (some transformed, so kept in object space); the closest
//! hit's distance and primitive, and any-hit answers, must equal testing every primitive. The
//! render scene (spheres packed four to a test, leaf-ordered storage) is held to the same
//! standard, and its hits to the bits `Primitive` computes.

use anim_core::accel::{Bvh, Packet};
use anim_core::math::{Ray, Transform};
use anim_core::render::compile::{RenderScene, Shadow};
use anim_core::render::primitive::{Primitive, SurfaceHit};
use anim_core::scene::{Instance, Material, Scene};
use anim_core::shape::Geometry;
use glam::{DVec3, Vec3, Vec3A};

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    fn vec(&mut self, scale: f64) -> DVec3 {
        DVec3::new(self.next(), self.next(), self.next()) * scale
    }
}

fn random_scene(rng: &mut Rng, n: usize) -> Vec<Primitive> {
    let mut prims = Vec::new();
    while prims.len() < n {
        let c = rng.vec(50.0);
        let geometry = match prims.len() % 3 {
            0 => Geometry::Sphere {
                center: c,
                radius: 0.2 + rng.next() * 2.0,
            },
            1 => Geometry::Box {
                p1: c,
                p2: c + rng.vec(3.0) + DVec3::splat(0.05),
            },
            _ => Geometry::Triangle {
                vertices: [c, c + rng.vec(4.0), c + rng.vec(4.0)],
            },
        };
        // Every seventh primitive rotated, so it keeps its matrix.
        let transform = if prims.len() % 7 == 3 {
            let turn = Transform::rotate(10.0 + rng.next() * 70.0, DVec3::Y).unwrap();
            Transform::translate(c).then_after(&turn.then_after(&Transform::translate(-c)))
        } else {
            Transform::IDENTITY
        };
        if let Ok(p) = Primitive::new(&geometry, &transform, 0) {
            prims.push(p);
        }
    }
    prims
}

fn random_ray(rng: &mut Rng, i: usize) -> Ray {
    let o = rng.vec(80.0) - DVec3::splat(15.0);
    let mut dir = (rng.vec(50.0) - o).normalize();
    if i.is_multiple_of(4) {
        // Axis-parallel: direction components of exactly zero.
        dir = DVec3::ZERO;
        dir[i / 4 % 3] = if rng.next() < 0.5 { 1.0 } else { -1.0 };
    }
    Ray::new(Vec3A::from(o.as_vec3()), Vec3A::from(dir.as_vec3()))
}

/// Every third ray is bounded, so that the `t_max` paths are exercised too.
fn t_limit_of(i: usize) -> f32 {
    if i.is_multiple_of(3) {
        40.0
    } else {
        f32::INFINITY
    }
}

/// The nearest hit by testing every primitive in order (the first of equal distances wins).
fn brute_closest(prims: &[Primitive], ray: &Ray, t_limit: f32) -> Option<(usize, f32)> {
    let mut best: Option<(usize, f32)> = None;
    for (k, p) in prims.iter().enumerate() {
        let t_max = best.map_or(t_limit, |(_, t)| t);
        if let Some(h) = p.hit(ray, t_max) {
            best = Some((k, h.t));
        }
    }
    best
}

#[test]
fn wide_bvh_equals_brute_force_on_random_scenes() {
    let mut rng = Rng(0x853C49E6748FEA9B);
    for n in [1, 5, 60, 1500] {
        let prims = random_scene(&mut rng, n);
        let bounds: Vec<_> = prims.iter().map(|p| p.bounds).collect();
        let bvh = Bvh::build(&bounds, 0..prims.len() as u32);
        let mut hits = 0;
        for i in 0..4000 {
            let ray = random_ray(&mut rng, i);
            let t_limit = t_limit_of(i);
            let brute = brute_closest(&prims, &ray, t_limit).map(|(k, t)| (k as u32, t));
            let mut found: Option<(u32, f32)> = None;
            let t = bvh.closest(&ray, t_limit, |k, t_max| {
                let h = prims[k as usize].hit(&ray, t_max)?;
                found = Some((k, h.t));
                Some(h.t)
            });
            assert_eq!(
                brute.map(|(_, t)| t),
                found.map(|(_, t)| t),
                "n={n} ray {i}"
            );
            assert_eq!(t, found.map_or(t_limit, |(_, t)| t));
            if let (Some((a, _)), Some((b, _))) = (brute, found) {
                // The same primitive, unless two are hit at exactly the same distance.
                assert!(
                    a == b
                        || prims[a as usize].hit(&ray, t_limit).map(|h| h.t)
                            == prims[b as usize].hit(&ray, t_limit).map(|h| h.t)
                );
            }
            let blocked = bvh.any(&ray, t_limit, |k| {
                prims[k as usize].hit(&ray, t_limit).is_some()
            });
            assert_eq!(blocked, brute.is_some(), "n={n} ray {i}");
            hits += usize::from(brute.is_some());
        }
        // Not vacuous: a fair share of the rays meet something.
        assert!(n < 1500 || hits > 1000, "{hits} hits");
    }
}

/// Mostly world-space spheres (so leaves of four spheres, and leaves mixing spheres with other
/// kinds), with boxes, triangles, rotated and stretched shapes, an exact duplicate sphere (a
/// tie) and a plane. Instance `i` has material `i`, which names it after renumbering.
/// Each instance has its own transform slot, with the same index.
fn mixed_instances(rng: &mut Rng, n: usize) -> (Vec<Instance>, Vec<Transform>) {
    let mut transforms = Vec::new();
    let mut push = |out: &mut Vec<Instance>, geometry: Geometry, transform: Transform| {
        let material = out.len();
        let mut instance = Instance::new(geometry, material);
        instance.transform = transforms.len() as u32;
        transforms.push(transform);
        out.push(instance);
    };
    let mut out = Vec::new();
    for i in 0..n {
        let c = rng.vec(50.0);
        let spin = |rng: &mut Rng| {
            let turn = Transform::rotate(10.0 + rng.next() * 70.0, DVec3::Y).unwrap();
            Transform::translate(c).then_after(&turn.then_after(&Transform::translate(-c)))
        };
        match i % 10 {
            0 => push(
                &mut out,
                Geometry::Triangle {
                    vertices: [c, c + rng.vec(4.0), c + rng.vec(4.0)],
                },
                Transform::IDENTITY,
            ),
            1 => push(
                &mut out,
                Geometry::Box {
                    p1: c,
                    p2: c + rng.vec(3.0) + DVec3::splat(0.05),
                },
                spin(rng),
            ),
            2 => {
                let stretch = Transform::scale(DVec3::new(2.0, 0.5, 1.0)).unwrap();
                push(
                    &mut out,
                    Geometry::Sphere {
                        center: DVec3::ZERO,
                        radius: 0.5 + rng.next(),
                    },
                    Transform::translate(c).then_after(&stretch),
                )
            }
            _ => push(
                &mut out,
                Geometry::Sphere {
                    center: c,
                    radius: 0.2 + rng.next() * 2.0,
                },
                Transform::IDENTITY,
            ),
        }
    }
    let twin = out[3].geometry.clone();
    push(&mut out, twin, Transform::IDENTITY);
    push(
        &mut out,
        Geometry::Plane {
            point: DVec3::new(0.0, -5.0, 0.0),
            normal: DVec3::new(0.1, 1.0, 0.05),
        },
        Transform::IDENTITY,
    );
    (out, transforms)
}

/// Also on scenes of world-space spheres only (with a duplicate: a tie), which the render
/// scene tests without looking at kinds, and of world-space boxes only (with a duplicate, and
/// rooms around every ray origin); `occluder` names a primitive that is really hit.
#[test]
fn render_scene_equals_brute_force_on_mixed_scenes() {
    let mut rng = Rng(0x2545F4914F6CDD1D);
    for (n, spheres_only) in [
        (4, false),
        (40, false),
        (2000, false),
        (40, true),
        (2000, true),
    ] {
        let (instances, transforms) = mixed_instances(&mut rng, n);
        check_render_scene(
            &mut rng,
            n,
            instances_only(instances, &transforms, spheres_only),
            transforms,
        );
    }
    for n in [3, 40, 600] {
        let (instances, transforms) = world_boxes(&mut rng, n);
        check_render_scene(&mut rng, n, instances, transforms);
    }
}

/// World-space axis-aligned boxes (tested by distance alone, the surface built for the
/// winner): small ones, an exact duplicate (a tie), and rooms enclosing every ray origin,
/// so that rays start inside boxes and leave through them.
fn world_boxes(rng: &mut Rng, n: usize) -> (Vec<Instance>, Vec<Transform>) {
    let mut geometry: Vec<Geometry> = (0..n)
        .map(|_| {
            let c = rng.vec(50.0);
            Geometry::Box {
                p1: c,
                p2: c + rng.vec(6.0),
            }
        })
        .collect();
    geometry.push(geometry[1].clone());
    for half in [300.0, 400.0] {
        geometry.push(Geometry::Box {
            p1: DVec3::splat(-half),
            p2: DVec3::new(half, half, half * 0.9),
        });
    }
    let instances = geometry
        .into_iter()
        .enumerate()
        .map(|(k, g)| Instance::new(g, k))
        .collect();
    (instances, vec![Transform::IDENTITY])
}

/// With `spheres_only`, the world-space spheres alone, renumbered.
fn instances_only(
    mut instances: Vec<Instance>,
    transforms: &[Transform],
    spheres_only: bool,
) -> Vec<Instance> {
    if spheres_only {
        instances.retain(|i| {
            matches!(i.geometry, Geometry::Sphere { .. })
                && transforms[i.transform as usize] == Transform::IDENTITY
        });
        for (k, i) in instances.iter_mut().enumerate() {
            i.material = k;
        }
    }
    instances
}

/// `closest`, `intersect`, `occluded` and `occluder` of the render scene against brute force.
fn check_render_scene(
    rng: &mut Rng,
    n: usize,
    instances: Vec<Instance>,
    transforms: Vec<Transform>,
) {
    let prims: Vec<Primitive> = instances
        .iter()
        .map(|i| {
            let xf = &transforms[i.transform as usize];
            Primitive::new(&i.geometry, xf, i.material as u32).unwrap()
        })
        .collect();
    let scene = Scene {
        materials: (0..instances.len())
            .map(|i| Material::phong(&format!("m{i}"), Vec3::ONE, Vec3::ONE, Vec3::ONE, 1.0))
            .collect(),
        instances: instances.into(),
        transforms,
        ..Scene::default()
    };
    let (render, dropped) = RenderScene::compile(&scene);
    assert!(dropped.is_empty());
    assert_eq!(render.len(), prims.len());
    let mut hits = 0;
    for i in 0..4000 {
        let ray = random_ray(rng, i);
        let t_limit = t_limit_of(i);
        let brute = brute_closest(&prims, &ray, t_limit);
        let found = render.closest(&ray, t_limit);
        assert_eq!(
            brute.map(|(_, t)| t.to_bits()),
            found.map(|(_, h)| h.t.to_bits()),
            "n={n} ray {i}"
        );
        if let (Some((a, t)), Some((slot, h))) = (brute, found) {
            let b = render.material_of(slot) as usize;
            // The same primitive, unless two are hit at exactly the same distance.
            assert!(a == b || prims[b].hit(&ray, t_limit).map(|h| h.t) == Some(t));
            let expected = prims[b].intersect(&ray, t_limit).unwrap();
            assert_eq!(
                (expected.point.to_array(), expected.normal.to_array()),
                (h.point.to_array(), h.normal.to_array()),
                "n={n} ray {i}: surface of primitive {b}"
            );
            let again = render.intersect(slot, &ray, t_limit).unwrap();
            assert_eq!(again.t.to_bits(), h.t.to_bits());
            hits += 1;
        }
        assert_eq!(
            render.occluded(&ray, t_limit),
            brute.is_some(),
            "n={n} ray {i}"
        );
        let occluder = render.occluder(&ray, t_limit);
        assert_eq!(occluder.is_some(), brute.is_some(), "n={n} ray {i}");
        if let Some(id) = occluder {
            assert!(render.hit(id, &ray, t_limit).is_some(), "n={n} ray {i}");
        }
    }
    assert!(n < 2000 || hits > 1000, "{hits} hits");
    let hits = check_packets(rng, &render, DVec3::splat(-15.0), DVec3::splat(80.0));
    assert!(n < 600 || hits > 2000, "{hits} hits of packet rays");
}

/// Packets of eight rays from one origin towards nearby points (a fan narrow enough to share
/// an octant, as the camera rays of a pixel block do; some axis-parallel, some with limits,
/// some mixing octants, which go ray by ray): every ray's closest hit is `closest`'s to the
/// bit, the same primitive included. Origins lie in `lo + [0, size)³`. Returns how many
/// rays hit.
fn check_packets(rng: &mut Rng, scene: &RenderScene, lo: DVec3, size: DVec3) -> usize {
    let (mut packets, mut hits) = (0, 0);
    for i in 0..1500 {
        let origin = lo + rng.vec(1.0) * size;
        let target = lo + rng.vec(1.0) * size;
        let spread = [0.05, 0.5, 4.0][i % 3];
        let rays: [Ray; 8] = std::array::from_fn(|k| {
            let mut dir = (target + rng.vec(spread) - origin).normalize();
            if i % 10 == 0 {
                // Axis-parallel: zero direction components in every lane.
                let axis = i / 10 % 3;
                let sign = dir[axis].signum();
                dir = DVec3::ZERO;
                dir[axis] = sign;
            } else if i % 10 == 5 && k % 2 == 1 {
                // An exact copy of its neighbour: the same hits, ties included.
                dir = (target - origin).normalize();
            }
            Ray::new(Vec3A::from(origin.as_vec3()), Vec3A::from(dir.as_vec3()))
        });
        let t_limit = t_limit_of(i);
        packets += usize::from(Packet::new(&rays).is_some());
        let together = scene.closest_packet(&rays, t_limit);
        for (k, ray) in rays.iter().enumerate() {
            let bits = |h: Option<(u32, anim_core::render::primitive::SurfaceHit)>| {
                h.map(|(id, h)| {
                    (
                        id,
                        h.t.to_bits(),
                        h.point.to_array().map(f32::to_bits),
                        h.normal.to_array().map(f32::to_bits),
                    )
                })
            };
            let alone = scene.closest(ray, t_limit);
            hits += usize::from(alone.is_some());
            assert_eq!(bits(together[k]), bits(alone), "packet {i} ray {k}");
        }
    }
    // Not vacuous: most packets go together.
    assert!(packets > 1000, "{packets} packets");
    hits
}

#[path = "common/composites.rs"]
mod composites;

/// The render scene of a file's first job.
fn loaded_scene(text: &str) -> Scene {
    let loaded = anim_core::scene::load_str(
        text,
        std::path::Path::new("scene.sdf"),
        // A small budget: the composites are then worth instancing.
        &anim_core::sdf::LoadOptions {
            max_memory: 1 << 20,
            ..anim_core::sdf::LoadOptions::default()
        },
    )
    .unwrap_or_else(|d| panic!("{d:?}"));
    loaded.jobs[0].scene.clone()
}

/// The nearest hit over primitives in the flattened tree's order, as the render scene
/// resolves ties: unbounded primitives first, then the first in the tree.
fn brute_in_tree_order(prims: &[Primitive], ray: &Ray, t_limit: f32) -> Option<(usize, f32)> {
    let mut best: Option<(usize, f32)> = None;
    for bounded in [false, true] {
        for (k, p) in prims.iter().enumerate() {
            if p.is_bounded() != bounded {
                continue;
            }
            let t_max = best.map_or(t_limit, |(_, t)| t);
            if let Some(h) = p.hit(ray, t_max) {
                best = Some((k, h.t));
            }
        }
    }
    best
}

/// Instancing differential: a scene with shared and nested-shared composites, transforms and
/// exact ties, loaded as written (instanced) and with every use copied (flattened), must give
/// the same closest hits to the bit (distance, point, normal, material, the same winner of
/// ties), the same any-hit answers, and ids that tell the same primitives apart; both agree
/// with testing every primitive of the flattened tree in its order.
#[test]
fn instanced_render_scene_equals_flattened_and_brute_force() {
    for seed in [1, 2, 3] {
        let tree = composites::mixed(seed);
        let instanced = loaded_scene(&format!("{}{}", composites::MATERIALS, tree.shared()));
        let flat = loaded_scene(&format!("{}{}", composites::MATERIALS, tree.flattened()));
        assert!(instanced.has_prototypes() && !flat.has_prototypes());
        assert!(instanced.instances.len() < flat.instances.len() / 2);
        // The same shapes with bit-identical world transforms, in the same order.
        let expanded = instanced.flattened();
        assert_eq!(expanded.len(), flat.instances.len());
        assert_eq!(instanced.shape_count(), flat.instances.len() as u64);
        for ((inst, xf), f) in expanded.iter().zip(flat.instances.iter()) {
            assert_eq!((&inst.geometry, inst.material), (&f.geometry, f.material));
            assert_eq!(xf, flat.transform_of(f));
        }
        let prims: Vec<Primitive> = flat
            .instances
            .iter()
            .map(|i| Primitive::new(&i.geometry, flat.transform_of(i), i.material as u32).unwrap())
            .collect();
        let (a, dropped_a) = RenderScene::compile(&instanced);
        let (b, dropped_b) = RenderScene::compile(&flat);
        assert!(dropped_a.is_empty() && dropped_b.is_empty());
        assert!(a.instance_uses() > 0);
        let mut rng = Rng(seed.wrapping_mul(0x9E3779B97F4A7C15));
        let (mut hits, mut ties) = (0, 0);
        let mut same_id = std::collections::HashMap::new();
        let mut same_id_back = std::collections::HashMap::new();
        for i in 0..6000 {
            let o = rng.vec(100.0) - DVec3::new(50.0, 30.0, 20.0);
            let target = rng.vec(1.0) * DVec3::new(70.0, 50.0, 60.0) - DVec3::new(40.0, 25.0, 80.0);
            let mut dir = (target - o).normalize();
            if i % 5 == 0 {
                dir = DVec3::ZERO;
                dir[i / 5 % 3] = if rng.next() < 0.5 { 1.0 } else { -1.0 };
            }
            let ray = Ray::new(Vec3A::from(o.as_vec3()), Vec3A::from(dir.as_vec3()));
            let t_limit = t_limit_of(i);
            let brute = brute_in_tree_order(&prims, &ray, t_limit);
            let (ha, hb) = (a.closest(&ray, t_limit), b.closest(&ray, t_limit));
            let bits = |h: &Option<(u32, anim_core::render::primitive::SurfaceHit)>,
                        s: &RenderScene| {
                h.map(|(id, h)| {
                    (
                        h.t.to_bits(),
                        h.point.to_array().map(f32::to_bits),
                        h.normal.to_array().map(f32::to_bits),
                        s.material_of(id),
                    )
                })
            };
            assert_eq!(bits(&ha, &a), bits(&hb, &b), "seed {seed} ray {i}");
            assert_eq!(
                brute.map(|(k, t)| (t.to_bits(), prims[k].material)),
                hb.map(|(id, h)| (h.t.to_bits(), b.material_of(id))),
                "seed {seed} ray {i}"
            );
            if let (Some((k, t)), Some((ida, _)), Some((idb, _))) = (brute, ha, hb) {
                hits += 1;
                let tied = prims
                    .iter()
                    .enumerate()
                    .filter(|&(j, p)| j != k && p.hit(&ray, t_limit).is_some_and(|h| h.t == t))
                    .count();
                ties += usize::from(tied > 0);
                assert_eq!(
                    *same_id.entry(ida).or_insert(idb),
                    idb,
                    "seed {seed} ray {i}"
                );
                assert_eq!(
                    *same_id_back.entry(idb).or_insert(ida),
                    ida,
                    "seed {seed} ray {i}"
                );
                let again = a.intersect(ida, &ray, t_limit).unwrap();
                assert_eq!(again.t.to_bits(), t.to_bits());
            }
            let blocked = brute.is_some();
            assert_eq!(a.occluded(&ray, t_limit), blocked, "seed {seed} ray {i}");
            assert_eq!(b.occluded(&ray, t_limit), blocked, "seed {seed} ray {i}");
            for s in [&a, &b] {
                let occluder = s.occluder(&ray, t_limit);
                assert_eq!(occluder.is_some(), blocked, "seed {seed} ray {i}");
                if let Some(id) = occluder {
                    assert!(s.hit(id, &ray, t_limit).is_some(), "seed {seed} ray {i}");
                }
            }
            let any = a.any_candidate(&ray, t_limit, |id| a.hit(id, &ray, t_limit).is_some());
            assert_eq!(any, blocked, "seed {seed} ray {i}");
        }
        let (lo, size) = (DVec3::new(-50.0, -30.0, -20.0), DVec3::splat(100.0));
        for s in [&a, &b] {
            let packet_hits = check_packets(&mut rng, s, lo, size);
            assert!(
                packet_hits > 2000,
                "seed {seed}: {packet_hits} hits of packet rays"
            );
        }
        // Not vacuous: many rays meet something, and some meet two surfaces at once.
        assert!(hits > 1500, "seed {seed}: {hits} hits");
        assert!(ties > 20, "seed {seed}: {ties} ties");
    }
}

/// Shadow rays in scenes of few shapes, where each light keeps direction cells around itself
/// (a light buffer) and a shadow ray tests only what its cell lists: blocked exactly when
/// brute force finds a hit before the light. Camera rays likewise, from the eye's cells. Origins are lifted off at random by up to 10⁻³
/// (as `SurfaceHit::spawn_ray` moves them), and lights sit among the shapes, inside the
/// rooms, and far off. Rays aimed elsewhere must be answered too (the cells then answer
/// nothing, and the whole scene is tested).
#[test]
fn rays_through_direction_cells_meet_what_brute_force_meets() {
    let mut rng = Rng(0x9E3779B97F4A7C15);
    let mut blocked = 0;
    let mut clear = 0;
    let mut seen_hits = 0;
    let scenes = [
        mixed_instances(&mut rng, 6),
        mixed_instances(&mut rng, 13),
        world_boxes(&mut rng, 5),
        world_boxes(&mut rng, 10),
    ];
    for (instances, transforms) in scenes {
        let lights: Vec<DVec3> = (0..4)
            .map(|k| match k {
                0 => DVec3::new(200.0, 300.0, -150.0),
                _ => rng.vec(60.0) - DVec3::splat(5.0),
            })
            .collect();
        let (scene, prims) = lit_scene(instances, transforms, &lights);
        let (mut render, dropped) = RenderScene::compile(&scene);
        assert!(dropped.is_empty());
        // Camera rays from an eye with cells around it (and rays from elsewhere): the same
        // hit as `closest` and brute force find, to the bit.
        let eye = rng.vec(60.0) - DVec3::splat(5.0);
        let eye = Vec3A::from(eye.as_vec3());
        render.watch_from(eye);
        for i in 0..3000 {
            let ray = if i % 5 == 4 {
                random_ray(&mut rng, i)
            } else {
                let towards = Vec3A::from((rng.vec(2.0) - DVec3::ONE).as_vec3());
                Ray::new(eye, towards.normalize())
            };
            seen_hits += check_seen(&render, &prims, &ray, i) as usize;
        }
        let (b, c) = tally_shadows(&render, &prims, &lights, 3000, |light, i| {
            if i % 5 == 4 {
                (random_ray(&mut rng, i), t_limit_of(i))
            } else {
                shadow_ray(&mut rng, light, i)
            }
        });
        (blocked, clear) = (blocked + b, clear + c);
    }
    assert_both_kinds(blocked, clear, 5000);
    assert!(seen_hits > 2000, "{seen_hits} camera rays hit");
}

/// The scene of `instances` (one material) lit by point lights at `lights`, and its shapes as
/// primitives for brute force.
fn lit_scene(
    instances: Vec<Instance>,
    transforms: Vec<Transform>,
    lights: &[DVec3],
) -> (Scene, Vec<Primitive>) {
    let prims = instances
        .iter()
        .map(|i| Primitive::new(&i.geometry, &transforms[i.transform as usize], 0).unwrap())
        .collect();
    let scene = Scene {
        materials: vec![Material::phong("m", Vec3::ONE, Vec3::ONE, Vec3::ONE, 1.0)],
        instances: instances
            .into_iter()
            .map(|mut i| {
                i.material = 0;
                i
            })
            .collect::<Vec<_>>()
            .into(),
        transforms,
        lights: lights
            .iter()
            .map(|&position| anim_core::scene::Light {
                name: "l".into(),
                position,
                intensity: Vec3::ONE,
            })
            .collect(),
        ..Scene::default()
    };
    (scene, prims)
}

/// `closest_seen` of a camera ray against `closest` (to the bit) and brute force (the
/// distance); whether it hit.
fn check_seen(render: &RenderScene, prims: &[Primitive], ray: &Ray, i: usize) -> bool {
    let seen = render.closest_seen(ray);
    let found = render.closest(ray, f32::INFINITY);
    let brute = brute_closest(prims, ray, f32::INFINITY);
    assert_eq!(
        seen.map(|(_, h)| h.t.to_bits()),
        brute.map(|(_, t)| t.to_bits()),
        "camera ray {i}: {ray:?}"
    );
    let bits = |h: Option<(u32, SurfaceHit)>| {
        h.map(|(id, h)| (id, h.point.to_array(), h.normal.to_array()))
    };
    assert_eq!(bits(seen), bits(found), "camera ray {i}");
    seen.is_some()
}

/// A ray from a random point of the scenes' region towards `light`, its start lifted off at
/// random by up to 10⁻³ (as `SurfaceHit::spawn_ray` moves it) for two rays in three, and its
/// length to the light.
fn shadow_ray(rng: &mut Rng, light: Vec3A, i: usize) -> (Ray, f32) {
    let from = Vec3A::from((rng.vec(80.0) - DVec3::splat(15.0)).as_vec3());
    let dir = (light - from).normalize();
    let lift = Vec3A::from((rng.vec(2e-3) - DVec3::splat(1e-3)).as_vec3());
    let origin = from + lift * (i % 3) as f32;
    (Ray::new(origin, dir), (light - origin).dot(dir))
}

/// `shadow` of a ray towards light `k` against brute force (opaque shapes only); whether it
/// is blocked.
fn check_shadow(
    render: &RenderScene,
    prims: &[Primitive],
    ray: &Ray,
    t_limit: f32,
    k: usize,
) -> bool {
    let brute = brute_closest(prims, ray, t_limit).is_some();
    let found = render.shadow(ray, t_limit, k);
    match found {
        Shadow::Clear => {}
        Shadow::Blocked(id) => assert!(render.hit(id, ray, t_limit).is_some(), "{ray:?}"),
        other => panic!("opaque shapes only, yet {other:?}"),
    }
    assert_eq!(found != Shadow::Clear, brute, "light {k}: {ray:?}");
    brute
}

/// That a test met more than `at_least` blocked and as many clear shadow rays: it checked
/// both answers, not one.
fn assert_both_kinds(blocked: usize, clear: usize, at_least: usize) {
    assert!(
        blocked > at_least && clear > at_least,
        "{blocked} blocked, {clear} clear"
    );
}

/// `check_shadow` of `n` rays towards each of `lights` (`ray(light, i)`: ray `i` and its
/// length); how many were blocked, and how many clear.
fn tally_shadows(
    render: &RenderScene,
    prims: &[Primitive],
    lights: &[DVec3],
    n: usize,
    mut ray: impl FnMut(Vec3A, usize) -> (Ray, f32),
) -> (usize, usize) {
    let (mut blocked, mut clear) = (0, 0);
    for (k, light) in lights.iter().enumerate() {
        let light = Vec3A::from(light.as_vec3());
        for i in 0..n {
            let (ray, t_limit) = ray(light, i);
            *if check_shadow(render, prims, &ray, t_limit, k) {
                &mut blocked
            } else {
                &mut clear
            } += 1;
        }
    }
    (blocked, clear)
}

/// Image tiles (`RenderScene::watch_image`): in scenes larger than a flat one (mixed kinds
/// with a plane, world boxes with rooms around the eye, world spheres alone), camera rays
/// through random points of the image (and a few beyond its edges, or from elsewhere) get
/// `closest`'s hit to the bit, and brute force's distance; shadow rays towards lights far
/// off, among the shapes and inside the rooms, lifted off their start as `spawn_ray` does,
/// are blocked exactly when brute force finds a hit before the light.
#[test]
fn rays_through_image_tiles_meet_what_brute_force_meets() {
    use anim_core::render::camera::CameraRays;
    use anim_core::scene::Camera;
    let mut rng = Rng(0xD1B54A32D192ED03);
    let (mut blocked, mut clear, mut seen_hits) = (0, 0, 0);
    // Enough shapes for tiles around the lights too (64 bounded, `LIGHT_TILES_MIN`).
    let (mixed, mixed_transforms) = mixed_instances(&mut rng, 120);
    let spheres = instances_only(mixed.clone(), &mixed_transforms, true);
    assert!(spheres.len() >= 64);
    // And spheres packed close, where rays meet several and the nearest-first cut decides.
    let dense = (0..400)
        .map(|k| {
            let geometry = Geometry::Sphere {
                center: rng.vec(30.0) + DVec3::splat(10.0),
                radius: 0.5 + rng.next() * 2.0,
            };
            Instance::new(geometry, k)
        })
        .collect();
    let scenes = [
        (mixed, mixed_transforms.clone()),
        world_boxes(&mut rng, 80),
        (spheres, mixed_transforms),
        (dense, vec![Transform::IDENTITY]),
    ];
    for (instances, transforms) in scenes {
        let lights: Vec<DVec3> = (0..4)
            .map(|k| match k {
                0 => DVec3::new(200.0, 300.0, -150.0),
                1 => DVec3::new(-90.0, 20.0, 25.0),
                _ => rng.vec(60.0) - DVec3::splat(5.0),
            })
            .collect();
        let (scene, prims) = lit_scene(instances, transforms, &lights);
        let (mut render, dropped) = RenderScene::compile(&scene);
        assert!(dropped.is_empty());
        let mut camera = Camera::default_with_fov("c", 40.0 + 60.0 * rng.next());
        camera.eye = DVec3::new(25.0, 25.0, 110.0) + rng.vec(10.0);
        camera.dir = DVec3::splat(25.0) - camera.eye + rng.vec(20.0);
        let (width, height) = (96, 54);
        let rays = CameraRays::new(&camera, width, height).unwrap();
        render.watch_image(rays.view(), (width, height), u64::MAX);
        // Packets of a 4×4 block of pixels (one sample position each, as the uniform path
        // traces them), and of a run of 8 pixels of a row: each ray's hit is its own.
        for i in 0..300 {
            let (bx, by) = (
                (rng.next() * 24.0) as u32 * 4,
                (rng.next() * 13.0) as u32 * 4,
            );
            let (dx, dy) = (rng.next() as f32, rng.next() as f32);
            let at = |k: u32, w: u32| (bx + k % w) as f32 + dx;
            let block: [Ray; 16] =
                std::array::from_fn(|k| rays.ray(at(k as u32, 4), (by + k as u32 / 4) as f32 + dy));
            let run: [Ray; 8] = std::array::from_fn(|k| rays.ray(at(k as u32, 8), by as f32 + dy));
            let bits = |h: &Option<(u32, SurfaceHit)>| {
                h.map(|(id, h)| (id, h.t.to_bits(), h.normal.to_array()))
            };
            for (ray, hit) in block.iter().zip(render.closest_seen_packet(&block)) {
                assert_eq!(
                    bits(&hit),
                    bits(&render.closest_seen(ray)),
                    "block {i}: {ray:?}"
                );
            }
            for (ray, hit) in run.iter().zip(render.closest_seen_packet(&run)) {
                assert_eq!(
                    bits(&hit),
                    bits(&render.closest_seen(ray)),
                    "run {i}: {ray:?}"
                );
            }
        }
        for i in 0..4000 {
            let (x, y) = (
                rng.next() as f32 * 100.0 - 2.0,
                rng.next() as f32 * 58.0 - 2.0,
            );
            let ray = if i % 9 == 8 {
                random_ray(&mut rng, i)
            } else {
                rays.ray(x, y)
            };
            seen_hits += check_seen(&render, &prims, &ray, i) as usize;
        }
        let (b, c) = tally_shadows(&render, &prims, &lights, 4000, |light, i| {
            shadow_ray(&mut rng, light, i)
        });
        (blocked, clear) = (blocked + b, clear + c);
    }
    assert_both_kinds(blocked, clear, 5000);
    assert!(seen_hits > 3000, "{seen_hits} camera rays hit");
}

/// A frame with motion blur keeps its direction cells (a moving shape listed by its bounds
/// over the exposure; no light keeps cells once a light moves): camera rays from the eye and
/// shadow rays towards the lights, at instants all over the exposure, meet what the
/// hierarchy finds, to the bit, moving shapes included.
#[test]
fn direction_cells_in_a_frame_with_motion_answer_as_the_hierarchy() {
    let shapes = "define material m 0.1 0.1 0.1 0.5 0.5 0.5 0 0 0 1\n\
        define shape box floor -8 -3 -20 8 -2.5 0 m\n\
        define shape box wall -8 -3 -21 8 6 -20 m\n\
        define shape sphere a -3 0 -12 1 m\n\
        define shape sphere b 3 1 -14 1.5 m\n\
        define shape cylinder post -5 -2.5 -16 -5 3 -16 0.4 m\n\
        define shape box crate 1 -2.5 -9 2.5 -1 -7.5 m\n\
        define shape sphere slide -4 -0.5 -8 1.5 m\n\
        define shape box blade -3 1.2 -10 3 2.4 -9.6 m\n\
        define shape sphere c1 0 -1 -11 0.9 m\n\
        define shape box c2 -0.5 -2.5 -11.5 0.5 -2 -10.5 m\n\
        define shape composite pair c1 c2\n\
        define light key -6 8 -2 1 1 1 1\n\
        define light fill 7 3 -4 1 1 1 1\n\
        define camera eye 60\n\
        motion slide 0 translate -1 0 0\nmotion slide 0.5\nmotion slide 1 translate 6 0 0\n\
        motion blade 0 rotate -40 0 0 1\nmotion blade 0.5\nmotion blade 1 rotate 40 0 0 1\n\
        motion pair 0 translate 0 2 0\nmotion pair 0.5\nmotion pair 1 translate 0 -0.4 3\n";
    let mut rng = Rng(0xA0761D6478BD642F);
    let (mut moving_hits, mut blocked, mut clear) = (0, 0, 0);
    for light_moves in [false, true] {
        let motion = if light_moves {
            "motion fill 0 translate 0 -2 0\nmotion fill 0.5\nmotion fill 1 translate 0 2 0\n"
        } else {
            ""
        };
        let scene = loaded_scene(&format!("{shapes}{motion}render eye m.png 64 48\n"));
        let (mut render, dropped) = RenderScene::compile(&scene);
        assert!(dropped.is_empty() && render.has_motion());
        render.watch_from(Vec3A::ZERO);
        let lights = if light_moves { 0 } else { 2 };
        assert_eq!(render.cells_kept(), (lights, true));
        for i in 0..4000 {
            let time = rng.next() as f32;
            // Mostly across the image, some anywhere.
            let spread = if i % 5 == 4 { 2.0 } else { 0.7 };
            let towards = rng.vec(spread) - DVec3::new(spread / 2.0, spread / 2.0, 1.0);
            let towards = Vec3A::from(towards.as_vec3());
            let ray = Ray::new(Vec3A::ZERO, towards.normalize()).at_time(time);
            let seen = render.closest_seen(&ray);
            let found = render.closest(&ray, f32::INFINITY);
            let bits = |h: Option<(u32, SurfaceHit)>| {
                h.map(|(id, h)| (id, h.point.to_array(), h.normal.to_array()))
            };
            assert_eq!(bits(seen), bits(found), "camera ray {i}: {ray:?}");
            moving_hits += seen.is_some_and(|(id, _)| render.moving_entry(id).is_some()) as usize;
            for (k, light) in render.lights.clone().iter().enumerate() {
                let Some((_, hit)) = found else { break };
                let to = render.light_position(k, light, time) - hit.point;
                let ray = hit.spawn_ray(to.normalize()).at_time(time);
                let t_limit = (hit.point + to - ray.origin).dot(ray.dir);
                let hierarchy = render.closest(&ray, t_limit).is_some();
                match render.shadow(&ray, t_limit, k) {
                    Shadow::Clear => assert!(!hierarchy, "light {k}, ray {i}: {ray:?}"),
                    Shadow::Blocked(id) => {
                        assert!(hierarchy && render.hit(id, &ray, t_limit).is_some());
                    }
                    other => panic!("opaque shapes only, yet {other:?}"),
                }
                *if hierarchy { &mut blocked } else { &mut clear } += 1;
            }
        }
    }
    assert!(
        moving_hits > 500,
        "{moving_hits} camera rays hit a moving shape"
    );
    assert_both_kinds(blocked, clear, 500);
}
