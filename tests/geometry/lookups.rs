//! Camera and shadow rays through the eye's and the lights' direction cells and image tiles
//! (as the scene's plan chooses them), against the hierarchy and brute force.

use super::*;

/// Shadow rays in scenes of few shapes, where each light keeps direction cells around itself
/// (a light buffer) and a shadow ray tests only what its cell lists: blocked exactly when
/// brute force finds a hit before the light. Camera rays likewise, from the eye's cells. Origins are lifted off at random by up to 10⁻³
/// (as `SurfaceHit::spawn_ray` moves them), and lights sit among the shapes, inside the
/// rooms, and far off. Rays aimed elsewhere must be answered too (the cells then answer
/// nothing, and the whole scene is tested).
#[test]
fn rays_through_direction_cells_meet_what_brute_force_meets() {
    let mut rng = SplitMix64::new(0x9E3779B97F4A7C15);
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
        // Camera rays from an eye with cells around it (and rays from elsewhere): the same
        // hit as `intersect` and brute force find, to the bit.
        let eye = rng.vec(60.0) - DVec3::splat(5.0);
        let eye = Vec3A::from(eye.as_vec3());
        let (render, dropped) = Compiled::new(&scene, Some(&viewpoint_at(eye, false)));
        assert!(dropped.is_empty());
        assert!(render.scene.view().kept().1, "the eye keeps cells");
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
        lights: white_lights(lights),
        ..Scene::default()
    };
    (scene, prims)
}

