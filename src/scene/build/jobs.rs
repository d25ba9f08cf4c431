//! One render job per render statement: the camera it names and the scene as it stands
//! there, with the composite tree flattened into instances.

use super::definitions::{Definitions, ObjectKind};
use super::transforms::{finite_transform, Snapshot, Space};
use super::{At, Builder, MAX_INSTANCES, MAX_TOTAL_INSTANCES};
use crate::diag::Diagnostic;
use crate::diag::Severity;
use crate::limits::{self, DEFAULT_IMAGE_SIZE, MAX_NESTING};
use crate::math::Transform;
use crate::scene::{Camera, Geometry, Instance, Light, RenderJob, Scene};
use crate::sdf::ast::{CameraDef, NameRef, Statement, StatementKind};
use crate::sdf::default_output;
use std::collections::HashSet;
use std::path::PathBuf;

impl Builder<'_> {
    // ----- jobs --------------------------------------------------------------------------

    pub(super) fn jobs<'s>(
        &mut self,
        statements: &'s [Statement],
        d: &Definitions<'s>,
    ) -> Vec<RenderJob> {
        let snapshots = self.snapshots(statements, d);
        let mut jobs = Vec::new();
        for (render, snapshot) in &snapshots {
            let job = match render {
                Some(stmt) => {
                    let StatementKind::Render(r) = &stmt.kind else {
                        continue;
                    };
                    let Some(camera) = self.render_camera(d, &r.camera, snapshot) else {
                        continue;
                    };
                    RenderJob {
                        scene: self.scene(d, snapshot),
                        camera,
                        output: PathBuf::from(&r.output),
                        width: r.width,
                        height: r.height,
                        samples: r.samples,
                        loc: Some(stmt.loc.clone()),
                    }
                }
                None => {
                    if self.omissions.render_lines > 0
                        || (self.omissions.cameras_rejected && d.cameras.is_empty())
                    {
                        // The render line or the camera was rejected, with an error: no stand-in.
                        continue;
                    }
                    let camera = match d.cameras.first() {
                        Some(c) => place_camera(c, snapshot),
                        None => Camera::default_with_fov("default", limits::DEFAULT_FOV_DEG),
                    };
                    let output = default_output(self.path);
                    let mut w = Diagnostic::file_error(
                        self.path,
                        format!(
                            "no render statement: camera `{}` is rendered to `{output}` at {}×{}",
                            camera.name, DEFAULT_IMAGE_SIZE.0, DEFAULT_IMAGE_SIZE.1
                        ),
                    )
                    .with_help("add e.g. `render <camera> image.png 800 600`");
                    w.severity = Severity::Warning;
                    self.diagnostics.push(w);
                    RenderJob {
                        scene: self.scene(d, snapshot),
                        camera,
                        output: PathBuf::from(output),
                        width: DEFAULT_IMAGE_SIZE.0,
                        height: DEFAULT_IMAGE_SIZE.1,
                        samples: None,
                        loc: None,
                    }
                }
            };
            jobs.push(job);
        }
        jobs
    }

    pub(super) fn render_camera(
        &mut self,
        d: &Definitions,
        name: &NameRef,
        snapshot: &Snapshot,
    ) -> Option<Camera> {
        match d.camera_index.get(name.name.as_str()) {
            Some(&i) => Some(place_camera(d.cameras[i], snapshot)),
            None => {
                if !self.skipped(&name.name) {
                    let help = self
                        .name_help(&name.name, d.camera_index.keys().copied())
                        .or_else(|| {
                            d.cameras
                                .first()
                                .map(|c| format!("the file defines camera `{}`", c.name))
                        });
                    self.at_ref(
                        Severity::Error,
                        name,
                        format!("unknown camera `{}`", name.name),
                        help,
                    );
                }
                None
            }
        }
    }

    pub(super) fn scene(&mut self, d: &Definitions, snapshot: &Snapshot) -> Scene {
        let roots: Vec<usize> = match d.object_index.get("root") {
            Some(&i) if matches!(d.objects[i].kind, ObjectKind::Composite { .. }) => vec![i],
            _ => {
                let contained: HashSet<&str> = d
                    .object_index
                    .values()
                    .filter_map(|&i| match &d.objects[i].kind {
                        ObjectKind::Composite { children } => Some(children.iter().copied()),
                        ObjectKind::Shape { .. } => None,
                    })
                    .flatten()
                    .collect();
                let mut roots: Vec<usize> = d
                    .object_index
                    .iter()
                    .filter(|(name, _)| !contained.contains(*name))
                    .map(|(_, &i)| i)
                    .collect();
                roots.sort_unstable(); // definition order
                roots
            }
        };
        let mut instances = Vec::new();
        let mut stack = Vec::new();
        for root in roots {
            let name = d.objects[root].name;
            self.flatten(
                d,
                snapshot,
                name,
                &Transform::IDENTITY,
                "",
                &mut stack,
                &mut instances,
            );
        }
        let lights = d
            .lights
            .iter()
            .map(|l| {
                let t = snapshot
                    .get(&(Space::Light, l.name.as_str()))
                    .copied()
                    .unwrap_or_default();
                Light {
                    name: l.name.clone(),
                    position: t.point(l.position),
                    intensity: l.color * l.brightness,
                }
            })
            .collect();
        Scene {
            materials: d.materials.clone(),
            instances,
            lights,
            ambient: d.ambient,
            background: d.background,
        }
    }

    /// Appends the instances below object `name`, placed by `parent` (its parent's world
    /// transform). `stack` holds the composites being expanded, to stop at cycles.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn flatten<'s>(
        &mut self,
        d: &Definitions<'s>,
        snapshot: &Snapshot,
        name: &'s str,
        parent: &Transform,
        prefix: &str,
        stack: &mut Vec<&'s str>,
        out: &mut Vec<Instance>,
    ) {
        let Some(&i) = d.object_index.get(name) else {
            return;
        };
        if self.too_many_reported {
            return; // the scene is refused anyway; do not walk the rest of a huge tree
        }
        let object = &d.objects[i];
        let own = snapshot
            .get(&(Space::Object, name))
            .copied()
            .unwrap_or_default();
        let world = parent.then_after(&own);
        if !finite_transform(&world) {
            if self.reported_composites.insert(name.to_string()) {
                self.error(
                    At::Name(object.statement),
                    format!(
                        "the transforms above `{name}` multiply out beyond floating-point range"
                    ),
                    Some("use scale factors nearer to 1".to_string()),
                );
            }
            return;
        }
        let path = if prefix.is_empty() {
            name.to_string()
        } else {
            format!("{prefix}/{name}")
        };
        match &object.kind {
            ObjectKind::Shape { geometry, material } => {
                let Some(material) = *material else {
                    return;
                };
                if out.len() >= MAX_INSTANCES || self.total_instances >= MAX_TOTAL_INSTANCES {
                    if !self.too_many_reported {
                        self.too_many_reported = true;
                        let (message, help) = if out.len() >= MAX_INSTANCES {
                            (
                                format!("the composite tree expands to more than {MAX_INSTANCES} shapes"),
                                "a composite listing another twice, level after level, doubles the scene each time",
                            )
                        } else {
                            (
                                format!("the file's render statements together need more than {MAX_TOTAL_INSTANCES} shapes"),
                                "write one file per frame (as `anim generate` does) instead of many render lines",
                            )
                        };
                        self.error(At::Name(object.statement), message, Some(help.to_string()));
                    }
                    return;
                }
                self.total_instances += 1;
                // The parser makes radii positive; statements made by a program may not.
                let mut geometry = (*geometry).clone();
                if let Geometry::Sphere { radius, .. }
                | Geometry::Cylinder { radius, .. }
                | Geometry::Cone { radius, .. } = &mut geometry
                {
                    *radius = limits::fixed_radius(*radius);
                }
                out.push(Instance {
                    name: path,
                    geometry,
                    material,
                    transform: world,
                    loc: Some(object.statement.loc.clone()),
                });
            }
            ObjectKind::Composite { children } => {
                if let Some(pos) = stack.iter().position(|&s| s == name) {
                    if self.reported_composites.insert(name.to_string()) {
                        let mut cycle: Vec<&str> = stack[pos..].to_vec();
                        cycle.push(name);
                        self.error(
                            At::Name(object.statement),
                            format!("composite `{name}` contains itself ({})", cycle.join(" → ")),
                            None,
                        );
                    }
                    return;
                }
                if stack.len() >= MAX_NESTING {
                    if self.reported_composites.insert(name.to_string()) {
                        self.error(
                            At::Name(object.statement),
                            format!("composites are nested more than {MAX_NESTING} deep"),
                            None,
                        );
                    }
                    return;
                }
                stack.push(name);
                for &child in children {
                    self.flatten(d, snapshot, child, &world, &path, stack, out);
                }
                stack.pop();
            }
        }
    }
}

/// A camera definition with its transform applied: the eye as a point, dir and up as vectors.
pub(super) fn place_camera(c: &CameraDef, snapshot: &Snapshot) -> Camera {
    let t = snapshot
        .get(&(Space::Camera, c.name.as_str()))
        .copied()
        .unwrap_or_default();
    Camera {
        name: c.name.clone(),
        fov_x_deg: c.fov_x_deg,
        eye: t.point(c.eye),
        dir: t.vector(c.dir),
        up: t.vector(c.up),
    }
}
