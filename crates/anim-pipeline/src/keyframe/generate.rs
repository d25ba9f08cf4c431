//! Frame generation: the base scene's statements, with the tracks applied at each frame's
//! time, written back out as one complete SDF file per frame.
//!
//! How keyed motion composes with the base file (documented in docs/animation.md): a track's
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

pub use super::base::BaseScene;
use super::keyed;
use super::motion::{self, TrackPose};
use super::orbit::{self, Pose};
use super::placement::Placer;
use super::ranges;
use super::spec_file::{Animation, Source, TargetKind};
use super::split::{Split, STATIC_FILE};
use super::tidy::tidy;
use anim_core::diag::{Diagnostic, Loc};
use anim_core::sdf::ast::{MotionDef, NameRef, RenderDef, Statement, StatementKind, TransformOp};
use glam::DVec3;
use std::fmt::Write as _;

/// Everything needed to write the frames of one animation.
pub struct Generator<'a> {
    pub base: &'a BaseScene,
    pub anim: &'a Animation,
    pub src: &'a Source,
    placer: Placer<'a>,
    /// The cameras that a track aims, each with the path of its `look_at`.
    aimed_cameras: Vec<(&'a str, &'a str)>,
    /// The spec's file name, for the frame header.
    spec_name: String,
}

impl<'a> Generator<'a> {
    pub fn new(base: &'a BaseScene, anim: &'a Animation, src: &'a Source) -> Self {
        let spec_name = src
            .path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let aimed_cameras = anim
            .tracks
            .iter()
            .filter(|t| t.kind == TargetKind::Camera)
            .filter_map(|t| Some((t.target.as_str(), t.aim.as_ref()?.path.as_str())))
            .collect();
        Generator {
            base,
            anim,
            src,
            placer: Placer::new(base, anim),
            aimed_cameras,
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

    fn is_aimed_camera(&self, name: &str) -> bool {
        self.aimed_cameras.iter().any(|(c, _)| *c == name)
    }

    /// The pose of the camera that the orbit or a `look_at` moves, at time `t`; `None` for
    /// a camera that neither moves.
    fn camera_rig(
        &self,
        name: &str,
        t: f64,
        when: &dyn Fn() -> String,
    ) -> Option<Result<Pose, Vec<Diagnostic>>> {
        let anim = self.anim;
        if let Some(o) = anim.orbit.as_ref().filter(|_| name == anim.camera) {
            return Some(orbit::pose_at(o, t, anim.duration()).ok_or_else(|| {
                vec![self.src.error(
                    &["orbit.look_at", "orbit"],
                    format!(
                        "{} the orbiting camera would look straight up or down",
                        when()
                    ),
                )]
            }));
        }
        let (_, path) = self.aimed_cameras.iter().find(|(c, _)| *c == name)?;
        let pose = self.placer.camera_pose(name, t)?;
        Some(pose.map_err(|why| vec![self.src.error(&[path], format!("{} {why}", when()))]))
    }

    /// The statements of frame `i`.
    pub fn frame_statements(&self, i: usize) -> Result<Vec<Statement>, Vec<Diagnostic>> {
        let anim = self.anim;
        ranges::check_span(anim, i).map_err(|e| vec![self.src.error(&[&e.path], e.message)])?;
        // A blurred frame states the scene at the middle of its exposure (see `shutter`).
        let t = if anim.shutter > 0.0 {
            anim.shutter_time(i, 0.5)
        } else {
            anim.time(i)
        };
        let when = || format!("at frame {i} (t = {} s)", tidy(t));
        let mut out: Vec<Statement> = self.base.statements.clone();

        let mut rigged = vec![anim.camera.as_str()];
        rigged.extend(self.aimed_cameras.iter().map(|(c, _)| *c));
        rigged.dedup();
        for name in rigged {
            if let Some(pose) = self.camera_rig(name, t, &when) {
                keyed::place_camera(&mut out, name, &pose?);
            }
        }

        keyed::set_ambient_and_background(&mut out, anim, t, &self.loc());

        for (k, track) in anim.tracks.iter().enumerate() {
            keyed::set_parameters(&mut out, track, t, self.src, &when)?;
            keyed::set_material(&mut out, track, t, self.src, &when)?;
            if self.is_aimed_camera(&track.target) {
                continue;
            }
            for op in self.motion(k, t, &when)? {
                out.push(self.statement(StatementKind::Transform {
                    target: NameRef {
                        name: track.target.clone(),
                        loc: self.loc(),
                    },
                    ops: vec![op],
                }));
            }
        }

        // A target follows its parent after all its own tracks have placed it.
        for (target, path) in self.followers() {
            for op in self.follow(target, path, t, &when)? {
                out.push(self.statement(StatementKind::Transform {
                    target: NameRef {
                        name: target.to_string(),
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

        // The last track that keys a thing's `visible` says whether it is shown.
        let mut shown: Vec<(&str, bool)> = Vec::new();
        for tr in &anim.tracks {
            if let Some(v) = tr.visible.as_ref().and_then(|v| v.at(t)) {
                shown.retain(|(name, _)| *name != tr.target);
                shown.push((&tr.target, v != 0.0));
            }
        }
        let hidden: Vec<&str> = shown
            .iter()
            .filter(|(_, on)| !on)
            .map(|(name, _)| *name)
            .collect();
        keyed::hide(&mut out, self.base, &hidden);

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

    /// The transform operations that move track `k`'s target at time `t` (see the module
    /// doc).
    fn motion(
        &self,
        k: usize,
        t: f64,
        when: &dyn Fn() -> String,
    ) -> Result<Vec<TransformOp>, Vec<Diagnostic>> {
        let track = &self.anim.tracks[k];
        Ok(self
            .pose(k, t, when)?
            .ops(self.placer.pivot_at(k, t), track.axis))
    }

    /// The targets that follow a parent (each once) with the path of their `parent`, but
    /// aimed cameras, whose pose has it.
    fn followers(&self) -> Vec<(&'a str, &'a str)> {
        let anim: &'a Animation = self.anim;
        let mut out: Vec<(&str, &str)> = Vec::new();
        for track in &anim.tracks {
            if let Some(p) = &track.parent {
                if !self.is_aimed_camera(&track.target)
                    && !out.iter().any(|(t, _)| *t == track.target)
                {
                    out.push((&track.target, &p.path));
                }
            }
        }
        out
    }

    /// The operations by which `target` follows its parent at time `t`.
    fn follow(
        &self,
        target: &str,
        path: &str,
        t: f64,
        when: &dyn Fn() -> String,
    ) -> Result<Vec<TransformOp>, Vec<Diagnostic>> {
        self.placer
            .follow(target, t, true)
            .map_err(|why| vec![self.src.error(&[path], format!("{} {why}", when()))])
    }

    /// Where track `k` puts its target at time `t`; an error if its scale is 0 there or its
    /// aim cannot be taken.
    fn pose(
        &self,
        k: usize,
        t: f64,
        when: &dyn Fn() -> String,
    ) -> Result<TrackPose, Vec<Diagnostic>> {
        let track = &self.anim.tracks[k];
        let pose = self.placer.pose(k, t).map_err(|why| {
            let path = track
                .aim
                .as_ref()
                .map_or(track.path.as_str(), |a| a.path.as_str());
            vec![self.src.error(&[path], format!("{} {why}", when()))]
        })?;
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
        let (t0, t1) = (anim.shutter_time(i, 0.0), anim.shutter_time(i, 1.0));
        let steps = motion::steps(anim, i, self.placer.degrees_turned(t0, t1));
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
        let when = || format!("during frame {i}");
        let mut cameras: Vec<&str> = anim.orbit.iter().map(|_| anim.camera.as_str()).collect();
        cameras.extend(self.aimed_cameras.iter().map(|(c, _)| *c));
        for name in cameras {
            let pose = |t: f64| {
                self.camera_rig(name, t, &|| format!("at frame {i} (t = {} s)", tidy(t)))
                    .unwrap_or_else(|| Err(Vec::new()))
            };
            let centre = pose(mid)?;
            let deltas = instants
                .iter()
                .map(|&(_, t)| Ok(motion::camera_delta_ops(&centre, &pose(t)?)))
                .collect::<Result<_, Vec<Diagnostic>>>()?;
            add(name, deltas);
        }
        // Tracks on one target compose (each applies after the one before), so a target's
        // motion undoes all of them at the middle and applies all of them at the instant.
        let mut targets: Vec<&str> = Vec::new();
        for t in anim
            .tracks
            .iter()
            .filter(|t| !self.is_aimed_camera(&t.target))
        {
            if !targets.contains(&t.target.as_str()) {
                targets.push(&t.target);
            }
        }
        let followers = self.followers();
        for target in targets {
            let parent = followers
                .iter()
                .find(|(t, _)| *t == target)
                .map(|(_, p)| *p);
            if let Some(deltas) = self.target_motion(target, parent, mid, &instants, &when)? {
                add(target, deltas);
            }
        }
        Ok(out)
    }

    /// The motion of `target` (which follows the parent at `parent`, the path of its
    /// `parent`) at each instant, from where it is at `mid`; `None` if it stays put.
    fn target_motion(
        &self,
        target: &str,
        parent: Option<&str>,
        mid: f64,
        instants: &[(f64, f64)],
        when: &dyn Fn() -> String,
    ) -> Result<Option<Vec<Vec<TransformOp>>>, Vec<Diagnostic>> {
        let anim = self.anim;
        let tracks: Vec<usize> = (0..anim.tracks.len())
            .filter(|&k| anim.tracks[k].target == target && anim.tracks[k].moves())
            .collect();
        // The poses of its tracks, and then the operations that place it by them and by
        // the parent it follows.
        type Placed = (Vec<TrackPose>, Vec<TransformOp>, Vec<TransformOp>);
        let placed = |t: f64| -> Result<Placed, Vec<Diagnostic>> {
            let mut poses = Vec::new();
            let mut ops = Vec::new();
            for &k in &tracks {
                let pose = self.pose(k, t, when)?;
                ops.extend(pose.ops(self.placer.pivot_at(k, t), anim.tracks[k].axis));
                poses.push(pose);
            }
            let follow = match parent {
                Some(path) => self.follow(target, path, t, when)?,
                None => Vec::new(),
            };
            ops.extend(follow.iter().copied());
            Ok((poses, ops, follow))
        };
        let (centre, centre_ops, centre_follow) = placed(mid)?;
        let at: Vec<Placed> = instants
            .iter()
            .map(|&(_, t)| placed(t))
            .collect::<Result<_, _>>()?;
        if at
            .iter()
            .all(|(p, _, f)| *p == centre && *f == centre_follow)
        {
            return Ok(None);
        }
        let deltas = at
            .iter()
            .map(|(poses, ops, _)| match tracks.as_slice() {
                [k] if anim.tracks[*k].aim.is_none() && parent.is_none() => motion::delta_ops(
                    &centre[0],
                    &poses[0],
                    self.placer.pivots[*k],
                    anim.tracks[*k].axis,
                ),
                _ => {
                    let mut delta = motion::inverse_ops(&centre_ops);
                    delta.extend(ops.iter().copied());
                    motion::simplify(delta)
                }
            })
            .collect();
        Ok(Some(deltas))
    }

    /// The complete SDF text of frame `i`.
    pub fn frame_text(&self, i: usize) -> Result<String, Vec<Diagnostic>> {
        Ok(self.write_frame(i, &self.frame_statements(i)?, None))
    }

    /// The text of frame `i`, whose statements are `statements`: whole, or with `split`
    /// its static part included from [`STATIC_FILE`] and the rest written out.
    pub fn write_frame(&self, i: usize, statements: &[Statement], split: Option<&Split>) -> String {
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
        if split.is_some() {
            let _ = writeln!(text, "include {STATIC_FILE}");
        }
        for s in statements {
            if !split.is_some_and(|split| split.is_static(s)) {
                let _ = writeln!(text, "{s}");
            }
        }
        text
    }

    /// The text of [`STATIC_FILE`]: the base scene's statements that `split` finds static.
    pub fn static_text(&self, split: &Split) -> String {
        let mut text = format!(
            "# The part of every frame of {} that no track changes, generated {} {}: each frame includes it.\n\
             # Edit the spec and run `anim generate` again rather than this file.\n",
            self.spec_name,
            anim_core::sdf::GENERATED_FRAME_SIGNATURE,
            env!("CARGO_PKG_VERSION")
        );
        for s in self.base.statements.iter().filter(|s| split.is_static(s)) {
            let _ = writeln!(text, "{s}");
        }
        text
    }
}