/// `intersect_camera` of a camera ray against `intersect` (to the bit) and brute force (the
/// distance); whether it hit.
fn check_seen(render: &Compiled, prims: &[Primitive], ray: &Ray, i: usize) -> bool {
    let seen = render.intersect_camera(ray);
    let found = render.intersect(ray, f32::INFINITY);
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
fn shadow_ray(rng: &mut SplitMix64, light: Vec3A, i: usize) -> (Ray, f32) {
    let from = Vec3A::from((rng.vec(80.0) - DVec3::splat(15.0)).as_vec3());
    let dir = (light - from).normalize();
    let lift = Vec3A::from((rng.vec(2e-3) - DVec3::splat(1e-3)).as_vec3());
    let origin = from + lift * (i % 3) as f32;
    (Ray::new(origin, dir), (light - origin).dot(dir))
}

/// `occlusion` of a ray towards light `k` against brute force (opaque shapes only); whether
/// it is blocked.
fn check_shadow(render: &Compiled, prims: &[Primitive], ray: &Ray, t_limit: f32, k: usize) -> bool {
    let brute = brute_closest(prims, ray, t_limit).is_some();
    let found = render.occlusion(ray, t_limit, RayHint::Shadow(k));
    match found {
        Occlusion::Clear => {}
        Occlusion::Blocked(id) => {
            let hit = render.intersect_primitive(id, ray, t_limit);
            assert!(hit.is_some(), "{ray:?}");
        }
        other => panic!("opaque shapes only, yet {other:?}"),
    }
    assert_eq!(found != Occlusion::Clear, brute, "light {k}: {ray:?}");
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
    render: &Compiled,
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

/// Image tiles (`View`'s, which `RayHint::Camera` and `RayHint::Shadow` rays look up): in scenes larger than a flat one (mixed kinds
/// with a plane, world boxes with rooms around the eye, world spheres alone), camera rays
/// through random points of the image (and a few beyond its edges, or from elsewhere) get
/// `intersect`'s hit to the bit, and brute force's distance; shadow rays towards lights far
/// off, among the shapes and inside the rooms, lifted off their start as `spawn_ray` does,
/// are blocked exactly when brute force finds a hit before the light.
#[test]
fn rays_through_image_tiles_meet_what_brute_force_meets() {
    let mut rng = SplitMix64::new(0xD1B54A32D192ED03);
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
                radius: 0.5 + rng.unit_f64() * 2.0,
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
        let mut camera = Camera::default_with_fov("c", 40.0 + 60.0 * rng.unit_f64());
        camera.eye = DVec3::new(25.0, 25.0, 110.0) + rng.vec(10.0);
        camera.dir = DVec3::splat(25.0) - camera.eye + rng.vec(20.0);
        let (width, height) = (96, 54);
        let rays = PinholeCamera::new(&camera, width, height).unwrap();
        let view = viewpoint(&camera, (width, height), false);
        let (render, dropped) = Compiled::new(&scene, Some(&view));
        assert!(dropped.is_empty());
        // Packets of a 4×4 block of pixels (one sample position each, as the uniform path
        // traces them), and of a run of 8 pixels of a row: each ray's hit is its own.
        for i in 0..300 {
            let (bx, by) = (
                (rng.unit_f64() * 24.0) as u32 * 4,
                (rng.unit_f64() * 13.0) as u32 * 4,
            );
            let (dx, dy) = (rng.unit_f64() as f32, rng.unit_f64() as f32);
            let at = |k: u32, w: u32| (bx + k % w) as f32 + dx;
            let block: [Ray; 16] =
                std::array::from_fn(|k| rays.ray(at(k as u32, 4), (by + k as u32 / 4) as f32 + dy));
            let run: [Ray; 8] = std::array::from_fn(|k| rays.ray(at(k as u32, 8), by as f32 + dy));
            let bits = |h: &Option<(u32, SurfaceHit)>| {
                h.map(|(id, h)| (id, h.t.to_bits(), h.normal.to_array()))
            };
            for (ray, hit) in block.iter().zip(render.intersect_camera_packet(&block)) {
                assert_eq!(
                    bits(&hit),
                    bits(&render.intersect_camera(ray)),
                    "block {i}: {ray:?}"
                );
            }
            for (ray, hit) in run.iter().zip(render.intersect_camera_packet(&run)) {
                assert_eq!(
                    bits(&hit),
                    bits(&render.intersect_camera(ray)),
                    "run {i}: {ray:?}"
                );
            }
        }
        for i in 0..4000 {
            let (x, y) = (
                rng.unit_f64() as f32 * 100.0 - 2.0,
                rng.unit_f64() as f32 * 58.0 - 2.0,
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
    let mut rng = SplitMix64::new(0xA0761D6478BD642F);
    let (mut moving_hits, mut blocked, mut clear) = (0, 0, 0);
    for light_moves in [false, true] {
        let motion = if light_moves {
            "motion fill 0 translate 0 -2 0\nmotion fill 0.5\nmotion fill 1 translate 0 2 0\n"
        } else {
            ""
        };
        let scene = loaded_scene(&format!("{shapes}{motion}render eye m.png 64 48\n"));
        let view = viewpoint_at(Vec3A::ZERO, true);
        let (render, dropped) = Compiled::new(&scene, Some(&view));
        assert!(dropped.is_empty() && render.scene.aggregate().has_motion());
        let lights = if light_moves { 0 } else { 2 };
        assert_eq!(render.scene.view().kept(), (lights, true));
        for i in 0..4000 {
            let time = rng.unit_f64() as f32;
            // Mostly across the image, some anywhere.
            let spread = if i % 5 == 4 { 2.0 } else { 0.7 };
            let towards = rng.vec(spread) - DVec3::new(spread / 2.0, spread / 2.0, 1.0);
            let towards = Vec3A::from(towards.as_vec3());
            let ray = Ray::new(Vec3A::ZERO, towards.normalize()).at_time(time);
            let seen = render.intersect_camera(&ray);
            let found = render.intersect(&ray, f32::INFINITY);
            let bits = |h: Option<(u32, SurfaceHit)>| {
                h.map(|(id, h)| (id, h.point.to_array(), h.normal.to_array()))
            };
            assert_eq!(bits(seen), bits(found), "camera ray {i}: {ray:?}");
            let geometry = render.scene.aggregate();
            moving_hits += seen.is_some_and(|(id, _)| geometry.moving_entry(id).is_some()) as usize;
            for (k, light) in render.lights().iter().enumerate() {
                let Some((_, hit)) = found else { break };
                let to = render.scene.shading().light_position(k, light, time) - hit.point;
                let ray = hit.spawn_ray(to.normalize()).at_time(time);
                let t_limit = (hit.point + to - ray.origin).dot(ray.dir);
                let hierarchy = render.intersect(&ray, t_limit).is_some();
                match render.occlusion(&ray, t_limit, RayHint::Shadow(k)) {
                    Occlusion::Clear => assert!(!hierarchy, "light {k}, ray {i}: {ray:?}"),
                    Occlusion::Blocked(id) => {
                        let hit = render.intersect_primitive(id, &ray, t_limit);
                        assert!(hierarchy && hit.is_some());
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
