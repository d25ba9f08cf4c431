//! The closed set of primitives. Each works in its own object space; `Primitive` (in
//! `crate::render::compile`) pairs one with an optional transform.
//!
//! Contract shared by every primitive:
//! - `intersect(ray, t_max)` returns the nearest hit with `0 < t < t_max`, where the ray
//!   direction need not be unit length (t is in the caller's units);
//! - the returned `point` lies on the surface (re-projected where the shape allows), and
//!   `normal` is the geometric normal there, pointing outwards for closed shapes, not
//!   necessarily unit length;
//! - `bounds()` is a conservative object-space box (infinite for the plane).

mod aabox;
mod cone;
mod cylinder;
pub mod geometry;
pub mod mesh;
mod plane;
mod sphere;
mod triangle;

pub use aabox::{AaBox, BoxRay, Slabs4};
pub use cone::Cone;
pub use cylinder::Cylinder;
pub use geometry::{degeneracy, Degenerate, Geometry};
pub use mesh::{Mesh, MeshCache, MeshFile};
pub use plane::Plane;
pub use sphere::{Sphere, SphereRay};
pub use triangle::Triangle;

use crate::math::{Aabb, Ray};
use glam::Vec3A;
use std::sync::Arc;

/// Up to three faces of a shape meeting at or passing near a surface point (shape space):
/// each face's outward unit normal and the point's distance from its plane. Empty for a point
/// with no edge nearby: the hit's normal is then the only face.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NearFaces {
    /// The outward unit normals of the listed faces, in the first `len` places.
    pub normals: [Vec3A; 3],
    /// The point's distance from each face's plane, in shape space: 0 for a face it lies on.
    pub distances: [f32; 3],
    /// How many faces are listed, from 0 to 3.
    pub len: usize,
    /// At a cone's apex (no faces listed): the unit direction into the solid along the axis
    /// and the sine of the half-angle, the clearance from every generator's plane per unit
    /// moved along it. The reported normal, the axis, is that direction only in the cone's
    /// own space: a shear maps normals and directions differently, and the world normal can
    /// leave a narrow cone through its side.
    pub apex: Option<(Vec3A, f32)>,
}

impl NearFaces {
    /// Both faces of an edge a hit was snapped onto: the point lies on both.
    pub fn edge(normals: [Vec3A; 2]) -> NearFaces {
        NearFaces {
            normals: [normals[0], normals[1], Vec3A::ZERO],
            distances: [0.0; 3],
            len: 2,
            apex: None,
        }
    }

    /// The listed faces, each as its normal and the point's distance from it.
    pub fn iter(&self) -> impl Iterator<Item = (Vec3A, f32)> + '_ {
        self.normals
            .iter()
            .copied()
            .zip(self.distances.iter().copied())
            .take(self.len)
    }
}

/// A hit in the shape's own space.
#[derive(Clone, Copy, Debug)]
pub struct ShapeHit {
    /// The ray parameter of the hit, in multiples of the ray's `dir`.
    pub t: f32,
    /// The hit point, on the surface to within f32 rounding.
    pub point: Vec3A,
    /// The geometric normal at `point`, outwards for a closed shape; not necessarily unit
    /// length.
    pub normal: Vec3A,
}

/// One primitive of the closed set, in its own space, ready to be intersected.
#[derive(Clone, Debug)]
pub enum Shape {
    /// A sphere.
    Sphere(Sphere),
    /// A box with faces along the axes.
    Box(AaBox),
    /// An infinite plane.
    Plane(Plane),
    /// One triangle, hit from both sides.
    Triangle(Triangle),
    /// A cylinder closed at both ends.
    Cylinder(Cylinder),
    /// A cone closed at its base.
    Cone(Cone),
    /// Shared by every instance of the mesh.
    Mesh(Arc<Mesh>),
}

