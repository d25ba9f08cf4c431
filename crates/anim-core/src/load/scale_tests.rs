//! Scenes of many shapes: the memory budget, and what the jobs of a file share.

use super::*;
use crate::diag::Diagnostic;
use crate::sdf::LoadOptions;
use glam::DVec3;

const MATERIAL: &str = "define material m 1 1 1 1 1 1 1 1 1 10\n";

fn load(text: &str) -> Loaded {
    load_str(text, Path::new("scene.sdf"), &LoadOptions::default())
        .unwrap_or_else(|d| panic!("{d:?}"))
}

#[test]
fn a_flat_scene_is_refused_only_beyond_the_memory_budget() {
    let mut text = format!("{MATERIAL}define camera c 60\nrender c o.png 1 1\n");
    for i in 0..1000 {
        text.push_str(&format!("define shape sphere s{i} {i} 0 -5 0.5 m\n"));
    }
    let fits = LoadOptions {
        max_memory: crate::limits::scene_memory(1000),
        ..LoadOptions::default()
    };
    let loaded = load_str(&text, Path::new("scene.sdf"), &fits).unwrap();
    assert_eq!(loaded.jobs[0].scene.instances.len(), 1000);
    let tight = LoadOptions {
        max_memory: crate::limits::scene_memory(999),
        ..LoadOptions::default()
    };
    let ds = load_str(&text, Path::new("scene.sdf"), &tight).unwrap_err();
    let want = format!(
        "the scene's 1000 shapes need about {} of memory, more than the {} allowed",
        crate::util::human_bytes(crate::limits::scene_memory(1000)),
        crate::util::human_bytes(crate::limits::scene_memory(999))
    );
    assert_eq!(ds.len(), 1, "{ds:?}");
    assert_eq!(ds[0].message, want);
    // Located at the first shape, the largest part of a flat scene.
    assert_eq!(ds[0].loc.as_ref().map(|l| l.line), Some(4));
}

#[test]
fn the_jobs_of_a_file_share_their_instances_and_unmoved_ones_share_one_transform() {
    let text = format!(
        "{MATERIAL}define shape sphere a 0 0 0 1 m
define shape sphere b 0 0 0 1 m
         define shape sphere s 0 0 0 1 m
define shape composite g s b
         define camera c 60
render c f0.png 1 1
transform s translate 1 0 0
         render c f1.png 1 1
transform g translate 0 2 0
render c f2.png 1 1
"
    );
    let loaded = load(&text);
    let [j0, j1, j2] = &loaded.jobs[..] else {
        panic!("{:?}", loaded.jobs.len())
    };
    assert!(std::sync::Arc::ptr_eq(
        &j0.scene.instances,
        &j1.scene.instances
    ));
    assert!(std::sync::Arc::ptr_eq(
        &j0.scene.instances,
        &j2.scene.instances
    ));
    // a: slot 0; g: its own slot; s in g: another; b in g: g's.
    assert_eq!(j0.scene.transforms.len(), 3);
    let slot = |name: &str| {
        let i = j2
            .scene
            .instances
            .iter()
            .find(|i| j2.scene.instance_name(i) == name)
            .unwrap_or_else(|| panic!("{name}"));
        (i.transform, j2.scene.transform_of(i).point(DVec3::ZERO))
    };
    assert_eq!(slot("a"), (0, DVec3::ZERO));
    assert_eq!(slot("g/b").1, DVec3::new(0.0, 2.0, 0.0));
    assert_eq!(slot("g/s").1, DVec3::new(1.0, 2.0, 0.0));
    assert_ne!(slot("g/b").0, slot("g/s").0);
    let loc = j2.scene.instance_loc(&j2.scene.instances[0]).unwrap();
    assert_eq!((loc.line, loc.col), (2, 1));
}

