//! Frame generation: the base scene's statements, with the tracks applied at each frame's
//! time, written back out as one complete SDF file per frame.
//!
//! How keyed motion composes with the base file (documented in README.md): a track's
//! translate `T`, rotate `R` (about `axis`) and scale `S` at time t, with pivot `p`, give
//!
//! ```text
//! M_frame = Translate(T) · Translate(p) · R · S · Translate(−p) · M_base
//! ```
//!
//! applied *after* the object's own base transforms, in its parent's frame. So an object turns
//! and scales about its pivot (by default its centre, where the base file put it) and then
//! moves by `T` along the parent's axes, wherever and however the base file placed it. In SDF
//! (each transform statement applies after the earlier ones) that is four statements appended
//! after the base file's: translate −p, scale S, rotate R, translate p + T.

use super::motion::{self, TrackPose};
use super::orbit;
use super::spec::{Animation, SceneNames, Source, TargetKind, Track};
use super::tidy::{tidy, tidy3};
use anim_core::diag::{Diagnostic, Loc};
use anim_core::limits;
use anim_core::math::Transform;
use anim_core::scene::Geometry;
use anim_core::sdf::ast::{MotionDef, NameRef, RenderDef, Statement, StatementKind, TransformOp};
use glam::{DVec3, Vec3};
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// The base scene: its statements without render lines, and what each name is.
pub struct BaseScene {
    pub statements: Vec<Statement>,
    kinds: BTreeMap<String, TargetKind>,
    default_camera: Option<String>,
}

impl BaseScene {
    pub fn new(statements: Vec<Statement>) -> BaseScene {
        let mut kinds = BTreeMap::new();
        let mut render_camera = None;
        let mut first_camera = None;
        for s in &statements {
            let entry = match &s.kind {
                StatementKind::Shape { name, .. } => Some((name, TargetKind::Shape)),
                StatementKind::Composite { name, .. } => Some((name, TargetKind::Composite)),
                StatementKind::Light(l) => Some((&l.name, TargetKind::Light)),
                StatementKind::Camera(c) => {
                    first_camera.get_or_insert_with(|| c.name.clone());
                    Some((&c.name, TargetKind::Camera))
                }
                StatementKind::Render(r) => {
                    render_camera.get_or_insert_with(|| r.camera.name.clone());
                    None
                }
                _ => None,
            };
            // A later definition of a name replaces the earlier one (docs/scene-language.md §2).
            if let Some((name, kind)) = entry {
                kinds.insert(name.clone(), kind);
            }
        }
        let default_camera = render_camera
            .filter(|c| kinds.get(c) == Some(&TargetKind::Camera))
            .or(first_camera);
        let statements = statements
            .into_iter()
            .filter(|s| !matches!(s.kind, StatementKind::Render(_)))
            .collect();
        BaseScene {
            statements,
            kinds,
            default_camera,
        }
    }

    /// `name`'s own transform statements composed as the scene builder composes them for
    /// generated frames (`TransformOrder::World`: each applies after the ones before it).
    pub fn own_transform(&self, name: &str) -> Transform {
        let ops = self.statements.iter().flat_map(|s| match &s.kind {
            StatementKind::Transform { target, ops } if target.name == name => ops.as_slice(),
            _ => &[],
        });
        ops.filter_map(op_transform)
            .fold(Transform::IDENTITY, |m, t| t.then_after(&m))
    }

    /// The last definition of `name` (later definitions replace earlier ones).
    fn definition(&self, name: &str) -> Option<&StatementKind> {
        self.statements
            .iter()
            .rev()
            .map(|s| &s.kind)
            .find(|k| match k {
                StatementKind::Shape { name: n, .. } | StatementKind::Composite { name: n, .. } => {
                    n == name
                }
                StatementKind::Light(l) => l.name == name,
                StatementKind::Camera(c) => c.name == name,
                _ => false,
            })
    }

