// PLACEHOLDER: being implemented by the primitives helper; replaced before any commit.
use super::ShapeHit;
use crate::math::{Aabb, Ray};
use glam::Vec3A;

#[derive(Clone, Debug)]
pub struct Triangle {
    pub bounds: Aabb,
}

impl Triangle {
    pub fn new(v0: Vec3A, v1: Vec3A, v2: Vec3A) -> Option<Self> {
        let _ = (v0, v1, v2);
        None
    }

    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    #[inline]
    pub fn intersect(&self, _ray: &Ray, _t_max: f32) -> Option<ShapeHit> {
        None
    }
}
