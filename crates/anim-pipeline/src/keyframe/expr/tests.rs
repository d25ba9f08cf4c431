//! The expression language against values worked by hand.

use super::noise::noise;
use super::*;
use glam::DVec3;

fn scope(named: &[(String, Ty)], value: Ty) -> Scope<'_> {
    Scope {
        named,
        has_value: true,
        value_ty: value,
    }
}

fn num(text: &str, t: f64, value: f64) -> f64 {
    let e = Expr::parse(text, &scope(&[], Ty::Num), Arc::default()).expect(text);
    assert_eq!(e.ty, Ty::Num, "{text}");
    e.eval(t, 24.0, Val::Num(value), 7).num()
}

fn error(text: &str) -> ExprError {
    Expr::parse(text, &scope(&[], Ty::Num), Arc::default()).expect_err(text)
}

#[test]
fn arithmetic_follows_the_usual_precedence() {
    assert_eq!(num("1 + 2 * 3", 0.0, 0.0), 7.0);
    assert_eq!(num("(1 + 2) * 3", 0.0, 0.0), 9.0);
    assert_eq!(num("2 ^ 3 ^ 2", 0.0, 0.0), 512.0);
    assert_eq!(num("-2 ^ 2", 0.0, 0.0), -4.0);
    assert_eq!(num("7 % 3 + -1 % 3", 0.0, 0.0), 3.0);
    assert_eq!(num("1e-3 * 2", 0.0, 0.0), 0.002);
    assert_eq!(num("10 / 4 - .5", 0.0, 0.0), 2.0);
}

#[test]
fn variables_functions_and_constants() {
    assert_eq!(num("t * fps", 0.5, 0.0), 12.0);
    assert_eq!(num("frame", 0.5, 0.0), 12.0);
    assert_eq!(num("value * 2", 0.0, 1.5), 3.0);
    let tau_t = num("1 + 0.5 * sin(tau * t)", 0.125, 0.0);
    assert_eq!(tau_t, 1.0 + 0.5 * (std::f64::consts::TAU * 0.125).sin());
    assert_eq!(num("clamp(5, 0, 1) + mix(2, 4, 0.25)", 0.0, 0.0), 3.5);
    assert_eq!(num("smoothstep(0, 2, 1)", 0.0, 0.0), 0.5);
    assert_eq!(num("floor(2.7) + fract(2.75) + abs(-1)", 0.0, 0.0), 3.75);
    assert_eq!(
        num(
            "sqrt(16) + exp(0) + pow(2, 10) + min(1, 2) + max(1, 2)",
            0.0,
            0.0
        ),
        1032.0
    );
    assert_eq!(num("step(1, 0.5) + step(1, 1)", 0.0, 0.0), 1.0);
    assert_eq!(num("pi - atan2(0, -1)", 0.0, 0.0), 0.0);
}

#[test]
fn vectors_apply_numbers_to_each_part() {
    let e = Expr::parse(
        "(1, 2, 3) * 2 + value",
        &scope(&[], Ty::Vec),
        Arc::default(),
    )
    .unwrap();
    assert_eq!(e.ty, Ty::Vec);
    let v = e
        .eval(0.0, 24.0, Val::Vec(DVec3::new(0.5, 0.0, -1.0)), 0)
        .vec();
    assert_eq!(v, DVec3::new(2.5, 4.0, 5.0));
    assert_eq!(
        num(
            "length((3, 4, 0)) + (1, 2, 3).z + dot((1, 0, 0), (2, 5, 5))",
            0.0,
            0.0
        ),
        10.0
    );
}

#[test]
fn named_values_are_read_in_order() {
    let named_scope = Scope {
        named: &[],
        has_value: false,
        value_ty: Ty::Num,
    };
    let a = Expr::parse("2 * t", &named_scope, Arc::default()).unwrap();
    let list = [("a".to_string(), Ty::Num)];
    let b_scope = Scope {
        named: &list,
        has_value: false,
        value_ty: Ty::Num,
    };
    let b = Expr::parse("a + 1", &b_scope, Arc::new(vec![a.clone()])).unwrap();
    let named = Arc::new(vec![a, b]);
    let both = [("a".to_string(), Ty::Num), ("b".to_string(), Ty::Num)];
    let e = Expr::parse("b * value", &scope(&both, Ty::Num), named).unwrap();
    assert_eq!(e.eval(3.0, 24.0, Val::Num(2.0), 0).num(), 14.0);
    // A named value has no keyed value.
    assert!(Expr::parse("value", &named_scope, Arc::default())
        .unwrap_err()
        .message
        .contains("named value has none"));
}

