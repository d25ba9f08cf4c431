//! Keyframe interpolation: easing curves and sampling a list of keys at a time.
//!
//! A key's `interp` governs the segment that *starts* at that key and ends at the next one:
//! `EaseIn` on a key means the motion towards the next key starts slowly.

use glam::DVec3;
use serde::Deserialize;

/// How a segment between two keys is traversed. With `s ∈ [0, 1]` the fraction of the
/// segment's time that has passed, the value is `a + (b − a)·e(s)` for:
///
/// | mode        | `e(s)`                    | feel                                   |
/// |-------------|---------------------------|----------------------------------------|
/// | `Step`      | 0 (until the next key)    | holds, then jumps                      |
/// | `Linear`    | `s`                       | constant speed                         |
/// | `EaseIn`    | `s²`                      | starts at rest, speeds up              |
/// | `EaseOut`   | `1 − (1 − s)²`            | arrives at rest                        |
/// | `EaseInOut` | `3s² − 2s³` (smoothstep)  | starts and arrives at rest             |
///
/// `Smooth` is a Catmull-Rom spline: a cubic Hermite segment whose tangents at each key are
/// the slope between the neighbouring keys, so a path through several keys has no corners.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Deserialize)]
pub enum Interp {
    Step,
    #[default]
    Linear,
    Smooth,
    EaseIn,
    EaseOut,
    EaseInOut,
}

impl Interp {
    /// The eased fraction `e(s)` for the non-spline modes (`Smooth` is linear here: the spline
    /// needs the neighbouring keys, see [`sample`]).
    pub fn ease(self, s: f64) -> f64 {
        let s = s.clamp(0.0, 1.0);
        match self {
            Interp::Step => {
                if s >= 1.0 {
                    1.0
                } else {
                    0.0
                }
            }
            Interp::Linear | Interp::Smooth => s,
            Interp::EaseIn => s * s,
            Interp::EaseOut => 1.0 - (1.0 - s) * (1.0 - s),
            Interp::EaseInOut => s * s * (3.0 - 2.0 * s),
        }
    }
}

/// Values that can be keyed: numbers and 3-vectors.
pub trait Keyable: Copy {
    fn add(self, o: Self) -> Self;
    fn sub(self, o: Self) -> Self;
    fn mul(self, k: f64) -> Self;
}

impl Keyable for f64 {
    fn add(self, o: Self) -> Self {
        self + o
    }
    fn sub(self, o: Self) -> Self {
        self - o
    }
    fn mul(self, k: f64) -> Self {
        self * k
    }
}

impl Keyable for DVec3 {
    fn add(self, o: Self) -> Self {
        self + o
    }
    fn sub(self, o: Self) -> Self {
        self - o
    }
    fn mul(self, k: f64) -> Self {
        self * k
    }
}

/// One key, already validated: times strictly increase along a channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Key<T> {
    pub at: f64,
    pub value: T,
    pub interp: Interp,
}

/// The value of a keyed channel at time `t` (seconds).
///
/// Outside the keyed span the first or last value holds, unless `looping`: then the keys
/// repeat with period `last.at − first.at` (the first and last key are the same instant of
/// the cycle), and the spline's neighbours wrap around so a loop has no corner at the seam.
/// `keys` must have strictly increasing times; `None` only when there are no keys.
pub fn sample<T: Keyable>(keys: &[Key<T>], t: f64, looping: bool) -> Option<T> {
    let (first, last) = (keys.first()?, keys.last()?);
    Some(sample_nonempty(keys, first, last, t, looping))
}

fn sample_nonempty<T: Keyable>(
    keys: &[Key<T>],
    first: &Key<T>,
    last: &Key<T>,
    t: f64,
    looping: bool,
) -> T {
    if keys.len() == 1 {
        return first.value;
    }
    let period = last.at - first.at;
    let t = if looping && period > 0.0 {
        first.at + (t - first.at).rem_euclid(period)
    } else {
        t
    };
    if t <= first.at {
        return first.value;
    }
    if t >= last.at {
        return last.value;
    }
    // The segment [k, k+1] holding t: the last key at or before t.
    let k = keys.partition_point(|key| key.at <= t) - 1;
    let (a, b) = (&keys[k], &keys[k + 1]);
    let h = b.at - a.at;
    let s = (t - a.at) / h;
    match a.interp {
        Interp::Smooth => {
            let m0 = tangent(keys, k, looping);
            let m1 = tangent(keys, k + 1, looping);
            hermite(a.value, m0, b.value, m1, h, s)
        }
        mode => a.value.add(b.value.sub(a.value).mul(mode.ease(s))),
    }
}