/// Loads `text` both ways: with the shapes of a flat file kept compactly by the reader (when
/// `flat`, checked) and with every shape as a statement; the results must be the same.
fn same_both_ways(text: &str, opts: &LoadOptions, flat: bool) -> Result<Loaded, Vec<Diagnostic>> {
    let path = Path::new("scene.sdf");
    let parsed = crate::sdf::parse_source(text, path, opts);
    assert_eq!(!parsed.shapes.is_empty(), flat, "{text}");
    let compact = load_str(text, path, opts);
    let whole = super::load_str_whole(text, path, opts);
    match (&compact, &whole) {
        (Ok(a), Ok(b)) => {
            assert_eq!(a.jobs, b.jobs, "{text}");
            assert_eq!(a.diagnostics, b.diagnostics, "{text}");
        }
        (Err(a), Err(b)) => assert_eq!(a, b, "{text}"),
        _ => panic!("{text}\n{compact:?}\n{whole:?}"),
    }
    compact
}

#[test]
fn flat_shapes_kept_compactly_load_as_their_statements_do() {
    let opts = LoadOptions::default();
    let cases = [
        // Plain, with a material defined after the shapes that use it and one never defined.
        format!(
            "define shape sphere a 0 0 -5 1 m\n{MATERIAL}define shape box b 0 0 0 1 1 1 m\n\
             define shape sphere c 1 1 1 1 nowhere\ndefine shape sphere d 1 1 1 1 nowhere\n\
             define camera c 60\nrender c o.png 4 3\n"
        ),
        // A name defined three times, a degenerate shape, every primitive kind.
        format!(
            "{MATERIAL}define shape sphere s 0 0 0 1 m\ndefine shape sphere s 1 0 0 1 m\n\
             define shape cylinder cy 0 0 0 0 1 0 0.5 m\ndefine shape cone co 0 0 0 0 1 0 0.5 m\n\
             define shape triangle t 0 0 0 1 0 0 0 1 0 m\ndefine shape plane p 0 -1 0 0 1 0 m\n\
             define shape sphere z 0 0 0 0 m\n  define shape sphere s 2 0 0 1 m\n\
             define camera c 60\nrender c o.png 4 3\nrender c p.png 4 3\n"
        ),
        // No render line, a rejected material, the `define sphere` variant, odd spacing.
        "define material bad 1 1 1 1 1 1 1 1 1\ndefine sphere a 0 0 -5 1 bad\n\
         define   shape   sphere   jklö 0 0 -5 1 bad  # comment\n"
            .to_string(),
        // A material defined twice, a second file-wide ambient, a light.
        format!(
            "{MATERIAL}{MATERIAL}ambient 0.1 0.1 0.1\ndefine light l 0 5 0 1 1 1 1\n\
             define shape sphere a 0 0 -5 1 m\ndefine camera c 60\nrender c o.png 4 3\n"
        ),
    ];
    // Some of these files are refused (an error), some load: either way, as statements.
    for text in &cases {
        let _ = same_both_ways(text, &opts, true);
    }
    // A transform or a composite anywhere puts the shapes back among the statements.
    for tail in [
        "transform a translate 1 0 0\n",
        "define shape composite g a\n",
    ] {
        let text = format!("{}{tail}", cases[0]);
        let _ = same_both_ways(&text, &opts, false);
    }
    // Over the memory budget: refused at the first shape, as for statements.
    let tight = LoadOptions {
        max_memory: crate::limits::scene_memory(1),
        ..LoadOptions::default()
    };
    let ds = same_both_ways(&cases[0], &tight, true).unwrap_err();
    assert!(
        ds.iter().any(|d| d.message.contains("shapes need about")),
        "{ds:?}"
    );
}

