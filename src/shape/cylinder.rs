// PLACEHOLDER: being implemented by the primitives helper; replaced before any commit.
use super::ShapeHit;
use crate::math::{Aabb, Ray};
use glam::Vec3A;

#[derive(Clone, Debug)]
pub struct Cylinder {
    pub bounds: Aabb,
}

impl Cylinder {
    pub fn new(p1: Vec3A, p2: Vec3A, radius: f32) -> Option<Self> {
        let _ = (p1, p2, radius);
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
