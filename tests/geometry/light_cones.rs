//! What a point sees of a spherical light as a whole (`RenderScene::whole_light`) against
//! brute force: where it answers that all of the light is visible, every shadow ray from the
//! point to a fine grid of points over the light's disc (rim included) leaves the surface on
//! the lit side and meets no primitive; where it answers none, every one meets an opaque
//! primitive. Points are where random rays first meet random opaque scenes (shaded with the
//! normal turned to the ray, as the integrator shades them); the scratch, and with it each
//! light's last blocker, is kept from point to point, as a worker keeps it.

use super::*;
use anim_core::math::sampling::concentric;
use anim_core::render::compile::{LightSight, WholeLight};
use anim_core::render::shading::LightDisc;

/// Points of the disc brute force sends shadow rays to: a 16×16 grid of the unit square
/// through the concentric map, its outer cells on the rim.
fn disc_grid(disc: &LightDisc) -> Vec<Vec3A> {
    let step = |i: usize| i as f32 / 15.0;
    (0..16)
        .flat_map(|i| (0..16).map(move |j| [step(i), step(j)]))
        .map(|uv| disc.at(concentric(uv)))
        .collect()
}

/// What shadow rays from `hit` (normal `n` facing the lit side) to `points` find, by brute
/// force over `prims`: whether every one is clear, and whether every one is blocked.
fn brute_sight(prims: &[Primitive], hit: &SurfaceHit, n: Vec3A, points: &[Vec3A]) -> (bool, bool) {
    let (mut all_clear, mut all_blocked) = (true, true);
    for &p in points {
        let d = p - hit.point;
        let dist = d.length();
        let shadow = ShadowRay::new(hit, d / dist, dist, 0.5, 0);
        let below = n.dot(shadow.ray.dir) <= 0.0;
        let blocked = prims
            .iter()
            .any(|q| q.hit(&shadow.ray, shadow.t_max).is_some());
        all_clear &= !below && !blocked;
        all_blocked &= blocked;
    }
    (all_clear, all_blocked)
}

#[test]
fn whole_lights_are_what_shadow_rays_over_their_discs_find() {
    let mut rng = SplitMix64::new(0x9E37_79B9_7F4A_7C15);
    let mut tally = [0usize; 3];
    let scenes = [
        mixed_instances(&mut rng, 30),
        mixed_instances(&mut rng, 400),
        world_boxes(&mut rng, 12),
    ];
    for (s, (instances, transforms)) in scenes.into_iter().enumerate() {
        let prims: Vec<Primitive> = instances
            .iter()
            .map(|i| Primitive::new(&i.geometry, &transforms[i.transform as usize], 0).unwrap())
            .collect();
        let grey = Material::phong("grey", Vec3::splat(0.1), Vec3::splat(0.5), Vec3::ZERO, 1.0);
        let mut lights = white_lights(&[rng.vec(60.0), rng.vec(60.0) + DVec3::Y * 40.0]);
        for light in &mut lights {
            light.radius = 1.0 + rng.unit_f64() * 4.0;
        }
        let scene = Scene {
            materials: vec![grey; instances.len()],
            instances: instances.into(),
            transforms,
            lights,
            ..Scene::default()
        };
        let (compiled, dropped) = Compiled::new(&scene, None);
        assert!(dropped.is_empty());
        for i in 0..3000 {
            let ray = random_ray(&mut rng, i);
            let Some((prim, hit)) = compiled.intersect(&ray, f32::INFINITY) else {
                continue;
            };
            let n = if hit.normal.dot(ray.dir) < 0.0 {
                hit.normal
            } else {
                -hit.normal
            };
            for (k, light) in compiled.lights().to_vec().iter().enumerate() {
                let sight = LightSight {
                    hit: &hit,
                    leaving: prim,
                    normal: n,
                    light: k,
                    centre: light.position,
                    radius: light.radius,
                    time: 0.5,
                };
                let answer = {
                    let scratch = &mut compiled.scratch.borrow_mut();
                    compiled.scene.whole_light(&sight, scratch)
                };
                let axis = (light.position - hit.point).normalize();
                let disc = LightDisc::new(light.position, light.radius, axis);
                let (clear, blocked) = brute_sight(&prims, &hit, n, &disc_grid(&disc));
                let what = format!("scene {s}, ray {i}, light {k}: {answer:?}");
                match answer {
                    WholeLight::Visible => assert!(clear, "{what}: a shadow ray is blocked"),
                    WholeLight::Hidden => assert!(blocked, "{what}: a shadow ray is clear"),
                    WholeLight::Partial => {}
                }
                tally[answer as usize] += 1;
            }
        }
    }
    // Not vacuous: each answer, many times.
    assert!(tally.iter().all(|&n| n > 100), "{tally:?}");
}
