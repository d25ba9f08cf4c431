//! Keyframe interpolation: easing curves, splines, cycles, and sampling a list of keys at a time.
//!
//! A key's `interp` governs the segment that *starts* at that key and ends at the next one:
//! `EaseIn` on a key means the motion towards the next key starts slowly. The curves are
//! documented for users in `docs/animation.md` ("Keys and curves").

use super::expr::Val;
use glam::DVec3;
use serde::Deserialize;
use std::f64::consts::PI;

/// How a segment between two keys is traversed. With `s ∈ [0, 1]` the fraction of the
/// segment's time that has passed, the value is `a + (b − a)·e(s)` for an easing `e`
/// ([`Interp::ease`]), except for the three splines, which need the neighbouring keys:
///
/// - `Smooth`: a Catmull-Rom spline (each key's tangent is the slope between its
///   neighbours); no corners, but it can overshoot its keys.
/// - `Monotone`: a monotone cubic (Fritsch–Carlson tangents, as in PCHIP): no corners where
///   the keys keep rising or falling, a flat tangent at every peak and dip, and never a value
///   outside the two keys of its segment.
/// - `Auto`: Blender's auto-clamped handles: Catmull-Rom tangents, but flat at every peak and
///   dip and at the ends of a channel that does not repeat (it starts and stops at rest).
#[derive(Clone, Copy, Debug, PartialEq, Default, Deserialize)]
pub enum Interp {
    Step,
    #[default]
    Linear,
    Smooth,
    Monotone,
    Auto,
    EaseIn,
    EaseOut,
    EaseInOut,
    SineIn,
    SineOut,
    SineInOut,
    CubicIn,
    CubicOut,
    CubicInOut,
    QuartIn,
    QuartOut,
    QuartInOut,
    ExpoIn,
    ExpoOut,
    ExpoInOut,
    BackIn,
    BackOut,
    BackInOut,
    BounceIn,
    BounceOut,
    BounceInOut,
    ElasticIn,
    ElasticOut,
    ElasticInOut,
    /// CSS `cubic-bezier(x1, y1, x2, y2)`: the timing curve from (0, 0) to (1, 1) with those
    /// two control points; `x1` and `x2` lie in [0, 1] so that time never runs backwards.
    CubicBezier(f64, f64, f64, f64),
}

/// One side of a key's curve (`in:` the end of the segment arriving at the key, `out:` the
/// start of the one leaving it): a Bézier handle `Handle(x, y)`, pointing from the key into
/// the segment as fractions of its time and of its change in value, or a named ease whose
/// handle is the cubic Bézier form of that family's `InOut` curve (as easings.net gives
/// them). A segment with a side given is the CSS timing curve
/// `CubicBezier(x₁, y₁, 1 − x₂, 1 − y₂)` of its start's `out` handle `(x₁, y₁)` and its end's
/// `in` handle `(x₂, y₂)`.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
pub enum Side {
    /// On the straight line: no easing on this side.
    Linear,
    Sine,
    Quad,
    Cubic,
    Quart,
    Expo,
    /// Pulls back before leaving (or overshoots before arriving).
    Back,
    Handle(f64, f64),
}

impl Side {
    /// The handle `(x, y)`, from the key into the segment.
    pub fn handle(self) -> (f64, f64) {
        match self {
            Side::Linear => (1.0 / 3.0, 1.0 / 3.0),
            Side::Sine => (0.37, 0.0),
            Side::Quad => (0.45, 0.0),
            Side::Cubic => (0.65, 0.0),
            Side::Quart => (0.76, 0.0),
            Side::Expo => (0.87, 0.0),
            Side::Back => (0.68, -0.6),
            Side::Handle(x, y) => (x, y),
        }
    }

