//! Renderer tests on scene descriptions built directly (no SDF reader involved), with
//! expected values derived from the physics rather than from earlier output.

use super::*;
use crate::scene::{Camera, Geometry, Instance, Light, Material, Scene};
use glam::{DVec3, Vec3};

fn material(name: &str, ka: f32, kd: [f32; 3], ks: f32, m: f32) -> Material {
    Material::phong(name, Vec3::splat(ka), Vec3::from(kd), Vec3::splat(ks), m)
}

fn instance(geometry: Geometry, material: usize) -> Instance {
    Instance::new(geometry, material)
}

fn sphere(c: [f64; 3], r: f64, material: usize) -> Instance {
    instance(
        Geometry::Sphere {
            center: DVec3::from(c),
            radius: r,
        },
        material,
    )
}

fn job(scene: Scene, camera: Camera, w: u32, h: u32) -> RenderJob {
    RenderJob {
        scene,
        camera,
        output: "x.png".into(),
        width: w,
        height: h,
        samples: Some(1),
        loc: None,
    }
}

fn render(job: &RenderJob) -> HdrImage {
    render_job(job, &RenderSettings::default(), &|_| {})
        .unwrap()
        .image
}

/// A lit scene: a red ball on a grey floor, two lights.
fn base_scene() -> Scene {
    Scene {
        materials: vec![
            material("red", 0.1, [0.8, 0.1, 0.1], 0.5, 20.0),
            material("grey", 0.1, [0.5, 0.5, 0.5], 0.0, 1.0),
        ],
        instances: vec![
            sphere([0.5, 0.0, -8.0], 1.0, 0),
            instance(
                Geometry::Box {
                    p1: DVec3::new(-20.0, -2.0, -30.0),
                    p2: DVec3::new(20.0, -1.0, 0.0),
                },
                1,
            ),
        ]
        .into(),
        lights: vec![
            Light {
                name: "a".into(),
                position: DVec3::new(5.0, 10.0, 0.0),
                intensity: Vec3::splat(1.2),
                radius: 0.0,
                spot: None,
            },
            Light {
                name: "b".into(),
                position: DVec3::new(-8.0, 4.0, -2.0),
                intensity: Vec3::new(0.3, 0.3, 0.6),
                radius: 0.0,
                spot: None,
            },
        ],
        ambient: Vec3::splat(0.4),
        background: Vec3::new(0.1, 0.2, 0.3),
        ..Scene::default()
    }
}

fn assert_close(a: &HdrImage, b: &HdrImage, max_lsb: u8, max_differing: usize) {
    let (x, y) = (film::to_rgb8(a), film::to_rgb8(b));
    let mut differing = 0;
    for (p, q) in x.chunks(3).zip(y.chunks(3)) {
        let d = p.iter().zip(q).map(|(u, v)| u.abs_diff(*v)).max().unwrap();
        assert!(d <= max_lsb, "pixel differs by {d} LSB");
        differing += usize::from(d > 0);
    }
    assert!(differing <= max_differing, "{differing} pixels differ");
}

#[test]
fn glass_of_index_one_is_invisible() {
    let cam = Camera::default_with_fov("c", 60.0);
    let plain = render(&job(base_scene(), cam.clone(), 96, 64));
    let mut with_glass = base_scene();
    let mut glass = material("glass", 0.7, [0.9, 0.9, 0.9], 0.8, 50.0);
    glass.opacity = 0.0;
    glass.ior = 1.0;
    with_glass.materials.push(glass);
    // In front of the ball, and in the path of shadow rays to the floor.
    with_glass.push_instance(sphere([0.0, 0.0, -5.0], 1.5, 2));
    let seen_through = render(&job(with_glass, cam, 96, 64));
    assert_close(&plain, &seen_through, 1, 96 * 64);
}

