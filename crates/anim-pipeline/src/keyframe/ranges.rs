//! Values that must stay in range between keys: a scale that would pass through 0 (and turn
//! its object inside out), a field of view outside 0–180°, a negative brightness, an opacity
//! or reflectivity outside 0–1, an index of refraction at or below 0. Keys are checked where
//! they are written; curves that overshoot (Catmull-Rom, Back, Elastic) can leave the range
//! between them, so every frame's span of time is checked too, not only its instant.

use super::expr::Val;
use super::interp::Keyable;
use super::spec_file::{Animation, Blend, Channel, Track};
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
        expressions_are_finite(track, &instants, &span, i)?;
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

/// Every expression of `track` gives finite values over the span (`sqrt(-1)` does not).
fn expressions_are_finite(
    track: &Track,
    instants: &[f64],
    span: &str,
    i: usize,
) -> Result<(), OutOfRange> {
    let name = &track.target;
    let m = &track.material;
    let numbers = [
        (&track.rotate, "turn"),
        (&track.brightness, "brightness"),
        (&track.fov, "field of view"),
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

/// An error at channel `c`'s expression where it gives a value that is not finite.
fn finite<T: Keyable>(
    c: &Channel<T>,
    instants: &[f64],
    what: &str,
    span: &str,
    i: usize,
) -> Result<(), OutOfRange> {
    let Some(d) = &c.expr else {
        return Ok(());
    };
    for &t in instants {
        let v = c.at(t).map(T::to_val);
        if let Some(v) = v.filter(|v| !v.is_finite()) {
            let shown = match v {
                Val::Num(n) => format!("{n}"),
                Val::Vec(v) => format!("({}, {}, {})", v.x, v.y, v.z),
            };
            return Err(OutOfRange {
                path: d.path.clone(),
                message: format!(
                    "at frame {i} ({span}) {what} is {shown} at t = {} s: the expression gives no number there (a square root or logarithm of a negative number, a division by 0?)",
                    tidy(t)
                ),
            });
        }
    }
    Ok(())
}

fn check_track(track: &Track, instants: &[f64], span: &str, i: usize) -> Result<(), OutOfRange> {
    let name = &track.target;
    if let Some(c) = &track.scale {
        scale_keeps_its_sign(c, instants, name, span, i)?;
    }
    let checks: [RangeCheck; 5] = [
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