    /// What is wrong with the handle, if anything: time cannot run backwards.
    pub fn problem(self) -> Option<String> {
        let (x, y) = self.handle();
        if !(x.is_finite() && y.is_finite()) {
            return Some("a handle's x and y must be finite".into());
        }
        (!(0.0..=1.0).contains(&x))
            .then(|| format!("a handle's x is a fraction of the segment's time, in 0..1, not {x}"))
    }

    /// The curve of a segment whose start has curve `interp` and sides `out` (of its start)
    /// and `into` (the `in` of its end), at least one given. A side not given is the
    /// curve's own when that is a Bézier (`Linear` is one), else there is none to take: `Err`
    /// says so.
    pub fn segment(
        interp: Interp,
        out: Option<Side>,
        into: Option<Side>,
    ) -> Result<Interp, String> {
        let (own_out, own_in) = match interp {
            Interp::Linear => (Side::Linear.handle(), Side::Linear.handle()),
            Interp::CubicBezier(x1, y1, x2, y2) => ((x1, y1), (1.0 - x2, 1.0 - y2)),
            other => {
                return Err(format!(
                    "a key's `in` and `out` shape its segments as Bézier curves, which `{other:?}` is not: leave `interp` out (or Linear, or CubicBezier)"
                ))
            }
        };
        let (x1, y1) = out.map_or(own_out, Side::handle);
        let (x2, y2) = into.map_or(own_in, Side::handle);
        Ok(Interp::CubicBezier(x1, y1, 1.0 - x2, 1.0 - y2))
    }
}

/// Back's overshoot constant: about a tenth past the target (Penner's easing equations).
const BACK: f64 = 1.70158;

impl Interp {
    /// Whether this segment's curve needs the neighbouring keys (the two splines).
    pub fn is_spline(self) -> bool {
        matches!(self, Interp::Smooth | Interp::Monotone | Interp::Auto)
    }

    /// The eased fraction `e(s)`: 0 at `s = 0`, 1 at `s = 1` (the splines are linear here:
    /// they need the neighbouring keys, see [`sample`]). Back and Elastic leave [0, 1] on
    /// the way, as they are meant to.
    pub fn ease(self, s: f64) -> f64 {
        let s = s.clamp(0.0, 1.0);
        let in_out = |e: fn(f64) -> f64| {
            if s < 0.5 {
                e(2.0 * s) / 2.0
            } else {
                1.0 - e(2.0 - 2.0 * s) / 2.0
            }
        };
        match self {
            Interp::Step => {
                if s >= 1.0 {
                    1.0
                } else {
                    0.0
                }
            }
            Interp::Linear | Interp::Smooth | Interp::Monotone | Interp::Auto => s,
            Interp::EaseIn => s * s,
            Interp::EaseOut => 1.0 - (1.0 - s) * (1.0 - s),
            Interp::EaseInOut => s * s * (3.0 - 2.0 * s),
            Interp::SineIn => sine_in(s),
            Interp::SineOut => 1.0 - sine_in(1.0 - s),
            Interp::SineInOut => in_out(sine_in),
            Interp::CubicIn => s.powi(3),
            Interp::CubicOut => 1.0 - (1.0 - s).powi(3),
            Interp::CubicInOut => in_out(|s| s.powi(3)),
            Interp::QuartIn => s.powi(4),
            Interp::QuartOut => 1.0 - (1.0 - s).powi(4),
            Interp::QuartInOut => in_out(|s| s.powi(4)),
            Interp::ExpoIn => expo_in(s),
            Interp::ExpoOut => 1.0 - expo_in(1.0 - s),
            Interp::ExpoInOut => in_out(expo_in),
            Interp::BackIn => back_in(s),
            Interp::BackOut => 1.0 - back_in(1.0 - s),
            Interp::BackInOut => in_out(back_in),
            Interp::BounceIn => 1.0 - bounce_out(1.0 - s),
            Interp::BounceOut => bounce_out(s),
            Interp::BounceInOut => in_out(|s| 1.0 - bounce_out(1.0 - s)),
            Interp::ElasticIn => elastic_in(s),
            Interp::ElasticOut => 1.0 - elastic_in(1.0 - s),
            Interp::ElasticInOut => in_out(elastic_in),
            Interp::CubicBezier(x1, y1, x2, y2) => cubic_bezier(x1, y1, x2, y2, s),
        }
    }

