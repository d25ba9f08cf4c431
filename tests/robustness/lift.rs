//! Proptest of the spawn lift (`SurfaceHit::spawn_ray`): from points on the faces, rims,
//! apexes, box edges and corners of closed shapes under any affine placement (shears from a
//! rotation before a non-uniform scale included), rays spawned either way never meet their
//! own primitive except by leaving it.

use super::*;

/// `translate · rotate_after · scale · rotate_before`: a rotation before a non-uniform scale
/// shears, so right angles (a box's edges, a cylinder's rims) become acute or obtuse.
fn sheared(factors: DVec3, before: (f64, DVec3), after: (f64, DVec3), shift: DVec3) -> Transform {
    let rot = |(deg, axis): (f64, DVec3)| Transform::rotate(deg, axis).unwrap_or_default();
    Transform::translate(shift)
        .then_after(&rot(after))
        .then_after(&Transform::scale(factors).unwrap())
        .then_after(&rot(before))
}

/// Object-space points on the features of `obj` where spawning is hardest: vertices and edges
/// exactly, points near them (log-uniformly 1e-7 … 1e-2 of the size away, along a face), and
/// points on the faces.
fn feature_points(obj: &Object, rng: &mut SplitMix64) -> Vec<DVec3> {
    let mut out = Vec::new();
    let near = |rng: &mut SplitMix64| rng.log_uniform(1e-7, 1e-2);
    match obj.geometry {
        Geometry::Cylinder { p1, p2, radius }
        | Geometry::Cone {
            base: p1,
            tip: p2,
            radius,
        } => {
            let is_cone = obj.kind == Kind::Cone;
            let axis = p2 - p1;
            let w = axis.normalize();
            let (u, v) = w.any_orthonormal_pair();
            if is_cone {
                out.push(p2);
                out.push(p2 - axis * near(rng));
            }
            let ends: &[(DVec3, f64)] = if is_cone {
                &[(p1, 1.0)]
            } else {
                &[(p1, 1.0), (p2, -1.0)]
            };
            for &(end, inwards) in ends {
                for _ in 0..4 {
                    let phi = rng.range(0.0, TAU);
                    let radial = u * phi.cos() + v * phi.sin();
                    let rim = end + radial * radius;
                    out.push(rim);
                    // Along the cap towards the axis, and along the side away from the cap.
                    out.push(rim - radial * (radius * near(rng)));
                    let along_side = if is_cone {
                        (p2 - rim).normalize()
                    } else {
                        w * inwards
                    };
                    out.push(rim + along_side * (axis.length() * near(rng)));
                    // On the cap and on the side, anywhere.
                    out.push(end + radial * (radius * rng.unit_f64()));
                    let s = rng.range(0.05, 0.95);
                    out.push(if is_cone {
                        rim + (p2 - rim) * s
                    } else {
                        rim + axis * s
                    });
                }
            }
        }
        Geometry::Box { p1, p2 } => {
            let (lo, hi) = (p1.min(p2), p1.max(p2));
            let pick = |rng: &mut SplitMix64, i: usize, mode: usize| match mode {
                0 => lo[i],
                1 => hi[i],
                2 => lo[i] + (hi[i] - lo[i]) * near(rng),
                3 => hi[i] - (hi[i] - lo[i]) * near(rng),
                _ => rng.range(lo[i], hi[i]),
            };
            for _ in 0..16 {
                // At least one coordinate on a face; the others anywhere, on or near an edge.
                let on = rng.below(3);
                let mut p = DVec3::ZERO;
                for i in 0..3 {
                    let mode = if i == on { rng.below(2) } else { rng.below(5) };
                    p[i] = pick(rng, i, mode);
                }
                out.push(p);
            }
        }
        Geometry::Sphere { center, radius } => {
            for _ in 0..8 {
                out.push(center + rng.direction() * radius);
            }
        }
        _ => unreachable!("closed shapes only"),
    }
    out
}

fn closed_kind() -> impl Strategy<Value = Kind> {
    prop_oneof![
        Just(Kind::Cylinder),
        Just(Kind::Cone),
        Just(Kind::Box),
        Just(Kind::Sphere),
    ]
}

fn axis() -> impl Strategy<Value = DVec3> {
    (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

proptest! {
    #![proptest_config(ProptestConfig {
        // PROPTEST_CASES raises it for a soak.
        cases: ProptestConfig::default().cases.max(600),
        failure_persistence: Some(Box::new(
            proptest::test_runner::FileFailurePersistence::WithSource("proptest-regressions"),
        )),
        ..ProptestConfig::default()
    })]

    #[test]
    fn spawned_rays_never_meet_their_own_shape_again(
        kind in closed_kind(),
        seed in any::<u64>(),
        log_factors in (-1.4f64..1.4, -1.4f64..1.4, -1.4f64..1.4),
        log_scale in -4.0f64..5.0,
        before in (-180.0f64..180.0, axis()),
        after in (-180.0f64..180.0, axis()),
        shift in (axis(), 0.0f64..30.0),
    ) {
        let mut rng = SplitMix64::new(seed);
        let obj = random_object(kind, &mut rng);
        let scale = 10f64.powf(log_scale);
        let factors = DVec3::new(log_factors.0.exp(), log_factors.1.exp(), log_factors.2.exp());
        let xf = sheared(factors * scale, before, after, shift.0 * (shift.1 * scale));
        let Ok(prim) = Primitive::new(&obj.geometry, &xf, 0) else {
            return Ok(());
        };
        // Thinnest world dimension, at worst: the object's over the strongest shrink.
        let target = Target {
            prim: &prim,
            obj: &obj,
            xf: &xf,
            size: obj.min_dim * scale * factors.min_element(),
        };
        let mut stats = Stats {
            min_exit_ratio: f64::INFINITY,
            ..Stats::default()
        };
        for point in feature_points(&obj, &mut rng) {
            let p_w = xf.point(point);
            for from_inside in [false, true] {
                let c_w = xf.point(interior_point(&obj, &mut rng));
                let origin = if from_inside {
                    c_w
                } else {
                    p_w + (p_w - c_w) * rng.range(0.5, 4.0)
                };
                let ray = world_ray(origin, p_w - origin);
                let Some(hit) = prim.intersect(&ray, f32::INFINITY) else {
                    continue;
                };
                for side in [1.0, -1.0, 1.0, -1.0] {
                    let dir = v32(rng.hemisphere(hit.normal.as_dvec3() * side));
                    let what = || {
                        format!("{kind:?} seed {seed}, at {point:?} (object space) of {:?}", obj.geometry)
                    };
                    spawn_and_check(&target, &hit, dir, 1.0, &mut stats, &what);
                }
            }
        }
        prop_assert!(
            stats.failures == 0,
            "{} of {} spawned rays met their shape again:\n{}",
            stats.failures,
            stats.rays,
            stats.messages.join("\n")
        );
    }
}
