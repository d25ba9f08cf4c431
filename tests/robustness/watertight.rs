//! Watertightness of meshes and of quadric apexes and rims.

use super::*;

// ------------------------------------------------------------------------------------------
// Watertightness
// ------------------------------------------------------------------------------------------

struct Mesh {
    vertices: Vec<DVec3>,
    triangles: Vec<[usize; 3]>,
}

fn cube_mesh() -> Mesh {
    let vertices = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            )
        })
        .collect();
    // Two triangles per face, wound outwards.
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let triangles = quads
        .iter()
        .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
        .collect();
    Mesh {
        vertices,
        triangles,
    }
}

/// Unit UV sphere: `rings` latitude bands, `segments` longitude slices; the seam re-uses the
/// first column's vertices and the poles are single vertices, so the mesh is closed.
fn uv_sphere(segments: usize, rings: usize) -> Mesh {
    let mut vertices = vec![DVec3::Y];
    for i in 1..rings {
        let theta = PI * i as f64 / rings as f64;
        for j in 0..segments {
            let phi = TAU * j as f64 / segments as f64;
            vertices.push(DVec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            ));
        }
    }
    vertices.push(-DVec3::Y);
    let south = vertices.len() - 1;
    let ring = |i: usize, j: usize| 1 + (i - 1) * segments + j % segments;
    let mut triangles = Vec::new();
    for j in 0..segments {
        triangles.push([0, ring(1, j + 1), ring(1, j)]);
        for i in 1..rings - 1 {
            let (a, b) = (ring(i, j), ring(i, j + 1));
            let (c, d) = (ring(i + 1, j), ring(i + 1, j + 1));
            triangles.push([a, b, d]);
            triangles.push([a, d, c]);
        }
        triangles.push([south, ring(rings - 1, j), ring(rings - 1, j + 1)]);
    }
    Mesh {
        vertices,
        triangles,
    }
}

/// The triangles of `mesh` placed by `xf`, as the renderer holds them.
fn placed_triangles(mesh: &Mesh, xf: &Transform) -> Vec<Primitive> {
    mesh.triangles
        .iter()
        .map(|t| {
            Primitive::new(
                &Geometry::Triangle {
                    vertices: t.map(|i| mesh.vertices[i]),
                },
                xf,
                0,
            )
            .expect("mesh triangles are not degenerate")
        })
        .collect()
}

/// An edge of a mesh, its ends in ascending order, with the triangles around it.
type Edge = ((usize, usize), Vec<usize>);

/// The triangles around each vertex of `mesh`, and its edges, sorted.
fn triangles_around(mesh: &Mesh) -> (Vec<Vec<usize>>, Vec<Edge>) {
    let mut around_vertex: Vec<Vec<usize>> = vec![Vec::new(); mesh.vertices.len()];
    let mut around_edge: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
    for (ti, t) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            around_vertex[t[k]].push(ti);
            let (a, b) = (t[k], t[(k + 1) % 3]);
            around_edge
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push(ti);
        }
    }
    let mut edges: Vec<_> = around_edge.into_iter().collect();
    edges.sort();
    (around_vertex, edges)
}