    /// What is wrong with this curve's parameters, if anything.
    pub fn problem(self) -> Option<String> {
        let Interp::CubicBezier(x1, y1, x2, y2) = self else {
            return None;
        };
        if ![x1, y1, x2, y2].iter().all(|v| v.is_finite()) {
            return Some("the control points of CubicBezier must be finite".into());
        }
        (!((0.0..=1.0).contains(&x1) && (0.0..=1.0).contains(&x2))).then(|| {
            format!(
                "CubicBezier's x1 and x2 must lie in 0..1 (time cannot run backwards), not {x1} and {x2}"
            )
        })
    }
}

fn sine_in(s: f64) -> f64 {
    1.0 - (s * PI / 2.0).cos()
}

fn expo_in(s: f64) -> f64 {
    // 2^(10s − 10) is 1/1024 at s = 0: shifted and scaled so that the curve starts at 0.
    let floor = 2f64.powi(-10);
    (2f64.powf(10.0 * s - 10.0) - floor) / (1.0 - floor)
}

fn back_in(s: f64) -> f64 {
    (BACK + 1.0) * s * s * s - BACK * s * s
}

fn bounce_out(s: f64) -> f64 {
    // Four parabolic arcs of falling heights (Penner): 1, 1/4, 1/16, 1/64 of the first.
    const N: f64 = 7.5625;
    const D: f64 = 2.75;
    if s < 1.0 / D {
        N * s * s
    } else if s < 2.0 / D {
        let s = s - 1.5 / D;
        N * s * s + 0.75
    } else if s < 2.5 / D {
        let s = s - 2.25 / D;
        N * s * s + 0.9375
    } else {
        let s = s - 2.625 / D;
        N * s * s + 0.984375
    }
}

fn elastic_in(s: f64) -> f64 {
    if s <= 0.0 || s >= 1.0 {
        return s.clamp(0.0, 1.0);
    }
    let c4 = 2.0 * PI / 3.0;
    -(2f64.powf(10.0 * s - 10.0)) * ((10.0 * s - 10.75) * c4).sin()
}

/// The CSS timing curve: solves `x(u) = s` for the Bézier parameter `u` (Newton's method,
/// bisection where its slope vanishes), then returns `y(u)`.
fn cubic_bezier(x1: f64, y1: f64, x2: f64, y2: f64, s: f64) -> f64 {
    let coord = |p1: f64, p2: f64, u: f64| {
        let v = 1.0 - u;
        3.0 * v * v * u * p1 + 3.0 * v * u * u * p2 + u * u * u
    };
    let slope = |p1: f64, p2: f64, u: f64| {
        let v = 1.0 - u;
        3.0 * v * v * p1 + 6.0 * v * u * (p2 - p1) + 3.0 * u * u * (1.0 - p2)
    };
    let (mut lo, mut hi, mut u) = (0.0f64, 1.0f64, s);
    for _ in 0..64 {
        let x = coord(x1, x2, u) - s;
        if x.abs() < 1e-14 {
            break;
        }
        if x > 0.0 {
            hi = u;
        } else {
            lo = u;
        }
        let d = slope(x1, x2, u);
        let newton = u - x / d;
        u = if d.abs() > 1e-9 && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
    }
    coord(y1, y2, u)
}

