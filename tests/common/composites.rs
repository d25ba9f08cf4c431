//! Scenes with shared composites, written two ways: as a file that lists each composite
//! once and uses it in several places (which the loader instances), and as the same scene
//! with every use a copy under its own names (which it flattens). Both draw the same shapes
//! in the same depth-first order, so their images must be the same bytes.
#![allow(dead_code)]

use anim_core::util::SplitMix64;
use std::fmt::Write;

pub enum Kind {
    /// `<kind> <numbers…> <material>` of a `define shape` line.
    Shape(String),
    /// Children, by index of earlier definitions.
    Composite(Vec<usize>),
}

pub struct Def {
    pub name: String,
    pub kind: Kind,
    /// Transform operations (`translate 1 2 3`), in order.
    pub ops: Vec<String>,
}

/// Definitions, children before their composites; the last is the root.
#[derive(Default)]
pub struct Tree {
    pub defs: Vec<Def>,
}

impl Tree {
    pub fn shape(&mut self, name: &str, line: String, ops: &[String]) -> usize {
        self.defs.push(Def {
            name: name.to_string(),
            kind: Kind::Shape(line),
            ops: ops.to_vec(),
        });
        self.defs.len() - 1
    }

    pub fn composite(&mut self, name: &str, children: &[usize], ops: &[String]) -> usize {
        self.defs.push(Def {
            name: name.to_string(),
            kind: Kind::Composite(children.to_vec()),
            ops: ops.to_vec(),
        });
        self.defs.len() - 1
    }

    fn define(out: &mut String, name: &str, d: &Def, children: &[String]) {
        match &d.kind {
            Kind::Shape(line) => {
                let (kind, rest) = line.split_once(' ').unwrap();
                writeln!(out, "define shape {kind} {name} {rest}").unwrap();
            }
            Kind::Composite(_) => {
                writeln!(out, "define shape composite {name} {}", children.join(" ")).unwrap()
            }
        }
        for op in &d.ops {
            writeln!(out, "transform {name} {op}").unwrap();
        }
    }

    /// Each definition once, composites listing their children by name.
    pub fn shared(&self) -> String {
        let mut out = String::new();
        for d in &self.defs {
            let children: Vec<String> = match &d.kind {
                Kind::Composite(c) => c.iter().map(|&i| self.defs[i].name.clone()).collect(),
                Kind::Shape(_) => Vec::new(),
            };
            Self::define(&mut out, &d.name, d, &children);
        }
        out
    }

    /// Every use a copy of its own, named `<name>_<n>`; the root keeps its name.
    pub fn flattened(&self) -> String {
        let mut out = String::new();
        let mut count = 0;
        let root = self.defs.len() - 1;
        self.copy(root, &mut count, &mut out, true);
        out
    }

    fn copy(&self, i: usize, count: &mut usize, out: &mut String, root: bool) -> String {
        let d = &self.defs[i];
        let children: Vec<String> = match &d.kind {
            Kind::Composite(c) => c.iter().map(|&k| self.copy(k, count, out, false)).collect(),
            Kind::Shape(_) => Vec::new(),
        };
        *count += 1;
        let name = if root {
            d.name.clone()
        } else {
            format!("{}_{count}", d.name)
        };
        Self::define(out, &name, d, &children);
        name
    }
}

/// Scene-text numbers drawn from the one test generator.
trait SceneNumbers {
    /// A number in [`lo`, `hi`), written with three decimals.
    fn num(&mut self, lo: f64, hi: f64) -> String;
}

impl SceneNumbers for SplitMix64 {
    fn num(&mut self, lo: f64, hi: f64) -> String {
        format!("{:.3}", self.range(lo, hi))
    }
}

/// Materials m0…m5 (opaque), a light and ambient light.
pub const MATERIALS: &str = "define material m0 0.1 0.1 0.1 0.8 0.8 0.8 0.3 0.3 0.3 20\n\
    define material m1 0.2 0 0 0.9 0.1 0.1 0.5 0.5 0.5 30\n\
    define material m2 0 0 0.2 0.1 0.1 0.9 0.5 0.5 0.5 30\n\
    define material m3 0 0.2 0 0.1 0.9 0.1 0.2 0.2 0.2 10\n\
    define material m4 0.1 0.1 0 0.7 0.7 0.1 0.9 0.9 0.9 80\n\
    define material m5 0.1 0 0.1 0.6 0.2 0.6 0.1 0.1 0.1 5\n\
    define light sun 30 60 80 1 1 1 1\n\
    define light fill -40 20 30 0.5 0.5 0.6 1\n\
    ambient 0.15 0.15 0.15\n";

