//! Where things are at a time: each target's placement by its tracks, the centre of a moving
//! object (what `look_at: Object(…)` follows), and the turn of a track that looks at
//! something. The rules are documented for users in `docs/animation.md` ("Aim").

use super::base::{ops_transform, BaseScene};
use super::follow::follow_ops;
use super::motion::TrackPose;
use super::orbit::Pose;
use super::rotation::{can_look, facing, rolled_up};
use super::spec_file::{Aim, AimTarget, AlongPath, Animation, Parent, PathMotion, TargetKind};
use super::tidy::tidy3;
use anim_core::limits;
use anim_core::math::Transform;
use anim_core::sdf::ast::{StatementKind, TransformOp};
use glam::{DMat4, DQuat, DVec3};
use std::collections::BTreeMap;

/// Places the targets of one animation's tracks. What the base scene says of them (centres,
/// the composites above them, the cameras' eyes) is looked up once here: a frame asks for it
/// many times, and finding it in the statements costs their number.
pub struct Placer<'a> {
    pub anim: &'a Animation,
    base: &'a BaseScene,
    /// Each track's pivot: its own or the default.
    pub pivots: Vec<DVec3>,
    /// The centre of each object looked at or followed, in its parent's frame, as the base
    /// scene puts it.
    centres: BTreeMap<String, DVec3>,
    /// The composites above each object aimed or looked at, nearest first, with their own
    /// transforms (the first composite that lists it, at each level).
    ancestors: BTreeMap<String, Vec<(String, Transform)>>,
    /// Each aimed camera's eye where the base scene puts it.
    eyes: BTreeMap<String, DVec3>,
    /// The view direction of each camera that turns along a path, as the base scene puts it.
    views: BTreeMap<String, DVec3>,
    /// Each aimed camera that leads others, as the base scene puts it in the world.
    led_by_cameras: BTreeMap<String, Pose>,
}

/// The gravity `bank` leans against, in scene units (as metres) a second squared.
const GRAVITY: f64 = 9.81;

impl<'a> Placer<'a> {
    pub fn new(base: &'a BaseScene, anim: &'a Animation) -> Self {
        let pivots = anim
            .tracks
            .iter()
            .map(|t| t.pivot.unwrap_or_else(|| base.default_pivot(&t.target)))
            .collect();
        let (mut centres, mut ancestors, mut eyes) =
            (BTreeMap::new(), BTreeMap::new(), BTreeMap::new());
        let mut views = BTreeMap::new();
        for track in anim.tracks.iter().filter(|t| t.along_path.is_some()) {
            let dir = base.statements.iter().rev().find_map(|s| match &s.kind {
                StatementKind::Camera(c) if c.name == track.target => Some(c.dir),
                _ => None,
            });
            if let Some(dir) = dir {
                views.insert(
                    track.target.clone(),
                    base.own_transform(&track.target).vector(dir),
                );
            }
        }
        for track in &anim.tracks {
            let Some(aim) = &track.aim else {
                continue;
            };
            if let AimTarget::Object(name) = &aim.target {
                centres.insert(name.clone(), base.default_pivot(name));
                ancestors.insert(name.clone(), ancestors_of(base, name));
            }
            ancestors.insert(track.target.clone(), ancestors_of(base, &track.target));
            if track.kind == TargetKind::Camera {
                let eye = base.statements.iter().rev().find_map(|s| match &s.kind {
                    StatementKind::Camera(c) if c.name == track.target => Some(c.eye),
                    _ => None,
                });
                if let Some(eye) = eye {
                    let placed = base.own_transform(&track.target).point(eye);
                    eyes.insert(track.target.clone(), placed);
                }
            }
        }
        for parent in anim.tracks.iter().filter_map(|t| t.parent.as_ref()) {
            centres.insert(parent.name.clone(), base.default_pivot(&parent.name));
            ancestors.insert(parent.name.clone(), ancestors_of(base, &parent.name));
        }
        let led_by_cameras = anim
            .tracks
            .iter()
            .filter_map(|t| t.parent.as_ref())
            .filter_map(|p| Some((p.name.clone(), base_pose(base, &p.name)?)))
            .collect();
        Placer {
            anim,
            base,
            pivots,
            centres,
            ancestors,
            eyes,
            views,
            led_by_cameras,
        }
    }

