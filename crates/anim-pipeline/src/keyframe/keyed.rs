//! Keyed values written into a frame's definitions: a camera's pose and field of view, a
//! light's brightness and colour, a material's colours and coefficients, the ambient and
//! background colours, and which shapes and composites are shown.

use super::base::BaseScene;
use super::orbit::Pose;
use super::ranges::{in_unit_interval, RangeCheck};
use super::spec_file::{Animation, Blend, Channel, Source, Track};
use super::tidy::{tidy, tidy3};
use anim_core::diag::{Diagnostic, Loc};
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

/// Sets the keyed ambient and background colours of `anim` at time `t` in the statements that
/// set them, or in new statements (at `loc`) where the base scene sets none.
pub fn set_ambient_and_background(out: &mut Vec<Statement>, anim: &Animation, t: f64, loc: &Loc) {
    if let Some(ch) = &anim.ambient {
        let v = color(ch.at(t).unwrap_or(DVec3::ZERO));
        set_or_append(
            out,
            |k| matches!(k, StatementKind::Ambient(_)),
            StatementKind::Ambient(v),
            loc,
        );
    }
    if let Some(ch) = &anim.background {
        let v = color(ch.at(t).unwrap_or(DVec3::ZERO));
        set_or_append(
            out,
            |k| matches!(k, StatementKind::Background(_)),
            StatementKind::Background(v),
            loc,
        );
    }
}

/// Sets every statement matching `is` to `kind`, or appends `kind` (at `loc`) if none matches.
fn set_or_append(
    out: &mut Vec<Statement>,
    is: impl Fn(&StatementKind) -> bool,
    kind: StatementKind,
    loc: &Loc,
) {
    let mut found = false;
    for s in out.iter_mut() {
        if is(&s.kind) {
            s.kind = kind.clone();
            found = true;
        }
    }
    if !found {
        out.push(Statement::new(kind, loc.clone()));
    }
}

/// Sets the keyed light and camera parameters of `track` at time `t` (`when` says which frame
/// that is) in the definitions themselves, each combined by the track's `blend` with what the
/// definition holds (the base scene's value, or the earlier tracks'); a field of view outside
/// 0–180° or a negative brightness is an error at the channel of spec `src`.
pub fn set_parameters(
    out: &mut [Statement],
    track: &Track,
    t: f64,
    src: &Source,
    when: &dyn Fn() -> String,
) -> Result<(), Vec<Diagnostic>> {
    let brightness = track.brightness.as_ref().and_then(|c| Some((c.at(t)?, c)));
    let rgb = track.color.as_ref().and_then(|c| c.at(t));
    let fov = track.fov.as_ref().and_then(|c| Some((c.at(t)?, c)));
    let out_of_range = |c: &Channel<f64>, what: &str, v: f64, why: &str| {
        vec![src.error(
            &[&c.key_path_at(t)],
            format!(
                "{} the {what} of '{}' is {}, {why} (a smooth curve overshoots here, or its tracks combine so: add a key or use another interp)",
                when(),
                track.target,
                tidy(v)
            ),
        )]
    };
    for s in out.iter_mut() {
        match &mut s.kind {
            StatementKind::Light(l) if l.name == track.target => {
                if let Some((b, c)) = brightness {
                    let b = Blend::combine(track.blend, f64::from(l.brightness), b);
                    if b < 0.0 && track.blend.is_some() {
                        return Err(out_of_range(c, "brightness", b, "below 0"));
                    }
                    l.brightness = tidy(b.max(0.0)) as f32;
                }
                if let Some(c) = rgb {
                    l.color = combined_colour(track.blend, l.color, c);
                }
            }
            StatementKind::Camera(cam) if cam.name == track.target => {
                if let Some((f, c)) = fov {
                    let f = Blend::combine(track.blend, cam.fov_x_deg, f);
                    if !limits::fov_is_valid(f) {
                        return Err(out_of_range(c, "field of view", f, "outside 0–180°"));
                    }
                    cam.fov_x_deg = tidy(f);
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// `new` combined with the colour a definition holds, as frames write colours.
fn combined_colour(blend: Option<Blend>, current: Vec3, new: DVec3) -> Vec3 {
    let current = current.as_dvec3();
    color(DVec3::new(
        Blend::combine(blend, current.x, new.x),
        Blend::combine(blend, current.y, new.y),
        Blend::combine(blend, current.z, new.z),
    ))
}

/// Sets the keyed values of material track `track` at time `t` in the material's
/// definitions, each combined by the track's `blend`; a combination out of its range is an
/// error at the channel (a single track's values are kept in range by `ranges.rs`).
pub fn set_material(
    out: &mut [Statement],
    track: &Track,
    t: f64,
    src: &Source,
    when: &dyn Fn() -> String,
) -> Result<(), Vec<Diagnostic>> {
    let m = &track.material;
    let colour = |c: &Option<Channel<DVec3>>| c.as_ref().and_then(|c| c.at(t));
    let (ka, kd, ks) = (colour(&m.ka), colour(&m.kd), colour(&m.ks));
    let numbers: [RangeCheck; 3] = [
        (
            &m.reflectivity,
            "reflectivity",
            in_unit_interval,
            "outside 0–1",
        ),
        (&m.opacity, "opacity", in_unit_interval, "outside 0–1"),
        (&m.ior, "index of refraction", |v| v > 0.0, "at or below 0"),
    ];
    for s in out.iter_mut() {
        let StatementKind::Material(def) = &mut s.kind else {
            continue;
        };
        if def.name != track.target {
            continue;
        }
        for (v, field) in [(ka, &mut def.ka), (kd, &mut def.kd), (ks, &mut def.ks)] {
            if let Some(v) = v {
                *field = combined_colour(track.blend, *field, v);
            }
        }
        let fields = [&mut def.reflectivity, &mut def.opacity, &mut def.ior];
        for ((channel, what, ok, range), field) in numbers.iter().zip(fields) {
            let Some((v, c)) = channel.as_ref().and_then(|c| Some((c.at(t)?, c))) else {
                continue;
            };
            let v = Blend::combine(track.blend, f64::from(*field), v);
            if track.blend.is_some() && !ok(v) {
                return Err(vec![src.error(
                    &[&c.key_path_at(t)],
                    format!(
                        "{} the {what} of '{}' is {} once its tracks combine, {range}",
                        when(),
                        track.target,
                        tidy(v)
                    ),
                )]);
            }
            *field = tidy(v) as f32;
        }
    }
    Ok(())
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
