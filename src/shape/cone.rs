// PLACEHOLDER: being implemented by the primitives helper; replaced before any commit.
use super::ShapeHit;
use crate::math::{Aabb, Ray};
use glam::Vec3A;

#[derive(Clone, Debug)]
pub struct Cone {
    pub bounds: Aabb,
}

impl Cone {
    pub fn new(base: Vec3A, tip: Vec3A, radius: f32) -> Option<Self> {
        let _ = (base, tip, radius);
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
