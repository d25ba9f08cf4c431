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
    // Barycentric weights (0.25, 0.5, 0.25).
    let expected = Vec3A::new(0.5, 0.0, 1.0);
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
