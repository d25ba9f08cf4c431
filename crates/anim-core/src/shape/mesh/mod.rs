//! Triangle meshes read from Wavefront OBJ files (`define shape obj`). A mesh is one shape to
//! the rest of the renderer: it sits in the scene's hierarchy as a single primitive and keeps
//! its own hierarchy over its triangles inside.
//!
//! Memory per triangle, as rendered: one index triple (12 bytes), its share of the vertex
//! positions and normals (about half a vertex per triangle in a closed mesh, 12 bytes each)
//! and its share of the 4-wide hierarchy (a 128-byte node per few leaves plus the leaf index
//! lists); `Mesh::bytes` adds it up. BENCHMARKS.md records what a million-triangle mesh
//! costs a whole render.

mod cache;
mod obj;

pub use cache::MeshCache;
pub use obj::{load, load_open};

use super::triangle::RaySpace;
use super::ShapeHit;
use crate::accel::Bvh;
use crate::math::{Aabb, Ray};
use glam::{Vec3, Vec3A};
use std::fmt;
use std::sync::{Arc, OnceLock};

/// Triangles over shared vertices, with an optional normal per vertex for smooth shading.
pub struct Mesh {
    positions: Vec<Vec3>,
    /// Empty when the file gives no normal for some vertex: the mesh is then shaded flat.
    normals: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    bvh: Bvh,
    bounds: Aabb,
}

/// Why vertex and index arrays cannot make a mesh.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MeshError {
    /// The triangle array is empty.
    NoTriangles,
    /// A triangle names a vertex beyond the position array.
    BadIndex,
    /// A vertex position is not finite.
    NonFinite,
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            MeshError::NoTriangles => "holds no triangles (no face with three or more vertices)",
            MeshError::BadIndex => "has a face whose vertex index is out of range",
            MeshError::NonFinite => "has a coordinate or normal that is not a finite number",
        })
    }
}

impl Mesh {
    /// Builds the mesh and its hierarchy. `normals` is used only when it gives one finite
    /// normal per position (each made unit length); otherwise the mesh is shaded flat.
    pub fn new(
        positions: Vec<Vec3>,
        normals: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
    ) -> Result<Mesh, MeshError> {
        if triangles.is_empty() {
            return Err(MeshError::NoTriangles);
        }
        if !positions.iter().all(|p| p.is_finite()) {
            return Err(MeshError::NonFinite);
        }
        let n = positions.len();
        if triangles.iter().flatten().any(|&i| i as usize >= n) {
            return Err(MeshError::BadIndex);
        }
        let normals = if normals.len() == n && normals.iter().all(|v| v.is_finite()) {
            // Files need not write unit normals; interpolation weighs them alike.
            normals.into_iter().map(Vec3::normalize_or_zero).collect()
        } else {
            Vec::new()
        };
        // The per-triangle boxes live only while the hierarchy is built.
        let boxes: Vec<Aabb> = triangles
            .iter()
            .map(|t| Aabb::from_points(t.map(|i| Vec3A::from(positions[i as usize]))))
            .collect();
        let bounds = boxes.iter().fold(Aabb::EMPTY, |b, &t| b.union(t));
        let bvh = Bvh::build(&boxes, 0..triangles.len() as u32);
        drop(boxes);
        Ok(Mesh {
            positions,
            normals,
            triangles,
            bvh,
            bounds,
        })
    }

    /// How many triangles the mesh has.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// How many vertex positions the mesh holds, shared among its triangles.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Whether the mesh is shaded with its vertex normals.
    pub fn is_smooth(&self) -> bool {
        !self.normals.is_empty()
    }

    /// Bytes the mesh holds for rendering: its arrays and its hierarchy.
    pub fn bytes(&self) -> usize {
        (self.positions.len() + self.normals.len()) * size_of::<Vec3>()
            + self.triangles.len() * size_of::<[u32; 3]>()
            + self.bvh.bytes()
    }

    /// The smallest box holding every triangle, in the mesh's own space.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    #[inline]
    fn vertices(&self, triangle: u32) -> [Vec3A; 3] {
        self.triangles[triangle as usize].map(|i| Vec3A::from(self.positions[i as usize]))
    }

    /// Nearest hit with `0 < t < t_max`, from either side. The normal is the interpolated
    /// vertex normal for a smooth mesh (turned to the side of the geometric normal, which
    /// decides inside and outside), else the geometric normal `(v1 − v0) × (v2 − v0)`:
    /// outward for the counter-clockwise faces OBJ files write.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        let space = RaySpace::new(ray)?;
        let mut best = None;
        self.bvh.closest(ray, t_max, |i, t_max| {
            let [a, b, c] = self.vertices(i);
            let hit = space.hit(a, b, c, t_max)?;
            best = Some((i, hit));
            Some(hit.t)
        });
        let (i, hit) = best?;
        let [a, b, c] = self.vertices(i);
        let geometric = (b - a).cross(c - a);
        let normal = if self.normals.is_empty() {
            geometric
        } else {
            let [na, nb, nc] =
                self.triangles[i as usize].map(|v| Vec3A::from(self.normals[v as usize]));
            let [wa, wb, wc] = hit.barycentric;
            let smooth = na * wa + nb * wb + nc * wc;
            let d = smooth.dot(geometric);
            if d > 0.0 {
                smooth
            } else if d < 0.0 {
                -smooth
            } else {
                // Normals that cancel out (or lie in the plane) give no direction to shade.
                geometric
            }
        };
        Some(ShapeHit {
            t: hit.t,
            point: hit.point,
            normal,
        })
    }
}

impl fmt::Debug for Mesh {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Mesh")
            .field("triangles", &self.triangles.len())
            .field("vertices", &self.positions.len())
            .field("smooth", &self.is_smooth())
            .finish()
    }
}

/// A mesh as a scene file names it: the file as written, and the mesh once the scene
/// builder has loaded it (relative to the scene file). Copies share the loaded mesh, so
/// every instance of a shape draws from one set of arrays.
#[derive(Clone)]
pub struct MeshFile {
    /// The path as the statement writes it; a relative one is taken from the scene file's
    /// folder.
    pub file: String,
    loaded: Arc<OnceLock<Arc<Mesh>>>,
}

impl MeshFile {
    /// The file named `file`, its mesh not loaded yet.
    pub fn new(file: impl Into<String>) -> MeshFile {
        MeshFile {
            file: file.into(),
            loaded: Arc::default(),
        }
    }

    /// A mesh file whose mesh is already in memory (tests and programs).
    pub fn with_mesh(file: impl Into<String>, mesh: Mesh) -> MeshFile {
        let m = MeshFile::new(file);
        m.set(Arc::new(mesh));
        m
    }

    /// The loaded mesh; `None` until the scene builder has loaded it, or when it could not.
    pub fn mesh(&self) -> Option<&Arc<Mesh>> {
        self.loaded.get()
    }

    /// Records the loaded mesh; a mesh loaded before (the same statements built twice) stays.
    pub fn set(&self, mesh: Arc<Mesh>) {
        let _ = self.loaded.set(mesh);
    }
}

/// Two statements are equal when they name the same file, loaded or not.
impl PartialEq for MeshFile {
    fn eq(&self, other: &Self) -> bool {
        self.file == other.file
    }
}

impl fmt::Debug for MeshFile {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("MeshFile")
            .field("file", &self.file)
            .field("mesh", &self.mesh())
            .finish()
    }
}

#[cfg(test)]
mod tests;
