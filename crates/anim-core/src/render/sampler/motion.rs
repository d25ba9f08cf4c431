//! What adaptive sampling asks of a frame's motion ([`MotionProbe`]): whether a pixel
//! changes during the exposure, and the streak a moving camera draws a pixel's hit point
//! along. The exposure itself (`crate::render::motion::Shutter`) only places the camera at an
//! instant. Motion, one home per layer: `crate::render::geometry::motion` (the moving shapes),
//! `crate::render::motion` (the exposure), `crate::scene::motion` (what moves in a scene
//! description).

use super::pattern::{tone3, FLAT_CONTRAST};
use super::Frame;
use crate::render::camera::PinholeCamera;
use crate::render::integrator::{PixelPrior, TraceState};
use crate::render::motion::Shutter;
use glam::Vec3A;

/// Longest way (pixels) across the image along which adaptive sampling judges a pixel flat
/// under a moving camera; a hit point that moves further is refined.
const MAX_FLAT_SWEEP: f32 = 96.0;

/// Instants at which a moving camera's sweep over the image is measured, besides its keys.
const SWEEP_STEPS: usize = 8;

/// Most instants at which adaptive sampling's first pass probes a pixel whose rays met
/// something moving; motion that sweeps further refines the pixel without probing.
const MAX_PROBES: u32 = 9;

/// How much further than the moving thing itself its shadow or reflection may move across
/// the image, as the probes allow for.
const STRETCH: f32 = 2.0;

/// Pixels the image of a point may stray from its streak's line for a slide to skip checking
/// the instants between its ends, far below the pixel those checks allow.
const SLIDE_SLACK: f32 = 1.0 / 64.0;

/// A frame's motion, as adaptive sampling's first pass asks it.
pub(super) struct MotionProbe<'f> {
    frame: &'f Frame<'f>,
    shutter: &'f Shutter,
    /// The camera at instants spread over the exposure, when it moves.
    sweep: Vec<PinholeCamera>,
    /// When the camera slides without turning, with every eye of `sweep` on the way between
    /// the first and the last: how far (world units) one strays from that segment at most,
    /// times the view's `reach`. Then a point's image moves along a straight line (a line
    /// seen in perspective), whatever the speed, up to that stray over the point's depth.
    slide_stray: Option<f32>,
}