/// Values that can be keyed: numbers and 3-vectors.
pub trait Keyable: Copy {
    /// How many numbers the value holds.
    const COMPONENTS: usize;
    /// As an expression sees it (`value`).
    fn to_val(self) -> Val;
    /// An expression's result as this kind of value (a number on every axis of a vector).
    fn from_val(v: Val) -> Self;
    fn add(self, o: Self) -> Self;
    fn sub(self, o: Self) -> Self;
    fn mul(self, k: f64) -> Self;
    fn component(self, i: usize) -> f64;
    fn with_component(self, i: usize, v: f64) -> Self;
}

impl Keyable for f64 {
    const COMPONENTS: usize = 1;
    fn to_val(self) -> Val {
        Val::Num(self)
    }
    fn from_val(v: Val) -> Self {
        v.num()
    }
    fn add(self, o: Self) -> Self {
        self + o
    }
    fn sub(self, o: Self) -> Self {
        self - o
    }
    fn mul(self, k: f64) -> Self {
        self * k
    }
    fn component(self, _: usize) -> f64 {
        self
    }
    fn with_component(self, _: usize, v: f64) -> Self {
        v
    }
}

impl Keyable for DVec3 {
    const COMPONENTS: usize = 3;
    fn to_val(self) -> Val {
        Val::Vec(self)
    }
    fn from_val(v: Val) -> Self {
        v.vec()
    }
    fn add(self, o: Self) -> Self {
        self + o
    }
    fn sub(self, o: Self) -> Self {
        self - o
    }
    fn mul(self, k: f64) -> Self {
        self * k
    }
    fn component(self, i: usize) -> f64 {
        self[i]
    }
    fn with_component(mut self, i: usize, v: f64) -> Self {
        self[i] = v;
        self
    }
}

/// One key, already validated: times strictly increase along a channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Key<T> {
    pub at: f64,
    pub value: T,
    pub interp: Interp,
}

/// What a channel does outside its keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Deserialize)]
pub enum Cycle {
    /// The first value holds before the keys, the last after them.
    #[default]
    Hold,
    /// The keys repeat with period `last.at − first.at`, before and after.
    Repeat,
    /// The keys play forwards, then backwards, then forwards again.
    PingPong,
    /// The keys repeat, each repetition starting where the last ended (Blender's "repeat
    /// with offset"): a walk cycle that keeps walking.
    RepeatOffset,
}

/// When a channel's keys play: shifted by `offset` seconds, and cycled.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Timing {
    /// The keys play this many seconds later than written.
    pub offset: f64,
    pub cycle: Cycle,
    /// How many times the keys play when cycled (`None`: forever, before and after); after
    /// the last time the value holds where it ended, before the first it holds the first.
    pub count: Option<u32>,
}

impl Timing {
    /// The timing of a plain channel (`looping: false`) or of a repeating one.
    pub fn looping(looping: bool) -> Timing {
        Timing {
            cycle: if looping { Cycle::Repeat } else { Cycle::Hold },
            ..Timing::default()
        }
    }

    /// Whether the keys repeat forever with no offset: the spline's tangents then wrap
    /// around the seam.
    fn wraps(&self) -> bool {
        self.cycle == Cycle::Repeat && self.count.is_none()
    }
}

/// Where time `t` falls in a channel's keys once cycled: a time within the keys' span (or
/// outside it, where the end values hold) and how many whole periods came before (a whole
/// number, as a float: a tiny period repeats more often than any integer type counts).
pub fn cycled_time(first: f64, last: f64, t: f64, timing: &Timing) -> (f64, f64) {
    let t = t - timing.offset;
    let period = last - first;
    if timing.cycle == Cycle::Hold || period <= 0.0 {
        return (t, 0.0);
    }
    if timing.wraps() {
        // Written as it always was, so that looping channels keep their exact values.
        return (first + (t - first).rem_euclid(period), 0.0);
    }
    let cycles = ((t - first) / period).floor();
    let limit = timing.count.map_or(f64::INFINITY, f64::from);
    if timing.count.is_some() && cycles < 0.0 {
        return (first, 0.0);
    }
    if cycles >= limit {
        // Held where the last cycle ended: a ping-pong with an even count ends at the start.
        let last_cycle = limit - 1.0;
        let back = timing.cycle == Cycle::PingPong && last_cycle.rem_euclid(2.0) == 1.0;
        return (if back { first } else { last }, last_cycle);
    }
    let within = (t - first) - cycles * period;
    let backwards = timing.cycle == Cycle::PingPong && cycles.rem_euclid(2.0) == 1.0;
    let local = if backwards {
        last - within
    } else {
        first + within
    };
    (local, cycles)
}

