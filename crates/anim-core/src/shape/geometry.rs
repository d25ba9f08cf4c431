//! Primitives as a scene file writes them, in their own (object) space, and the rules that
//! say whether one can be drawn at all. The reader and the scene builder both judge
//! degeneracy here, so a shape cannot be accepted by one and refused by the other.

use super::mesh::MeshFile;
use glam::DVec3;

/// A primitive as written in its own (object) space.
#[derive(Clone, Debug, PartialEq)]
pub enum Geometry {
    Sphere {
        center: DVec3,
        radius: f64,
    },
    /// Corners in any order.
    Box {
        p1: DVec3,
        p2: DVec3,
    },
    Plane {
        point: DVec3,
        normal: DVec3,
    },
    Triangle {
        vertices: [DVec3; 3],
    },
    /// Axis p1 → p2, both ends capped.
    Cylinder {
        p1: DVec3,
        p2: DVec3,
        radius: f64,
    },
    /// Radius at the base, apex at the tip, base capped.
    Cone {
        base: DVec3,
        tip: DVec3,
        radius: f64,
    },
    /// Triangles of an OBJ file (`define shape obj`), loaded by the scene builder.
    Mesh(MeshFile),
}

/// Why a shape cannot be drawn, if it cannot (it is then dropped with a warning).
pub fn degeneracy(g: &Geometry) -> Option<&'static str> {
    // A radius whose square underflows is as good as 0 to the intersection tests.
    let no_radius = |r: f64| r * r == 0.0;
    match *g {
        Geometry::Sphere { radius, .. } if no_radius(radius) => Some("has radius 0"),
        Geometry::Cylinder { p1, p2, radius }
        | Geometry::Cone {
            base: p1,
            tip: p2,
            radius,
        } => {
            if no_radius(radius) {
                Some("has radius 0")
            } else if is_zero(p2 - p1) {
                Some("has coincident end points")
            } else {
                None
            }
        }
        Geometry::Triangle {
            vertices: [a, b, c],
        } => {
            if parallel(b - a, c - a) {
                Some("has collinear vertices")
            } else {
                None
            }
        }
        Geometry::Plane { normal, .. } if is_zero(normal) => Some("has a zero normal"),
        Geometry::Mesh(ref m) if m.mesh().is_none() => Some("has no mesh loaded"),
        _ => None,
    }
}

/// Whether two vectors are parallel (or one of them is zero), relative to their lengths.
pub fn parallel(a: DVec3, b: DVec3) -> bool {
    let scale = a.length() * b.length();
    is_zero(a) || is_zero(b) || scale == 0.0 || a.cross(b).length() <= 1e-9 * scale
}

/// Whether a direction is zero, or so short that it cannot be normalised (its squared
/// length underflows): either way it gives no direction.
pub fn is_zero(v: DVec3) -> bool {
    v.try_normalize().is_none()
}
