//! How much of a light passes what lies before it (`RenderScene::transmittance`, the glass
//! walk behind the facade) against brute force over every primitive: nothing where an
//! opaque shape lies on the shadow ray, else `1 − α` for each crossing of a transparent one,
//! each crossing the primitive's own hit, stepped past as a shadow ray steps. Asked with the
//! lights' direction cells (a flat scene), their image tiles and the hierarchy (a larger one),
//! rooms around the rays' starts, and instanced composites; the scratch, and with it the
//! last blocker tried first, is kept from ray to ray, as a worker keeps it.

use super::*;

/// Opacity of material `k` of the scenes below: one in four opaque, the others glass.
fn opacity(k: usize) -> f32 {
    [1.0, 0.3, 0.6, 0.85][k % 4]
}

/// What a shadow ray meets, by brute force over `prims` (each with its opacity): `None` when
/// an opaque one lies on it, else the light that passes and how many transparent
/// primitives it crosses.
fn brute_transmittance(prims: &[(Primitive, f32)], shadow: &ShadowRay) -> Option<(f32, usize)> {
    let (ray, l) = (&shadow.ray, shadow.ray.dir);
    let opaque = |&(ref p, a): &(Primitive, f32)| a >= 1.0 && p.hit(ray, shadow.t_max).is_some();
    if prims.iter().any(opaque) {
        return None;
    }
    let (mut transmit, mut crossed) = (1.0f32, 0);
    for (p, a) in prims.iter().filter(|(_, a)| *a < 1.0) {
        let (mut segment, mut left) = (*ray, shadow.t_max);
        crossed += usize::from(p.hit(ray, left).is_some());
        while let Some(hit) = p.intersect(&segment, left) {
            transmit *= 1.0 - a;
            segment = hit.spawn_ray(l).at_time(ray.time);
            left = (shadow.to - segment.origin).dot(l);
            if left <= 0.0 {
                break;
            }
        }
    }
    Some((transmit, crossed))
}

/// Tallies of the shadow rays checked: blocked, through glass, through two or more glass
/// primitives (the walk over several), clear.
#[derive(Default, Debug)]
struct Tally {
    blocked: usize,
    through: usize,
    several: usize,
    clear: usize,
}

/// `transmittance` of `shadow` against brute force over `prims`: exactly 0 where something
/// opaque blocks it, 1 where nothing lies on it, and the product of the crossings (in
/// whatever order, so to within rounding) where glass does.
fn check_transmittance(
    scene: &Compiled,
    prims: &[(Primitive, f32)],
    shadow: &ShadowRay,
    tally: &mut Tally,
    what: &str,
) {
    let found = scene.transmittance(shadow);
    match brute_transmittance(prims, shadow) {
        None => {
            assert_eq!(found, 0.0, "{what}: {shadow:?}");
            tally.blocked += 1;
        }
        Some((expected, crossed)) => {
            assert!(
                (found - expected).abs() <= 1e-6,
                "{what}: {found} passes, brute force {expected}: {shadow:?}"
            );
            match crossed {
                0 => tally.clear += 1,
                1 => tally.through += 1,
                _ => tally.several += 1,
            }
        }
    }
}

/// A shadow ray from a random point of the scenes' region towards light `k` at `light`.
fn shadow_towards(rng: &mut SplitMix64, light: Vec3A, k: usize) -> ShadowRay {
    let from = Vec3A::from(rng.vec(50.0).as_vec3());
    let dir = (light - from).normalize();
    ShadowRay {
        ray: Ray::new(from, dir),
        to: light,
        t_max: (light - from).dot(dir),
        light: k,
    }
}

/// The scene of `instances` (instance `i` in material `i`, of `opacity(i)`) lit by lights at
/// `lights`, and its shapes with their opacities for brute force.
fn glass_scene(
    instances: Vec<Instance>,
    transforms: Vec<Transform>,
    lights: &[DVec3],
) -> (Scene, Vec<(Primitive, f32)>) {
    let prims = instances
        .iter()
        .map(|i| {
            let xf = &transforms[i.transform as usize];
            let p = Primitive::new(&i.geometry, xf, 0).unwrap();
            (p, opacity(i.material))
        })
        .collect();
    let materials = (0..instances.len())
        .map(|k| Material {
            opacity: opacity(k),
            ior: 1.5,
            ..Material::phong(&format!("m{k}"), Vec3::ONE, Vec3::ONE, Vec3::ONE, 1.0)
        })
        .collect();
    let scene = Scene {
        materials,
        instances: instances.into(),
        transforms,
        lights: white_lights(lights),
        ..Scene::default()
    };
    (scene, prims)
}

