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

pub use aabox::AaBox;
pub use cone::Cone;
pub use cylinder::Cylinder;
pub use geometry::{degeneracy, Geometry};
pub use mesh::{Mesh, MeshFile};
pub use plane::Plane;
pub use sphere::{Sphere, SphereRay};
pub use triangle::Triangle;

use crate::math::{Aabb, Ray};
use glam::Vec3A;
use std::sync::Arc;

/// A hit in the shape's own space.
#[derive(Clone, Copy, Debug)]
pub struct ShapeHit {
    pub t: f32,
    pub point: Vec3A,
    pub normal: Vec3A,
}

#[derive(Clone, Debug)]
pub enum Shape {
    Sphere(Sphere),
    Box(AaBox),
    Plane(Plane),
    Triangle(Triangle),
    Cylinder(Cylinder),
    Cone(Cone),
    /// Shared by every instance of the mesh.
    Mesh(Arc<Mesh>),
}

impl Shape {
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

    /// The outward normals of the two faces meeting at `point` (shape space) when it lies on
    /// an edge that `intersect` snaps hits onto (the rims of cylinders and cones), `None`
    /// for a point on one face. Only the kept hit asks, once.
    pub fn rim_faces(&self, point: Vec3A) -> Option<[Vec3A; 2]> {
        match self {
            Shape::Cylinder(s) => s.rim_faces(point),
            Shape::Cone(s) => s.rim_faces(point),
            _ => None,
        }
    }

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
