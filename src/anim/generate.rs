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

use super::orbit;
use super::spec::{Animation, SceneNames, Source, TargetKind, Track};
use crate::diag::{Diagnostic, Loc};
use crate::scene::Geometry;
use crate::sdf::ast::{NameRef, RenderDef, Statement, StatementKind, TransformOp};
use glam::{DMat4, DVec3, Vec3};
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// The base scene: its statements without render lines, and what each name is.
pub struct BaseScene {
    pub statements: Vec<Statement>,
    kinds: BTreeMap<String, TargetKind>,
    default_camera: Option<String>,
}

/// Deeper than any real composite tree; guards against a malformed cycle.
const MAX_NESTING: usize = 256;

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
            // A later definition of a name replaces the earlier one (DIALECT.md).
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

    /// The product of `name`'s own transform statements, in file order (each applies after
    /// the ones before it: `M ← T·M`, the renderer's default rule).
    pub fn own_transform(&self, name: &str) -> DMat4 {
        let mut m = DMat4::IDENTITY;
        for s in &self.statements {
            if let StatementKind::Transform { target, ops } = &s.kind {
                if target.name == name {
                    for op in ops {
                        m = op_matrix(op) * m;
                    }
                }
            }
        }
        m
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
    fn local_bounds(&self, name: &str, depth: usize) -> Option<(DVec3, DVec3)> {
        if depth > MAX_NESTING {
            return None;
        }
        let (lo, hi) = match self.definition(name)? {
            StatementKind::Shape { geometry, .. } => geometry_bounds(geometry),
            StatementKind::Composite { children, .. } => {
                let mut acc: Option<(DVec3, DVec3)> = None;
                for c in children {
                    if let Some((lo, hi)) = self.local_bounds(&c.name, depth + 1) {
                        acc = Some(match acc {
                            Some((a, b)) => (a.min(lo), b.max(hi)),
                            None => (lo, hi),
                        });
                    }
                }
                acc?
            }
            StatementKind::Light(l) => (l.position, l.position),
            StatementKind::Camera(c) => (c.eye, c.eye),
            _ => return None,
        };
        Some(transform_box(&self.own_transform(name), lo, hi))
    }

    /// The default pivot of `name`: the centre of its bounding box where the base scene puts
    /// it (in its parent's frame); a light's or camera's position.
    pub fn default_pivot(&self, name: &str) -> DVec3 {
        self.local_bounds(name, 0)
            .map(|(lo, hi)| (lo + hi) * 0.5)
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

fn op_matrix(op: &TransformOp) -> DMat4 {
    match *op {
        TransformOp::Translate(v) => DMat4::from_translation(v),
        TransformOp::Rotate { degrees, axis } => match axis.try_normalize() {
            Some(a) => DMat4::from_axis_angle(a, degrees.to_radians()),
            None => DMat4::IDENTITY,
        },
        TransformOp::Scale(s) => DMat4::from_scale(s),
    }
}

/// Object-space bounds; infinite planes count as their anchor point.
fn geometry_bounds(g: &Geometry) -> (DVec3, DVec3) {
    let around = |points: &[DVec3], r: f64| {
        let lo = points.iter().copied().fold(DVec3::INFINITY, DVec3::min);
        let hi = points.iter().copied().fold(DVec3::NEG_INFINITY, DVec3::max);
        (lo - DVec3::splat(r.abs()), hi + DVec3::splat(r.abs()))
    };
    match g {
        Geometry::Sphere { center, radius } => around(&[*center], *radius),
        Geometry::Box { p1, p2 } => around(&[*p1, *p2], 0.0),
        Geometry::Plane { point, .. } => (*point, *point),
        Geometry::Triangle { vertices } => around(vertices, 0.0),
        Geometry::Cylinder { p1, p2, radius } => around(&[*p1, *p2], *radius),
        Geometry::Cone { base, tip, radius } => around(&[*base, *tip], *radius),
    }
}

fn transform_box(m: &DMat4, lo: DVec3, hi: DVec3) -> (DVec3, DVec3) {
    let mut out = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for i in 0..8 {
        let corner = DVec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        let p = m.transform_point3(corner);
        out = (out.0.min(p), out.1.max(p));
    }
    out
}

/// Rounds to 12 significant digits, so that generated files read `12` rather than
/// `11.999999999999998`; far below anything visible, and deterministic.
pub fn tidy(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return if x == 0.0 { 0.0 } else { x };
    }
    let scale = 10f64.powi(11 - x.abs().log10().floor() as i32);
    if !scale.is_finite() || scale == 0.0 {
        return x;
    }
    let r = (x * scale).round() / scale;
    if r.is_finite() {
        r
    } else {
        x
    }
}

/// [`tidy`] for a vector, to 12 significant digits of its largest component, so that the
/// round-off of a rotation (`2.4e-16` beside `4`) reads as 0.
fn tidy3(v: DVec3) -> DVec3 {
    let m = v.abs().max_element();
    if m == 0.0 || !m.is_finite() {
        return DVec3::new(tidy(v.x), tidy(v.y), tidy(v.z));
    }
    let scale = 10f64.powi(11 - m.log10().floor() as i32);
    if !scale.is_finite() || scale == 0.0 {
        return v;
    }
    let r = (v * scale).round() / scale;
    // `+ 0.0` turns −0 into 0, which prints as `0` rather than `-0`.
    if r.is_finite() {
        r + DVec3::ZERO
    } else {
        v
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
    pub fn frame_statements(&self, i: usize) -> Result<Vec<Statement>, Box<Diagnostic>> {
        let anim = self.anim;
        let t = anim.time(i);
        let when = || format!("at frame {i} (t = {} s)", tidy(t));
        let mut out: Vec<Statement> = self.base.statements.clone();

        if let Some(o) = &anim.orbit {
            let pose = orbit::pose_at(o, t, anim.duration()).ok_or_else(|| {
                Box::new(self.src.error(
                    &["orbit.look_at", "orbit"],
                    format!(
                        "{} the orbiting camera would look straight up or down",
                        when()
                    ),
                ))
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
    ) -> Result<(), Box<Diagnostic>> {
        let brightness = track.brightness.as_ref().and_then(|c| c.at(t));
        let rgb = track.color.as_ref().and_then(|c| c.at(t));
        let fov = match track.fov.as_ref().and_then(|c| c.at(t).map(|v| (v, c))) {
            Some((v, ch)) if !(v > 0.0 && v < 180.0) => {
                return Err(Box::new(self.src.error(
                    &[&ch.path],
                    format!(
                        "{} the field of view of '{}' is {}°, outside 0–180° (a smooth curve overshoots here: add a key or use another interp)",
                        when(),
                        track.target,
                        tidy(v)
                    ),
                )));
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
    ) -> Result<Vec<TransformOp>, Box<Diagnostic>> {
        let translate = tidy3(
            track
                .translate
                .as_ref()
                .and_then(|c| c.at(t))
                .unwrap_or(DVec3::ZERO),
        );
        let degrees = tidy(track.rotate.as_ref().and_then(|c| c.at(t)).unwrap_or(0.0));
        let scale = tidy3(
            track
                .scale
                .as_ref()
                .and_then(|c| c.at(t))
                .unwrap_or(DVec3::ONE),
        );
        if let Some(ch) = &track.scale {
            if scale.cmpeq(DVec3::ZERO).any() {
                return Err(Box::new(self.src.error(
                    &[&ch.path],
                    format!(
                        "{} the scale of '{}' passes through 0, which cannot be rendered",
                        when(),
                        track.target
                    ),
                )));
            }
        }
        let mut ops = Vec::new();
        let turns = degrees != 0.0;
        let scales = scale != DVec3::ONE;
        if turns || scales {
            let p = tidy3(pivot);
            if p != DVec3::ZERO {
                ops.push(TransformOp::Translate(-p));
            }
            if scales {
                ops.push(TransformOp::Scale(scale));
            }
            if turns {
                ops.push(TransformOp::Rotate {
                    degrees,
                    axis: track.axis,
                });
            }
            let back = tidy3(p + translate);
            if back != DVec3::ZERO {
                ops.push(TransformOp::Translate(back));
            }
        } else if translate != DVec3::ZERO {
            ops.push(TransformOp::Translate(translate));
        }
        Ok(ops)
    }

    /// The complete SDF text of frame `i`.
    pub fn frame_text(&self, i: usize) -> Result<String, Box<Diagnostic>> {
        let statements = self.frame_statements(i)?;
        let anim = self.anim;
        let mut text = String::new();
        let _ = writeln!(
            text,
            "# Frame {i} of {} (t = {} s at {} fps), generated from {} by anim {}.",
            anim.frames,
            tidy(anim.time(i)),
            anim.fps,
            self.spec_name,
            env!("CARGO_PKG_VERSION")
        );
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

/// Used by tests and the pivot logic: the matrix of a list of ops applied in order.
pub fn ops_matrix(ops: &[TransformOp]) -> DMat4 {
    ops.iter().fold(DMat4::IDENTITY, |m, op| op_matrix(op) * m)
}