    /// Bounding box of `name` in its parent's frame: its geometry (or its children) under
    /// its own transforms.
    fn local_bounds(&self, name: &str, depth: usize) -> Option<Bounds> {
        if depth > limits::MAX_NESTING {
            return None;
        }
        let own = match self.definition(name)? {
            StatementKind::Shape { geometry, .. } => Bounds::of_geometry(geometry),
            StatementKind::Composite { children, .. } => children
                .iter()
                .filter_map(|c| self.local_bounds(&c.name, depth + 1))
                .reduce(Bounds::union)?,
            StatementKind::Light(l) => Bounds::point(l.position),
            StatementKind::Camera(c) => Bounds::point(c.eye),
            _ => return None,
        };
        Some(own.transformed(&self.own_transform(name)))
    }

    /// The default pivot of `name`: the centre of its bounding box where the base scene puts
    /// it (in its parent's frame); a light's or camera's position.
    pub fn default_pivot(&self, name: &str) -> DVec3 {
        self.local_bounds(name, 0)
            .map(|b| b.center())
            .filter(|c| c.is_finite())
            .unwrap_or(DVec3::ZERO)
    }
}

impl SceneNames for BaseScene {
    fn kind_of(&self, name: &str) -> Option<TargetKind> {
        self.kinds.get(name).copied()
    }

    fn names(&self) -> Vec<&str> {
        self.kinds.keys().map(String::as_str).collect()
    }

    fn default_camera(&self) -> Option<&str> {
        self.default_camera.as_deref()
    }
}

/// The transform of one operation, as the scene builder makes it; `None` for a zero scale or
/// axis, which the builder rejects (the base scene has loaded, so none is left).
fn op_transform(op: &TransformOp) -> Option<Transform> {
    match *op {
        TransformOp::Translate(v) => Some(Transform::translate(v)),
        TransformOp::Rotate { degrees, axis } => Transform::rotate(degrees, axis),
        TransformOp::Scale(s) => Transform::scale(s),
    }
}

/// An axis-aligned box in f64. `anim_core::math::Aabb` is f32 and padded for ray traversal; the
/// default pivots written into frames need the exact centre.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Bounds {
    lo: DVec3,
    hi: DVec3,
}

impl Bounds {
    fn point(p: DVec3) -> Bounds {
        Bounds { lo: p, hi: p }
    }

    fn around(points: &[DVec3], radius: f64) -> Bounds {
        let r = DVec3::splat(limits::fixed_radius(radius));
        let lo = points.iter().copied().fold(DVec3::INFINITY, DVec3::min);
        let hi = points.iter().copied().fold(DVec3::NEG_INFINITY, DVec3::max);
        Bounds {
            lo: lo - r,
            hi: hi + r,
        }
    }

    /// Object-space bounds, loose for cylinders and cones (a sphere around each end); an
    /// infinite plane counts as its anchor point.
    fn of_geometry(g: &Geometry) -> Bounds {
        if let Some((points, radius)) = g.span() {
            return Bounds::around(&points, radius);
        }
        match g {
            Geometry::Plane { point, .. } => Bounds::point(*point),
            Geometry::Mesh(m) => m.mesh().map_or(Bounds::point(DVec3::ZERO), |m| {
                let b = m.bounds();
                Bounds::around(&[b.min.as_dvec3(), b.max.as_dvec3()], 0.0)
            }),
            // Every other primitive has a span.
            _ => Bounds::point(DVec3::ZERO),
        }
    }

    fn union(self, o: Bounds) -> Bounds {
        Bounds {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }

    /// The box around this box's eight corners mapped by `t`.
    fn transformed(&self, t: &Transform) -> Bounds {
        let corners: [DVec3; 8] = std::array::from_fn(|i| {
            t.point(DVec3::new(
                if i & 1 == 0 { self.lo.x } else { self.hi.x },
                if i & 2 == 0 { self.lo.y } else { self.hi.y },
                if i & 4 == 0 { self.lo.z } else { self.hi.z },
            ))
        });
        Bounds::around(&corners, 0.0)
    }

    fn center(&self) -> DVec3 {
        (self.lo + self.hi) * 0.5
    }
}

fn color(v: DVec3) -> Vec3 {
    tidy3(v.max(DVec3::ZERO)).as_vec3()
}

/// Everything needed to write the frames of one animation.
pub struct Generator<'a> {
    pub base: &'a BaseScene,
    pub anim: &'a Animation,
    pub src: &'a Source,
    /// Each track's pivot: its own or the default.
    pivots: Vec<DVec3>,
    /// The spec's file name, for the frame header.
    spec_name: String,
}

