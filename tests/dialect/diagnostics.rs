//! Malformed and suspicious SDF input: every row names the severity, line and column of the
//! diagnostic it must produce (or that it must produce none). The rows run through the
//! library; a handful of error rows also run through the real `anim render` binary.

use anim_core::diag::{Diagnostic, Severity};
use anim_core::load::load_str;
use anim_core::sdf::LoadOptions;
use assert_cmd::Command;
use std::path::Path;

/// A material, a camera and a render line around the rows that test something else, so
/// they are complete scenes: `head!()` (one line) before the tested line, `tail!()` after.
macro_rules! head {
    () => {
        "define material red 1 0 0 1 0 0 1 0 0 10\n"
    };
}
macro_rules! tail {
    () => {
        "define camera cam 60\nrender cam out.png 8 8\n"
    };
}
/// Both: three lines.
macro_rules! base {
    () => {
        concat!(head!(), tail!())
    };
}

#[derive(Clone, Copy, Debug)]
enum Expect {
    /// Loads without any diagnostic.
    Clean,
    /// A diagnostic of this severity at `line:col` (`None` for file-wide ones) whose message
    /// or help contains the text.
    Diag(Severity, Option<(u32, u32)>, &'static str),
}

use Expect::*;
use Severity::{Error as E, Warning as W};

struct Row {
    name: &'static str,
    text: &'static str,
    expect: Expect,
    strict: bool,
}

const fn row(name: &'static str, text: &'static str, expect: Expect) -> Row {
    Row {
        name,
        text,
        expect,
        strict: false,
    }
}

const fn strict(name: &'static str, text: &'static str, expect: Expect) -> Row {
    Row {
        name,
        text,
        expect,
        strict: true,
    }
}

const fn at(line: u32, col: u32) -> Option<(u32, u32)> {
    Some((line, col))
}

const ROWS: &[Row] = &[
    // ----- lexical ---------------------------------------------------------------------
    row("letter O for zero", concat!(head!(), "define shape sphere s 0 0 1O 1 red\n", tail!()),
        Diag(E, at(2, 27), "expected a number, found '1O'")),
    row("letter O gets a hint", concat!(head!(), "define shape sphere s 0 0 1O 1 red\n", tail!()),
        Diag(E, at(2, 27), "did you mean `10`?")),
    row("nan", concat!(head!(), "define shape sphere s 0 nan 0 1 red\n", tail!()),
        Diag(E, at(2, 25), "found 'nan'")),
    row("inf", concat!(head!(), "define light l 0 0 0 1 1 1 inf\n", tail!()),
        Diag(E, at(2, 28), "must be finite")),
    row("negative infinity", concat!(base!(), "transform cam translate -inf 0 0\n"),
        Diag(E, at(4, 25), "found '-inf'")),
    row("overflowing exponent", concat!(head!(), "define shape sphere s 0 0 0 1e999 red\n", tail!()),
        Diag(E, at(2, 29), "out of range")),
    row("hexadecimal", concat!(head!(), "define shape box b 0x10 0 0 1 1 1 red\n", tail!()),
        Diag(E, at(2, 20), "found '0x10'")),
    row("C float suffix", concat!(head!(), "define camera c2 1.5f\n", tail!()),
        Diag(W, at(2, 18), "read as `1.5`")),
    row("decimal comma", concat!(head!(), "define shape sphere s 0 0 0 1,5 red\n", tail!()),
        Diag(E, at(2, 29), "use a decimal point: `1.5`")),
    row("every documented number form", concat!(head!(),
        "define shape sphere s .5 -.5 +100 1e-3 red\ndefine shape sphere t -1.5 1 2E+2 3. red\n", tail!()),
        Clean),
    row("CRLF line endings", "define material red 1 0 0 1 0 0 1 0 0 10\r\ndefine camera cam 60\r\nrender cam out.png 8 8\r\n",
        Clean),
    row("CRLF keeps columns right", "define material red 1 0 0 1 0 0 1 0 0 10\r\ndefine shape sphere s 0 0 0 1 rde\r\ndefine camera cam 60\r\nrender cam out.png 8 8\r\n",
        Diag(W, at(2, 31), "unknown material `rde`")),
    row("no final newline", "define material red 1 0 0 1 0 0 1 0 0 10\ndefine camera cam 60\nrender cam out.png 8 8",
        Clean),
    row("error on a last line without newline", concat!(base!(), "transform cam scale 0"),
        Diag(E, at(4, 21), "scale by 0")),
    row("tabs separate tokens and count as one column", concat!(head!(), "define\tshape\tsphere\ts\t0 0 0 1\trde\n", tail!()),
        Diag(W, at(2, 31), "did you mean `red`?")),
    row("double-slash comment line", concat!(head!(), "// define shape sphere s 0 0 0 1 nothing\n", tail!()),
        Clean),
    row("trailing hash comment", concat!(head!(), "define shape sphere s 0 0 0 1 red # a ball\n", tail!()),
        Clean),
    row("hash comment glued to a token", concat!(head!(), "define shape sphere s 0 0 0 1 red#ball\n", tail!()),
        Clean),
    row("columns count characters, not bytes", concat!(head!(), "define shape sphere jklö 0 0 0 1 rde\n", tail!()),
        Diag(W, at(2, 34), "unknown material `rde`")),
    // ----- unknown statements ----------------------------------------------------------
    row("typo in define", concat!(head!(), "efine shape sphere s 0 0 0 1 red\n", tail!()),
        Diag(W, at(2, 1), "did you mean `define`?")),
    row("garbage line", concat!(base!(), "LOLOLOL\n"),
        Diag(W, at(4, 1), "unknown statement 'LOLOLOL'")),
    row("merge-conflict marker", concat!("<<<<<<< HEAD\n", base!()),
        Diag(W, at(1, 1), "merge-conflict marker")),
    row("unknown definition kind", concat!(head!(), "define lamp .3 .4 .5\n", tail!()),
        Diag(W, at(2, 8), "unknown definition kind 'lamp'")),
    row("amblight is the ambient light", concat!(head!(), "define amblight .3 .4 .5\n", tail!()),
        Diag(W, at(2, 8), "`define amblight` read as `ambient`")),
    row("unknown shape kind with suggestion", concat!(head!(), "define shape sphre s 0 0 0 1 red\n", tail!()),
        Diag(W, at(2, 14), "did you mean `sphere`?")),
    row("mesh shapes are skipped, and so are their transforms", concat!(head!(), "define shape obj teapot\ntransform teapot scale 2\n", tail!()),
        Diag(W, at(2, 14), "not supported")),
    // ----- materials -------------------------------------------------------------------
    row("material with too few numbers", concat!(head!(), "define material m 1 1 1 1 1 1 1 1\n", tail!()),
        Diag(E, at(2, 34), "needs 10 numbers")),
    row("material without its exponent", concat!(head!(), "define material m 1 1 1 1 1 1 1 1 1\n", tail!()),
        Diag(W, at(2, 36), "has no exponent m: read as 0")),
    row("material with too many numbers", concat!(head!(), "define material m 1 1 1 1 1 1 1 1 1 10 0 1 1 0.5\n", tail!()),
        Diag(E, at(2, 46), "too many numbers for a material: 14")),
    row("reflectivity above 1 is clamped", concat!(head!(), "define material m 1 1 1 1 1 1 1 1 1 10 1.5\n", tail!()),
        Diag(W, at(2, 40), "clamped to 1")),
    row("negative opacity is clamped", concat!(head!(), "define material m 1 1 1 1 1 1 1 1 1 10 0 -1\n", tail!()),
        Diag(W, at(2, 42), "opacity -1 is outside [0, 1]")),
    row("invisible material hints at the field list", concat!(head!(), "define material m 1 1 1 1 1 1 1 1 1 10 0 0\n", tail!()),
        Diag(W, at(2, 42), "--material-fields reflectivity,transparency,ior")),
    row("transparent glass is fine", concat!(head!(), "define material glass 0 0 0 0 0 0 1 1 1 100 0 0 1.5\n", tail!()),
        Clean),
    row("negative Phong exponent", concat!(head!(), "define material m 1 1 1 1 1 1 1 1 1 -5\n", tail!()),
        Diag(W, at(2, 37), "must not be negative")),
    row("zero Phong exponent", concat!(head!(), "define material m 1 1 1 1 1 1 1 1 1 0\n", tail!()),
        Diag(W, at(2, 37), "m is 0")),
    row("material used before its definition", concat!("define shape sphere s 0 0 0 1 red\n", base!()),
        Diag(W, at(1, 31), "used before its definition (line 2)")),
    row("materials and shapes share names freely", concat!(head!(), "define shape sphere red 0 0 0 1 red\n", tail!()),
        Clean),
    // ----- shapes ----------------------------------------------------------------------
    row("unknown material with suggestion", concat!(head!(), "define shape sphere s 0 0 0 1 rde\n", tail!()),
        Diag(W, at(2, 31), "did you mean `red`?")),
    row("sphere with too few numbers", concat!(head!(), "define shape sphere s 0 0 1 red\n", tail!()),
        Diag(E, at(2, 29), "a sphere takes 4 numbers")),
    row("shape without material", concat!(head!(), "define shape sphere s 0 0 0 1\n", tail!()),
        Diag(E, at(2, 30), "expected a material name")),
    row("negative sphere radius", concat!(head!(), "define shape sphere s 0 0 0 -2 red\n", tail!()),
        Diag(W, at(2, 29), "absolute value")),
    row("zero sphere radius", concat!(head!(), "define shape sphere s 0 0 0 0 red\n", tail!()),
        Diag(W, at(2, 29), "shape dropped")),
    row("box corners in any order", concat!(head!(), "define shape box b 1 1 1 -1 -1 -1 red\n", tail!()),
        Clean),
    row("cylinder with coincident ends", concat!(head!(), "define shape cylinder c 0 0 0 0 0 0 1 red\n", tail!()),
        Diag(W, at(2, 25), "coincident end points")),
    row("cone in another layout", concat!(head!(), "define shape cone c 0 0 0 0 1 0 5 10 red\n", tail!()),
        Diag(E, at(2, 35), "define shape cone <name> [base] [tip] <radius> <material>")),
    row("upright cone", concat!(head!(), "define shape cone c 0 0 0 5 10 red\n", tail!()),
        Diag(W, at(2, 21), "[base] <height> <radius>")),
    row("collinear triangle", concat!(head!(), "define shape triangle t 0 0 0 1 1 1 2 2 2 red\n", tail!()),
        Diag(W, at(2, 25), "collinear")),
    row("material written first", concat!(head!(), "define shape sphere s red 0 0 0 1\n", tail!()),
        Diag(W, at(2, 23), "read as `define shape sphere s 0 0 0 1 red`")),
    row("duplicate shape name", concat!(head!(), "define shape sphere s 0 0 0 1 red\ndefine shape sphere s 0 0 0 2 red\n", tail!()),
        Diag(W, at(3, 21), "already defined (line 2)")),
    row("duplicate material name", concat!(head!(), "define material red 1 1 1 1 1 1 1 1 1 1\n", tail!()),
        Diag(W, at(2, 17), "material `red` is already defined")),
    // ----- composites ------------------------------------------------------------------
    row("undefined composite child", concat!(head!(), "define shape sphere s 0 0 0 1 red\ndefine shape composite g s ghost\n", tail!()),
        Diag(W, at(3, 28), "undefined child `ghost`")),
    row("child commented out", concat!(head!(), "# define shape sphere s 0 0 0 1 red\ndefine shape composite g s\n", tail!()),
        Diag(W, at(3, 26), "only defined in a comment, on line 2")),
    row("child defined after the composite", concat!(head!(), "define shape composite g s\ndefine shape sphere s 0 0 0 1 red\n", tail!()),
        Diag(W, at(2, 26), "defined after this composite")),
    row("composite containing itself", concat!(head!(), "define shape sphere s 0 0 0 1 red\ndefine shape composite g s g\n", tail!()),
        Diag(W, at(3, 28), "cannot contain itself")),
    // ----- transforms ------------------------------------------------------------------
    row("unknown transform target with suggestion", concat!(head!(), "define shape sphere ball 0 0 0 1 red\ntransform bal translate 1 0 0\n", tail!()),
        Diag(E, at(3, 11), "did you mean `ball`?")),
    row("transform of a commented-out shape", concat!(head!(), "#define shape sphere ball 0 0 0 1 red\ntransform ball translate 1 0 0\n", tail!()),
        Diag(W, at(3, 11), "only defined in a comment (line 2)")),
    row("transforming a material", concat!(base!(), "transform red scale 2\n"),
        Diag(E, at(4, 11), "is a material")),
    row("unknown operation", concat!(base!(), "transform cam move 1 0 0\n"),
        Diag(E, at(4, 15), "expected translate, rotate or scale, found 'move'")),
    row("zero scale", concat!(base!(), "transform cam scale 0\n"),
        Diag(E, at(4, 21), "no inverse")),
    row("zero scale on one axis", concat!(base!(), "transform cam scale 1 0 1\n"),
        Diag(E, at(4, 21), "scale by 0")),
    row("zero rotation axis", concat!(base!(), "transform cam rotate 45 0 0 0\n"),
        Diag(E, at(4, 25), "zero axis")),
    row("zero rotation about a zero axis is harmless", concat!(base!(), "transform cam rotate 0 0 0 0\n"),
        Diag(W, at(4, 22), "no effect")),
    row("translate with four numbers", concat!(base!(), "transform cam translate 1 2 3 4\n"),
        Diag(E, at(4, 25), "translate takes 3 numbers, found 4")),
    row("ambiguous Euler angles", concat!(base!(), "transform cam rotate 10 20 0\n"),
        Diag(E, at(4, 22), "order is ambiguous")),
    row("rotate with an axis letter", concat!(base!(), "transform cam rotate 45 y\n"),
        Clean),
    row("several operations on one line", concat!(base!(), "transform cam rotate 10 0 1 0 translate 1 2 3 scale 2\n"),
        Clean),
    // ----- lights and cameras ----------------------------------------------------------
    row("light with 8 numbers", concat!(head!(), "define light l 0 0 0 1 1 1 1 1\n", tail!()),
        Diag(E, at(2, 30), "a light takes 7 numbers")),
    row("4-number light is an ambient term", concat!(head!(), "define light ambient1 .3 .2 .6 5\n", tail!()),
        Diag(W, at(2, 23), "read as ambient light")),
    row("9-number lecture light", concat!(head!(), "define light l 0 0 0 .2 .2 .2 .8 .8 .8\n", tail!()),
        Diag(W, at(2, 22), "lecture form")),
    row("spherical light", concat!(head!(), "define light l 0 5 0 1 1 1 1 radius 0.5\n", tail!()),
        Clean),
    row("spot light with a radius", concat!(head!(), "define light l 0 5 0 1 1 1 1 spot 0 0 0 20 30 radius 0.5\n", tail!()),
        Clean),
    row("8-number light is a spherical light", concat!(head!(), "define light l 0 100 0 10 1 1 1 0.7\n", tail!()),
        Diag(W, at(2, 24), "a spherical light of radius 10")),
    row("negative light radius", concat!(head!(), "define light l 0 5 0 1 1 1 1 radius -2\n", tail!()),
        Diag(W, at(2, 37), "read as 2")),
    row("light radius without its number", concat!(head!(), "define light l 0 5 0 1 1 1 1 radius\n", tail!()),
        Diag(E, at(2, 30), "`radius` takes 1 number")),
    row("radius after a 9-number light", concat!(head!(), "define light l 0 5 0 1 1 1 1 1 1 radius 2\n", tail!()),
        Diag(E, at(2, 34), "follows the 7 numbers")),
    row("two radii", concat!(head!(), "define light l 0 5 0 1 1 1 1 radius 1 radius 2\n", tail!()),
        Diag(E, at(2, 39), "one `radius`")),
    row("misspelt spot", concat!(head!(), "define light l 0 5 0 1 1 1 1 radius 1 spto 0 0 0 5 9\n", tail!()),
        Diag(E, at(2, 39), "did you mean `spot`?")),
    row("spot with too few numbers", concat!(head!(), "define light l 0 5 0 1 1 1 1 spot 0 0 0 20\n", tail!()),
        Diag(E, at(2, 35), "`spot` takes 5 numbers")),
    row("spot aimed at itself", concat!(head!(), "define light l 0 5 0 1 1 1 1 spot 0 5 0 20 30\n", tail!()),
        Diag(E, at(2, 35), "must differ from the light's position")),
    row("spot angles the wrong way round", concat!(head!(), "define light l 0 5 0 1 1 1 1 spot 0 0 0 30 20\n", tail!()),
        Diag(E, at(2, 41), "larger than its outer one")),
    row("spot angle beyond a half turn", concat!(head!(), "define light l 0 5 0 1 1 1 1 spot 0 0 0 20 190\n", tail!()),
        Diag(E, at(2, 41), "from 0 to 180 degrees")),
    row("lens", concat!(base!(), "lens cam 0.1 5\n"), Clean),
    row("lens of an unknown camera", concat!(base!(), "lens cma 0.1 5\n"),
        Diag(E, at(4, 6), "did you mean `cam`?")),
    row("lens with a negative aperture", concat!(base!(), "lens cam -0.1 5\n"),
        Diag(E, at(4, 10), "at least 0")),
    row("second lens of a camera", concat!(base!(), "lens cam 0.1 5\nlens cam 0.2 5\n"),
        Diag(W, at(5, 6), "already has a lens")),
    row("camera up parallel to dir", concat!(head!(), "define camera c 60 0 0 0 0 0 -1 0 0 2\n", tail!()),
        Diag(W, at(2, 33), "parallel to its viewing direction: +y is up")),
    row("camera looking along y with up parallel", concat!(head!(), "define camera c 60 0 0 0 0 1 0 0 2 0\nrender c out.png 8 8\n"),
        Diag(E, at(2, 32), "parallel")),
    row("camera with a field of view of nearly a half turn", concat!(head!(), "define camera c 175 0 0 0 0 0 -1 0 1 0\nrender c out.png 8 8\n"),
        Diag(W, at(2, 17), "a field of view of 175° is nearly a half turn")),
    row("camera with a field of view of a radian", concat!(head!(), "define camera c 1.0 0 0 0 0 0 -1 0 1 0\nrender c out.png 8 8\n"),
        Diag(W, at(2, 17), "a field of view of 1° is very narrow")),
    row("camera with zero direction", concat!(head!(), "define camera c 60 0 0 0 0 0 0 0 1 0\nrender c out.png 8 8\n"),
        Diag(W, at(2, 26), "viewing direction is zero: read as its field of view alone")),
    row("camera with fov last and zero direction", concat!(head!(), "define camera c 0 2 3 0 0 0 45\nrender c out.png 8 8\n"),
        Diag(W, at(2, 23), "viewing direction is zero: read as its field of view alone")),
    row("broken camera beside a good one", concat!(head!(), "define camera c 60 0 0 0 0 1 0 0 1 0\nrender c a.png 8 8\n", tail!()),
        Diag(W, at(2, 32), "camera `c` is skipped with the render line that uses it (line 3)")),
    row("camera with fov last", concat!(head!(), "define camera c 0 0 0 0 0 -1 0 1 0 90\n", tail!()),
        Diag(W, at(2, 17), "the fov comes first")),
    row("camera with a resolution after the fov", concat!(head!(), "camera c 45 500 500\n", tail!()),
        Diag(W, at(2, 10), "belongs on the render line")),
    row("camera with only an eye", concat!(head!(), "define camera c 60 10 0 0\n", tail!()),
        Diag(W, at(2, 20), "looking along -z with y up")),
    row("camera with a stray number after up", concat!(head!(), "define camera c 60 0 0 0 0 0 -1 0 1 0 0\n", tail!()),
        Diag(W, at(2, 39), "extra number '0'")),
    row("duplicate camera", concat!(base!(), "define camera cam 45\n"),
        Diag(W, at(4, 15), "camera `cam` is already defined")),
    // ----- render ----------------------------------------------------------------------
    row("render with an unknown camera", "define camera eye 60\nrender eey out.png 8 8\n",
        Diag(W, at(2, 8), "did you mean `eye`?")),
    row("render size not whole", "define camera eye 60\nrender eye out.png 8.5 8\n",
        Diag(E, at(2, 20), "whole number")),
    row("render without height", "define camera eye 60\nrender eye out.png 8\n",
        Diag(E, at(2, 21), "expected the image height")),
    row("broken file name", "define camera eye 60\nrender eye image . ppm 8 8\n",
        Diag(W, at(2, 12), "read as `image.ppm`")),
    row("render overwriting its scene file", "define camera eye 60\nrender eye scene.sdf 8 8\n",
        Diag(W, at(2, 1), "`scene.sdf` is no image file name: `scene.ppm` is written")),
    row("zero samples", "define camera eye 60\nrender eye out.png 8 8 0\n",
        Diag(W, at(2, 24), "0 samples")),
    row("transform after the last of several renders", concat!(base!(), "render cam b.png 8 8\ntransform cam translate 1 0 0\n"),
        Diag(W, at(5, 1), "after the last render")),
    row("no render statement", "define camera eye 60\n",
        Diag(W, None, "no render statement")),
    // ----- strict mode -----------------------------------------------------------------
    strict("strict: an unknown statement is an error", concat!(head!(), "efine x\n", tail!()),
        Diag(E, at(2, 1), "unknown statement 'efine'")),
    strict("strict: a clamped value is an error", concat!(head!(), "define material m 1 1 1 1 1 1 1 1 1 10 1.5\n", tail!()),
        Diag(E, at(2, 40), "clamped")),
    strict("strict: a clean file stays clean", base!(), Clean),
];

fn describe(ds: &[Diagnostic]) -> String {
    ds.iter()
        .map(|d| d.to_string())
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn table_of_malformed_inputs() {
    assert!(ROWS.len() >= 45, "only {} rows", ROWS.len());
    let mut failures = Vec::new();
    for row in ROWS {
        let opts = LoadOptions {
            strict: row.strict,
            ..LoadOptions::default()
        };
        let result = load_str(row.text, Path::new("scene.sdf"), &opts);
        let problem = match (row.expect, &result) {
            (Clean, Ok(l)) if l.diagnostics.is_empty() => None,
            (Clean, Ok(l)) => Some(format!(
                "expected no diagnostics, got:\n{}",
                describe(&l.diagnostics)
            )),
            (Clean, Err(ds)) => Some(format!("expected no diagnostics, got:\n{}", describe(ds))),
            (Diag(severity, place, text), _) => {
                let ds = match &result {
                    Ok(l) => &l.diagnostics,
                    Err(ds) => ds,
                };
                // Errors must fail the load; warnings alone must not.
                let outcome_ok = match severity {
                    Severity::Error => result.is_err(),
                    Severity::Warning => result.is_ok(),
                };
                let found = ds.iter().any(|d| {
                    d.severity == severity
                        && d.loc.as_ref().map(|l| (l.line, l.col)) == place
                        && (d.message.contains(text)
                            || d.help.as_deref().is_some_and(|h| h.contains(text)))
                        // Located diagnostics quote their line.
                        && (d.loc.is_none() || d.source_line.is_some())
                });
                if found && outcome_ok {
                    None
                } else {
                    Some(format!(
                        "expected {severity:?} at {place:?} containing {text:?} (load {}), got:\n{}",
                        if result.is_ok() { "succeeded" } else { "failed" },
                        describe(ds)
                    ))
                }
            }
        };
        if let Some(p) = problem {
            failures.push(format!("row `{}`: {p}", row.name));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n\n"));
}

#[test]
fn diagnostics_quote_the_line_with_a_caret_under_the_token() {
    let text = concat!(head!(), "define shape sphere s 0 0 1O 1 red\n", tail!());
    let ds = load_str(text, Path::new("scene.sdf"), &LoadOptions::default()).unwrap_err();
    let shown = ds[0].to_string();
    assert!(
        shown.starts_with("scene.sdf:2:27: error: expected a number, found '1O'"),
        "{shown}"
    );
    assert!(
        shown.contains("2 | define shape sphere s 0 0 1O 1 red\n  |                           ^^"),
        "{shown}"
    );
}

/// Error rows run through the real binary: non-zero exit, a located message, no image.
#[test]
fn the_binary_refuses_broken_files_without_writing_images() {
    let cases = [
        ("define shape sphere s 0 0 1O 1 red\n", "2:27"),
        ("transform ghost scale 2\n", "2:11"),
        ("define shape box b 0 0 0 1 1 red\n", "2:30"),
        (
            "define material m 1 1 1 1 1 1 1 1 1 10 0 1 1 0.5 0.5\n",
            "2:46",
        ),
    ];
    for (bad_line, place) in cases {
        let dir = tempfile::tempdir().expect("temp dir");
        let scene = dir.path().join("scene.sdf");
        std::fs::write(&scene, format!("{}{bad_line}{}", head!(), tail!())).expect("write scene");
        let out = dir.path().join("out");
        std::fs::create_dir(&out).expect("out dir");
        let output = Command::cargo_bin("anim")
            .expect("the anim binary is built")
            .arg("render")
            .arg(&scene)
            .arg("--out")
            .arg(&out)
            .output()
            .expect("anim runs");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            !output.status.success(),
            "{bad_line}: exit status 0\n{stderr}"
        );
        assert!(
            stderr.contains(&format!("scene.sdf:{place}:")),
            "{bad_line}: stderr lacks scene.sdf:{place}:\n{stderr}"
        );
        let written: Vec<_> = std::fs::read_dir(&out)
            .expect("read out dir")
            .flatten()
            .map(|e| e.path())
            .collect();
        assert!(written.is_empty(), "{bad_line}: files written: {written:?}");
    }
}

/// `anim check` reports and counts.
#[test]
fn check_command_summarises() {
    let dir = tempfile::tempdir().expect("temp dir");
    // A file with nothing to see is itself worth a warning (the image would be blank).
    std::fs::write(
        dir.path().join("good.sdf"),
        concat!(
            head!(),
            "define shape sphere s 0 0 -5 1 red\ndefine light l 0 5 0 1 1 1 1\n",
            tail!()
        ),
    )
    .expect("write");
    std::fs::write(
        dir.path().join("warned.txt"),
        concat!(head!(), "efine x\n", tail!()),
    )
    .expect("write");
    std::fs::write(
        dir.path().join("bad"),
        concat!(head!(), "define shape sphere s 0 0 1O 1 red\n", tail!()),
    )
    .expect("write");
    std::fs::write(dir.path().join("notes.md"), "not a scene").expect("write");
    let output = Command::cargo_bin("anim")
        .expect("the anim binary is built")
        .arg("check")
        .arg(dir.path())
        .output()
        .expect("anim runs");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("3 files: 1 ok, 1 with warnings, 1 rejected"),
        "{stdout}"
    );
    assert!(
        stderr.contains("bad:2:27: error: expected a number"),
        "{stderr}"
    );
    assert!(stderr.contains("warned.txt:2:1: warning"), "{stderr}");
}
