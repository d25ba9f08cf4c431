//! The range of a spec's numbers, and how messages show them. Every number a spec gives
//! (key values and times, quaternion parts, angles, offsets, points) ends up in frame files,
//! whose numbers the SDF reader takes only up to [`MAX_MAGNITUDE`]: so that is the range of
//! the spec's numbers too, refused where the spec writes them rather than in a frame.

use super::tidy::tidy;
pub use anim_core::sdf::MAX_MAGNITUDE;

/// Whether `v` is a number a spec may give (finite, within ±[`MAX_MAGNITUDE`]).
pub fn in_range(v: f64) -> bool {
    v.is_finite() && v.abs() <= MAX_MAGNITUDE
}

/// Why `v`, given as `what`, is refused; `None` when it is in range.
pub fn refusal(what: &str, v: f64) -> Option<String> {
    (!in_range(v)).then(|| {
        format!(
            "{what} must lie between {} and {}, not {}",
            shown(-MAX_MAGNITUDE),
            shown(MAX_MAGNITUDE),
            shown(v)
        )
    })
}

/// [`refusal`] for a vector, showing its first part out of range.
pub fn refusal3(what: &str, v: glam::DVec3) -> Option<String> {
    v.to_array().into_iter().find_map(|x| refusal(what, x))
}

/// Why `v`, given as the direction `what`, is refused: out of range, or of no length.
pub fn direction_refusal(what: &str, v: glam::DVec3) -> Option<String> {
    refusal3(what, v).or_else(|| {
        (v.length_squared() == 0.0).then(|| format!("{what} must be a non-zero direction"))
    })
}

/// `v` as a message shows it: plain up to a dozen digits, else in scientific notation
/// (`1e308`, not three hundred digits).
pub fn shown(v: f64) -> String {
    let t = tidy(v);
    if t == 0.0 || !t.is_finite() || (1e-6..1e12).contains(&t.abs()) {
        return format!("{t}");
    }
    // Rounded in decimal, as `tidy` cannot round where its scale is itself inexact.
    let text = format!("{v:.11e}");
    let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
    let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
    format!("{mantissa}e{exponent}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_show_readably() {
        assert_eq!(shown(1e308), "1e308");
        assert_eq!(shown(-1e12), "-1e12");
        assert_eq!(shown(18446744073709551615.0), "1.84467440737e19");
        assert_eq!(shown(-2.5e-9), "-2.5e-9");
        assert_eq!(shown(1e-300), "1e-300");
        assert_eq!(shown(0.125), "0.125");
        assert_eq!(shown(f64::INFINITY), "inf");
    }

    #[test]
    fn the_range_is_the_frame_readers() {
        assert!(in_range(MAX_MAGNITUDE) && in_range(-MAX_MAGNITUDE));
        assert!(!in_range(MAX_MAGNITUDE * 1.0000001) && !in_range(f64::NAN));
        assert_eq!(
            refusal("x", 1e308).as_deref(),
            Some("x must lie between -1e12 and 1e12, not 1e308")
        );
        assert_eq!(refusal("x", 3.0), None);
        let zero = direction_refusal("`up`", glam::DVec3::ZERO);
        assert_eq!(zero.as_deref(), Some("`up` must be a non-zero direction"));
        // Not refused for its length overflowing, but for its part out of range.
        let huge = direction_refusal("`up`", glam::DVec3::new(0.0, 1e308, 0.0));
        assert_eq!(
            huge.as_deref(),
            Some("`up` must lie between -1e12 and 1e12, not 1e308")
        );
    }
}
