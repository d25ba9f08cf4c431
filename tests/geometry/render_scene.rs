//! The compiled scene's queries against brute force, instanced composites against their
//! flattened trees, and packets against single rays.

use super::*;
use anim_core::accel::Packet;

/// Also on scenes of world-space spheres only (with a duplicate: a tie), which the render
/// scene tests without looking at kinds, and of world-space boxes only (with a duplicate, and
/// rooms around every ray origin); `occlusion` names a primitive that is really hit.
#[test]
fn render_scene_equals_brute_force_on_mixed_scenes() {
    let mut rng = SplitMix64::new(0x2545F4914F6CDD1D);
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

/// `intersect`, `intersect_primitive` and `occlusion` of the render scene against brute
/// force.
fn check_render_scene(
    rng: &mut SplitMix64,
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
    let (render, dropped) = Compiled::new(&scene, None);
    assert!(dropped.is_empty());
    assert_eq!(render.len(), prims.len());
    let mut hits = 0;
    for i in 0..4000 {
        let ray = random_ray(rng, i);
        let t_limit = t_limit_of(i);
        let brute = brute_closest(&prims, &ray, t_limit);
        let found = render.intersect(&ray, t_limit);
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
            let again = render.intersect_primitive(slot, &ray, t_limit).unwrap();
            assert_eq!(again.t.to_bits(), h.t.to_bits());
            hits += 1;
        }
        check_opaque_occlusion(
            &render,
            &ray,
            t_limit,
            brute.is_some(),
            &format!("n={n} ray {i}"),
        );
    }
    assert!(n < 2000 || hits > 1000, "{hits} hits");
    let hits = check_packets(rng, &render, DVec3::splat(-15.0), DVec3::splat(80.0));
    assert!(n < 600 || hits > 2000, "{hits} hits of packet rays");
}

/// Packets of eight rays from one origin towards nearby points (a fan narrow enough to share
/// an octant, as the camera rays of a pixel block do; some axis-parallel, some with limits,
/// some mixing octants, which go ray by ray): every ray's closest hit is `intersect`'s to the
/// bit, the same primitive included. Origins lie in `lo + [0, size)³`. Returns how many
/// rays hit.
fn check_packets(rng: &mut SplitMix64, scene: &Compiled, lo: DVec3, size: DVec3) -> usize {
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
            let bits = |h: Option<(u32, SurfaceHit)>| {
                h.map(|(id, h)| {
                    (
                        id,
                        h.t.to_bits(),
                        h.point.to_array().map(f32::to_bits),
                        h.normal.to_array().map(f32::to_bits),
                    )
                })
            };
            let alone = scene.intersect(ray, t_limit);
            hits += usize::from(alone.is_some());
            assert_eq!(bits(together[k]), bits(alone), "packet {i} ray {k}");
        }
    }
    // Not vacuous: most packets go together.
    assert!(packets > 1000, "{packets} packets");
    hits
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

/// The instanced scene expands to the flattened one's shapes, with bit-identical world
/// transforms, in the same order.
fn assert_same_shapes(instanced: &Scene, flat: &Scene) {
    assert!(instanced.has_prototypes() && !flat.has_prototypes());
    assert!(instanced.instances.len() < flat.instances.len() / 2);
    let expanded = instanced.flattened();
    assert_eq!(expanded.len(), flat.instances.len());
    assert_eq!(instanced.shape_count(), flat.instances.len() as u64);
    for ((inst, xf), f) in expanded.iter().zip(flat.instances.iter()) {
        assert_eq!((&inst.geometry, inst.material), (&f.geometry, f.material));
        assert_eq!(xf, flat.transform_of(f));
    }
}

/// `occlusion` of a ray (not a shadow ray: every primitive is asked) in a scene of opaque
/// shapes that brute force finds `blocked` or not: the same answer, and a blocker that the
/// ray does hit.
fn check_opaque_occlusion(scene: &Compiled, ray: &Ray, t_limit: f32, blocked: bool, what: &str) {
    match scene.occlusion(ray, t_limit, RayHint::Secondary) {
        Occlusion::Clear => assert!(!blocked, "{what}"),
        Occlusion::Blocked(id) => {
            assert!(blocked, "{what}");
            let hit = scene.intersect_primitive(id, ray, t_limit);
            assert!(hit.is_some(), "{what}");
        }
        other => panic!("opaque shapes only, yet {other:?}: {what}"),
    }
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
        assert_same_shapes(&instanced, &flat);
        let prims: Vec<Primitive> = flat
            .instances
            .iter()
            .map(|i| Primitive::new(&i.geometry, flat.transform_of(i), i.material as u32).unwrap())
            .collect();
        let (a, dropped_a) = Compiled::new(&instanced, None);
        let (b, dropped_b) = Compiled::new(&flat, None);
        assert!(dropped_a.is_empty() && dropped_b.is_empty());
        assert!(a.scene.aggregate().instance_uses() > 0);
        let mut rng = SplitMix64::new(seed.wrapping_mul(0x9E3779B97F4A7C15));
        let (mut hits, mut ties) = (0, 0);
        let mut same_id = std::collections::HashMap::new();
        let mut same_id_back = std::collections::HashMap::new();
        for i in 0..6000 {
            let o = rng.vec(100.0) - DVec3::new(50.0, 30.0, 20.0);
            let target = rng.vec(1.0) * DVec3::new(70.0, 50.0, 60.0) - DVec3::new(40.0, 25.0, 80.0);
            let mut dir = (target - o).normalize();
            if i % 5 == 0 {
                dir = DVec3::ZERO;
                dir[i / 5 % 3] = if rng.unit_f64() < 0.5 { 1.0 } else { -1.0 };
            }
            let ray = Ray::new(Vec3A::from(o.as_vec3()), Vec3A::from(dir.as_vec3()));
            let t_limit = t_limit_of(i);
            let brute = brute_in_tree_order(&prims, &ray, t_limit);
            let (ha, hb) = (a.intersect(&ray, t_limit), b.intersect(&ray, t_limit));
            let bits = |h: &Option<(u32, SurfaceHit)>, s: &Compiled| {
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
                let again = a.intersect_primitive(ida, &ray, t_limit).unwrap();
                assert_eq!(again.t.to_bits(), t.to_bits());
            }
            let what = format!("seed {seed} ray {i}");
            for s in [&a, &b] {
                check_opaque_occlusion(s, &ray, t_limit, brute.is_some(), &what);
            }
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
