use glam::{DMat3, DMat4, DVec3};

/// An affine transform kept with its inverse, composed in f64 so that deep hierarchies and
/// long statement sequences do not accumulate f32 round-off.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Maps object-space points and vectors to world space.
    pub world_from_object: DMat4,
    /// The inverse of `world_from_object`: maps world-space points and vectors to object space.
    pub object_from_world: DMat4,
}

impl Default for Transform {
    fn default() -> Self {
        Transform::IDENTITY
    }
}

impl Transform {
    /// The transform that leaves everything where it is.
    pub const IDENTITY: Transform = Transform {
        world_from_object: DMat4::IDENTITY,
        object_from_world: DMat4::IDENTITY,
    };

    /// A move by `v`.
    pub fn translate(v: DVec3) -> Self {
        Transform {
            world_from_object: DMat4::from_translation(v),
            object_from_world: DMat4::from_translation(-v),
        }
    }

    /// Right-handed rotation (counter-clockwise looking from the axis tip to the origin).
    /// `None` for a zero or non-finite axis.
    pub fn rotate(degrees: f64, axis: DVec3) -> Option<Self> {
        let axis = axis.try_normalize()?;
        let angle = degrees.to_radians();
        Some(Transform {
            world_from_object: DMat4::from_axis_angle(axis, angle),
            object_from_world: DMat4::from_axis_angle(axis, -angle),
        })
    }

    /// Per-axis scale; `None` when a factor is zero (no inverse) or not finite.
    pub fn scale(s: DVec3) -> Option<Self> {
        if s.cmpeq(DVec3::ZERO).any() || !s.is_finite() {
            return None;
        }
        Some(Transform {
            world_from_object: DMat4::from_scale(s),
            object_from_world: DMat4::from_scale(s.recip()),
        })
    }

    /// `self` applied after `inner`: maps through `inner` first.
    #[inline]
    pub fn then_after(&self, inner: &Transform) -> Transform {
        Transform {
            world_from_object: self.world_from_object * inner.world_from_object,
            object_from_world: inner.object_from_world * self.object_from_world,
        }
    }

    /// Whether the transform is exactly the identity, with no tolerance for round-off.
    pub fn is_identity(&self) -> bool {
        self.world_from_object == DMat4::IDENTITY
    }

    /// The point `p`, taken from object space to world space.
    pub fn point(&self, p: DVec3) -> DVec3 {
        self.world_from_object.transform_point3(p)
    }

    /// The direction or offset `v`, taken from object space to world space: the translation
    /// does not apply, and a unit vector may not stay unit length.
    pub fn vector(&self, v: DVec3) -> DVec3 {
        self.world_from_object.transform_vector3(v)
    }

    /// Maps object-space normals to world space: the inverse transpose of the linear part.
    pub fn normal_matrix(&self) -> DMat3 {
        DMat3::from_mat4(self.object_from_world).transpose()
    }

    /// The linear part of the object-to-world map (rotation, scale and shear), without the
    /// translation.
    pub fn linear(&self) -> DMat3 {
        DMat3::from_mat4(self.world_from_object)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_is_kept_exactly_in_step() {
        let t = Transform::translate(DVec3::new(1.0, 2.0, 3.0))
            .then_after(&Transform::rotate(37.0, DVec3::new(1.0, 1.0, 0.0)).unwrap())
            .then_after(&Transform::scale(DVec3::new(2.0, 0.5, 4.0)).unwrap());
        let product = t.world_from_object * t.object_from_world;
        assert!(product.abs_diff_eq(DMat4::IDENTITY, 1e-12));
    }

    #[test]
    fn rotation_is_right_handed() {
        let r = Transform::rotate(90.0, DVec3::Z).unwrap();
        assert!(r.vector(DVec3::X).abs_diff_eq(DVec3::Y, 1e-12));
    }

    #[test]
    fn zero_scale_and_zero_axis_are_rejected() {
        assert!(Transform::scale(DVec3::new(1.0, 0.0, 1.0)).is_none());
        assert!(Transform::rotate(10.0, DVec3::ZERO).is_none());
    }
}
