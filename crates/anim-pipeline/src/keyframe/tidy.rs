//! Numbers as generated files and messages write them: rounded to 12 significant digits, so
//! that they read `12` rather than `11.999999999999998`; far below anything visible, and
//! deterministic.

use glam::DVec3;

/// `x` rounded to 12 significant digits.
pub fn tidy(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return if x == 0.0 { 0.0 } else { x };
    }
    let scale = 10f64.powi(11 - x.abs().log10().floor() as i32);
    if !scale.is_finite() || scale == 0.0 {
        return x;
    }
    let r = (x * scale).round() / scale;
    if r.is_finite() {
        r
    } else {
        x
    }
}

/// [`tidy`] for a vector, to 12 significant digits of its largest component, so that the
/// round-off of a rotation (`2.4e-16` beside `4`) reads as 0.
pub fn tidy3(v: DVec3) -> DVec3 {
    let m = v.abs().max_element();
    if m == 0.0 || !m.is_finite() {
        return DVec3::new(tidy(v.x), tidy(v.y), tidy(v.z));
    }
    let scale = 10f64.powi(11 - m.log10().floor() as i32);
    if !scale.is_finite() || scale == 0.0 {
        return v;
    }
    let r = (v * scale).round() / scale;
    // `+ 0.0` turns −0 into 0, which prints as `0` rather than `-0`.
    if r.is_finite() {
        r + DVec3::ZERO
    } else {
        v
    }
}
