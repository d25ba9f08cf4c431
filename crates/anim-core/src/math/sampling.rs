//! Maps of the unit square onto the shapes that sampled integrals range over (the disc of a
//! spherical light as a point sees it, the aperture of a thin lens), and the frame across a
//! direction they are laid in.

use glam::Vec3A;

/// Shirley and Chiu's concentric map of `[0,1)²` onto the unit disc: equal areas to equal
/// areas, and nearby points to nearby points.
#[inline]
pub fn concentric([u, v]: [f32; 2]) -> (f32, f32) {
    let (a, b) = (2.0 * u - 1.0, 2.0 * v - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    let quarter = std::f32::consts::FRAC_PI_4;
    let (r, phi) = if a.abs() > b.abs() {
        (a, quarter * (b / a))
    } else {
        (b, 2.0 * quarter - quarter * (a / b))
    };
    (r * phi.cos(), r * phi.sin())
}

/// Two unit vectors at right angles to unit `n` and to each other, without a branch on
/// `n`'s direction (Duff et al., "Building an orthonormal basis, revisited", 2017).
#[inline]
pub fn orthonormal_pair(n: Vec3A) -> [Vec3A; 2] {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    [
        Vec3A::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3A::new(b, sign + n.y * n.y * a, -n.y),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_concentric_map_keeps_areas_and_stays_in_the_disc() {
        // Each cell of an 8×8 grid of the square maps onto 1/64 of the disc's area: count
        // the points of a fine grid that land in each of 8 rings × 8 sectors, by area.
        let n = 256;
        let mut rings = [0u32; 8];
        for i in 0..n {
            for j in 0..n {
                let uv = [(i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32];
                let (x, y) = concentric(uv);
                let r2 = x * x + y * y;
                assert!(r2 <= 1.0 + 1e-6);
                rings[((r2 * 8.0) as usize).min(7)] += 1;
            }
        }
        // Rings of equal area (r² steps of 1/8) hold equal shares of the points.
        for count in rings {
            let share = count as f32 / (n * n) as f32;
            assert!((share - 0.125).abs() < 0.01, "{rings:?}");
        }
    }
}
