use super::*;

fn tetrahedron() -> Mesh {
    let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
    // Counter-clockwise seen from outside.
    let triangles = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    Mesh::new(positions, Vec::new(), triangles).unwrap()
}

#[test]
fn flat_normals_point_outwards() {
    let m = tetrahedron();
    let h = m
        .intersect(
            &Ray::new(Vec3A::new(0.2, 0.2, 5.0), -Vec3A::Z),
            f32::INFINITY,
        )
        .unwrap();
    // Enters through the slanted face x + y + z = 1.
    assert!((h.t - 4.4).abs() < 1e-5, "{}", h.t);
    let n = h.normal.normalize();
    assert!((n - Vec3A::ONE.normalize()).length() < 1e-6, "{n:?}");
    let below = m
        .intersect(
            &Ray::new(Vec3A::new(0.2, 0.2, -5.0), Vec3A::Z),
            f32::INFINITY,
        )
        .unwrap();
    assert!((below.t - 5.0).abs() < 1e-6);
    assert!((below.normal.normalize() - -Vec3A::Z).length() < 1e-6);
}

#[test]
fn smooth_normals_are_interpolated() {
    let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    let normals = vec![Vec3::Z, Vec3::new(1.0, 0.0, 1.0), Vec3::Z];
    let m = Mesh::new(positions, normals, vec![[0, 1, 2]]).unwrap();
    assert!(m.is_smooth());
    let h = m
        .intersect(
            &Ray::new(Vec3A::new(0.5, 0.25, 1.0), -Vec3A::Z),
            f32::INFINITY,
        )
        .unwrap();
    // Barycentric weights (0.25, 0.5, 0.25) of the unit normals.
    let expected = Vec3A::Z * 0.5 + Vec3A::new(1.0, 0.0, 1.0).normalize() * 0.5;
    assert!((h.normal - expected).length() < 1e-6, "{:?}", h.normal);
}

#[test]
fn bad_arrays_are_refused_and_partial_normals_mean_flat() {
    assert_eq!(
        Mesh::new(vec![Vec3::ZERO], Vec::new(), Vec::new()).unwrap_err(),
        MeshError::NoTriangles
    );
    assert_eq!(
        Mesh::new(vec![Vec3::ZERO, Vec3::X], Vec::new(), vec![[0, 1, 2]]).unwrap_err(),
        MeshError::BadIndex
    );
    assert_eq!(
        Mesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::new(f32::NAN, 0.0, 0.0)],
            Vec::new(),
            vec![[0, 1, 2]]
        )
        .unwrap_err(),
        MeshError::NonFinite
    );
    let m = Mesh::new(
        vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        vec![Vec3::Z],
        vec![[0, 1, 2]],
    );
    assert!(!m.unwrap().is_smooth());
}

#[test]
fn t_max_and_misses() {
    let m = tetrahedron();
    let r = Ray::new(Vec3A::new(0.2, 0.2, 5.0), -Vec3A::Z);
    assert!(m.intersect(&r, 4.0).is_none());
    let miss = Ray::new(Vec3A::new(2.0, 2.0, 5.0), -Vec3A::Z);
    assert!(m.intersect(&miss, f32::INFINITY).is_none());
    assert_eq!(m.triangle_count(), 4);
    assert_eq!(m.vertex_count(), 4);
}

#[test]
fn mesh_files_compare_by_name() {
    let a = MeshFile::with_mesh("a.obj", tetrahedron());
    assert_eq!(a, MeshFile::new("a.obj"));
    assert_ne!(a, MeshFile::new("b.obj"));
    let copy = a.clone();
    assert!(Arc::ptr_eq(copy.mesh().unwrap(), a.mesh().unwrap()));
}

/// A closed torus of `2·nu·nv` triangles over `nu·nv` shared vertices.
fn torus(nu: u32, nv: u32, smooth: bool) -> Mesh {
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    for i in 0..nu {
        let a = std::f32::consts::TAU * i as f32 / nu as f32;
        for j in 0..nv {
            let b = std::f32::consts::TAU * j as f32 / nv as f32;
            let n = Vec3::new(a.cos() * b.cos(), b.sin(), a.sin() * b.cos());
            positions.push(Vec3::new(a.cos(), 0.0, a.sin()) + n * 0.35);
            normals.push(n);
        }
    }
    let mut triangles = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            let p = i * nv + j;
            let q = (i + 1) % nu * nv + j;
            let r = (i + 1) % nu * nv + (j + 1) % nv;
            let s = i * nv + (j + 1) % nv;
            triangles.push([p, s, r]);
            triangles.push([p, r, q]);
        }
    }
    Mesh::new(
        positions,
        if smooth { normals } else { Vec::new() },
        triangles,
    )
    .unwrap()
}

#[test]
fn a_mesh_costs_at_most_100_bytes_per_triangle() {
    for smooth in [false, true] {
        let m = torus(400, 125, smooth);
        let per_triangle = m.bytes() as f64 / m.triangle_count() as f64;
        assert!(per_triangle <= 100.0, "{per_triangle} B/triangle");
    }
}

mod watertight {
    use super::*;
    use proptest::prelude::*;

    /// Whether every triangle of `mesh` holding all of `corners` faces `origin` (seen from the
    /// front, not edge-on): a ray from there through the shared corners crosses the surface.
    fn faces_towards(mesh: &Mesh, corners: &[u32], origin: Vec3A) -> bool {
        (0..mesh.triangle_count() as u32)
            .filter(|&t| {
                corners
                    .iter()
                    .all(|c| mesh.triangles[t as usize].contains(c))
            })
            .all(|t| {
                let [a, b, c] = mesh.vertices(t);
                let n = (b - a).cross(c - a).normalize();
                n.dot((origin - a).normalize()) > 0.05
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]

        /// Rays aimed exactly at a shared vertex, or at a point of a shared edge, of a closed
        /// mesh from outside where the faces there are seen from the front, always hit it.
        #[test]
        fn rays_at_shared_edges_and_vertices_never_slip_through(
            i in 0u32..24, j in 0u32..9, edge in 0usize..3,
            s in prop_oneof![Just(0.0f32), Just(1.0f32), 0.0f32..1.0],
            theta in 0.0f32..std::f32::consts::TAU, phi in -1.5f32..1.5, dist in 2.5f32..40.0,
        ) {
            let mesh = torus(24, 9, false);
            let [a, b, c] = mesh.triangles[(2 * (i * 9 + j)) as usize];
            let corner = |k: u32| Vec3A::from(mesh.positions[k as usize]);
            let (p, q) = [(a, b), (b, c), (c, a)][edge];
            let (target, shared) = if s == 0.0 {
                (corner(p), vec![p])
            } else if s == 1.0 {
                (corner(q), vec![q])
            } else {
                (corner(p).lerp(corner(q), s), vec![p, q])
            };
            let origin =
                Vec3A::new(theta.cos() * phi.cos(), phi.sin(), theta.sin() * phi.cos()) * dist;
            prop_assume!(faces_towards(&mesh, &shared, origin));
            let ray = Ray::new(origin, target - origin);
            prop_assert!(
                mesh.intersect(&ray, f32::INFINITY).is_some(),
                "slipped through at {target:?}"
            );
        }
    }
}