/// A scene of shared composites, nested sharing, transforms of every kind and exact ties:
/// a part of mixed shapes used twice inside an arm that is used three times; two
/// composites of the same spheres in different materials listed together (every sphere hit
/// at exactly the same distance twice, the first listed winning), one of them also listed
/// alone; a plane and a loose sphere at the top.
pub fn mixed(seed: u64) -> Tree {
    let mut r = SplitMix64::new(seed);
    let mut t = Tree::default();
    let mut part = Vec::new();
    for k in 0..20 {
        let (line, ops) = part_shape(&mut r, k);
        part.push(t.shape(&format!("s{k}"), line, &ops));
    }
    let part = t.composite("part", &part, &[]);
    let turned = t.composite(
        "turned",
        &[part],
        &[
            "rotate 90 0 0 1".to_string(),
            "translate 12 0 0".to_string(),
        ],
    );
    let arm = t.composite("arm", &[part, turned], &[]);
    let mut uses = Vec::new();
    let placements = [
        vec!["translate -30 0 -40".to_string()],
        vec![
            "rotate 35 0 1 0".to_string(),
            "translate 5 -4 -60".to_string(),
        ],
        vec![
            "scale 0.5 0.5 0.5".to_string(),
            "translate 20 10 -35".to_string(),
        ],
        vec![
            "scale 1 1.5 0.75".to_string(),
            "rotate -20 1 0 0".to_string(),
            "translate -10 15 -70".to_string(),
        ],
    ];
    for (k, ops) in placements.iter().enumerate() {
        uses.push(t.composite(&format!("u{k}"), &[arm], ops));
    }
    let mut red = Vec::new();
    let mut blue = Vec::new();
    for k in 0..16 {
        let (x, y, z, rad) = (
            r.num(0.0, 8.0),
            r.num(0.0, 8.0),
            r.num(0.0, 8.0),
            r.num(0.4, 1.0),
        );
        red.push(t.shape(
            &format!("r{k}"),
            format!("sphere {x} {y} {z} {rad} m1"),
            &[],
        ));
        blue.push(t.shape(
            &format!("b{k}"),
            format!("sphere {x} {y} {z} {rad} m2"),
            &[],
        ));
    }
    let red = t.composite("red", &red, &[]);
    let blue = t.composite("blue", &blue, &[]);
    let pair = t.composite("pair", &[red, blue], &[]);
    uses.push(t.composite("v0", &[pair], &["translate -5 -20 -50".to_string()]));
    uses.push(t.composite(
        "v1",
        &[pair],
        &[
            "rotate 180 0 1 0".to_string(),
            "translate 25 -15 -45".to_string(),
        ],
    ));
    uses.push(t.composite("v2", &[red], &["translate 0 -5 -30".to_string()]));
    uses.push(t.shape("floor", "plane 0 -30 0 0 1 0.1 m0".to_string(), &[]));
    uses.push(t.shape("loose", "sphere 3 3 -25 2 m4".to_string(), &[]));
    t.composite("root", &uses, &[]);
    t
}

/// The line (`<kind> <numbers…> <material>`) and transform operations of shape `k` of
/// `mixed`'s part: each kind of shape in turn, some moved.
fn part_shape(r: &mut SplitMix64, k: usize) -> (String, Vec<String>) {
    let m = format!("m{}", k % 6);
    let (x, y, z) = (r.num(0.0, 10.0), r.num(0.0, 10.0), r.num(0.0, 10.0));
    match k % 7 {
        0 => (
            format!(
                "box {x} {y} {z} {} {} {} {m}",
                r.num(10.5, 12.0),
                r.num(10.5, 12.0),
                r.num(10.5, 12.0)
            ),
            vec![format!("rotate {} 0 1 0.3", r.num(5.0, 60.0))],
        ),
        1 => (
            format!(
                "triangle {x} {y} {z} {} {} {} {} {} {} {m}",
                r.num(0.0, 10.0),
                r.num(0.0, 10.0),
                r.num(0.0, 10.0),
                r.num(0.0, 10.0),
                r.num(0.0, 10.0),
                r.num(0.0, 10.0)
            ),
            Vec::new(),
        ),
        2 => (
            format!(
                "cylinder {x} {y} {z} {} {} {} {} {m}",
                r.num(0.0, 10.0),
                r.num(0.0, 10.0),
                r.num(0.0, 10.0),
                r.num(0.3, 1.0)
            ),
            Vec::new(),
        ),
        3 => (
            format!("sphere 0 0 0 {} {m}", r.num(0.5, 1.5)),
            vec![
                "scale 2 0.6 1".to_string(),
                format!("translate {x} {y} {z}"),
            ],
        ),
        4 => (
            format!(
                "cone {x} {y} {z} {} {} {} {} {m}",
                r.num(0.0, 10.0),
                r.num(0.0, 10.0),
                r.num(0.0, 10.0),
                r.num(0.3, 1.5)
            ),
            Vec::new(),
        ),
        5 => (
            format!("sphere {x} {y} {z} {} {m}", r.num(0.3, 1.2)),
            vec![
                "scale 1.5 1.5 1.5".to_string(),
                "translate 0.5 -1 0.25".to_string(),
            ],
        ),
        _ => (
            format!("sphere {x} {y} {z} {} {m}", r.num(0.3, 1.5)),
            Vec::new(),
        ),
    }
}