#[test]
fn perfect_mirror_shows_the_mirrored_configuration() {
    // A mirror in the plane z = −20 facing the camera; the ball and the light sit behind the
    // camera. Seen in the mirror they look exactly like the configuration reflected in z = −20.
    let ball = material("ball", 0.2, [0.2, 0.6, 0.9], 0.4, 15.0);
    let mut mirror = material("mirror", 0.0, [0.0; 3], 0.0, 1.0);
    mirror.reflectivity = 1.0;
    let light_at = |z: f64| Light {
        name: "l".into(),
        position: DVec3::new(2.0, 6.0, z),
        intensity: Vec3::splat(1.5),
        radius: 0.0,
        spot: None,
    };
    let in_front = Scene {
        materials: vec![ball.clone(), mirror],
        instances: vec![
            sphere([1.5, 0.5, 6.0], 2.0, 0),
            instance(
                Geometry::Box {
                    p1: DVec3::new(-200.0, -200.0, -21.0),
                    p2: DVec3::new(200.0, 200.0, -20.0),
                },
                1,
            ),
        ]
        .into(),
        lights: vec![light_at(10.0)],
        ambient: Vec3::splat(0.3),
        background: Vec3::new(0.3, 0.1, 0.0),
        ..Scene::default()
    };
    let mirrored = Scene {
        materials: vec![ball],
        instances: vec![sphere([1.5, 0.5, -46.0], 2.0, 0)].into(),
        lights: vec![light_at(-50.0)],
        ..in_front.clone()
    };
    let cam = Camera::default_with_fov("c", 40.0);
    let a = render(&job(in_front, cam.clone(), 80, 60));
    let b = render(&job(mirrored, cam, 80, 60));
    // A known pixel: the centre of the ball's image (derived: the mirrored centre projects to
    // x = 40 + 1.5·d/46, y = 30 − 0.5·d/46 with d = 40/tan 20°).
    let d = 40.0 / 20f64.to_radians().tan();
    let (px, py) = (
        (40.0 + 1.5 * d / 46.0) as usize,
        (30.0 - 0.5 * d / 46.0) as usize,
    );
    let i = py * 80 + px;
    assert_ne!(
        b.pixels[i],
        in_front_background(),
        "the known pixel shows the ball"
    );
    assert!((a.pixels[i] - b.pixels[i]).abs().max_element() < 1e-3);
    assert_close(&a, &b, 1, 40);
}

fn in_front_background() -> Vec3 {
    Vec3::new(0.3, 0.1, 0.0)
}

#[test]
fn total_internal_reflection_is_not_black() {
    // Camera inside a slab of glass (η = 1.5) looking up at the top face at 80° incidence,
    // beyond the critical angle of 41.8°: everything reflects down onto an ambient-lit red ball
    // inside the glass, whose colour is exactly Ka·I_ambient = 1, i.e. 255·½ = 128.
    let mut glass = material("glass", 0.0, [0.0; 3], 0.0, 1.0);
    glass.opacity = 0.0;
    glass.ior = 1.5;
    let red = Material::phong("red", Vec3::new(1.0, 0.0, 0.0), Vec3::ZERO, Vec3::ZERO, 1.0);
    let scene = Scene {
        materials: vec![glass, red],
        instances: vec![
            instance(
                Geometry::Box {
                    p1: DVec3::new(-10.0, -1.0, -50.0),
                    p2: DVec3::new(10.0, 1.0, 10.0),
                },
                0,
            ),
            sphere([0.0, -0.5, -14.0], 0.5, 1),
        ]
        .into(),
        lights: vec![],
        ambient: Vec3::ONE,
        background: Vec3::ZERO,
        ..Scene::default()
    };
    let angle = 10f64.to_radians();
    let cam = Camera {
        name: "c".into(),
        fov_x_deg: 1.0,
        eye: DVec3::ZERO,
        dir: DVec3::new(0.0, angle.sin(), -angle.cos()),
        up: DVec3::Y,
        lens: None,
    };
    let img = render(&job(scene, cam, 3, 3));
    assert_eq!(film::to_rgb8(&img)[12..15], [128, 0, 0]);
}