/// The value of a keyed channel at time `t` (seconds): repeating when `looping`. See
/// [`sample_timed`].
pub fn sample<T: Keyable>(keys: &[Key<T>], t: f64, looping: bool) -> Option<T> {
    sample_timed(keys, t, &Timing::looping(looping))
}

/// The value of a keyed channel at time `t` (seconds) under `timing`.
///
/// Outside the keyed span the first or last value holds, unless the channel cycles: a
/// repeating channel's first and last key are the same instant of the cycle, and the
/// spline's neighbours wrap around so a loop has no corner at the seam. `keys` must have
/// strictly increasing times; `None` only when there are no keys.
pub fn sample_timed<T: Keyable>(keys: &[Key<T>], t: f64, timing: &Timing) -> Option<T> {
    let (first, last) = (keys.first()?, keys.last()?);
    if keys.len() == 1 {
        return Some(first.value);
    }
    let (t, cycles) = cycled_time(first.at, last.at, t, timing);
    let value = within_keys(keys, t, timing.wraps());
    if timing.cycle == Cycle::RepeatOffset && cycles != 0.0 {
        return Some(value.add(last.value.sub(first.value).mul(cycles)));
    }
    Some(value)
}

/// The segment `[k, k + 1]` holding `t` and the fraction `s` of it passed; `Err(false)` at
/// or before the first key, `Err(true)` at or after the last.
pub fn segment<T>(keys: &[Key<T>], t: f64) -> Result<(usize, f64), bool> {
    let (first, last) = (&keys[0], &keys[keys.len() - 1]);
    if t <= first.at {
        return Err(false);
    }
    if t >= last.at {
        return Err(true);
    }
    // The last key at or before t.
    let k = keys.partition_point(|key| key.at <= t) - 1;
    let (a, b) = (&keys[k], &keys[k + 1]);
    Ok((k, (t - a.at) / (b.at - a.at)))
}

fn within_keys<T: Keyable>(keys: &[Key<T>], t: f64, wraps: bool) -> T {
    let (k, s) = match segment(keys, t) {
        Ok(found) => found,
        Err(after) => return if after { keys[keys.len() - 1] } else { keys[0] }.value,
    };
    let (a, b) = (&keys[k], &keys[k + 1]);
    let h = b.at - a.at;
    match a.interp {
        Interp::Smooth => {
            let m0 = tangent(keys, k, wraps);
            let m1 = tangent(keys, k + 1, wraps);
            hermite(a.value, m0, b.value, m1, h, s)
        }
        Interp::Auto => {
            let m0 = clamped_tangent(keys, k, wraps);
            let m1 = clamped_tangent(keys, k + 1, wraps);
            hermite(a.value, m0, b.value, m1, h, s)
        }
        Interp::Monotone => {
            let m0 = monotone_tangent(keys, k, wraps);
            let m1 = monotone_tangent(keys, k + 1, wraps);
            hermite(a.value, m0, b.value, m1, h, s)
        }
        mode => a.value.add(b.value.sub(a.value).mul(mode.ease(s))),
    }
}

/// The (value, time) of the keys before and after key `i`, wrapping around the cycle when
/// `wraps`. Keys 0 and n−1 are the same instant of a loop, so the neighbour across the seam
/// skips one.
type Neighbours<T> = (Option<(T, f64)>, Option<(T, f64)>);