/// Fires rays at every vertex, every edge mid-point and random points along every edge of
/// `mesh` placed by `xf`, each from outside and heading into the solid (towards a random
/// interior point), and requires the nearest hit among the triangles around that feature to
/// be at the aimed point. A ray slipping through would instead hit the far side or nothing.
/// Returns the number of rays.
fn check_watertight(
    name: &str,
    mesh: &Mesh,
    interior_radius: f64,
    xf: &Transform,
    rng: &mut SplitMix64,
) -> usize {
    let prims = placed_triangles(mesh, xf);
    // The vertices exactly as the baked triangles hold them.
    let baked: Vec<DVec3> = mesh
        .vertices
        .iter()
        .map(|&v| v32(xf.point(v)).as_dvec3())
        .collect();
    let (around_vertex, edges) = triangles_around(mesh);

    let mut targets: Vec<(DVec3, &[usize], String)> = Vec::new();
    for (v, tris) in around_vertex.iter().enumerate() {
        targets.push((baked[v], tris.as_slice(), format!("vertex {v}")));
    }
    // A point on an edge within rounding distance of one of its ends may be taken by any
    // triangle around that end, so the candidates for an edge are both ends' fans.
    let fans: Vec<Vec<usize>> = edges
        .iter()
        .map(|((a, b), _)| {
            let mut f = around_vertex[*a].clone();
            f.extend(&around_vertex[*b]);
            f.sort_unstable();
            f.dedup();
            f
        })
        .collect();
    for (((a, b), tris), fan) in edges.iter().zip(&fans) {
        assert_eq!(
            tris.len(),
            2,
            "{name}: edge ({a}, {b}) is not shared by two triangles"
        );
        let (pa, pb) = (baked[*a], baked[*b]);
        targets.push((
            (pa + pb) * 0.5,
            fan.as_slice(),
            format!("mid-point of edge ({a}, {b})"),
        ));
        for _ in 0..2 {
            // Uniform along the edge, or very close to one of its ends.
            let s = match rng.below(3) {
                0 => rng.unit_f64(),
                1 => rng.log_uniform(1e-7, 1e-2),
                _ => 1.0 - rng.log_uniform(1e-7, 1e-2),
            };
            targets.push((
                pa + (pb - pa) * s,
                fan.as_slice(),
                format!("edge ({a}, {b}) at {s:e}"),
            ));
        }
    }

    let size = (baked.iter().fold(DVec3::ZERO, |m, v| m.max(v.abs()))).max_element();
    let mut rays = 0;
    for (target, tris, what) in &targets {
        for _ in 0..3 {
            let inside = xf.point(rng.in_ball() * interior_radius);
            let into = (inside - *target).normalize();
            let origin = v32(*target - into * (size * rng.range(1.0, 4.0)));
            let dir = v32(*target - origin.as_dvec3());
            let ray = Ray::new(origin, dir);
            rays += 1;
            let nearest = tris
                .iter()
                .filter_map(|&ti| prims[ti].intersect(&ray, f32::INFINITY))
                .map(|h| h.t)
                .fold(f32::INFINITY, f32::min);
            // t = 1 at the aimed point (dir = target − origin).
            assert!(
                (nearest - 1.0).abs() < 1e-4,
                "{name}: ray {origin:?} + t·{dir:?} aimed at {what} {target:?}: nearest hit \
                 around it at t = {nearest} instead of 1 (slipped through)"
            );
        }
    }
    rays
}

fn watertight_placements() -> Vec<(String, Transform)> {
    let mut rng = SplitMix64::new(0x3A7E_0001 ^ soak());
    let mut out = vec![("identity".to_string(), Transform::IDENTITY)];
    for scale in [1e-3, 0.7, 1e2, 1e4] {
        let pl = random_placement(&mut rng, scale, 4.0, 10.0);
        out.push((format!("scale {scale:e}"), pl.xf));
    }
    out
}

#[test]
fn watertight_cube_mesh() {
    let mut rng = SplitMix64::new(0xC0BE ^ soak());
    let mesh = cube_mesh();
    let mut rays = 0;
    for (what, xf) in watertight_placements() {
        for _ in 0..20 {
            rays += check_watertight(&format!("cube, {what}"), &mesh, 0.9, &xf, &mut rng);
        }
    }
    eprintln!("watertight cube: {rays} rays through edges and vertices, none slipped through");
}

#[test]
fn watertight_uv_sphere_mesh() {
    let start = Instant::now();
    let mut rng = SplitMix64::new(0x5F3E ^ soak());
    let mesh = uv_sphere(64, 32);
    assert_eq!(mesh.triangles.len(), 2 * 64 * 31);
    let mut rays = 0;
    for (what, xf) in watertight_placements() {
        rays += check_watertight(&format!("UV sphere, {what}"), &mesh, 0.5, &xf, &mut rng);
    }
    eprintln!(
        "watertight UV sphere: {rays} rays through edges and vertices, none slipped through, {:.2?}",
        start.elapsed()
    );
}