    /// Where track `i` puts its target at time `t`; an aimed object turned to face its
    /// target. `Err` says why an aim cannot be taken.
    pub fn pose(&self, i: usize, t: f64) -> Result<TrackPose, String> {
        let track = &self.anim.tracks[i];
        let mut pose = TrackPose::at(track, t);
        if let (Some(along), Some(travel)) = (&track.along_path, &track.travel) {
            pose.orient = self.along_path(&track.target, along, travel, t)?;
        }
        let Some(aim) = track
            .aim
            .as_ref()
            .filter(|_| track.kind != TargetKind::Camera)
        else {
            return Ok(pose);
        };
        let from = self.pivot_at(i, t) + pose.translate;
        let to = self.world_to_parent(&track.target, self.aim_point(aim, t), t)?;
        let roll = aim.roll.as_ref().and_then(|r| r.at(t)).unwrap_or(0.0);
        pose.orient = facing(aim.forward, to - from, aim.up, roll).ok_or_else(|| {
            if (to - from).length() <= 1e-12 {
                format!("'{}' would look at a point where it stands", track.target)
            } else {
                format!(
                    "'{}' would look straight along its up direction {}",
                    track.target,
                    fmt3(aim.up)
                )
            }
        })?;
        Ok(pose)
    }

    /// The turn that faces `target` the way `travel` goes at time `t`, its up leaning into the
    /// turn by `along.bank`: the sideways acceleration `v²·κ` (speed along the path, curvature
    /// vector) against a gravity of 9.81 down `up`, as an aircraft banks in a coordinated turn.
    fn along_path(
        &self,
        target: &str,
        along: &AlongPath,
        travel: &PathMotion,
        t: f64,
    ) -> Result<DQuat, String> {
        let (dir, curvature) = travel.path.bend(travel.progress(t));
        let speed = travel.speed(t);
        let up = along.up.normalize();
        let leaning = up * GRAVITY + curvature * (speed * speed * along.bank);
        // The bank as a roll about the direction of travel, from `up` to the leaning up.
        let across = |v: DVec3| v - dir * v.dot(dir);
        let (u0, u1) = (across(up), across(leaning));
        let roll = dir.dot(u0.cross(u1)).atan2(u0.dot(u1)).to_degrees();
        let forward = along
            .forward
            .or_else(|| self.views.get(target).copied())
            .unwrap_or(DVec3::NEG_Z);
        facing(forward, dir, up, if roll.is_finite() { roll } else { 0.0 }).ok_or_else(|| {
            format!(
                "'{target}' would face straight along its up direction {} on its path",
                fmt3(along.up)
            )
        })
    }

    /// Track `i`'s pivot at time `t`. An aimed track's pivot moves with its target as the
    /// earlier tracks on it move it, so that the object turns where it is; other tracks keep
    /// the pivot where the base scene puts it (docs/animation.md, "Several tracks").
    pub fn pivot_at(&self, i: usize, t: f64) -> DVec3 {
        let track = &self.anim.tracks[i];
        if track.aim.is_none() {
            return self.pivots[i];
        }
        self.placed_by(&track.target, i, t).point(self.pivots[i])
    }

    /// The transform by which the first `end` tracks place `target` at time `t`, without the
    /// turns of aims (which follow from the placement, not the other way).
    fn placed_by(&self, target: &str, end: usize, t: f64) -> Transform {
        self.anim.tracks[..end]
            .iter()
            .enumerate()
            .filter(|(_, tr)| tr.target == target && tr.moves())
            .fold(Transform::IDENTITY, |m, (j, tr)| {
                let ops = TrackPose::at(tr, t).ops(self.pivot_at(j, t), tr.axis);
                ops_transform(&ops).then_after(&m)
            })
    }

    /// World from the frame of `name`'s parent at time `t`: the placements of the composites
    /// above it.
    fn parent_frame(&self, name: &str, t: f64) -> DMat4 {
        let chain = self.ancestors.get(name).map_or(&[][..], Vec::as_slice);
        chain.iter().fold(DMat4::IDENTITY, |m, (parent, own)| {
            let placed = self.follow_without_aims(parent, t).then_after(
                &self
                    .placed_by(parent, self.anim.tracks.len(), t)
                    .then_after(own),
            );
            placed.world_from_object * m
        })
    }

    /// `p` in the frame where `name`'s tracks move it: the world without the composites
    /// above it and the parent it follows.
    fn world_to_parent(&self, name: &str, p: DVec3, t: f64) -> Result<DVec3, String> {
        let follow = ops_transform(&self.follow(name, t, true)?);
        let m = self.parent_frame(name, t) * follow.world_from_object;
        if m == DMat4::IDENTITY {
            return Ok(p);
        }
        Ok(m.inverse().transform_point3(p))
    }

    /// The centre of `name` in the world at time `t`: the centre of its box where the base
    /// scene puts it, carried by its tracks, the parent it follows and the composites above
    /// it (without the turns of aims, like the pivots).
    pub fn centre_at(&self, name: &str, t: f64) -> DVec3 {
        let local = self
            .placed_by(name, self.anim.tracks.len(), t)
            .point(self.centres.get(name).copied().unwrap_or(DVec3::ZERO));
        let followed = self.follow_without_aims(name, t).point(local);
        self.parent_frame(name, t).transform_point3(followed)
    }