#[test]
fn no_pixel_is_ever_nan_or_infinite() {
    let mut scene = base_scene();
    let mut glass = material("glass", 0.1, [0.2, 0.2, 0.2], 0.5, 30.0);
    glass.opacity = 0.2;
    glass.reflectivity = 0.3;
    glass.ior = 1.5;
    scene.materials.push(glass);
    scene.push_instance(sphere([-1.0, 0.0, -6.0], 1.0, 2));
    // A light exactly on a surface, and a camera inside an object.
    scene.lights.push(Light {
        name: "on".into(),
        position: DVec3::new(0.5, 1.0, -8.0),
        intensity: Vec3::ONE,
        radius: 0.0,
        spot: None,
    });
    for eye in [DVec3::ZERO, DVec3::new(-1.0, 0.0, -6.0)] {
        let cam = Camera {
            eye,
            ..Camera::default_with_fov("c", 70.0)
        };
        let img = render(&job(scene.clone(), cam, 64, 48));
        assert!(img
            .pixels
            .iter()
            .all(|p| p.is_finite() && p.min_element() >= 0.0));
    }
}

#[test]
fn opaque_scenes_trace_no_secondary_rays() {
    let counts = render_job(
        &job(base_scene(), Camera::default_with_fov("c", 60.0), 32, 32),
        &RenderSettings::default(),
        &|_| {},
    )
    .unwrap()
    .rays;
    assert_eq!(counts.reflected + counts.refracted, 0);
    assert_eq!(counts.primary, 32 * 32);
}

#[test]
fn shadow_through_glass_is_attenuated_per_surface_crossed() {
    // The light straight above the floor point (0,0,0) shines through a sphere of opacity
    // α = 0.5: the shadow ray crosses two surfaces, so (1 − α)² = 1/4 of the light arrives.
    // Expected: Ka·I_a + ¼·I·Kd·(N·L) with N·L = 1 (no specular: Ks = 0).
    let floor = Material::phong(
        "floor",
        Vec3::splat(0.2),
        Vec3::new(0.6, 0.4, 0.2),
        Vec3::ZERO,
        1.0,
    );
    let mut veil = material("veil", 0.0, [0.0; 3], 0.0, 1.0);
    veil.opacity = 0.5;
    let scene = Scene {
        materials: vec![floor, veil],
        instances: vec![
            instance(
                Geometry::Box {
                    p1: DVec3::new(-10.0, -1.0, -10.0),
                    p2: DVec3::new(10.0, 0.0, 10.0),
                },
                0,
            ),
            sphere([0.0, 5.0, 0.0], 1.0, 1),
        ]
        .into(),
        lights: vec![Light {
            name: "l".into(),
            position: DVec3::new(0.0, 10.0, 0.0),
            intensity: Vec3::splat(2.0),
            radius: 0.0,
            spot: None,
        }],
        ambient: Vec3::splat(0.5),
        background: Vec3::ZERO,
        ..Scene::default()
    };
    let cam = Camera {
        name: "c".into(),
        fov_x_deg: 10.0,
        eye: DVec3::new(0.0, 1.0, 5.0),
        dir: DVec3::new(0.0, -1.0, -5.0),
        up: DVec3::Y,
        lens: None,
    };
    let img = render(&job(scene, cam, 3, 3));
    let expected = Vec3::splat(0.2 * 0.5) + Vec3::new(0.6, 0.4, 0.2) * (2.0 * 0.25);
    assert!(
        (img.pixels[4] - expected).abs().max_element() < 1e-5,
        "{:?} vs {expected:?}",
        img.pixels[4]
    );
}

