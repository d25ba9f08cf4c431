//! Values that must stay in range between keys: a scale that would pass through 0 (and turn
//! its object inside out), a field of view outside 0–180°, a negative brightness, an opacity
//! or reflectivity outside 0–1, an index of refraction at or below 0, a negative radius or
//! aperture, a spot's half-angle outside 0–180°, a focus distance at or below 0. Keys are
//! checked where they are written; curves that overshoot (Catmull-Rom, Back, Elastic) can
//! leave the range between them, so every frame's span of time is checked too, not only its
//! instant.

use super::bounds::{self, shown};
use super::expr::Val;
use super::interp::Keyable;
use super::interp::{cycled_time, Cycle};
use super::locate::{field, index};
use super::spec_file::{Animation, Blend, Channel, Focus, Track};
use super::tidy::tidy;
use anim_core::limits;
use glam::DVec3;

/// Instants checked in each frame's span of time, besides its start and end: fine enough to
/// catch any overshoot of a cubic segment that lasts a frame or more, and the exposure of a
/// blurred frame lies inside the span.
const SPAN_SAMPLES: usize = 8;

/// A value found out of range: where in the spec (the key whose segment plays then), and what.
pub struct OutOfRange {
    pub path: String,
    pub message: String,
}

/// Checks every ranged channel over frame `i`'s span of time.
pub fn check_span(anim: &Animation, i: usize) -> Result<(), OutOfRange> {
    let (t0, t1) = anim.frame_span(i);
    let instants: Vec<f64> = (0..=SPAN_SAMPLES)
        .map(|k| t0 + (t1 - t0) * k as f64 / SPAN_SAMPLES as f64)
        .collect();
    let span = if t1 > t0 {
        format!("between t = {} and {} s", tidy(t0), tidy(t1))
    } else {
        format!("at t = {} s", tidy(t0))
    };
    for track in &anim.tracks {
        values_in_range(track, &instants, &span, i)?;
        check_track(track, &instants, &span, i)?;
    }
    let scene = [
        (&anim.ambient, "ambient light"),
        (&anim.background, "background"),
    ];
    for (channel, what) in scene {
        if let Some(c) = channel {
            finite(c, &instants, &format!("the {what}"), &span, i)?;
        }
    }
    Ok(())
}

/// Every channel of `track` gives values a frame can hold over the span (`sqrt(-1)` does not).
fn values_in_range(
    track: &Track,
    instants: &[f64],
    span: &str,
    i: usize,
) -> Result<(), OutOfRange> {
    let name = &track.target;
    let m = &track.material;
    let focus = match &track.optics.focus {
        Some(Focus::Distance(c)) => Some(c.clone()),
        _ => None,
    };
    let numbers = [
        (&track.rotate, "turn"),
        (&track.brightness, "brightness"),
        (&track.fov, "field of view"),
        (&track.optics.radius, "radius"),
        (&track.optics.inner, "inner half-angle"),
        (&track.optics.outer, "outer half-angle"),
        (&track.optics.aperture, "aperture"),
        (&focus, "focus distance"),
        (&m.reflectivity, "reflectivity"),
        (&m.opacity, "opacity"),
        (&m.ior, "index of refraction"),
        (&track.aim.as_ref().and_then(|a| a.roll.clone()), "roll"),
    ];
    for (c, what) in numbers {
        if let Some(c) = c {
            finite(c, instants, &format!("the {what} of '{name}'"), span, i)?;
        }
    }
    let vectors = [
        (&track.translate, "translation"),
        (&track.scale, "scale"),
        (&track.color, "colour"),
        (&m.ka, "ka"),
        (&m.kd, "kd"),
        (&m.ks, "ks"),
    ];
    for (c, what) in vectors {
        if let Some(c) = c {
            finite(c, instants, &format!("the {what} of '{name}'"), span, i)?;
        }
    }
    Ok(())
}

/// An error where channel `c` gives a value a frame cannot hold: no number at all (an
/// expression's), or one beyond [`bounds::MAX_MAGNITUDE`] (an expression's, or keys that
/// repeat with `RepeatOffset` so often that their sum outgrows it).
fn finite<T: Keyable>(
    c: &Channel<T>,
    instants: &[f64],
    what: &str,
    span: &str,
    i: usize,
) -> Result<(), OutOfRange> {
    for &t in instants {
        let Some(v) = c.at(t).map(T::to_val) else {
            continue;
        };
        let parts = match v {
            Val::Num(n) => vec![n],
            Val::Vec(v) => v.to_array().to_vec(),
        };
        let Some(why) = parts.iter().find_map(|&x| bounds::refusal("values", x)) else {
            continue;
        };
        let shown = match v {
            Val::Num(n) => shown(n),
            Val::Vec(v) => format!("({}, {}, {})", shown(v.x), shown(v.y), shown(v.z)),
        };
        let at = format!(
            "at frame {i} ({span}) {what} is {shown} at t = {} s",
            tidy(t)
        );
        return Err(match (&c.expr, v.is_finite()) {
            (Some(d), false) => OutOfRange {
                path: d.path.clone(),
                message: format!("{at}: the expression gives no number there (a square root or logarithm of a negative number, a division by 0?)"),
            },
            (Some(d), true) => OutOfRange {
                path: d.path.clone(),
                message: format!("{at}: {why}"),
            },
            (None, _) => repeated_too_often(c, t, &at, &why),
        });
    }
    Ok(())
}