#[test]
fn light_through_glass_is_what_brute_force_finds() {
    let mut rng = SplitMix64::new(0x5851F42D4C957F2D);
    let mut tally = Tally::default();
    let scenes = [
        (mixed_instances(&mut rng, 8), None),
        (mixed_instances(&mut rng, 400), None),
        (mixed_instances(&mut rng, 400), Some(true)),
        (world_boxes(&mut rng, 10), None),
    ];
    for (s, ((instances, transforms), view)) in scenes.into_iter().enumerate() {
        let lights: Vec<DVec3> = (0..3)
            .map(|k| match k {
                0 => DVec3::new(200.0, 300.0, -150.0),
                _ => rng.vec(50.0),
            })
            .collect();
        let (scene, prims) = glass_scene(instances, transforms, &lights);
        // With a view of many camera rays, the lights of a larger scene keep image tiles.
        let eye = viewpoint_at(Vec3A::new(25.0, 25.0, 110.0), false);
        let (compiled, dropped) = Compiled::new(&scene, view.map(|_| &eye));
        assert!(dropped.is_empty());
        for (k, light) in lights.iter().enumerate() {
            let light = Vec3A::from(light.as_vec3());
            for i in 0..2000 {
                let shadow = shadow_towards(&mut rng, light, k);
                let what = format!("scene {s}, light {k}, ray {i}");
                check_transmittance(&compiled, &prims, &shadow, &mut tally, &what);
            }
        }
    }
    // Not vacuous: every answer, and the walk over several glass primitives, many times.
    assert!(
        tally.blocked > 1000 && tally.through > 2000 && tally.several > 500 && tally.clear > 1000,
        "{tally:?}"
    );
}

/// Instanced composites of glass: the walk offers the shapes inside each use, and answers
/// as brute force over the flattened tree's shapes does. (A file that draws glass is never
/// instanced, `scene::builder::instancing`; the materials are made glass once the scene is
/// loaded, for the facade must answer any compiled scene right.)
#[test]
fn light_through_instanced_glass_is_what_brute_force_finds() {
    let mut tally = Tally::default();
    for seed in [1, 2, 3] {
        let tree = composites::mixed(seed);
        let glass = |mut scene: Scene| {
            for (k, m) in scene.materials.iter_mut().enumerate() {
                m.opacity = opacity(k);
            }
            scene
        };
        let instanced = glass(loaded_scene(&format!(
            "{}{}",
            composites::MATERIALS,
            tree.shared()
        )));
        let flat = glass(loaded_scene(&format!(
            "{}{}",
            composites::MATERIALS,
            tree.flattened()
        )));
        let prims: Vec<(Primitive, f32)> = flat
            .instances
            .iter()
            .map(|i| {
                let p = Primitive::new(&i.geometry, flat.transform_of(i), 0).unwrap();
                (p, opacity(i.material))
            })
            .collect();
        let (compiled, dropped) = Compiled::new(&instanced, None);
        assert!(dropped.is_empty() && compiled.scene.aggregate().instance_uses() > 0);
        let mut rng = SplitMix64::new(seed.wrapping_mul(0xD6E8FEB86659FD93));
        for (k, light) in compiled.lights().to_vec().iter().enumerate() {
            for i in 0..3000 {
                // From among the composites' shapes.
                let from =
                    rng.vec(1.0) * DVec3::new(70.0, 50.0, 60.0) - DVec3::new(40.0, 25.0, 80.0);
                let from = Vec3A::from(from.as_vec3());
                let dir = (light.position - from).normalize();
                let shadow = ShadowRay {
                    ray: Ray::new(from, dir),
                    to: light.position,
                    t_max: (light.position - from).dot(dir),
                    light: k,
                };
                let what = format!("seed {seed}, light {k}, ray {i}");
                check_transmittance(&compiled, &prims, &shadow, &mut tally, &what);
            }
        }
    }
    assert!(
        tally.blocked > 1000 && tally.through > 400 && tally.several > 300 && tally.clear > 1000,
        "{tally:?}"
    );
}