/// Issue 8's budget: a world-space sphere costs at most 100 bytes of the render scene, its
/// share of the hierarchy included (a million spheres must fit a small process).
#[test]
fn a_world_space_sphere_costs_at_most_100_bytes() {
    let mut rng = crate::util::SplitMix64::new(0x853C_49E6_748F_EA9B);
    let mut next = move || rng.unit_f64();
    let n = 20_000;
    let instances: Vec<Instance> = (0..n)
        .map(|_| {
            let c = [next() * 100.0, next() * 100.0, next() * 100.0];
            sphere(c, 0.1 + next() * 0.4, 0)
        })
        .collect();
    let scene = Scene {
        materials: vec![material("m", 0.1, [0.5; 3], 0.0, 1.0)],
        instances: instances.into(),
        ..Scene::default()
    };
    let (compiled, dropped) = RenderScene::compile(&scene, None);
    assert!(dropped.is_empty());
    assert_eq!(compiled.aggregate().len(), n);
    let per_sphere = compiled.memory_bytes() as f64 / n as f64;
    assert!(per_sphere <= 100.0, "{per_sphere:.1} bytes per sphere");
    // Not vacuous: the packed sphere alone is 16 bytes, its material 4.
    assert!(per_sphere >= 20.0, "{per_sphere:.1} bytes per sphere");
}

#[test]
fn shadow_rays_are_traced_only_where_light_can_change_the_colour() {
    // Ambient-only materials (Kd = Ks = 0): a light adds exactly zero, so no shadow ray.
    let shadow_rays = |kd: f32, ks: f32| {
        let mut scene = base_scene();
        for m in &mut scene.materials {
            m.kd = Vec3::splat(kd);
            m.ks = Vec3::splat(ks);
        }
        let cam = Camera::default_with_fov("c", 60.0);
        let rendered = render_job(
            &job(scene, cam, 32, 32),
            &RenderSettings::default(),
            &|_| {},
        );
        rendered.unwrap().rays.shadow
    };
    assert_eq!(shadow_rays(0.0, 0.0), 0);
    // A highlight alone needs its shadow ray, but only on the side where R·V > 0.
    let specular_only = shadow_rays(0.0, 0.5);
    let diffuse = shadow_rays(0.5, 0.0);
    assert!(specular_only > 0, "{specular_only}");
    assert!(specular_only < diffuse, "{specular_only} vs {diffuse}");
}

#[test]
fn an_opaque_blocker_above_glass_casts_a_full_shadow() {
    // As in the test above, but an opaque slab between the glass and the light: whatever
    // order the crossings come in, the floor point sees no light, only ambient.
    let floor = Material::phong(
        "floor",
        Vec3::splat(0.2),
        Vec3::new(0.6, 0.4, 0.2),
        Vec3::ZERO,
        1.0,
    );
    let mut veil = material("veil", 0.0, [0.0; 3], 0.0, 1.0);
    veil.opacity = 0.5;
    let slab = material("slab", 0.0, [0.5; 3], 0.0, 1.0);
    let scene = Scene {
        materials: vec![floor, veil, slab],
        instances: vec![
            instance(
                Geometry::Box {
                    p1: DVec3::new(-10.0, -1.0, -10.0),
                    p2: DVec3::new(10.0, 0.0, 10.0),
                },
                0,
            ),
            sphere([0.0, 3.0, 0.0], 1.0, 1),
            sphere([0.0, 6.0, 0.0], 0.5, 1),
            instance(
                Geometry::Box {
                    p1: DVec3::new(-1.0, 7.0, -1.0),
                    p2: DVec3::new(1.0, 7.5, 1.0),
                },
                2,
            ),
        ]
        .into(),
        lights: vec![Light {
            name: "l".into(),
            position: DVec3::new(0.0, 10.0, 0.0),
            intensity: Vec3::splat(2.0),
            radius: 0.0,
            spot: None,
        }],
        ambient: Vec3::splat(0.5),
        background: Vec3::ZERO,
        ..Scene::default()
    };
    let cam = Camera {
        name: "c".into(),
        fov_x_deg: 10.0,
        eye: DVec3::new(0.0, 1.0, 5.0),
        dir: DVec3::new(0.0, -1.0, -5.0),
        up: DVec3::Y,
        lens: None,
    };
    let img = render(&job(scene, cam, 3, 3));
    let expected = Vec3::splat(0.2 * 0.5);
    assert!(
        (img.pixels[4] - expected).abs().max_element() < 1e-6,
        "{:?} vs {expected:?}",
        img.pixels[4]
    );
}

