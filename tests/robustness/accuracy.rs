//! Cone and cylinder accuracy against f64.

use super::*;

// ------------------------------------------------------------------------------------------
// Cone and cylinder accuracy
// ------------------------------------------------------------------------------------------

/// Distance of object-space point `q` from the surface, as the spec measures it: for the
/// side, |distance to the axis − radius at that height|; for a cap, the distance to its
/// plane (when within the cap's radius); whichever part is nearer.
fn surface_error(g: &Geometry, q: DVec3) -> f64 {
    // Axis start, axis, radius at the start and at the end, whether the end is capped.
    let (from, axis, r0, r1, top_cap) = match *g {
        Geometry::Cylinder { p1, p2, radius } => (p1, p2 - p1, radius, radius, true),
        Geometry::Cone { base, tip, radius } => (base, tip - base, radius, 0.0, false),
        _ => unreachable!(),
    };
    let h = axis.length();
    let w = axis / h;
    let r_at = |z: f64| r0 + (r1 - r0) * (z / h);
    let rel = q - from;
    let z = rel.dot(w);
    let rho = (rel - w * z).length();
    let slack = 1e-5 * h;
    let mut err = f64::INFINITY;
    if (-slack..=h + slack).contains(&z) {
        err = (rho - r_at(z.clamp(0.0, h))).abs();
    }
    let caps: &[f64] = if top_cap { &[0.0, h] } else { &[0.0] };
    for &zc in caps {
        if rho <= r_at(zc) * (1.0 + 1e-5) {
            err = err.min((z - zc).abs());
        }
    }
    err
}

/// Special rays for one object (object space): along the axis, parallel to it, along and
/// parallel to cone generators. Each is (origin, direction, whether t is well defined): a ray
/// lying in the surface (along a generator) meets it everywhere, and one within 1e-2 of it
/// is closer to the surface than f32 can place the transformed ray, so whether it enters at
/// one end or grazes in along the side is a matter of rounding: for those only the point is
/// checked.
fn special_rays(g: &Geometry, rng: &mut SplitMix64) -> Vec<(DVec3, DVec3, bool)> {
    let mut rays = Vec::new();
    match *g {
        Geometry::Cylinder { p1, p2, radius } => {
            let axis = p2 - p1;
            let w = axis.normalize();
            let (u, v) = w.any_orthonormal_pair();
            // Exactly along the axis, from beyond either end.
            rays.push((p2 + axis * rng.range(0.1, 2.0), -w, true));
            rays.push((p1 - axis * rng.range(0.1, 2.0), w, true));
            // Parallel to the axis: inside the radius (caps), just inside and just outside the
            // side (lines along the surface), and from inside.
            for _ in 0..6 {
                let phi = rng.range(0.0, TAU);
                let radial = u * phi.cos() + v * phi.sin();
                let (rho, clear) = match rng.below(3) {
                    0 => (rng.range(0.0, 0.99), true),
                    1 => (1.0 - rng.log_uniform(1e-6, 1e-2), false),
                    _ => (1.0 + rng.log_uniform(1e-6, 1e-2), false),
                };
                let rho = rho * radius;
                rays.push((p1 - axis + radial * rho, w, clear));
                rays.push((
                    p1 + axis * rng.range(0.1, 0.9) + radial * rho.min(radius * 0.99),
                    -w,
                    true,
                ));
            }
        }
        Geometry::Cone { base, tip, radius } => {
            let axis = tip - base;
            let w = axis.normalize();
            let (u, v) = w.any_orthonormal_pair();
            // Along the axis: onto the apex from beyond it, onto the base centre from below.
            rays.push((tip + axis * rng.range(0.1, 2.0), -w, true));
            rays.push((base - axis * rng.range(0.1, 2.0), w, true));
            // Onto the apex from within the cone of directions that enter through it (up to
            // 0.9 of the half-angle off the axis): these must not slip in past the apex.
            let half_angle = (radius / axis.length()).atan();
            for _ in 0..4 {
                let (a, b) = (rng.range(0.0, TAU), rng.range(0.0, 0.9 * half_angle));
                let from_axis = (u * a.cos() + v * a.sin()) * b.sin() + w * b.cos();
                rays.push((tip + from_axis * rng.range(0.1, 2.0), -from_axis, true));
            }
            for _ in 0..6 {
                let phi = rng.range(0.0, TAU);
                let radial = u * phi.cos() + v * phi.sin();
                let rim = base + radial * radius;
                let g_dir = tip - rim;
                // Parallel to the generator through `rim`, shifted radially: exactly on it,
                // just inside/outside, or well inside; started before the base.
                let (shift, clear) = match rng.below(4) {
                    0 => (0.0, false),
                    1 => (-rng.log_uniform(1e-6, 1e-2), false),
                    2 => (rng.log_uniform(1e-6, 1e-2), false),
                    _ => (-rng.range(0.1, 0.9), true),
                };
                rays.push((
                    rim + radial * (shift * radius) - g_dir * rng.range(0.1, 1.0),
                    g_dir,
                    clear,
                ));
                // From inside the cone, parallel to a generator: the linear case from within.
                let inside = base + axis * rng.range(0.05, 0.5) + radial * (0.3 * radius);
                rays.push((inside, g_dir, true));
                // From outside beyond the apex, back along the generator.
                rays.push((tip + g_dir * rng.range(0.1, 1.0), -g_dir, false));
            }
        }
        _ => unreachable!(),
    }
    rays
}

