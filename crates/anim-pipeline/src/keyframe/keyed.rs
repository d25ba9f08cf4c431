//! Keyed values written into a frame's definitions: a camera's pose, a material's colours
//! and coefficients, and which shapes and composites are shown.

use super::base::BaseScene;
use super::orbit::Pose;
use super::spec::Track;
use super::tidy::{tidy, tidy3};
use anim_core::limits;
use anim_core::sdf::ast::{Statement, StatementKind};
use glam::{DVec3, Vec3};
use std::collections::BTreeSet;

/// A colour as frames write it: never negative, tidy.
pub fn color(v: DVec3) -> Vec3 {
    tidy3(v.max(DVec3::ZERO)).as_vec3()
}

/// Sets camera `name` to `pose` outright: its base transforms would move it off the pose,
/// so they are dropped.
pub fn place_camera(out: &mut Vec<Statement>, name: &str, pose: &Pose) {
    out.retain(
        |s| !matches!(&s.kind, StatementKind::Transform { target, .. } if target.name == name),
    );
    for s in out.iter_mut() {
        if let StatementKind::Camera(c) = &mut s.kind {
            if c.name == name {
                c.eye = tidy3(pose.eye);
                c.dir = tidy3(pose.dir);
                c.up = pose.up;
            }
        }
    }
}

/// Sets the keyed values of material track `track` at time `t` in the material's
/// definitions.
pub fn set_material(out: &mut [Statement], track: &Track, t: f64) {
    let m = &track.material;
    let colour = |c: &Option<super::spec::Channel<DVec3>>| c.as_ref().and_then(|c| c.at(t));
    let number = |c: &Option<super::spec::Channel<f64>>| {
        c.as_ref().and_then(|c| c.at(t)).map(|v| tidy(v) as f32)
    };
    let (ka, kd, ks) = (colour(&m.ka), colour(&m.kd), colour(&m.ks));
    let (reflectivity, opacity, ior) =
        (number(&m.reflectivity), number(&m.opacity), number(&m.ior));
    for s in out.iter_mut() {
        let StatementKind::Material(def) = &mut s.kind else {
            continue;
        };
        if def.name != track.target {
            continue;
        }
        if let Some(v) = ka {
            def.ka = color(v);
        }
        if let Some(v) = kd {
            def.kd = color(v);
        }
        if let Some(v) = ks {
            def.ks = color(v);
        }
        if let Some(v) = reflectivity {
            def.reflectivity = v;
        }
        if let Some(v) = opacity {
            def.opacity = v;
        }
        if let Some(v) = ior {
            def.ior = v;
        }
    }
}

/// Takes the things in `hidden` out of the frame: their definitions, the statements that
/// place or move them, and their places in composites. A composite's children that no shown
/// composite lists go with it, or they would be drawn on their own at the top level.
pub fn hide(out: &mut Vec<Statement>, base: &BaseScene, hidden: &[&str]) {
    if hidden.is_empty() {
        return;
    }
    let mut gone: BTreeSet<String> = hidden.iter().map(|h| h.to_string()).collect();
    for _ in 0..limits::MAX_NESTING {
        let orphans: Vec<String> = gone
            .iter()
            .flat_map(|g| base.children(g))
            .filter(|c| !gone.contains(*c))
            .filter(|c| base.parents(c).iter().all(|p| gone.contains(*p)))
            .cloned()
            .collect();
        if orphans.is_empty() {
            break;
        }
        gone.extend(orphans);
    }
    out.retain(|s| match &s.kind {
        StatementKind::Shape { name, .. } | StatementKind::Composite { name, .. } => {
            !gone.contains(name)
        }
        StatementKind::Transform { target, .. } => !gone.contains(&target.name),
        StatementKind::Motion(m) => !gone.contains(&m.target.name),
        _ => true,
    });
    for s in out.iter_mut() {
        if let StatementKind::Composite { children, .. } = &mut s.kind {
            children.retain(|c| !gone.contains(&c.name));
        }
    }
}