impl<'a> Generator<'a> {
    pub fn new(base: &'a BaseScene, anim: &'a Animation, src: &'a Source) -> Self {
        let pivots = anim
            .tracks
            .iter()
            .map(|t| t.pivot.unwrap_or_else(|| base.default_pivot(&t.target)))
            .collect();
        let spec_name = src
            .path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        Generator {
            base,
            anim,
            src,
            pivots,
            spec_name,
        }
    }

    fn loc(&self) -> Loc {
        Loc {
            file: self.src.path.clone(),
            line: 1,
            col: 1,
        }
    }

    fn statement(&self, kind: StatementKind) -> Statement {
        Statement::new(kind, self.loc())
    }

    /// The statements of frame `i`.
    pub fn frame_statements(&self, i: usize) -> Result<Vec<Statement>, Vec<Diagnostic>> {
        let anim = self.anim;
        // A blurred frame states the scene at the middle of its exposure (see `shutter`).
        let t = if anim.shutter > 0.0 {
            anim.shutter_time(i, 0.5)
        } else {
            anim.time(i)
        };
        let when = || format!("at frame {i} (t = {} s)", tidy(t));
        let mut out: Vec<Statement> = self.base.statements.clone();

        if let Some(o) = &anim.orbit {
            let pose = orbit::pose_at(o, t, anim.duration()).ok_or_else(|| {
                vec![self.src.error(
                    &["orbit.look_at", "orbit"],
                    format!(
                        "{} the orbiting camera would look straight up or down",
                        when()
                    ),
                )]
            })?;
            // The orbit sets the camera outright: its base transforms would move it off.
            out.retain(|s| !matches!(&s.kind, StatementKind::Transform { target, .. } if target.name == anim.camera));
            for s in &mut out {
                if let StatementKind::Camera(c) = &mut s.kind {
                    if c.name == anim.camera {
                        c.eye = tidy3(pose.eye);
                        c.dir = tidy3(pose.dir);
                        c.up = pose.up;
                    }
                }
            }
        }

        if let Some(ch) = &anim.ambient {
            let v = color(ch.at(t).unwrap_or(DVec3::ZERO));
            set_or_append(
                &mut out,
                |k| matches!(k, StatementKind::Ambient(_)),
                StatementKind::Ambient(v),
                self,
            );
        }
        if let Some(ch) = &anim.background {
            let v = color(ch.at(t).unwrap_or(DVec3::ZERO));
            set_or_append(
                &mut out,
                |k| matches!(k, StatementKind::Background(_)),
                StatementKind::Background(v),
                self,
            );
        }

        for (track, pivot) in anim.tracks.iter().zip(&self.pivots) {
            self.apply_parameters(track, t, &mut out, &when)?;
            for op in self.motion(track, *pivot, t, &when)? {
                out.push(self.statement(StatementKind::Transform {
                    target: NameRef {
                        name: track.target.clone(),
                        loc: self.loc(),
                    },
                    ops: vec![op],
                }));
            }
        }

        if anim.shutter > 0.0 {
            let moving = self.exposure_motion(i, t)?;
            out.extend(moving);
        }

        out.push(self.statement(StatementKind::Render(RenderDef {
            camera: NameRef {
                name: anim.camera.clone(),
                loc: self.loc(),
            },
            output: anim.output.image(i, anim.digits()),
            width: anim.width,
            height: anim.height,
            samples: anim.samples,
        })));
        Ok(out)
    }