/// Spheres of radius 0.3 at z = −10 on an `n × n` grid, one unit apart, centred on the view.
fn sphere_grid(n: usize) -> Scene {
    let half = (n as f64 - 1.0) / 2.0;
    let instances: Vec<Instance> = (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f64 - half, (i / n) as f64 - half);
            sphere([x, y, -10.0], 0.3, 0)
        })
        .collect();
    Scene {
        materials: vec![material("m", 0.2, [0.6, 0.5, 0.4], 0.0, 1.0)],
        instances: instances.into(),
        background: Vec3::new(0.3, 0.2, 0.1),
        ..Scene::default()
    }
}

/// How many of the rays of `camera` through pixel (x, y) at `offsets` meet one of `scene`'s
/// spheres, worked out from the ray's distance to each centre; `None` when a ray passes
/// within a hair of a silhouette, where f32 and f64 may disagree.
fn hits_by_formula(
    scene: &Scene,
    camera: &camera::PinholeCamera,
    (x, y): (u32, u32),
    offsets: &[(f32, f32)],
) -> Option<u32> {
    let mut hits = 0;
    for &(dx, dy) in offsets {
        let ray = camera.ray(x as f32 + dx, y as f32 + dy);
        let (o, d) = (
            Vec3::from(ray.origin).as_dvec3(),
            Vec3::from(ray.dir).as_dvec3().normalize(),
        );
        let mut hit = false;
        for instance in scene.instances.iter() {
            let Geometry::Sphere { center, radius } = instance.geometry else {
                continue;
            };
            let to = center - o;
            let miss = to.cross(d).length() - radius;
            if miss.abs() < 1e-4 {
                return None;
            }
            hit |= miss < 0.0 && to.dot(d) > 0.0;
        }
        hits += u32::from(hit);
    }
    Some(hits)
}

/// A pixel's coverage is the share of its camera samples that hit a surface, whether its rays
/// were traced one by one or in packets (the grid's hierarchy is deep enough for them).
#[test]
fn coverage_is_the_share_of_samples_that_hit() {
    let camera = Camera::default_with_fov("cam", 40.0);
    for (n, packets) in [(1, false), (12, true)] {
        let job = job(sphere_grid(n), camera.clone(), 48, 36);
        let prepared = Prepared::new(&job);
        let pinhole = camera::PinholeCamera::new(prepared.camera(), 48, 36).unwrap();
        for spp in [1, 16] {
            let settings = RenderSettings {
                spp: Some(spp),
                ..RenderSettings::default()
            };
            let viewpoint = Viewpoint {
                view: pinhole.view(),
                size: (48, 36),
                camera_rays: 48 * 36 * u64::from(spp),
                motion: false,
            };
            let plan = prepared.compile(Some(&viewpoint)).plan();
            assert_eq!(plan.1.camera_packets, packets, "{n}×{n} spheres");
            let rendered = render_prepared(&prepared, &settings, &|_| {}).unwrap();
            let offsets = sampler::sample_offsets(spp);
            let (mut partial, mut checked) = (0, 0);
            for (i, &coverage) in rendered.coverage.iter().enumerate() {
                let at = (i as u32 % 48, i as u32 / 48);
                let Some(hits) = hits_by_formula(&job.scene, &pinhole, at, &offsets) else {
                    continue;
                };
                assert_eq!(
                    coverage,
                    hits as f32 / spp as f32,
                    "pixel {at:?}, {spp} spp"
                );
                partial += usize::from(coverage > 0.0 && coverage < 1.0);
                checked += 1;
            }
            assert!(checked > 48 * 36 * 9 / 10, "{checked} pixels checked");
            assert_eq!(partial > 0, spp > 1, "{partial} pixels partly covered");
        }
    }
}
