use super::*;
use proptest::prelude::*;

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
    // 1 − cos(π/4) and sin(π/4).
    close(Interp::SineIn.ease(0.5), 1.0 - 0.5f64.sqrt());
    close(Interp::SineOut.ease(0.5), 0.5f64.sqrt());
    // In-out curves: the In curve at 2s, halved: CubicInOut(0.25) = 0.5³/2 = 1/16.
    close(Interp::CubicInOut.ease(0.25), 0.0625);
    close(Interp::CubicOut.ease(0.5), 0.875);
    close(Interp::QuartIn.ease(0.5), 0.0625);
    close(Interp::QuartInOut.ease(0.75), 1.0 - 0.0625 / 2.0);
    // (2^-5 − 2^-10) / (1 − 2^-10) = 31/1023.
    close(Interp::ExpoIn.ease(0.5), 31.0 / 1023.0);
    // Back: 2.70158·s³ − 1.70158·s² at 0.5 = 0.3376975 − 0.425395.
    close(Interp::BackIn.ease(0.5), 2.70158 * 0.125 - 1.70158 * 0.25);
    // Bounce lands (reaches 1) at s = 1/2.75, 2/2.75 … : 7.5625/2.75² = 1.
    close(Interp::BounceOut.ease(1.0 / 2.75), 1.0);
    // Elastic: −2^(−5)·sin((5 − 10.75)·2π/3) at s = 0.5.
    let expected = -(2f64.powi(-5)) * ((5.0 - 10.75) * 2.0 * PI / 3.0).sin();
    close(Interp::ElasticIn.ease(0.5), expected);
    // cubic-bezier(0, 0, 1, 1) is linear; (0.42, 0, 0.58, 1) (CSS ease-in-out) is symmetric.
    close(Interp::CubicBezier(0.0, 0.0, 1.0, 1.0).ease(0.3), 0.3);
    close(Interp::CubicBezier(0.42, 0.0, 0.58, 1.0).ease(0.5), 0.5);
}

#[test]
fn every_easing_starts_at_0_and_ends_at_1() {
    let all = [
        Interp::Step,
        Interp::Linear,
        Interp::EaseIn,
        Interp::EaseOut,
        Interp::EaseInOut,
        Interp::SineIn,
        Interp::SineOut,
        Interp::SineInOut,
        Interp::CubicIn,
        Interp::CubicOut,
        Interp::CubicInOut,
        Interp::QuartIn,
        Interp::QuartOut,
        Interp::QuartInOut,
        Interp::ExpoIn,
        Interp::ExpoOut,
        Interp::ExpoInOut,
        Interp::BackIn,
        Interp::BackOut,
        Interp::BackInOut,
        Interp::BounceIn,
        Interp::BounceOut,
        Interp::BounceInOut,
        Interp::ElasticIn,
        Interp::ElasticOut,
        Interp::ElasticInOut,
        Interp::CubicBezier(0.25, 0.1, 0.25, 1.0),
    ];
    for e in all {
        assert!(e.ease(0.0).abs() < 1e-12, "{e:?} at 0: {}", e.ease(0.0));
        assert!(
            (e.ease(1.0) - 1.0).abs() < 1e-12,
            "{e:?} at 1: {}",
            e.ease(1.0)
        );
        // The halves of an in-out curve meet: no jump at s = 0.5.
        let (a, b) = (e.ease(0.5 - 1e-9), e.ease(0.5 + 1e-9));
        if e != Interp::Step {
            assert!((a - b).abs() < 1e-6, "{e:?} jumps at 0.5: {a} {b}");
        }
    }
    // Back overshoots, as it should: BackOut passes 1 on its way.
    assert!((0..100).any(|i| Interp::BackOut.ease(i as f64 / 100.0) > 1.05));
}

