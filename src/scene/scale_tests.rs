//! Scenes of many shapes: the memory budget, and what the jobs of a file share.

use super::*;
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