/// Catmull-Rom tangent (value per second) at key `i`: the slope between its neighbours.
/// At the ends of a non-looping channel, the slope of the one adjacent segment.
fn tangent<T: Keyable>(keys: &[Key<T>], i: usize, looping: bool) -> T {
    let n = keys.len();
    let period = keys[n - 1].at - keys[0].at;
    // (value, time) of the neighbours, wrapping around the cycle when looping. Keys 0 and
    // n−1 are the same instant of a loop, so the neighbour across the seam skips one.
    let prev = if i > 0 {
        Some((keys[i - 1].value, keys[i - 1].at))
    } else if looping && n > 2 {
        Some((keys[n - 2].value, keys[n - 2].at - period))
    } else {
        None
    };
    let next = if i + 1 < n {
        Some((keys[i + 1].value, keys[i + 1].at))
    } else if looping && n > 2 {
        Some((keys[1].value, keys[1].at + period))
    } else {
        None
    };
    let (v, t) = (keys[i].value, keys[i].at);
    match (prev, next) {
        (Some((pv, pt)), Some((nv, nt))) => nv.sub(pv).mul(1.0 / (nt - pt)),
        (None, Some((nv, nt))) => nv.sub(v).mul(1.0 / (nt - t)),
        (Some((pv, pt)), None) => v.sub(pv).mul(1.0 / (t - pt)),
        (None, None) => v.mul(0.0),
    }
}

/// Cubic Hermite segment from `p0` (tangent `m0`) to `p1` (tangent `m1`), tangents in value
/// per second over a segment `h` seconds long, at fraction `s`.
pub fn hermite<T: Keyable>(p0: T, m0: T, p1: T, m1: T, h: f64, s: f64) -> T {
    let s2 = s * s;
    let s3 = s2 * s;
    let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
    let h10 = s3 - 2.0 * s2 + s;
    let h01 = -2.0 * s3 + 3.0 * s2;
    let h11 = s3 - s2;
    p0.mul(h00)
        .add(m0.mul(h10 * h))
        .add(p1.mul(h01))
        .add(m1.mul(h11 * h))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn k(at: f64, value: f64, interp: Interp) -> Key<f64> {
        Key { at, value, interp }
    }

    fn close(a: impl Into<Option<f64>>, b: f64) {
        let a = a.into().expect("keys");
        assert!((a - b).abs() < 1e-12, "{a} != {b}");
    }

    #[test]
    fn easing_curves_at_known_fractions() {
        close(Interp::Linear.ease(0.25), 0.25);
        close(Interp::EaseIn.ease(0.5), 0.25);
        close(Interp::EaseOut.ease(0.5), 0.75);
        close(Interp::EaseInOut.ease(0.5), 0.5);
        // 3·0.0625 − 2·0.015625 = 0.15625
        close(Interp::EaseInOut.ease(0.25), 0.15625);
        close(Interp::Step.ease(0.999), 0.0);
        close(Interp::Step.ease(1.0), 1.0);
    }

    #[test]
    fn holds_outside_the_keys() {
        let keys = [k(1.0, 10.0, Interp::Linear), k(2.0, 20.0, Interp::Linear)];
        close(sample(&keys, 0.0, false), 10.0);
        close(sample(&keys, 3.0, false), 20.0);
        close(sample(&keys, 1.5, false), 15.0);
    }

    #[test]
    fn loop_wraps_time() {
        let keys = [
            k(0.0, 0.0, Interp::Linear),
            k(1.0, 10.0, Interp::Linear),
            k(2.0, 0.0, Interp::Linear),
        ];
        close(sample(&keys, 2.5, true), 5.0);
        close(sample(&keys, -0.5, true), 5.0);
        close(sample(&keys, 2.5, false), 0.0);
    }

    #[test]
    fn smooth_passes_through_keys_and_uses_neighbour_slopes() {
        // Keys 0→0, 1→1, 2→4 (y = x² at the keys). Tangents: m0 = 1 (one-sided),
        // m1 = (4 − 0)/2 = 2. At s = 0.5 of the first segment (h = 1):
        // h00 = 0.5, h10 = 0.125, h01 = 0.5, h11 = −0.125 →
        // 0.5·0 + 0.125·1 + 0.5·1 − 0.125·2 = 0.375.
        let keys = [
            k(0.0, 0.0, Interp::Smooth),
            k(1.0, 1.0, Interp::Smooth),
            k(2.0, 4.0, Interp::Smooth),
        ];
        close(sample(&keys, 0.5, false), 0.375);
        close(sample(&keys, 1.0, false), 1.0);
    }
}
