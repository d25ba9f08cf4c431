//! What a render traced: its rays counted by kind ([`RayCounts`]). A leaf of the render core:
//! the samplers, the integrator and the facade's per-worker scratch all add to it, and the
//! entry reports it.

/// How many rays of each kind a render traced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Rays from the camera.
    pub primary: u64,
    /// Rays towards lights.
    pub shadow: u64,
    /// Mirror rays.
    pub reflected: u64,
    /// Rays through transparent surfaces.
    pub refracted: u64,
}

impl RayCounts {
    /// Rays of every kind.
    pub fn total(&self) -> u64 {
        self.primary + self.shadow + self.reflected + self.refracted
    }

    /// `a + b`, for reductions over workers.
    pub fn sum(mut a: RayCounts, b: RayCounts) -> RayCounts {
        a += b;
        a
    }
}

impl std::ops::AddAssign for RayCounts {
    fn add_assign(&mut self, o: RayCounts) {
        self.primary += o.primary;
        self.shadow += o.shadow;
        self.reflected += o.reflected;
        self.refracted += o.refracted;
    }
}