    /// Keyed light and camera parameters, set in the definitions themselves.
    fn apply_parameters(
        &self,
        track: &Track,
        t: f64,
        out: &mut [Statement],
        when: &dyn Fn() -> String,
    ) -> Result<(), Vec<Diagnostic>> {
        let brightness = track.brightness.as_ref().and_then(|c| c.at(t));
        let rgb = track.color.as_ref().and_then(|c| c.at(t));
        let fov = match track.fov.as_ref().and_then(|c| c.at(t).map(|v| (v, c))) {
            Some((v, ch)) if !limits::fov_is_valid(v) => {
                return Err(vec![self.src.error(
                    &[&ch.path],
                    format!(
                        "{} the field of view of '{}' is {}°, outside 0–180° (a smooth curve overshoots here: add a key or use another interp)",
                        when(),
                        track.target,
                        tidy(v)
                    ),
                )]);
            }
            other => other.map(|(v, _)| v),
        };
        for s in out.iter_mut() {
            match &mut s.kind {
                StatementKind::Light(l) if l.name == track.target => {
                    if let Some(b) = brightness {
                        // A smooth curve may dip below zero between keys; light cannot.
                        l.brightness = tidy(b.max(0.0)) as f32;
                    }
                    if let Some(c) = rgb {
                        l.color = color(c);
                    }
                }
                StatementKind::Camera(c) if c.name == track.target => {
                    if let Some(f) = fov {
                        c.fov_x_deg = tidy(f);
                    }
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// The transform operations that move `track`'s target at time `t` (see the module doc).
    fn motion(
        &self,
        track: &Track,
        pivot: DVec3,
        t: f64,
        when: &dyn Fn() -> String,
    ) -> Result<Vec<TransformOp>, Vec<Diagnostic>> {
        Ok(self.pose(track, t, when)?.ops(pivot, track.axis))
    }

    /// Where `track` puts its target at time `t`; an error if its scale is 0 there.
    fn pose(
        &self,
        track: &Track,
        t: f64,
        when: &dyn Fn() -> String,
    ) -> Result<TrackPose, Vec<Diagnostic>> {
        let pose = TrackPose::at(track, t);
        if let Some(ch) = &track.scale {
            if pose.scale.cmpeq(DVec3::ZERO).any() {
                return Err(vec![self.src.error(
                    &[&ch.path],
                    format!(
                        "{} the scale of '{}' passes through 0, which cannot be rendered",
                        when(),
                        track.target
                    ),
                )]);
            }
        }
        Ok(pose)
    }

    /// The `motion` lines of frame `i`, whose statements stand at `mid`, the middle of its
    /// exposure (see `shutter`): for each thing that moves during the exposure, its motion
    /// at evenly spread instants.
    fn exposure_motion(&self, i: usize, mid: f64) -> Result<Vec<Statement>, Vec<Diagnostic>> {
        let anim = self.anim;
        let steps = motion::steps(anim, i);
        let instants: Vec<(f64, f64)> = (0..=steps)
            .map(|j| {
                let u = j as f64 / steps as f64;
                (tidy(u), anim.shutter_time(i, u))
            })
            .collect();
        let mut out = Vec::new();
        let mut add = |target: &str, deltas: Vec<Vec<TransformOp>>| {
            if deltas.iter().all(Vec::is_empty) {
                return;
            }
            for (&(u, _), ops) in instants.iter().zip(deltas) {
                out.push(self.statement(StatementKind::Motion(MotionDef {
                    target: NameRef {
                        name: target.to_string(),
                        loc: self.loc(),
                    },
                    at: u,
                    ops,
                })));
            }
        };
        if let Some(o) = &anim.orbit {
            let pose = |t: f64| {
                orbit::pose_at(o, t, anim.duration()).ok_or_else(|| {
                    vec![self.src.error(
                        &["orbit.look_at", "orbit"],
                        format!(
                            "at frame {i} (t = {} s) the orbiting camera would look straight up or down",
                            tidy(t)
                        ),
                    )]
                })
            };
            let centre = pose(mid)?;
            let deltas = instants
                .iter()
                .map(|&(_, t)| Ok(motion::camera_delta_ops(&centre, &pose(t)?)))
                .collect::<Result<_, Vec<Diagnostic>>>()?;
            add(&anim.camera, deltas);
        }
        // Tracks on one target compose (each applies after the one before), so a target's
        // motion undoes all of them at the middle and applies all of them at the instant.
        let mut targets: Vec<&str> = Vec::new();
        for t in &anim.tracks {
            if !targets.contains(&t.target.as_str()) {
                targets.push(&t.target);
            }
        }
        let when = || format!("during frame {i}");
        for target in targets {
            let tracks: Vec<(&Track, DVec3)> = anim
                .tracks
                .iter()
                .zip(self.pivots.iter().copied())
                .filter(|(t, _)| t.target == target)
                .filter(|(t, _)| t.translate.is_some() || t.rotate.is_some() || t.scale.is_some())
                .collect();
            let poses_at = |t: f64| -> Result<Vec<TrackPose>, Vec<Diagnostic>> {
                tracks
                    .iter()
                    .map(|(tr, _)| self.pose(tr, t, &when))
                    .collect()
            };
            let centre = poses_at(mid)?;
            let poses: Vec<Vec<TrackPose>> = instants
                .iter()
                .map(|&(_, t)| poses_at(t))
                .collect::<Result<_, _>>()?;
            if poses.iter().all(|p| *p == centre) {
                continue;
            }
            let deltas = poses
                .iter()
                .map(|at| match tracks.as_slice() {
                    [(track, pivot)] => motion::delta_ops(&centre[0], &at[0], *pivot, track.axis),
                    _ => {
                        let placed = |ps: &[TrackPose]| -> Vec<TransformOp> {
                            ps.iter()
                                .zip(&tracks)
                                .flat_map(|(p, (tr, pivot))| p.ops(*pivot, tr.axis))
                                .collect()
                        };
                        let mut ops = motion::inverse_ops(&placed(&centre));
                        ops.extend(placed(at));
                        motion::simplify(ops)
                    }
                })
                .collect();
            add(target, deltas);
        }
        Ok(out)
    }

    /// The complete SDF text of frame `i`.
    pub fn frame_text(&self, i: usize) -> Result<String, Vec<Diagnostic>> {
        let statements = self.frame_statements(i)?;
        let anim = self.anim;
        let mut text = String::new();
        let _ = writeln!(
            text,
            "# Frame {i} of {} (t = {} s at {} fps), generated from {} {} {}.",
            anim.frames,
            tidy(anim.time(i)),
            anim.fps,
            self.spec_name,
            anim_core::sdf::GENERATED_FRAME_SIGNATURE,
            env!("CARGO_PKG_VERSION")
        );
        if anim.shutter > 0.0 {
            let _ = writeln!(
                text,
                "# Shutter open from t = {} to {} s: the statements give the scene at t = {} s, the motion lines where moving things are meanwhile.",
                tidy(anim.shutter_time(i, 0.0)),
                tidy(anim.shutter_time(i, 1.0)),
                tidy(anim.shutter_time(i, 0.5))
            );
        }
        let _ = writeln!(
            text,
            "# Edit the spec and run `anim generate` again rather than this file."
        );
        for s in statements {
            let _ = writeln!(text, "{s}");
        }
        Ok(text)
    }
}

/// Sets every statement matching `is` to `kind`, or appends `kind` if none matches.
fn set_or_append(
    out: &mut Vec<Statement>,
    is: impl Fn(&StatementKind) -> bool,
    kind: StatementKind,
    g: &Generator,
) {
    let mut found = false;
    for s in out.iter_mut() {
        if is(&s.kind) {
            s.kind = kind.clone();
            found = true;
        }
    }
    if !found {
        out.push(g.statement(kind));
    }
}