fn neighbours<T: Keyable>(keys: &[Key<T>], i: usize, wraps: bool) -> Neighbours<T> {
    let n = keys.len();
    let period = keys[n - 1].at - keys[0].at;
    let prev = if i > 0 {
        Some((keys[i - 1].value, keys[i - 1].at))
    } else if wraps && n > 2 {
        Some((keys[n - 2].value, keys[n - 2].at - period))
    } else {
        None
    };
    let next = if i + 1 < n {
        Some((keys[i + 1].value, keys[i + 1].at))
    } else if wraps && n > 2 {
        Some((keys[1].value, keys[1].at + period))
    } else {
        None
    };
    (prev, next)
}

/// Catmull-Rom tangent (value per second) at key `i`: the slope between its neighbours.
/// At the ends of a non-looping channel, the slope of the one adjacent segment.
fn tangent<T: Keyable>(keys: &[Key<T>], i: usize, wraps: bool) -> T {
    let (v, t) = (keys[i].value, keys[i].at);
    match neighbours(keys, i, wraps) {
        (Some((pv, pt)), Some((nv, nt))) => nv.sub(pv).mul(1.0 / (nt - pt)),
        (None, Some((nv, nt))) => nv.sub(v).mul(1.0 / (nt - t)),
        (Some((pv, pt)), None) => v.sub(pv).mul(1.0 / (t - pt)),
        (None, None) => v.mul(0.0),
    }
}

/// Auto-clamped tangent at key `i`, per component: the Catmull-Rom slope between its
/// neighbours, but 0 at a peak or dip (the neighbours on one side of the value) and at the
/// ends of a channel that does not wrap.
fn clamped_tangent<T: Keyable>(keys: &[Key<T>], i: usize, wraps: bool) -> T {
    let v = keys[i].value;
    let mut out = v.mul(0.0);
    let (Some((pv, pt)), Some((nv, nt))) = neighbours(keys, i, wraps) else {
        return out;
    };
    for c in 0..T::COMPONENTS {
        let (before, after) = (
            v.component(c) - pv.component(c),
            nv.component(c) - v.component(c),
        );
        let m = if before * after <= 0.0 {
            0.0
        } else {
            (nv.component(c) - pv.component(c)) / (nt - pt)
        };
        out = out.with_component(c, m);
    }
    out
}

/// Fritsch–Carlson tangent at key `i`, per component: 0 at a peak, a dip or beside a flat
/// segment; otherwise the weighted harmonic mean of the two slopes (Fritsch–Butland), which
/// is at most three times the smaller one, so no segment overshoots its keys. At the ends of
/// a non-looping channel, the slope of the end segment.
fn monotone_tangent<T: Keyable>(keys: &[Key<T>], i: usize, wraps: bool) -> T {
    let (v, t) = (keys[i].value, keys[i].at);
    let (prev, next) = neighbours(keys, i, wraps);
    let mut out = v.mul(0.0);
    for c in 0..T::COMPONENTS {
        let slope =
            |(pv, pt): (T, f64), (nv, nt): (T, f64)| (nv.component(c) - pv.component(c), nt - pt);
        let m = match (prev, next) {
            (Some(p), Some(n)) => {
                let (dy0, h0) = slope(p, (v, t));
                let (dy1, h1) = slope((v, t), n);
                let (d0, d1) = (dy0 / h0, dy1 / h1);
                if d0 * d1 <= 0.0 {
                    0.0
                } else {
                    3.0 * (h0 + h1) / ((2.0 * h1 + h0) / d0 + (h1 + 2.0 * h0) / d1)
                }
            }
            (None, Some(n)) => {
                let (dy, h) = slope((v, t), n);
                dy / h
            }
            (Some(p), None) => {
                let (dy, h) = slope(p, (v, t));
                dy / h
            }
            (None, None) => 0.0,
        };
        out = out.with_component(c, m);
    }
    out
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
mod tests;