#[test]
fn cubic_bezier_checks_its_control_points() {
    assert!(Interp::CubicBezier(0.1, -2.0, 0.9, 3.0).problem().is_none());
    assert!(Interp::CubicBezier(1.2, 0.0, 0.5, 1.0).problem().is_some());
    assert!(Interp::CubicBezier(0.2, f64::NAN, 0.5, 1.0)
        .problem()
        .is_some());
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

#[test]
fn monotone_flattens_at_peaks_and_blends_slopes_elsewhere() {
    // Keys (0, 0), (1, 1), (2, 3), (3, 1). Slopes 1, 2, −2. Key 1: h0 = h1 = 1, so the
    // Fritsch–Butland tangent is 3·2 / (3/1 + 3/2) = 4/3; key 2 is a peak: 0. Segment 1→2 at
    // s = 0.5: 0.5·1 + 0.125·(4/3) + 0.5·3 − 0.125·0 = 2 + 1/6.
    let keys = [
        k(0.0, 0.0, Interp::Monotone),
        k(1.0, 1.0, Interp::Monotone),
        k(2.0, 3.0, Interp::Monotone),
        k(3.0, 1.0, Interp::Monotone),
    ];
    close(sample(&keys, 1.5, false), 2.0 + 1.0 / 6.0);
}

#[test]
fn monotone_stays_flat_where_catmull_rom_dips() {
    // Keys (0, 0), (1, 0), (2, 1), (3, 1). Catmull-Rom's tangent at key 1 is (1 − 0)/2 = 0.5,
    // so the flat first segment dips: at s = 0.75, h11 = 0.421875 − 0.5625 = −0.140625 and
    // the value is 0.5·(−0.140625) = −0.0703125. The monotone tangent there is 0 (beside a
    // flat segment): the segment stays at 0.
    let keys = |interp| {
        [
            k(0.0, 0.0, interp),
            k(1.0, 0.0, interp),
            k(2.0, 1.0, interp),
            k(3.0, 1.0, interp),
        ]
    };
    close(sample(&keys(Interp::Smooth), 0.75, false), -0.0703125);
    close(sample(&keys(Interp::Monotone), 0.75, false), 0.0);
}

#[test]
fn the_overshooting_scale_stays_in_range_when_monotone() {
    // 3 → 0.1 → 0.1 over 0, 1, 2 s: Catmull-Rom dips below zero between 1 and 2 s.
    let keys = |interp| {
        [
            k(0.0, 3.0, interp),
            k(1.0, 0.1, interp),
            k(2.0, 0.1, interp),
        ]
    };
    let smooth_min = (0..=200)
        .map(|i| sample(&keys(Interp::Smooth), i as f64 / 100.0, false).unwrap())
        .fold(f64::INFINITY, f64::min);
    assert!(smooth_min < 0.0, "{smooth_min}");
    for i in 0..=200 {
        let v = sample(&keys(Interp::Monotone), i as f64 / 100.0, false).unwrap();
        assert!((0.1 - 1e-12..=3.0 + 1e-12).contains(&v), "{v} at {i}");
    }
}

#[test]
fn offset_and_cycles() {
    let keys = [k(0.0, 0.0, Interp::Linear), k(1.0, 10.0, Interp::Linear)];
    let at = |t, timing: Timing| sample_timed(&keys, t, &timing).unwrap();
    let late = Timing {
        offset: 0.5,
        ..Timing::default()
    };
    close(at(0.75, late), 2.5);
    close(at(0.25, late), 0.0);
    let ping = Timing {
        cycle: Cycle::PingPong,
        ..Timing::default()
    };
    close(at(1.25, ping), 7.5);
    close(at(2.25, ping), 2.5);
    let onward = Timing {
        cycle: Cycle::RepeatOffset,
        ..Timing::default()
    };
    close(at(2.5, onward), 25.0);
    let twice = Timing {
        cycle: Cycle::Repeat,
        count: Some(2),
        ..Timing::default()
    };
    close(at(1.5, twice), 5.0);
    close(at(7.0, twice), 10.0);
    close(at(-3.0, twice), 0.0);
    let ping_twice = Timing {
        cycle: Cycle::PingPong,
        count: Some(2),
        ..Timing::default()
    };
    // Forwards, back, then held at the start where the second pass ended.
    close(at(9.0, ping_twice), 0.0);
}

fn keys_strategy() -> impl Strategy<Value = Vec<Key<f64>>> {
    prop::collection::vec((0.01f64..3.0, -100.0f64..100.0), 2..9).prop_map(|steps| {
        let mut at = 0.0;
        steps
            .into_iter()
            .map(|(dt, value)| {
                at += dt;
                k(at, value, Interp::Monotone)
            })
            .collect()
    })
}

proptest! {
    /// The clamped spline never leaves the range of the keys, nor of the two keys of each
    /// segment, whatever the keys.
    #[test]
    fn monotone_never_leaves_its_segment(keys in keys_strategy(), u in 0.0f64..1.0, looping: bool) {
        let (first, last) = (keys[0].at, keys[keys.len() - 1].at);
        let t = first + u * (last - first);
        let v = sample(&keys, t, looping).unwrap();
        let (k, _) = segment(&keys, t).unwrap_or((0, 0.0));
        let (a, b) = (keys[k].value, keys[k + 1].value);
        let (lo, hi) = (a.min(b), a.max(b));
        let slack = 1e-9 * (1.0 + lo.abs().max(hi.abs()));
        prop_assert!(v >= lo - slack && v <= hi + slack, "{v} outside {lo}..{hi}");
    }
}

#[test]
fn cycles_are_counted_past_any_integer_for_a_tiny_period() {
    // 1 s of keys repeating every 1e-300 s: 1e300 whole periods before t = 1, which an i64
    // count would have stopped at 2^63.
    let timing = Timing {
        offset: 0.0,
        cycle: Cycle::RepeatOffset,
        count: None,
    };
    let (_, cycles) = cycled_time(0.0, 1e-300, 1.0, &timing);
    assert!((cycles / 1e300 - 1.0).abs() < 1e-9, "{cycles}");
    // A count caps them where the last cycle ended.
    let counted = Timing {
        count: Some(u32::MAX),
        ..timing
    };
    assert_eq!(
        cycled_time(0.0, 1e-300, 1.0, &counted).1,
        f64::from(u32::MAX) - 1.0
    );
}