/// Keys within range give values beyond it by repeating with `RepeatOffset`, each repeat
/// adding the keys' change (the error is then at the last key's time, which sets the
/// period), or by a curve that overshoots them.
fn repeated_too_often<T: Keyable>(c: &Channel<T>, t: f64, at: &str, why: &str) -> OutOfRange {
    let (first, last) = match (c.keys.first(), c.keys.last()) {
        (Some(first), Some(last)) => (first.at, last.at),
        _ => (0.0, 0.0),
    };
    let repeats = cycled_time(first, last, t, &c.timing).1;
    if c.timing.cycle != Cycle::RepeatOffset || repeats == 0.0 {
        return OutOfRange {
            path: c.key_path_at(t),
            message: format!("{at}: {why}. {OVERSHOOT_HELP}"),
        };
    }
    OutOfRange {
        path: field(&index(&c.path, c.keys.len() - 1), "at"),
        message: format!(
            "{at}, after {} repeats of its keys every {} s (`cycle: RepeatOffset` adds each repeat to the last): {why}; a longer period or a `cycles` count keeps it in range",
            shown(repeats),
            shown(last - first)
        ),
    }
}

fn check_track(track: &Track, instants: &[f64], span: &str, i: usize) -> Result<(), OutOfRange> {
    let name = &track.target;
    if let Some(c) = &track.scale {
        scale_keeps_its_sign(c, instants, name, span, i)?;
    }
    let o = &track.optics;
    let focus = match &o.focus {
        Some(Focus::Distance(c)) => Some(c.clone()),
        _ => None,
    };
    let half_angle = |v: f64| (0.0..=180.0).contains(&v);
    let checks: [RangeCheck; 10] = [
        (&o.radius, "radius", |v| v >= 0.0, "below 0"),
        (&o.inner, "inner half-angle", half_angle, "outside 0–180°"),
        (&o.outer, "outer half-angle", half_angle, "outside 0–180°"),
        (&o.aperture, "aperture", |v| v >= 0.0, "below 0"),
        (&focus, "focus distance", |v| v > 0.0, "at or below 0"),
        (
            &track.fov,
            "field of view",
            limits::fov_is_valid,
            "outside 0–180°",
        ),
        (&track.brightness, "brightness", |v| v >= 0.0, "below 0"),
        (
            &track.material.opacity,
            "opacity",
            in_unit_interval,
            "outside 0–1",
        ),
        (
            &track.material.reflectivity,
            "reflectivity",
            in_unit_interval,
            "outside 0–1",
        ),
        (
            &track.material.ior,
            "index of refraction",
            |v| v > 0.0,
            "at or below 0",
        ),
    ];
    // A value added to or multiplied with others is checked once combined, as frames write
    // it (`keyed.rs`).
    let layered = matches!(track.blend, Some(Blend::Add | Blend::Multiply));
    for (channel, what, ok, range) in checks {
        let Some(c) = channel.as_ref().filter(|_| !layered) else {
            continue;
        };
        for &t in instants {
            let v = c.at(t).unwrap_or(1.0);
            if !ok(v) {
                return Err(OutOfRange {
                    path: c.key_path_at(t),
                    message: format!(
                        "at frame {i} ({span}) the {what} of '{name}' goes {range}: {} at t = {} s. {}",
                        tidy(v),
                        tidy(t),
                        OVERSHOOT_HELP
                    ),
                });
            }
        }
    }
    Ok(())
}

/// A channel, what it is called, whether a value is in range, and how it left the range.
pub type RangeCheck<'a> = (
    &'a Option<Channel<f64>>,
    &'static str,
    fn(f64) -> bool,
    &'static str,
);

pub fn in_unit_interval(v: f64) -> bool {
    (0.0..=1.0).contains(&v)
}

/// What to do about a curve that leaves its range.
const OVERSHOOT_HELP: &str =
    "The curve overshoots its keys here: `Monotone` never does, or add a key";

fn scale_keeps_its_sign(
    c: &Channel<DVec3>,
    instants: &[f64],
    name: &str,
    span: &str,
    i: usize,
) -> Result<(), OutOfRange> {
    let mut before: Option<(f64, DVec3)> = None;
    for &t in instants {
        let v = c.at(t).unwrap_or(DVec3::ONE);
        let flipped = before.is_some_and(|(_, b)| (b * v).cmple(DVec3::ZERO).any());
        if v.cmpeq(DVec3::ZERO).any() || flipped {
            return Err(OutOfRange {
                path: c.key_path_at(t),
                message: format!(
                    "at frame {i} ({span}) the scale of '{name}' passes through 0 (it is ({}, {}, {}) at t = {} s), which would turn it inside out. {}",
                    tidy(v.x),
                    tidy(v.y),
                    tidy(v.z),
                    tidy(t),
                    OVERSHOOT_HELP
                ),
            });
        }
        before = Some((t, v));
    }
    Ok(())
}