/// The quadrics' own "edges": the cone's apex, where the two roots of the side merge, and the
/// rims where a side meets a cap. Rays aimed exactly at them, from outside into the solid and
/// from inside out, must hit there (t = 1 for a direction of target − origin), neither
/// slipping in (hitting the far side from inside instead) nor out (no hit at all); and rays
/// spawned from those hits must not re-hit the surface, whether the quadric is baked into
/// world space (similarity transforms) or traced through its matrix (non-uniform scales).
///
/// The second kind used to fail (59 of 319,040 rays, all spawned inwards from a rim): the
/// rim's halfway normal, taken in object space and mapped by a non-uniform scale, may point
/// into the solid yet out of one face, so the origin moved "inwards" along it started outside
/// that face. Rays spawned inwards from a rim now move along the bisector of the faces' world
/// normals, by the hit's own error bound over cos(θ/2) (`Primitive::surface`).
#[test]
fn quadric_apex_and_rims_are_watertight() {
    let mut rng = SplitMix64::new(0xED6E ^ soak());
    let (mut rays, mut worst) = (0u64, 0.0f64);
    let mut spawned = Stats {
        min_exit_ratio: f64::INFINITY,
        ..Stats::default()
    };
    let mut spawned_object_space = Stats {
        min_exit_ratio: f64::INFINITY,
        ..Stats::default()
    };
    for kind in [Kind::Cone, Kind::Cylinder] {
        for object in 0..400 {
            let obj = random_object(kind, &mut rng);
            let scale = rng.log_uniform(1e-3, 1e4);
            let pl = random_placement(&mut rng, scale, 4.0, 10.0);
            let prim = Primitive::new(&obj.geometry, &pl.xf, 0).unwrap();
            let under_test = Target {
                prim: &prim,
                obj: &obj,
                xf: &pl.xf,
                size: obj.min_dim * pl.s_min,
            };
            let (apex, targets) = apex_and_rim_points(&obj, &mut rng);
            for target in targets {
                for _ in 0..16 {
                    let t_w = pl.xf.point(target);
                    let c_w = pl.xf.point(interior_point(&obj, &mut rng));
                    // As far outside as the interior point is inside (×0.5…4): a ray that
                    // slipped in would exit beyond the interior point, at t ≥ 1.25.
                    let from_outside = v32(t_w + (t_w - c_w) * rng.range(0.5, 4.0));
                    let from_inside = v32(c_w);
                    for origin in [from_outside, from_inside] {
                        let ray = Ray::new(origin, v32(t_w - origin.as_dvec3()));
                        rays += 1;
                        let hit = prim.intersect(&ray, f32::INFINITY);
                        let t = hit.map(|h| h.t);
                        if let Some(t) = t {
                            worst = worst.max((t as f64 - 1.0).abs());
                        }
                        // 1e-2 leaves room for rays that meet a rim at a grazing angle, where
                        // t is ill-conditioned, and is far from what a leak would give.
                        assert!(
                            t.is_some_and(|t| (t - 1.0).abs() < 1e-2),
                            "{kind:?} object {object} scale {scale:e}: ray {ray:?} aimed at \
                             {target:?} (object space; apex {apex:?}) hits at t = {t:?}, not 1"
                        );
                        // The apex and rims are also where the normal is least defined: rays
                        // leaving from there must behave like any other spawned ray.
                        let Some(hit) = hit else { continue };
                        // Modes 0 and 1 are similarity transforms: the quadric is baked.
                        let stats = if pl.mode < 2 {
                            &mut spawned
                        } else {
                            &mut spawned_object_space
                        };
                        for side in [1.0, -1.0] {
                            let dir = v32(rng.hemisphere(hit.normal.as_dvec3() * side));
                            let what = || {
                                format!(
                                    "{kind:?} object {object} mode {} scale {scale:e}, spawned at \
                                     {target:?} (object space; apex {apex:?})",
                                    pl.mode
                                )
                            };
                            spawn_and_check(&under_test, &hit, dir, 1.0, stats, &what);
                        }
                    }
                }
            }
        }
    }
    eprintln!(
        "apex and rims: {rays} rays, none slipped through, worst |t − 1| = {worst:.2e}; rays \
         spawned from the hits: {} on baked quadrics with {} failures, {} on object-space \
         (non-uniformly scaled) ones with {} failures",
        spawned.rays, spawned.failures, spawned_object_space.rays, spawned_object_space.failures
    );
    for (stats, what) in [(&spawned, "baked"), (&spawned_object_space, "object-space")] {
        assert!(
            stats.failures == 0,
            "{} of {} rays spawned from apex or rim hits of {what} quadrics hit the surface \
             they left:\n{}",
            stats.failures,
            stats.rays,
            stats.messages.join("\n")
        );
    }
    assert!(spawned.rays > 300_000 && spawned_object_space.rays > 300_000);
}

/// The apex of `obj` (a cone's) and the points to aim at on it (object space): the apex and
/// eight points at random angles around each rim.
fn apex_and_rim_points(obj: &Object, rng: &mut SplitMix64) -> (Option<DVec3>, Vec<DVec3>) {
    let (ends, radius, apex) = match obj.geometry {
        Geometry::Cone { base, tip, radius } => (vec![base], radius, Some(tip)),
        Geometry::Cylinder { p1, p2, radius } => (vec![p1, p2], radius, None),
        _ => unreachable!(),
    };
    let w = match obj.geometry {
        Geometry::Cone { base, tip, .. } => (tip - base).normalize(),
        Geometry::Cylinder { p1, p2, .. } => (p2 - p1).normalize(),
        _ => unreachable!(),
    };
    let (u, v) = w.any_orthonormal_pair();
    let mut targets: Vec<DVec3> = apex.into_iter().collect();
    for end in &ends {
        for _ in 0..8 {
            let phi = rng.range(0.0, TAU);
            targets.push(*end + (u * phi.cos() + v * phi.sin()) * radius);
        }
    }
    (apex, targets)
}
