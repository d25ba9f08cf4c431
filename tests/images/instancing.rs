//! Instancing, through the real binary: a composite listed in several places is kept once,
//! so a chain of composites that doubles twenty times loads, checks and renders within a
//! memory budget its flattened tree would exceed a thousand times over; and a scene of shared
//! composites renders to exactly the bytes of the same scene with every use written out.

use crate::common;

#[path = "../common/composites.rs"]
mod composites;

use common::{anim, read_ppm};
use composites::{Tree, MATERIALS};
use std::path::Path;

/// A chain `depth` composites deep over one sphere, doubling at `doublings` evenly spread
/// levels: level `k` lists two wrappers of the level below, one moved aside (alternately in
/// x and y, so the spheres fill a grid); every other level lists the one below once and
/// moves it slightly.
fn chain(doublings: usize, depth: usize) -> Tree {
    let mut t = Tree::default();
    let s = t.shape("s", "sphere 0 0 0 1 m1".to_string(), &[]);
    let mut prev = t.composite("c0", &[s], &[]);
    let passes = depth - 1 - 2 * doublings;
    let mut n = 0;
    for k in 1..=doublings {
        let here = passes / doublings + usize::from(k - 1 < passes % doublings);
        for _ in 0..here {
            n += 1;
            let dz = if n % 2 == 1 { 0.001 } else { -0.001 };
            prev = t.composite(&format!("p{n}"), &[prev], &[format!("translate 0 0 {dz}")]);
        }
        let a = t.composite(&format!("a{k}"), &[prev], &[]);
        let shift = 2.5 * f64::from(1u32 << ((k - 1) / 2));
        let (x, y) = if k % 2 == 1 {
            (shift, 0.0)
        } else {
            (0.0, shift)
        };
        let b = t.composite(&format!("b{k}"), &[prev], &[format!("translate {x} {y} 0")]);
        prev = t.composite(&format!("c{k}"), &[a, b], &[]);
    }
    t.composite("root", &[prev], &[]);
    t
}

/// A camera looking down −z at the chain's grid of `2^doublings` spheres, whole in view.
fn chain_view(doublings: usize, size: &str) -> String {
    let w = 2.5 * f64::from(1u32 << (doublings / 2));
    let h = 2.5 * f64::from(1u32 << doublings.div_ceil(2));
    format!(
        "define camera eye 60 0 0 0 0 0 -1 0 1 0\ntransform eye translate {} {} {}\nrender eye image.ppm {size}\n",
        w / 2.0,
        h / 2.0,
        1.3 * w.max(h)
    )
}

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// Runs `anim` with `args` on `file`; its exit status and stderr.
fn run(args: &[&str], file: &Path) -> (bool, String) {
    let out = anim().args(args).arg(file).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_chain_doubling_twenty_times_checks_and_renders_within_a_small_budget() {
    let dir = tempfile::tempdir().unwrap();
    let tree = chain(20, 250);
    let text = format!("{MATERIALS}{}{}", chain_view(20, "48 32"), tree.shared());
    let file = write(dir.path(), "chain.sdf", &text);
    // The flattened tree has 2^20 spheres: about 512 MiB at the loader's count per shape. Kept
    // once, the chain fits in 1 MiB (the budget is checked on what the scene stores).
    let budget = ["--max-memory", "1M"];
    let (ok, stderr) = run(&[&["check"][..], &budget].concat(), &file);
    assert!(ok, "{stderr}");
    assert!(!stderr.contains("blank"), "{stderr}");
    let (ok, stderr) = run(
        &[&["render", "--spp", "1", "-q"][..], &budget].concat(),
        &file,
    );
    assert!(ok, "{stderr}");
    let image = read_ppm(&dir.path().join("image.ppm"));
    // The grid of red spheres (about half its area, two thirds of the view's width, each
    // smaller than a pixel) covers about a third of the view: a fair share of red pixels.
    let lit = image
        .data
        .chunks(3)
        .filter(|p| p[0] > p[2] && p[0] > 20)
        .count();
    assert!(lit > image.width * image.height / 10, "{lit} red pixels");

    // The same chain with nothing to instance (a material that lets light through turns
    // instancing off) is refused under that budget: the count is what instancing changed.
    let glass = "define material glass 0 0 0 0.1 0.1 0.1 0.9 0.9 0.9 50 0 0.5 1.5\n";
    let text = text.replace("sphere s 0 0 0 1 m1", "sphere s 0 0 0 1 glass");
    let flat = write(dir.path(), "flat.sdf", &format!("{glass}{text}"));
    let (ok, stderr) = run(
        &[
            &["check", "--material-fields", "reflectivity,opacity,ior"][..],
            &budget,
        ]
        .concat(),
        &flat,
    );
    assert!(!ok && stderr.contains("shapes"), "{stderr}");
}

/// Renders `text` in `dir` (it writes `image.ppm`) and returns the image's bytes.
fn render_bytes(dir: &Path, name: &str, text: &str, args: &[&str]) -> Vec<u8> {
    let file = write(dir, name, text);
    let (ok, stderr) = run(&[&["render", "-q"][..], args].concat(), &file);
    assert!(ok, "{stderr}");
    std::fs::read(dir.join("image.ppm")).unwrap()
}

#[test]
fn shared_composites_render_the_bytes_of_their_flattened_rewrite() {
    let camera = "define camera eye 70 4 6 25 -0.1 -0.15 -1 0 1 0\nrender eye image.ppm 96 72\n";
    let mut cases: Vec<(String, String)> = [4, 5]
        .into_iter()
        .map(|seed| {
            let t = composites::mixed(seed);
            (t.shared(), t.flattened())
        })
        .collect();
    let small = chain(8, 30);
    cases.push((small.shared(), small.flattened()));
    let dir = tempfile::tempdir().unwrap();
    for (k, (shared, flattened)) in cases.iter().enumerate() {
        let view = if k < 2 {
            camera.to_string()
        } else {
            chain_view(8, "96 72")
        };
        let shared = format!("{MATERIALS}{view}{shared}");
        let flattened = format!("{MATERIALS}{view}{flattened}");
        // Adaptive sampling (the default) and uniform 4 spp: both compare what pixels hit. A
        // small budget makes the composites worth instancing.
        for args in [
            &["--max-memory", "1M"][..],
            &["--max-memory", "1M", "--spp", "4"][..],
        ] {
            let a = render_bytes(dir.path(), "shared.sdf", &shared, args);
            let b = render_bytes(dir.path(), "flattened.sdf", &flattened, args);
            assert!(a == b, "case {k} {args:?}: the images differ");
            // Not vacuous: the scene is in view (many pixels differ from the first).
            let first = &a[a.len() - 96 * 72 * 3..][..3];
            let varied = a[a.len() - 96 * 72 * 3..]
                .chunks(3)
                .filter(|p| p != &first)
                .count();
            assert!(
                varied > 96 * 72 / 10,
                "case {k}: {varied} pixels differ from the corner"
            );
        }
    }
}
