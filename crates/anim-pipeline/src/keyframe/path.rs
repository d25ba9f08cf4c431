//! Paths: a translate channel given as points (docs/animation.md, "Paths"), travelled at
//! constant speed, with the timing kept apart from the curve: a `progress` channel says how
//! far along the path (0 at its start, 1 at its end) the target is at each time, so an
//! easing acts on the distance travelled, not on the curve's parameter.
//!
//! The curve through the points is a Catmull-Rom spline (each point's tangent the chord
//! between its neighbours; at the ends of an open path, the end chord), or straight lines.
//! Distance along it is measured by [`ARC_SAMPLES`] chords per segment, and a distance is
//! turned back into a point on the segment's cubic, so equal distances are equal arcs to far
//! below a pixel.

use glam::DVec3;

/// Chords per segment of the table that measures distance along the path.
const ARC_SAMPLES: usize = 256;

/// A path through points, measured by arc length.
#[derive(Clone, Debug, PartialEq)]
pub struct Path {
    points: Vec<DVec3>,
    closed: bool,
    smooth: bool,
    /// The distance from the start at each sample: `ARC_SAMPLES` a segment, plus the end.
    lengths: Vec<f64>,
}

impl Path {
    /// The path through `points` (at least 2), back to the first when `closed`, curved when
    /// `smooth`.
    pub fn new(points: Vec<DVec3>, closed: bool, smooth: bool) -> Path {
        let mut path = Path {
            points,
            closed,
            smooth,
            lengths: Vec::new(),
        };
        let mut total = 0.0;
        let mut previous = path.at_parameter(0.0);
        path.lengths.push(0.0);
        for k in 1..=path.segments() * ARC_SAMPLES {
            let p = path.at_parameter(k as f64 / ARC_SAMPLES as f64);
            total += (p - previous).length();
            path.lengths.push(total);
            previous = p;
        }
        path
    }

    fn segments(&self) -> usize {
        if self.closed {
            self.points.len()
        } else {
            self.points.len() - 1
        }
    }

    /// Its whole length.
    pub fn length(&self) -> f64 {
        self.lengths.last().copied().unwrap_or(0.0)
    }

    fn point(&self, i: isize) -> DVec3 {
        let n = self.points.len() as isize;
        if self.closed {
            self.points[i.rem_euclid(n) as usize]
        } else {
            self.points[i.clamp(0, n - 1) as usize]
        }
    }

    /// The point at parameter `u`: segment `floor(u)`, at fraction `u − floor(u)` of it.
    fn at_parameter(&self, u: f64) -> DVec3 {
        let segments = self.segments();
        let u = u.clamp(0.0, segments as f64);
        let k = (u.floor() as usize).min(segments - 1);
        let s = u - k as f64;
        let k = k as isize;
        let (p1, p2) = (self.point(k), self.point(k + 1));
        if !self.smooth {
            return p1 + (p2 - p1) * s;
        }
        // Catmull-Rom with unit spacing: tangents (p2 − p0)/2 and (p3 − p1)/2; an open path's
        // end repeats its end point, so its end tangent is half the end chord.
        let (p0, p3) = (self.point(k - 1), self.point(k + 2));
        let (m1, m2) = ((p2 - p0) * 0.5, (p3 - p1) * 0.5);
        let (s2, s3) = (s * s, s * s * s);
        p1 * (2.0 * s3 - 3.0 * s2 + 1.0)
            + m1 * (s3 - 2.0 * s2 + s)
            + p2 * (-2.0 * s3 + 3.0 * s2)
            + m2 * (s3 - s2)
    }