    /// How `name` follows its parent at `t`, without the turns of aims: that asks no aim, so
    /// it cannot fail but by a loop of parents, which the spec's checks refuse.
    fn follow_without_aims(&self, name: &str, t: f64) -> Transform {
        ops_transform(&self.follow(name, t, false).unwrap_or_default())
    }

    /// The parent `name` follows, if a track gives it one.
    fn parent_of(&self, name: &str) -> Option<&'a Parent> {
        let anim: &'a Animation = self.anim;
        anim.tracks
            .iter()
            .filter(|t| t.target == name)
            .find_map(|t| t.parent.as_ref())
    }

    /// Whether a track aims camera `name`: the frames then write its pose, not transforms.
    fn is_aimed_camera(&self, name: &str) -> bool {
        self.anim
            .tracks
            .iter()
            .any(|t| t.target == name && t.kind == TargetKind::Camera && t.aim.is_some())
    }

    /// The operations by which `name` follows its parent at time `t`, after its own tracks
    /// (none without a parent; see `follow`'s module doc). `aims`: whether the parent's
    /// placement has the turns of aims, as the frames place it, or not, as the centres that
    /// aims look at (which must not ask an aim in turn).
    pub fn follow(&self, name: &str, t: f64, aims: bool) -> Result<Vec<TransformOp>, String> {
        self.follow_at(name, t, aims, 0)
    }

    fn follow_at(
        &self,
        name: &str,
        t: f64,
        aims: bool,
        depth: usize,
    ) -> Result<Vec<TransformOp>, String> {
        let Some(parent) = self.parent_of(name) else {
            return Ok(Vec::new());
        };
        if depth > limits::MAX_NESTING {
            return Err(format!(
                "'{name}' follows parents nested more than {} deep",
                limits::MAX_NESTING
            ));
        }
        let p = parent.name.as_str();
        let aimed_camera = self
            .led_by_cameras
            .get(p)
            .filter(|_| aims && self.is_aimed_camera(p));
        let (moved, c0) = match aimed_camera {
            Some(base) => {
                let pose = match self.camera_pose(p, t) {
                    Some(pose) => pose?,
                    None => *base,
                };
                let ops = super::motion::camera_delta_ops(base, &pose);
                (ops_transform(&ops).world_from_object, base.eye)
            }
            None => {
                let frame = self.base_frame(p);
                let before = frame.then_after(&self.base.own_transform(p));
                let now = self.world_at(p, t, aims, depth + 1)?;
                let centre = self.centres.get(p).copied().unwrap_or(DVec3::ZERO);
                (
                    now.world_from_object * before.object_from_world,
                    frame.point(centre),
                )
            }
        };
        Ok(follow_ops(&moved, c0, &parent.follow))
    }

    /// Where `name` is placed in the world at time `t`: its own transforms, its tracks, its
    /// parent, and the same for each composite above it.
    fn world_at(&self, name: &str, t: f64, aims: bool, depth: usize) -> Result<Transform, String> {
        let chain = self.ancestors.get(name).map_or(&[][..], Vec::as_slice);
        let own = self.base.own_transform(name);
        let levels =
            std::iter::once((name, &own)).chain(chain.iter().map(|(a, m)| (a.as_str(), m)));
        let mut m = Transform::IDENTITY;
        for (level, own) in levels {
            let follow = ops_transform(&self.follow_at(level, t, aims, depth)?);
            let tracks = self.tracks_at(level, t, aims)?;
            m = follow.then_after(&tracks.then_after(&own.then_after(&m)));
        }
        Ok(m)
    }

    /// The transform by which all the tracks on `name` move it at time `t`, with the turns of
    /// aims or without.
    fn tracks_at(&self, name: &str, t: f64, aims: bool) -> Result<Transform, String> {
        let mut m = Transform::IDENTITY;
        for (j, tr) in self.anim.tracks.iter().enumerate() {
            if tr.target != name || !tr.moves() {
                continue;
            }
            let pose = if aims {
                self.pose(j, t)?
            } else {
                TrackPose::at(tr, t)
            };
            let ops = pose.ops(self.pivot_at(j, t), tr.axis);
            m = ops_transform(&ops).then_after(&m);
        }
        Ok(m)
    }

    /// World from the frame of `name`'s parent in the base scene: the composites above it.
    fn base_frame(&self, name: &str) -> Transform {
        let chain = self.ancestors.get(name).map_or(&[][..], Vec::as_slice);
        chain
            .iter()
            .fold(Transform::IDENTITY, |m, (_, own)| own.then_after(&m))
    }

    /// The point an aim looks at, in the world, at time `t`.
    fn aim_point(&self, aim: &Aim, t: f64) -> DVec3 {
        match &aim.target {
            AimTarget::Point(p) => *p,
            AimTarget::Keys(k) => k.at(t).unwrap_or(DVec3::ZERO),
            AimTarget::Object(o) => self.centre_at(o, t),
        }
    }

    /// The aimed camera `name`'s pose at time `t`, if a track aims it: its eye where the base
    /// scene and the tracks' translations put it, looking at the target. `Err` says why it
    /// cannot look there.
    pub fn camera_pose(&self, name: &str, t: f64) -> Option<Result<Pose, String>> {
        let aim = self
            .anim
            .tracks
            .iter()
            .filter(|tr| tr.target == name && tr.kind == TargetKind::Camera)
            .find_map(|tr| tr.aim.as_ref())?;
        let eye0 = *self.eyes.get(name)?;
        let moved: DVec3 = self
            .anim
            .tracks
            .iter()
            .filter(|tr| tr.target == name)
            .filter_map(|tr| tr.translate.as_ref().and_then(|c| c.at(t)))
            .map(tidy3)
            .sum();
        let follow = match self.follow(name, t, true) {
            Ok(ops) => ops_transform(&ops),
            Err(why) => return Some(Err(why)),
        };
        let eye = follow.point(eye0 + moved);
        let target = self.aim_point(aim, t);
        let roll = aim.roll.as_ref().and_then(|r| r.at(t)).unwrap_or(0.0);
        if !can_look(eye, target, aim.up) {
            let why = if (target - eye).length() <= 1e-12 {
                format!("camera '{name}' would look at the point where its eye is")
            } else {
                format!(
                    "camera '{name}' would look straight along its up direction {}",
                    fmt3(aim.up)
                )
            };
            return Some(Err(why));
        }
        let dir = target - eye;
        Some(Ok(Pose {
            eye,
            dir,
            up: tidy3(rolled_up(dir, aim.up, roll)),
        }))
    }

    /// How far (degrees) anything turns by orientations and aims over `[t0, t1]`, along its
    /// path: aims and slerps are followed by the frames' motion lines, not by `rotate`.
    pub fn degrees_turned(&self, t0: f64, t1: f64) -> f64 {
        let steps = limits::MOTION_TURN_SAMPLES;
        let at = |k: usize| t0 + (t1 - t0) * k as f64 / steps as f64;
        let path = |orientation: &dyn Fn(f64) -> Option<DQuat>| {
            (0..steps)
                .filter_map(|k| Some((orientation(at(k))?, orientation(at(k + 1))?)))
                .map(|(a, b)| super::rotation::angle_between(a, b))
                .sum::<f64>()
        };
        let mut most = 0.0f64;
        for (i, track) in self.anim.tracks.iter().enumerate() {
            let turned = if track.kind == TargetKind::Camera && track.aim.is_some() {
                path(&|t| {
                    let pose = self.camera_pose(&track.target, t)?.ok()?;
                    facing(-DVec3::Z, pose.dir, pose.up, 0.0)
                })
            } else if track.aim.is_some() || track.orient.is_some() || track.along_path.is_some() {
                path(&|t| self.pose(i, t).ok().map(|p| p.orient))
            } else {
                0.0
            };
            most = most.max(turned);
        }
        most
    }
}

/// The composites above `name`, nearest first, with their own transforms: at each level the
/// first composite that lists it.
fn ancestors_of(base: &BaseScene, name: &str) -> Vec<(String, Transform)> {
    let mut chain: Vec<(String, Transform)> = Vec::new();
    let mut child = name.to_string();
    while chain.len() < limits::MAX_NESTING {
        let Some(parent) = base.parents(&child).first().map(|p| p.to_string()) else {
            break;
        };
        if parent == name || chain.iter().any(|(p, _)| *p == parent) {
            break;
        }
        chain.push((parent.clone(), base.own_transform(&parent)));
        child = parent;
    }
    chain
}

/// Camera `name`'s pose as the base scene puts it in the world, if it is a camera.
fn base_pose(base: &BaseScene, name: &str) -> Option<Pose> {
    let own = base.own_transform(name);
    base.statements.iter().rev().find_map(|s| match &s.kind {
        StatementKind::Camera(c) if c.name == name => Some(Pose {
            eye: own.point(c.eye),
            dir: own.vector(c.dir),
            up: own.vector(c.up),
        }),
        _ => None,
    })
}

fn fmt3(v: DVec3) -> String {
    format!("({}, {}, {})", v.x, v.y, v.z)
}