#[test]
fn problems_are_found_at_their_place_in_the_text() {
    let e = error("1 + smoothstpe(0, 1, t)");
    assert_eq!((e.at, e.width), (4, 10));
    assert!(e.message.contains("unknown function `smoothstpe`"), "{e:?}");
    assert_eq!(e.help.as_deref(), Some("did you mean `smoothstep`?"));
    let e = error("1 + tt");
    assert_eq!((e.at, e.message.as_str()), (4, "unknown name `tt`"));
    assert_eq!(e.help.as_deref(), Some("did you mean `t`?"));
    let e = error("(1 + 2");
    assert_eq!(e.at, 6);
    assert!(e.message.contains("expected `)`"), "{e:?}");
    let e = error("1 + * 2");
    assert_eq!(
        (e.at, e.message.as_str()),
        (4, "expected a value, found `*`")
    );
    let e = error("clamp(1, 2)");
    assert!(e.message.contains("takes 3 arguments, not 2"), "{e:?}");
    let e = error("2 $ 3");
    assert_eq!(e.at, 2);
    let e = error("noise((1, 2, 3))");
    assert!(e.message.contains("numbers, not vectors"), "{e:?}");
    let e = error("(3).x");
    assert!(e.message.contains("only vectors"), "{e:?}");
    assert_eq!(error("").message, "the expression is empty");
    let e = error("1 2");
    assert_eq!(e.at, 2);
}

#[test]
fn nesting_and_length_are_bounded_without_exhausting_the_stack() {
    let deep = format!("{}1{}", "(".repeat(100_000), ")".repeat(100_000));
    let e = error(&deep);
    assert!(e.message.contains("characters long"), "{e:?}");
    let nested = format!("{}1{}", "(".repeat(1000), ")".repeat(1000));
    let e = error(&nested);
    assert!(e.message.contains("nests more than"), "{e:?}");
    let signs = format!("{}1", "-".repeat(1000));
    assert!(error(&signs).message.contains("nests more than"));
    let calls = format!("{}t{}", "sin(".repeat(300), ")".repeat(300));
    assert!(error(&calls).message.contains("nests more than"));
    let fine = format!("{}1{}", "(".repeat(20), ")".repeat(20));
    assert_eq!(num(&fine, 0.0, 0.0), 1.0);
}

#[test]
fn noise_is_zero_at_whole_numbers_bounded_smooth_and_seeded() {
    for i in -5..5 {
        assert_eq!(noise(i as f64, 3), 0.0);
    }
    let samples: Vec<f64> = (0..4000)
        .map(|k| noise(k as f64 * 0.01 - 20.0, 3))
        .collect();
    assert!(samples.iter().all(|v| (-1.0..=1.0).contains(v)));
    assert!(
        samples.iter().any(|v| v.abs() > 0.2),
        "noise that never moves"
    );
    // Smooth: the slope changes little between close samples, across whole numbers too.
    let h = 1e-4;
    for k in 0..400 {
        let x = k as f64 * 0.05 - 10.0;
        let slope = |x: f64| (noise(x + h, 3) - noise(x - h, 3)) / (2.0 * h);
        assert!((slope(x + h) - slope(x - h)).abs() < 0.1, "a kink at {x}");
    }
    // Deterministic, and another seed is another noise.
    assert_eq!(noise(1.37, 3), noise(1.37, 3));
    assert_ne!(noise(1.37, 3), noise(1.37, 4));
    // The formula at one point, by hand: g(0) = slope at 0, g(1) at 1.
    let (g0, g1) = (
        (noise(1e-7, 3) - noise(0.0, 3)) / 1e-7 / 2.0,
        (noise(1.0, 3) - noise(1.0 - 1e-7, 3)) / 1e-7 / 2.0,
    );
    let f: f64 = 0.3;
    let u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    let by_hand = 2.0 * (g0 * f + u * (g1 * (f - 1.0) - g0 * f));
    assert!(
        (noise(f, 3) - by_hand).abs() < 1e-5,
        "{} vs {by_hand}",
        noise(f, 3)
    );
}

#[test]
fn wiggle_moves_the_keyed_value_by_at_most_its_amplitude() {
    for k in 0..200 {
        let t = k as f64 * 0.037;
        let w = num("wiggle(3, 0.5)", t, 10.0);
        assert!((w - 10.0).abs() <= 0.5, "{w} at {t}");
        assert_eq!(w, num("wiggle(3, 0.5)", t, 10.0));
    }
    assert_ne!(num("wiggle(3, 0.5)", 0.3, 10.0), 10.0);
}
