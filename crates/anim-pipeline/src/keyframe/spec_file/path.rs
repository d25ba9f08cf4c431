//! The checks of a track's `path` (points, closing, spline, progress) and of
//! `orient: AlongPath` with its `forward`, `up` and `bank`.

use super::checker::{number, ChannelAt, Checker};
use super::model::{AlongPath, PathMotion, TargetKind};
use super::raw::PathSpline;
use super::track::Sources;
use crate::keyframe::bounds;
use crate::keyframe::expr::Val;
use crate::keyframe::interp::Timing;
use crate::keyframe::locate::{field, index};
use crate::keyframe::path::Path;
use glam::DVec3;

impl Checker<'_> {
    /// The track's path, checked: at least two finite points, some length, and a progress
    /// that is keys or an expression of finite fractions.
    pub(super) fn path_motion(&mut self, s: &Sources, timing: Timing) -> Option<PathMotion> {
        let (spec, path) = s.setting(|t| t.path.as_ref())?;
        let path = field(&path, "path");
        if s.either(|t| !t.translate.is_empty()) {
            self.err(
                &[&path],
                "a track moves its target by `translate` keys or by a `path`, not both: put the other in a track of its own".into(),
            );
        }
        let points: Vec<DVec3> = spec.points.iter().map(|p| p.0).collect();
        let points_path = field(&path, "points");
        if points.len() < 2 {
            self.err(
                &[&points_path, &path],
                format!("a path needs at least two points, not {}", points.len()),
            );
            return None;
        }
        let refused = points
            .iter()
            .enumerate()
            .find_map(|(i, p)| Some((i, bounds::refusal3("a path's point", *p)?)));
        if let Some((i, why)) = refused {
            self.err(&[&index(&points_path, i), &points_path], why);
            return None;
        }
        let curve = Path::new(points, spec.closed, spec.spline == PathSpline::Smooth);
        if curve.length() <= 0.0 {
            self.err(
                &[&points_path, &path],
                "the path has no length: its points are all one point".into(),
            );
            return None;
        }
        let progress_path = field(&path, "progress");
        let target = s.track.target.as_deref().unwrap_or("");
        let at = ChannelAt::new(&progress_path, target, "progress", Val::Num(0.0));
        let progress = self.keyed(&spec.progress, at, timing, number, None);
        Some(PathMotion {
            path: curve,
            progress,
            duration: self.duration,
        })
    }

    /// `orient: AlongPath`, checked: it needs the track's path, and `bank` needs it.
    pub(super) fn along_path(
        &mut self,
        s: &Sources,
        kind: Option<TargetKind>,
    ) -> Option<AlongPath> {
        let bank = s.setting(|t| t.bank);
        let along = s.either(|t| t.orient.along_path);
        let orient_path = field(&s.path, "orient");
        if let Some((b, p)) = &bank {
            let at = field(p, "bank");
            if !along {
                self.err(
                    &[&at, p],
                    "`bank` leans a target that turns along its path: give it `orient: AlongPath`"
                        .into(),
                );
            } else if let Some(why) = bounds::refusal("`bank`", *b) {
                self.err(&[&at, p], why);
            }
        }
        if !along {
            return None;
        }
        if self
            .src
            .locations
            .variant(&orient_path)
            .is_some_and(|v| v != "AlongPath")
        {
            self.err(
                &[&orient_path],
                "`orient` is a list of keys or `AlongPath`".into(),
            );
        }
        if !s.either(|t| t.path.is_some()) {
            self.err(&[&orient_path, &s.path], "`orient: AlongPath` turns the target the way its `path` goes: this track has no path".into());
        }
        let direction = |c: &mut Self, what: &str, v: Option<(super::raw::V3, String)>| {
            let (v, p) = v?;
            if let Some(why) = bounds::direction_refusal(&format!("`{what}`"), v.0) {
                c.err(&[&field(&p, what), &p], why);
                return None;
            }
            Some(v.0)
        };
        let up = direction(self, "up", s.setting(|t| t.up)).unwrap_or(DVec3::Y);
        let forward = direction(self, "forward", s.setting(|t| t.forward));
        if kind == Some(TargetKind::Camera) && forward.is_some() {
            self.err(
                &[&field(&s.path, "forward"), &s.path],
                "a camera faces along its view direction: `forward` is for objects".into(),
            );
        }
        let forward = match kind {
            Some(TargetKind::Camera) => None,
            _ => Some(forward.unwrap_or(DVec3::NEG_Z)),
        };
        Some(AlongPath {
            forward,
            up,
            bank: bank.map_or(0.0, |(b, _)| b),
            path: orient_path,
        })
    }
}
