//! Primitives as a scene file writes them, in their own (object) space: the numbers of their
//! statements, their extent, the rules that say whether one can be drawn at all, and the
//! shape each becomes once placed. The reader, the scene builder, the renderer and the
//! animation generator all ask here, so a new kind of primitive is described in this file
//! (and its shape in a file of its own), not in each of them; and a shape cannot be accepted
//! by one and refused by another.

use super::mesh::MeshFile;
use super::{AaBox, Cone, Cylinder, Plane, Shape, Sphere, Triangle};
use crate::math::Transform;
use arrayvec::ArrayVec;
use glam::{DMat3, DVec3, Vec3A};

/// A primitive as written in its own (object) space.
#[derive(Clone, Debug, PartialEq)]
pub enum Geometry {
    /// A sphere of `radius` around `center`.
    Sphere {
        /// The centre.
        center: DVec3,
        /// The radius; its sign is ignored.
        radius: f64,
    },
    /// Corners in any order.
    Box {
        /// One corner.
        p1: DVec3,
        /// The opposite corner.
        p2: DVec3,
    },
    /// An infinite plane through `point`, perpendicular to `normal`.
    Plane {
        /// A point the plane passes through.
        point: DVec3,
        /// A direction perpendicular to the plane, of any length but zero.
        normal: DVec3,
    },
    /// One triangle, hit from both sides.
    Triangle {
        /// The corners. Their order orients the normal, `(v1 − v0) × (v2 − v0)`.
        vertices: [DVec3; 3],
    },
    /// Axis p1 → p2, both ends capped.
    Cylinder {
        /// The centre of one end.
        p1: DVec3,
        /// The centre of the other end.
        p2: DVec3,
        /// The radius, positive for a shape that can be drawn (the reader makes a negative
        /// radius positive).
        radius: f64,
    },
    /// Radius at the base, apex at the tip, base capped.
    Cone {
        /// The centre of the base.
        base: DVec3,
        /// The apex.
        tip: DVec3,
        /// The radius of the base, positive for a shape that can be drawn (the reader makes
        /// a negative radius positive).
        radius: f64,
    },
    /// Triangles of an OBJ file (`define shape obj`), loaded by the scene builder.
    Mesh(MeshFile),
}

/// A shape that cannot be placed: degenerate once transformed. The reader reports these
/// before the renderer ever sees them, so here they only guard against misuse.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Degenerate;

impl Geometry {
    /// The primitive of the statement keyword `kind` (`sphere`, `box`, …) from its numbers in
    /// canonical order (points as three numbers each, then the radius), or `None` for a
    /// keyword that names no primitive of numbers.
    pub fn from_numbers(kind: &str, nums: &[f64]) -> Option<Geometry> {
        let p = |i: usize| DVec3::new(nums[i], nums[i + 1], nums[i + 2]);
        Some(match kind {
            "sphere" => Geometry::Sphere {
                center: p(0),
                radius: nums[3],
            },
            "box" => Geometry::Box { p1: p(0), p2: p(3) },
            "plane" => Geometry::Plane {
                point: p(0),
                normal: p(3),
            },
            "triangle" => Geometry::Triangle {
                vertices: [p(0), p(3), p(6)],
            },
            "cylinder" => Geometry::Cylinder {
                p1: p(0),
                p2: p(3),
                radius: nums[6],
            },
            "cone" => Geometry::Cone {
                base: p(0),
                tip: p(3),
                radius: nums[6],
            },
            _ => return None,
        })
    }

    /// The keyword of its statement and its numbers in canonical order, as
    /// [`Geometry::from_numbers`] reads them; `None` for a mesh, which names a file.
    pub fn numbers(&self) -> Option<(&'static str, ArrayVec<f64, 9>)> {
        let mut nums = ArrayVec::new();
        let mut put = |points: &[DVec3], scalars: &[f64]| {
            for p in points {
                nums.extend(p.to_array());
            }
            nums.extend(scalars.iter().copied());
        };
        let kind = match *self {
            Geometry::Sphere { center, radius } => ("sphere", put(&[center], &[radius])).0,
            Geometry::Box { p1, p2 } => ("box", put(&[p1, p2], &[])).0,
            Geometry::Plane { point, normal } => ("plane", put(&[point, normal], &[])).0,
            Geometry::Triangle { vertices } => ("triangle", put(&vertices, &[])).0,
            Geometry::Cylinder { p1, p2, radius } => ("cylinder", put(&[p1, p2], &[radius])).0,
            Geometry::Cone { base, tip, radius } => ("cone", put(&[base, tip], &[radius])).0,
            Geometry::Mesh(_) => return None,
        };
        Some((kind, nums))
    }

    /// The radius of a round primitive (sphere, cylinder, cone).
    pub fn radius(&self) -> Option<f64> {
        match *self {
            Geometry::Sphere { radius, .. }
            | Geometry::Cylinder { radius, .. }
            | Geometry::Cone { radius, .. } => Some(radius),
            _ => None,
        }
    }

    /// [`Geometry::radius`], to be changed.
    pub fn radius_mut(&mut self) -> Option<&mut f64> {
        match self {
            Geometry::Sphere { radius, .. }
            | Geometry::Cylinder { radius, .. }
            | Geometry::Cone { radius, .. } => Some(radius),
            _ => None,
        }
    }