#[test]
fn cone_and_cylinder_hits_lie_on_the_surface() {
    let start = Instant::now();
    for (kind, seed) in [(Kind::Cylinder, 0xACC0_0001u64), (Kind::Cone, 0xACC0_0002)] {
        let mut rng = SplitMix64::new(seed ^ soak());
        let (mut hits, mut special_hits, mut compared) = (0u64, 0u64, 0u64);
        let (mut worst_point, mut worst_t) = (0.0f64, 0.0f64);
        for object in 0..500 {
            let obj = random_object(kind, &mut rng);
            let scale = rng.log_uniform(1e-3, 1e4);
            let pl = random_placement(&mut rng, scale, 2.0, 10.0);
            let prim = Primitive::new(&obj.geometry, &pl.xf, 0).unwrap();
            let obj_size = match obj.geometry {
                Geometry::Cylinder { p1, p2, radius } => (p2 - p1).length().max(radius),
                Geometry::Cone { base, tip, radius } => (tip - base).length().max(radius),
                _ => unreachable!(),
            };
            let specials = special_rays(&obj.geometry, &mut rng);
            let n_special = specials.len();
            let mut rays = specials;
            for _ in 0..200 {
                let r = aim(&obj, &Transform::IDENTITY, &mut rng);
                rays.push((r.origin.as_dvec3(), r.dir.as_dvec3(), true));
            }
            for (i, (o, d, t_defined)) in rays.into_iter().enumerate() {
                let special = i < n_special;
                let ray = world_ray(pl.xf.point(o), pl.xf.vector(d));
                let Some(hit) = prim.intersect(&ray, f32::INFINITY) else {
                    continue;
                };
                hits += 1;
                special_hits += special as u64;
                let q = pl
                    .xf
                    .object_from_world
                    .transform_point3(hit.point.as_dvec3());
                let err = surface_error(&obj.geometry, q) / obj_size;
                worst_point = worst_point.max(err);
                assert!(
                    err <= 1e-5,
                    "{kind:?} object {object} ray {i} (special: {special}) scale {scale:e}: \
                     hit point {:?} is {err:.2e} (relative) off the surface",
                    hit.point
                );
                // Where both see a clean crossing, t must agree with the f64 reference. Not
                // compared: grazing crossings (either normal within 1e-2 of perpendicular to
                // the ray), where t is ill-conditioned, and hits on a cone's apex, a single
                // point the reference's double root may round away.
                let (ro, rd) = to_object(&pl.xf, &ray);
                let clean = t_defined
                    && (hit.normal.dot(ray.dir) / ray.dir.length()).abs() > 1e-2
                    && match obj.geometry {
                        Geometry::Cone { tip, .. } => (q - tip).length() > 1e-3 * obj_size,
                        _ => true,
                    };
                if let Some((t_ref, n_ref)) = reference_hit(&obj.geometry, ro, rd) {
                    let cos = n_ref.dot(rd).abs() / rd.length();
                    if cos > 1e-2 && clean {
                        compared += 1;
                        let t_err = (hit.t as f64 - t_ref).abs() * rd.length() / obj_size;
                        worst_t = worst_t.max(t_err);
                        assert!(
                            t_err <= 1e-4,
                            "{kind:?} object {object} ray {i} scale {scale:e}: t = {} but the \
                             f64 reference says {t_ref} ({t_err:.2e} of the size); {:?}, {:?}, \
                             {ray:?}, hit {hit:?}",
                            hit.t,
                            obj.geometry,
                            pl.xf
                        );
                    }
                }
            }
        }
        eprintln!(
            "accuracy {kind:?}: {hits} hits ({special_hits} from axis/generator rays), worst \
             point error {worst_point:.2e} of the size; {compared} t compared with f64, worst \
             {worst_t:.2e}"
        );
        assert!(special_hits > 1000);
    }
    eprintln!("accuracy: {:.2?}", start.elapsed());
}