impl Shape {
    /// The nearest hit with `0 < t < t_max`, in the shape's own space, as the module's
    /// contract describes it.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        match self {
            Shape::Sphere(s) => s.intersect(ray, t_max),
            Shape::Box(s) => s.intersect(ray, t_max),
            Shape::Plane(s) => s.intersect(ray, t_max),
            Shape::Triangle(s) => s.intersect(ray, t_max),
            Shape::Cylinder(s) => s.intersect(ray, t_max),
            Shape::Cone(s) => s.intersect(ray, t_max),
            Shape::Mesh(s) => s.intersect(ray, t_max),
        }
    }

    /// The faces a kept hit lies on or near, for lifting rays spawned from it off all of them
    /// (`crate::render::geometry::Primitive::surface`). Only the kept hit asks, once.
    // Always inlined: with a second caller of `surface` (moving shapes) it was not, and every
    // kept hit paid for the call.
    #[inline(always)]
    pub fn faces_near(&self, hit: &ShapeHit) -> NearFaces {
        match self {
            Shape::Cylinder(s) => s.faces_near(hit.point),
            Shape::Cone(s) => s.faces_near(hit.point),
            Shape::Box(s) => s.faces_near(hit),
            _ => NearFaces::default(),
        }
    }

    /// Whether the shape has an apex, where rays spawned near it may need
    /// [`Shape::apex_escape_near`] (a cone).
    #[inline]
    pub fn has_apex(&self) -> bool {
        matches!(self, Shape::Cone(_))
    }

    /// At a cone's side next to its apex, where moving by `step` into the solid would take a
    /// point half way to the axis or beyond, the apex's way out (`Cone::apex_escape_near`).
    pub fn apex_escape_near(&self, point: Vec3A, step: Vec3A) -> Option<(Vec3A, f32)> {
        match self {
            Shape::Cone(c) => c.apex_escape_near(point, step),
            _ => None,
        }
    }

    /// The names of the kinds of shape, in the order of [`Shape::kind_index`].
    pub const KINDS: [&'static str; 7] = [
        "sphere", "box", "plane", "triangle", "cylinder", "cone", "mesh",
    ];

    /// This shape's place in [`Shape::KINDS`].
    pub fn kind_index(&self) -> usize {
        match self {
            Shape::Sphere(_) => 0,
            Shape::Box(_) => 1,
            Shape::Plane(_) => 2,
            Shape::Triangle(_) => 3,
            Shape::Cylinder(_) => 4,
            Shape::Cone(_) => 5,
            Shape::Mesh(_) => 6,
        }
    }

    /// Whether the shape is convex: a ray leaving it outwards never meets it again.
    pub fn is_convex(&self) -> bool {
        matches!(
            self,
            Shape::Sphere(_) | Shape::Box(_) | Shape::Cylinder(_) | Shape::Cone(_)
        )
    }

    /// Whether the shape is one flat face: a ray leaving it never meets it again.
    pub fn is_flat(&self) -> bool {
        matches!(self, Shape::Plane(_) | Shape::Triangle(_))
    }

    /// Whether the shape encloses a solid, which a camera can be inside: planes, triangles
    /// and meshes are surfaces.
    pub fn is_closed(&self) -> bool {
        !matches!(self, Shape::Plane(_) | Shape::Triangle(_) | Shape::Mesh(_))
    }

    /// A box holding the whole shape in its own space; infinite for a plane.
    pub fn bounds(&self) -> Aabb {
        match self {
            Shape::Sphere(s) => s.bounds(),
            Shape::Box(s) => s.bounds(),
            Shape::Plane(_) => Aabb {
                min: Vec3A::NEG_INFINITY,
                max: Vec3A::INFINITY,
            },
            Shape::Triangle(s) => s.bounds(),
            Shape::Cylinder(s) => s.bounds(),
            Shape::Cone(s) => s.bounds(),
            Shape::Mesh(s) => s.bounds(),
        }
    }
}