    /// Whether every number of its statement is finite (a mesh's file is checked apart).
    pub fn is_finite(&self) -> bool {
        self.numbers()
            .is_none_or(|(_, nums)| nums.iter().all(|n| n.is_finite()))
    }

    /// Whether it has a finite extent (a plane has none).
    pub fn is_bounded(&self) -> bool {
        !matches!(self, Geometry::Plane { .. })
    }

    /// The points its statement places and the radius it sweeps around them: it lies within
    /// a ball of that radius around their box (loosely, for a cylinder or a cone). `None` for
    /// a plane, which has no extent, and a mesh, whose file decides.
    pub fn span(&self) -> Option<(ArrayVec<DVec3, 3>, f64)> {
        let span = |points: &[DVec3], radius: f64| (points.iter().copied().collect(), radius);
        Some(match *self {
            Geometry::Sphere { center, radius } => span(&[center], radius),
            Geometry::Box { p1, p2 } => span(&[p1, p2], 0.0),
            Geometry::Triangle { vertices } => span(&vertices, 0.0),
            Geometry::Cylinder { p1, p2, radius } => span(&[p1, p2], radius),
            Geometry::Cone { base, tip, radius } => span(&[base, tip], radius),
            Geometry::Plane { .. } | Geometry::Mesh(_) => return None,
        })
    }

    /// The shape in its own space.
    #[inline]
    pub fn own_shape(&self) -> Result<Shape, Degenerate> {
        self.shape_under(&Transform::IDENTITY)
    }

    /// Whether its kind survives the transform `xf`, so that it can be placed in world space
    /// ([`Geometry::shape_under`]): spheres, cylinders and cones under rotations with a
    /// uniform scale, boxes under scales along the axes, planes and triangles under anything,
    /// anything under the identity. Otherwise it is traced in its own space through the
    /// matrix, as a mesh always is (one mesh is shared by all its instances).
    #[inline]
    pub fn keeps_kind_under(&self, xf: &Transform) -> bool {
        if xf.is_identity() {
            return true;
        }
        let lin = xf.linear();
        match self {
            Geometry::Sphere { .. } | Geometry::Cylinder { .. } | Geometry::Cone { .. } => {
                similarity_scale(lin).is_some()
            }
            Geometry::Box { .. } => is_diagonal(lin),
            Geometry::Plane { .. } | Geometry::Triangle { .. } => true,
            Geometry::Mesh(_) => false,
        }
    }

    /// The shape mapped through `xf`, which must keep its kind
    /// ([`Geometry::keeps_kind_under`]).
    #[inline]
    pub fn shape_under(&self, xf: &Transform) -> Result<Shape, Degenerate> {
        let f = |v: DVec3| Vec3A::from(v.as_vec3());
        let p = |v: DVec3| f(xf.point(v));
        let shape = match self {
            Geometry::Sphere { center, radius } => {
                let s = similarity_scale(xf.linear()).ok_or(Degenerate)?;
                Sphere::new(p(*center), (radius.abs() * s) as f32).map(Shape::Sphere)
            }
            Geometry::Box { p1, p2 } => AaBox::new(p(*p1), p(*p2)).map(Shape::Box),
            Geometry::Plane { point, normal } => {
                Plane::new(p(*point), f(xf.normal_matrix() * *normal)).map(Shape::Plane)
            }
            Geometry::Triangle {
                vertices: [a, b, c],
            } => Triangle::new(p(*a), p(*b), p(*c)).map(Shape::Triangle),
            Geometry::Cylinder { p1, p2, radius } => {
                let s = similarity_scale(xf.linear()).ok_or(Degenerate)?;
                Cylinder::new(p(*p1), p(*p2), (radius * s) as f32).map(Shape::Cylinder)
            }
            Geometry::Cone { base, tip, radius } => {
                let s = similarity_scale(xf.linear()).ok_or(Degenerate)?;
                Cone::new(p(*base), p(*tip), (radius * s) as f32).map(Shape::Cone)
            }
            Geometry::Mesh(m) if xf.is_identity() => m.mesh().cloned().map(Shape::Mesh),
            Geometry::Mesh(_) => None,
        };
        shape.ok_or(Degenerate)
    }
}

/// Whether `m` is a rotation times a uniform scale (keeps spheres spheres, circles circles).
#[inline]
fn similarity_scale(m: DMat3) -> Option<f64> {
    let gram = m.transpose() * m;
    let s2 = gram.x_axis.x;
    let tol = 1e-9 * s2;
    let uniform = (gram.y_axis.y - s2).abs() <= tol
        && (gram.z_axis.z - s2).abs() <= tol
        && gram.x_axis.y.abs() <= tol
        && gram.x_axis.z.abs() <= tol
        && gram.y_axis.z.abs() <= tol;
    uniform.then(|| s2.sqrt())
}

/// Whether `m` is diagonal (an axis-aligned box stays axis-aligned).
fn is_diagonal(m: DMat3) -> bool {
    m.x_axis.y == 0.0
        && m.x_axis.z == 0.0
        && m.y_axis.x == 0.0
        && m.y_axis.z == 0.0
        && m.z_axis.x == 0.0
        && m.z_axis.y == 0.0
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
