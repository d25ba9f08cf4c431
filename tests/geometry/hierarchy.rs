//! The 4-wide hierarchy against brute force over random primitives.

use super::*;
use anim_core::accel::Bvh;

fn random_scene(rng: &mut SplitMix64, n: usize) -> Vec<Primitive> {
    let mut prims = Vec::new();
    while prims.len() < n {
        let c = rng.vec(50.0);
        let geometry = match prims.len() % 3 {
            0 => Geometry::Sphere {
                center: c,
                radius: 0.2 + rng.unit_f64() * 2.0,
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
            let turn = Transform::rotate(10.0 + rng.unit_f64() * 70.0, DVec3::Y).unwrap();
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

#[test]
fn wide_bvh_equals_brute_force_on_random_scenes() {
    let mut rng = SplitMix64::new(0x853C49E6748FEA9B);
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