impl<'f> MotionProbe<'f> {
    /// The probe of `frame`, whose exposure is `shutter`.
    pub fn new(frame: &'f Frame<'f>, shutter: &'f Shutter) -> MotionProbe<'f> {
        let sweep: Vec<PinholeCamera> = match shutter.camera_keys() {
            None => Vec::new(),
            Some(keys) => {
                let mut instants: Vec<f64> = (0..=SWEEP_STEPS)
                    .map(|s| s as f64 / SWEEP_STEPS as f64)
                    .chain(keys)
                    .collect();
                instants.sort_by(f64::total_cmp);
                instants.dedup();
                instants
                    .into_iter()
                    .filter_map(|u| shutter.camera_at(u as f32))
                    .collect()
            }
        };
        let slide_stray = slide_stray(&sweep);
        MotionProbe {
            frame,
            shutter,
            sweep,
            slide_stray,
        }
    }

    /// Where (pixels, from the centre of (`x`, `y`)) the point its middle-instant centre ray
    /// meets at distance `t` (`None`: nothing, the background far away) is seen when the
    /// shutter opens and closes, while the camera moves: the ends of its streak, which
    /// adaptive sampling's flat test walks. `None` when it leaves the view or sweeps further
    /// than `MAX_FLAT_SWEEP`, or strays more than a pixel from the two straight halves.
    pub fn camera_sweep(&self, x: u32, y: u32, t: Option<f32>) -> Option<[(f32, f32); 2]> {
        let (Some(first), Some(last)) = (self.sweep.first(), self.sweep.last()) else {
            return Some([(0.0, 0.0); 2]);
        };
        let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
        let ray = self.frame.camera.ray(cx, cy);
        // The background: a point far enough that the eye's slide does not move it.
        let p: Vec3A = ray.at(t.unwrap_or(1e7));
        let end = |c: &PinholeCamera| c.project(p).map(|(px, py)| (px - cx, py - cy));
        let ends = [end(first)?, end(last)?];
        if ends
            .iter()
            .any(|e| e.0.hypot(e.1).partial_cmp(&MAX_FLAT_SWEEP) != Some(std::cmp::Ordering::Less))
        {
            return None;
        }
        // The instants between lie on the halves, within a pixel: surely so on a slide, where
        // they are off the line through the ends by at most the stray over the depth.
        let near = first.world_per_pixel(p).min(last.world_per_pixel(p));
        if self
            .slide_stray
            .is_some_and(|stray| near > 0.0 && stray <= SLIDE_SLACK * near)
        {
            return Some(ends);
        }
        let n = self.sweep.len();
        for (i, c) in self.sweep.iter().enumerate() {
            let (dx, dy) = end(c)?;
            let (ex, ey) = if 2 * i < n { ends[0] } else { ends[1] };
            let len2 = ex * ex + ey * ey;
            let off = if len2 > 0.0 {
                (dx * ey - dy * ex).abs() / len2.sqrt()
            } else {
                dx.hypot(dy)
            };
            if off.is_nan() || off > 1.0 {
                return None;
            }
        }
        Some(ends)
    }

    /// Whether the pixel (`x`, `y`) changes during the exposure, for adaptive sampling's first
    /// pass: its centre sample `centre` (colour, primitive) was taken at the middle instant,
    /// and its rays met moving things that sweep up to `swept` radians. Probed with centre
    /// rays at instants evenly spread over the exposure, close enough that a moving thing
    /// (or its shadow or reflection, up to `STRETCH` times as fast) moves at most about a
    /// pixel between two of them: a probe that sees another surface or more than
    /// `FLAT_CONTRAST` levels of difference says it changes. Motion too fast for
    /// `MAX_PROBES` probes changes it without probing.
    pub fn changes(
        &self,
        (x, y): (u32, u32),
        centre: (Vec3A, u32),
        swept: f32,
        st: &mut TraceState,
    ) -> bool {
        let spread = STRETCH * swept / self.frame.camera.pixel_angle();
        if spread.is_nan() || spread >= (MAX_PROBES - 1) as f32 {
            return true;
        }
        let parts = (spread.ceil() as u32).max(2);
        let tone = tone3(centre.0);
        // The ends first: most motion that changes a pixel shows there.
        let order = [0, parts].into_iter().chain(1..parts);
        for i in order.filter(|&i| 2 * i != parts) {
            let u = i as f32 / parts as f32;
            let still = self.frame.camera;
            let ray = self.shutter.ray(still, x as f32 + 0.5, y as f32 + 0.5, u);
            let sample = self
                .frame
                .integrator
                .camera_sample(&ray, &PixelPrior::NONE, st);
            let (c, prim) = (sample.radiance, sample.prim);
            st.scratch.counts.primary += 1;
            if prim != centre.1 || 255.0 * (tone3(c) - tone).abs().max_element() > FLAT_CONTRAST {
                return true;
            }
        }
        false
    }
}

/// Pairs of pixels along the two halves of a streak from the centre of (`x`, `y`) to its
/// ends `ends` (pixels), at the same fraction of each half, about a pixel apart along the
/// longer one, each with its neighbours across its half: what must be flat for the pixel
/// to keep its centre sample under a moving camera.
#[inline]
pub(super) fn streak_pairs(
    x: usize,
    y: usize,
    ends: [(f32, f32); 2],
) -> impl Iterator<Item = [(i64, i64); 2]> {
    let span = |e: (f32, f32)| e.0.abs().max(e.1.abs());
    let steps = span(ends[0]).max(span(ends[1])).ceil() as i64;
    // Across a half: ±1 along the axis it runs less along.
    let across = |e: (f32, f32)| {
        if e.0.abs() >= e.1.abs() {
            (0, 1)
        } else {
            (1, 0)
        }
    };
    let (a0, a1) = (across(ends[0]), across(ends[1]));
    let (cx, cy) = (x as f32 + 0.5, y as f32 + 0.5);
    (1..=steps).flat_map(move |s| {
        let f = s as f32 / steps as f32;
        let p0 = (floor(cx + ends[0].0 * f), floor(cy + ends[0].1 * f));
        let p1 = (floor(cx + ends[1].0 * f), floor(cy + ends[1].1 * f));
        (-1..=1).map(move |k| {
            [
                (p0.0 + k * a0.0, p0.1 + k * a0.1),
                (p1.0 + k * a1.0, p1.1 + k * a1.1),
            ]
        })
    })
}

/// `MotionProbe::slide_stray` of a camera seen at the instants `sweep`.
fn slide_stray(sweep: &[PinholeCamera]) -> Option<f32> {
    let (first, last) = (sweep.first()?, sweep.last()?);
    let way = last.eye() - first.eye();
    let mut stray = 0.0f32;
    for c in sweep {
        if !c.same_view(first) {
            return None;
        }
        let off = c.eye() - first.eye();
        let along = if way == Vec3A::ZERO {
            0.0
        } else {
            (off.dot(way) / way.length_squared()).clamp(0.0, 1.0)
        };
        stray = stray.max(off.distance(way * along));
    }
    let stray = stray * first.reach(MAX_FLAT_SWEEP);
    stray.is_finite().then_some(stray)
}

/// `v.floor()` as an integer, without the library call `f32::floor` makes on CPUs the build
/// does not assume to round in hardware (the streak walk takes several per pixel).
#[inline]
fn floor(v: f32) -> i64 {
    let t = v as i64;
    t - ((t as f32) > v) as i64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Camera;

    #[test]
    fn floor_is_the_library_floor() {
        for v in [
            -3.0f32,
            -2.5,
            -1e-7,
            -0.0,
            0.0,
            1e-7,
            0.5,
            0.999_999_9,
            1.0,
            95.5,
            1e6 + 0.5,
        ] {
            assert_eq!(floor(v), v.floor() as i64, "{v}");
        }
    }

    fn view(eye: [f64; 3], dir: [f64; 3]) -> PinholeCamera {
        let cam = Camera {
            name: "eye".into(),
            fov_x_deg: 50.0,
            eye: eye.into(),
            dir: dir.into(),
            up: [0.0, 1.0, 0.0].into(),
            lens: None,
        };
        PinholeCamera::new(&cam, 64, 36).expect("a camera")
    }

    #[test]
    fn only_a_camera_sliding_one_way_without_turning_is_a_slide() {
        let ahead = [0.0, 0.0, -1.0];
        // Eased along a line: uneven steps, one way.
        let eased: Vec<_> = [0.0, 0.05, 0.3, 0.7, 0.95, 1.0]
            .iter()
            .map(|u| view([2.0 * u, 0.5 * u, -3.0 * u], ahead))
            .collect();
        let stray = slide_stray(&eased).expect("a slide");
        assert!(stray < 1e-5, "{stray}");
        // Off the line by 0.1 at one instant (across it: (3, 0, 2) is square to the way):
        // that far, times the view's reach.
        let across = 0.1 / 13f64.sqrt();
        let mut bent = eased.clone();
        bent[2] = view([0.6 + 3.0 * across, 0.15, -0.9 + 2.0 * across], ahead);
        let stray = slide_stray(&bent).expect("no turn");
        let reach = eased[0].reach(MAX_FLAT_SWEEP);
        assert!((stray - 0.1 * reach).abs() < 1e-4 * reach, "{stray}");
        // Past the last eye and back: the way beyond counts as stray.
        let mut back = eased.clone();
        back[4] = view([2.4, 0.6, -3.6], ahead);
        let stray = slide_stray(&back).expect("no turn");
        assert!(stray > 0.1 * reach, "{stray}");
        // Turning a little: not a slide.
        let mut turned = eased;
        turned[3] = view([1.4, 0.35, -2.1], [0.01, 0.0, -1.0]);
        assert_eq!(slide_stray(&turned), None);
    }

    #[test]
    fn a_streak_pairs_points_at_the_same_fraction_of_its_halves() {
        // Halves of 4 and 2 pixels: four steps, the shorter half at half-pixel strides.
        let pairs: Vec<_> = streak_pairs(10, 10, [(-4.0, 0.0), (2.0, 0.0)]).collect();
        assert_eq!(pairs.len(), 4 * 3);
        let middles: Vec<_> = pairs.iter().skip(1).step_by(3).copied().collect();
        assert_eq!(
            middles,
            [
                [(9, 10), (11, 10)],
                [(8, 10), (11, 10)],
                [(7, 10), (12, 10)],
                [(6, 10), (12, 10)]
            ]
        );
        // Across a horizontal half: the rows above and below.
        assert_eq!(pairs[0][0], (9, 9));
        assert_eq!(pairs[2][0], (9, 11));
    }
}