    /// The parameter at distance `d` from the start (clamped to the path; wrapped round a
    /// closed one), found in the table and refined on the chord it falls in.
    fn parameter_at(&self, d: f64) -> f64 {
        let total = self.length();
        if total <= 0.0 || !d.is_finite() {
            return 0.0;
        }
        let d = if self.closed {
            d.rem_euclid(total)
        } else {
            d.clamp(0.0, total)
        };
        let j = self
            .lengths
            .partition_point(|&l| l <= d)
            .clamp(1, self.lengths.len() - 1);
        let (a, b) = (self.lengths[j - 1], self.lengths[j]);
        let within = if b > a { (d - a) / (b - a) } else { 0.0 };
        ((j - 1) as f64 + within) / ARC_SAMPLES as f64
    }

    /// The point at the fraction `f` of the whole length (0 the start, 1 the end; a closed
    /// path goes round again past 1).
    pub fn at(&self, f: f64) -> DVec3 {
        self.at_parameter(self.parameter_at(f * self.length()))
    }

    /// The direction of travel at fraction `f` and the curvature vector `d²P/ds²` there
    /// (towards the centre of the turn, its length 1/radius), from points a little before and
    /// after.
    pub fn bend(&self, f: f64) -> (DVec3, DVec3) {
        let total = self.length();
        let h = total / (self.segments() * ARC_SAMPLES) as f64;
        let d = f * total;
        let (d0, d1) = if self.closed {
            (d - h, d + h)
        } else {
            let d = d.clamp(h, (total - h).max(h));
            (d - h, d + h)
        };
        let (a, m, b) = (
            self.at_parameter(self.parameter_at(d0)),
            self.at_parameter(self.parameter_at((d0 + d1) / 2.0)),
            self.at_parameter(self.parameter_at(d1)),
        );
        let step = (d1 - d0) / 2.0;
        (
            (b - a).normalize_or_zero(),
            (a - 2.0 * m + b) / (step * step),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(closed: bool, smooth: bool) -> Path {
        let p = [
            (0.0, 0.0, 0.0),
            (10.0, 0.0, 0.0),
            (10.0, 0.0, -10.0),
            (0.0, 0.0, -10.0),
        ];
        Path::new(
            p.iter().map(|&(x, y, z)| DVec3::new(x, y, z)).collect(),
            closed,
            smooth,
        )
    }

    #[test]
    fn straight_lines_are_measured_exactly() {
        let open = square(false, false);
        assert!((open.length() - 30.0).abs() < 1e-9);
        assert!(open.at(0.5).abs_diff_eq(DVec3::new(10.0, 0.0, -5.0), 1e-9));
        let closed = square(true, false);
        assert!((closed.length() - 40.0).abs() < 1e-9);
        assert!(closed
            .at(1.125)
            .abs_diff_eq(DVec3::new(5.0, 0.0, 0.0), 1e-9));
    }

    #[test]
    fn equal_fractions_are_equal_arcs_on_a_curve() {
        let path = square(true, true);
        let n = 400;
        let points: Vec<DVec3> = (0..=n).map(|i| path.at(i as f64 / n as f64)).collect();
        let steps: Vec<f64> = points.windows(2).map(|w| (w[1] - w[0]).length()).collect();
        let mean = path.length() / n as f64;
        for s in &steps {
            assert!((s - mean).abs() < 1e-3 * mean, "{s} vs {mean}");
        }
        // It passes through its points, and a closed path returns to the start.
        assert!(path.at(0.0).abs_diff_eq(DVec3::ZERO, 1e-9));
        assert!(path.at(1.0).abs_diff_eq(DVec3::ZERO, 1e-6));
    }

    #[test]
    fn the_bend_points_along_the_path_and_into_the_turn() {
        let path = square(true, true);
        // Half way along the first side: heading +x, turning towards −z (the next corner).
        let (dir, curve) = path.bend(0.125);
        assert!(dir.abs_diff_eq(DVec3::X, 1e-2), "{dir}");
        assert!(curve.z <= 1e-9, "{curve}");
        let (_, straight) = square(false, false).bend(0.2);
        assert!(straight.length() < 1e-6, "{straight}");
    }
}