#[test]
fn lines_the_direct_reader_leaves_to_the_general_one_load_as_their_statements_do() {
    // The reader takes a canonical primitive line straight into the compact shapes; every
    // other spelling (a warning to give, a variant to read, a number to repair, a shape to
    // drop) goes the general way. Each line here, among canonical ones, must load as the
    // same line read as a statement.
    let odd = [
        "define shape sphere neg 0 0 -5 -1 m",
        "define shape sphere zero 0 0 -5 0 m",
        "define shape box rect 0 0 0 1 1 0 m",
        "define shape box line 0 0 0 1 0 0 m",
        "define shape box point 1 1 1 1 1 1 m",
        "define shape sphere suffix 0 0 -5 1.0f m",
        "define shape sphere comma 0 0 -5 1,5 m",
        "define shape sphere numeric 0 0 -5 1 2",
        "define shape sphere many 0 0 -5 1 2 m",
        "define shape sphere few 0 0 -5 m",
        "define shape sphere bad 0 0 -5 1O m",
        "define shape sphere huge 0 0 -5 1e13 m",
        "define shape cone up 0 0 -5 2 1 m",
        "define shape cylinder negc 0 0 -5 0 1 -5 -1 m",
        "define shape triangle flat 0 0 0 1 1 1 2 2 2 m",
        "define shape plane nonormal 0 0 0 0 0 0 m",
        "define shape sphere 0 0 -5 1 m after",
        "define shape sphere first m 0 0 -5 1",
        "define sphere noshape 0 0 -5 1 m",
        "define shape sphere 12 0 0 -5 1 m",
        "define shape sphere exp 0 0 -5e0 1E-1 m",
        "define shape sphere signs +.5 -.5 -5. +1 m",
        "define shape sphere digits 0.1234567890123456 0 -5 1 m",
        "define\tshape\tsphere\ttab 0 0 -5 1 m\r",
        "define shape sphere jklö 0 0 -5 1 m",
        "define shape sphere a 0 0 -5 1 m # comment 1 2",
        "define shape sphere late 0 0 -5 1 later",
        "define shape sphere s1 0 0 -6 1 m",
    ];
    let opts = LoadOptions::default();
    let mut all = format!("{MATERIAL}define shape sphere s1 0 0 -5 1 m\n");
    for line in odd {
        let text = format!(
            "{MATERIAL}define shape sphere s1 0 0 -5 1 m\n{line}\n\
             define shape sphere s2 1 0 -5 1 m\ndefine camera c 60\nrender c o.png 4 3\n"
        );
        let _ = same_both_ways(&text, &opts, true);
        all.push_str(line);
        all.push('\n');
    }
    all.push_str(
        "define material later 1 1 1 1 1 1 1 1 1 10\ndefine camera c 60\nrender c o.png 4 3\n",
    );
    let _ = same_both_ways(&all, &opts, true);
    let strict = LoadOptions {
        strict: true,
        ..LoadOptions::default()
    };
    let _ = same_both_ways(&all, &strict, true);
}

#[test]
fn a_flat_sphere_costs_at_most_200_bytes_once_read() {
    let n = 20_000;
    let mut text = format!("{MATERIAL}define camera c 60\nrender c o.png 1 1\n");
    for i in 0..n {
        text.push_str(&format!(
            "define shape sphere s{i} {}.25 {}.5 -{}.125 0.5 m\n",
            i % 97,
            i % 89,
            i % 83 + 5
        ));
    }
    let parsed = crate::sdf::parse_source(&text, Path::new("scene.sdf"), &LoadOptions::default());
    assert_eq!(parsed.shapes.len(), n);
    // Everything the reader hands on: the compact shapes, the other statements (with what
    // their strings hold), the diagnostics and what was left out.
    let statements = parsed.statements.capacity()
        * std::mem::size_of::<crate::sdf::ast::Statement>()
        + parsed.statements.len() * 64;
    let diagnostics = parsed.diagnostics.capacity() * std::mem::size_of::<Diagnostic>();
    let omissions =
        parsed.omissions.skipped.capacity() * 32 + parsed.omissions.commented.capacity() * 40;
    let bytes = parsed.shapes.bytes() + statements + diagnostics + omissions;
    let per_sphere = bytes as f64 / n as f64;
    assert!(per_sphere <= 200.0, "{per_sphere:.1} bytes per sphere");
    // Not vacuous: the geometry alone is 80 bytes.
    assert!(per_sphere >= 80.0, "{per_sphere:.1} bytes per sphere");
}
