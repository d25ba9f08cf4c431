//! The collector of problems that the checks of a spec share, and the checks of keyed values:
//! every key's time and value, each problem at its place in the spec.

use super::model::{Channel, Driven, Fps};
use super::raw::{ChannelSpec, KeySpec};
use super::source::Source;
use crate::keyframe::bounds::{self, shown};
use crate::keyframe::expr::{Expr, ExprError, Scope, Ty, Val};
use crate::keyframe::interp::{Key, Keyable, Side, Timing};
use crate::keyframe::locate::{field, index};
use anim_core::diag::Diagnostic;
use anim_core::diag::Severity;
use anim_core::limits::{self, MAX_DIAGNOSTICS};
use anim_core::load::not_shown;
use glam::DVec3;
use std::sync::Arc;

/// What is wrong with a keyed value, seen as a vector (a number as `x`), to follow the
/// channel's name in the message.
pub type ValueCheck = fn(DVec3) -> Option<String>;

pub fn non_negative(v: DVec3) -> Option<String> {
    (v.x < 0.0).then(|| "must not be negative".to_string())
}

pub fn non_negative3(v: DVec3) -> Option<String> {
    v.cmplt(DVec3::ZERO)
        .any()
        .then(|| "must not be negative".to_string())
}

pub fn non_zero3(v: DVec3) -> Option<String> {
    v.cmpeq(DVec3::ZERO)
        .any()
        .then(|| "must not be 0 on any axis (a scale of 0 cannot be undone)".to_string())
}

pub fn valid_fov(v: DVec3) -> Option<String> {
    (!limits::fov_is_valid(v.x)).then(|| format!("must be {}", limits::FOV_RULE))
}

pub fn unit_interval(v: DVec3) -> Option<String> {
    (!(0.0..=1.0).contains(&v.x)).then(|| "must lie in 0..1".to_string())
}

pub fn positive(v: DVec3) -> Option<String> {
    (v.x <= 0.0).then(|| "must be more than 0".to_string())
}

pub fn rgb(v: &super::raw::Rgb) -> DVec3 {
    v.0
}

pub fn number(v: &f64) -> f64 {
    *v
}

pub fn names_list(names: &[&str]) -> String {
    names
        .iter()
        .map(|c| format!("'{c}'"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Where a channel stands in the spec, and what its expression reads besides the time.
pub struct ChannelAt<'p> {
    pub path: &'p str,
    /// `value` where no key sets it.
    pub base: Val,
    /// `wiggle`'s noise.
    pub seed: u64,
}

impl<'p> ChannelAt<'p> {
    /// Channel `name` of `target` at `path`, reading `base` where no key sets it; its noise is
    /// drawn from the two names, so that two channels wiggle differently.
    pub fn new(path: &'p str, target: &str, name: &str, base: Val) -> ChannelAt<'p> {
        let mut h = anim_core::util::Fnv64::default();
        h.write_part(target.as_bytes());
        h.write_part(name.as_bytes());
        ChannelAt {
            path,
            base,
            seed: h.finish(),
        }
    }
}

/// Collects errors and warnings while the spec is checked part by part.
pub struct Checker<'a> {
    /// The animation's length in seconds, once known: keys must fall inside it.
    pub duration: f64,
    /// The spec's named values, once checked, and their names and types.
    pub named: Arc<Vec<Expr>>,
    pub named_types: Vec<(String, Ty)>,
    /// The frame rate, once known: what keys written in frames count.
    pub fps: Fps,
    pub src: &'a Source,
    pub errors: Vec<Diagnostic>,
    pub warnings: Vec<Diagnostic>,
    /// Errors found past the first `MAX_DIAGNOSTICS`, counted but not made (quoting a line
    /// costs its length, and a spec may hold a million bad keys).
    unshown: usize,
}

impl<'a> Checker<'a> {
    pub fn new(src: &'a Source) -> Self {
        Checker {
            duration: 0.0,
            named: Arc::default(),
            named_types: Vec::new(),
            fps: Fps::whole(24),
            src,
            errors: Vec::new(),
            warnings: Vec::new(),
            unshown: 0,
        }
    }

    pub fn err(&mut self, paths: &[&str], msg: String) {
        if !self.full() {
            self.errors.push(self.src.error(paths, msg));
        }
    }

    pub fn warn(&mut self, paths: &[&str], msg: String) {
        if self.warnings.len() < MAX_DIAGNOSTICS {
            self.warnings.push(self.src.warning(paths, msg));
        }
    }

    /// Whether as many errors as are listed are found already; counts the one about to be.
    pub fn full(&mut self) -> bool {
        let full = self.errors.len() >= MAX_DIAGNOSTICS;
        self.unshown += usize::from(full);
        full
    }

    /// An error at characters `at..at + width` of the string at `path`.
    pub fn err_in_string(&mut self, path: &str, e: ExprError) {
        if self.full() {
            return;
        }
        let d = match self.src.in_string(path, e.at, e.width) {
            Some((pos, width)) => self.src.at_pos(Severity::Error, pos, width, e.message),
            None => self.src.error(&[path], e.message),
        };
        self.errors.push(match e.help {
            Some(h) => d.with_help(h),
            None => d,
        });
    }

    /// The expression `text` (the string at `path`), checked; `value` is the type of the
    /// channel it belongs to (`None` for a named value, which has no `value`).
    pub fn expression(&mut self, text: &str, path: &str, value: Option<Ty>) -> Option<Expr> {
        let scope = Scope {
            named: &self.named_types,
            has_value: value.is_some(),
            value_ty: value.unwrap_or(Ty::Num),
        };
        match Expr::parse(text, &scope, self.named.clone()) {
            Ok(e) => Some(e),
            Err(e) => {
                self.err_in_string(path, e);
                None
            }
        }
    }

    /// A channel as written (`spec`, at `at.path`): its keys, checked as [`Self::channel`]
    /// does, and its expression, checked and made ready to evaluate.
    pub fn keyed<S, T: Copy + Into3 + Keyable>(
        &mut self,
        spec: &ChannelSpec<S>,
        at: ChannelAt,
        timing: Timing,
        value: impl Fn(&S) -> T,
        check: Option<ValueCheck>,
    ) -> Option<Channel<T>> {
        let keys = self.channel(&spec.keys, &spec.keys_path(at.path), timing, value, check);
        let Some(text) = &spec.expr else {
            return keys;
        };
        let text_path = index(at.path, 0);
        if self.src.locations.variant(at.path) != Some("Expr") {
            self.err(
                &[at.path],
                "write an expression as `Expr(\"…\")` (with keys: `Expr(\"…\", [keys])`)".into(),
            );
        }
        let ty = if T::COMPONENTS == 1 { Ty::Num } else { Ty::Vec };
        let expr = self.expression(text, &text_path, Some(ty))?;
        if expr.ty == Ty::Vec && ty == Ty::Num {
            let what = at.path.rsplit('.').next().unwrap_or(at.path);
            self.err(
                &[&text_path],
                format!("this expression gives a vector (x, y, z), but {what} is a number"),
            );
        }
        let mut channel = keys.unwrap_or(Channel {
            keys: Vec::new(),
            timing,
            path: text_path.clone(),
            expr: None,
        });
        channel.expr = Some(Driven {
            expr: Arc::new(expr),
            base: at.base,
            fps: self.fps.as_f64(),
            seed: at.seed,
            path: text_path,
        });
        Some(channel)
    }

    /// The errors listed, and one counting those that were not.
    pub fn into_errors(mut self) -> Vec<Diagnostic> {
        if self.unshown > 0 {
            self.errors.push(not_shown(&self.src.path, self.unshown, 0));
        }
        self.errors
    }

    /// The keys at `path` as a channel, each key's time, value and curve checked. `check`
    /// sees each value as a vector (numbers as `x`) and names what is wrong.
    pub fn channel<S, T: Copy + Into3>(
        &mut self,
        keys: &[KeySpec<S>],
        path: &str,
        timing: Timing,
        value: impl Fn(&S) -> T,
        check: Option<ValueCheck>,
    ) -> Option<Channel<T>> {
        if keys.is_empty() {
            return None;
        }
        let what = path.rsplit('.').next().unwrap_or(path);
        let what = what.split('[').next().unwrap_or(what);
        let mut out = Vec::with_capacity(keys.len());
        for (i, k) in keys.iter().enumerate() {
            let key_path = index(path, i);
            let at = k.at.seconds(self.fps);
            let previous = i.checked_sub(1).map(|p| keys[p].at.seconds(self.fps));
            self.key_time(at, previous, &key_path);
            self.key_curve(k, &key_path);
            let v = value(&k.value).into3();
            let value_path = field(&key_path, "value");
            if let Some(why) = bounds::refusal3(&format!("the {what} value"), v) {
                self.err(&[&value_path, &key_path], why);
            } else if let Some(problem) = check.and_then(|c| c(v)) {
                self.err(&[&value_path, &key_path], format!("{what} {problem}"));
            }
            out.push(Key {
                at,
                value: value(&k.value),
                interp: k.interp,
            });
        }
        self.key_sides(keys, path, &mut out);
        Some(Channel {
            keys: out,
            timing,
            path: path.to_string(),
            expr: None,
        })
    }

    /// Shapes the segments of `out` (the keys at `path`, checked) by their keys' `in` and
    /// `out` sides.
    pub fn key_sides<S, T>(&mut self, keys: &[KeySpec<S>], path: &str, out: &mut [Key<T>]) {
        let n = keys.len();
        for (i, k) in keys.iter().enumerate() {
            let key_path = index(path, i);
            for (side, name) in [(k.ease_in, "in"), (k.ease_out, "out")] {
                let Some(side) = side else {
                    continue;
                };
                let at = [field(&key_path, name), key_path.clone()];
                let at = [at[0].as_str(), at[1].as_str()];
                if let Some(problem) = side.problem() {
                    self.err(&at, problem);
                } else if name == "in" && i == 0 {
                    self.err(&at, "the first key has no segment arriving at it".into());
                } else if name == "out" && i + 1 == n {
                    self.err(&at, "the last key has no segment leaving it".into());
                }
            }
        }
        for i in 0..n.saturating_sub(1) {
            let (out_side, in_side) = (keys[i].ease_out, keys[i + 1].ease_in);
            if out_side.is_none() && in_side.is_none() {
                continue;
            }
            match Side::segment(keys[i].interp, out_side, in_side) {
                Ok(curve) => out[i].interp = curve,
                Err(why) => {
                    let key_path = index(path, i);
                    self.err(&[&field(&key_path, "interp"), &key_path], why);
                }
            }
        }
    }

    /// A key's curve parameters.
    pub fn key_curve<S>(&mut self, k: &KeySpec<S>, key_path: &str) {
        if let Some(problem) = k.interp.problem() {
            self.err(&[&field(key_path, "interp"), key_path], problem);
        }
    }

    /// A key's time: finite, inside the animation, after the key before it.
    pub fn key_time(&mut self, at: f64, previous: Option<f64>, key_path: &str) {
        let paths = [field(key_path, "at"), key_path.to_string()];
        let paths = [paths[0].as_str(), paths[1].as_str()];
        if let Some(why) = bounds::refusal("a key's time in seconds", at) {
            self.err(&paths, why);
        } else if at < 0.0 {
            self.err(
                &paths,
                format!(
                    "the key at {} s is before the start of the animation (0 s)",
                    shown(at)
                ),
            );
        } else if at > self.duration + 1e-9 {
            self.err(
                &paths,
                format!(
                    "the key at {} s is after the end of the animation ({} s)",
                    shown(at),
                    shown(self.duration)
                ),
            );
        }
        if let Some(p) = previous.filter(|&p| at <= p) {
            self.err(
                &paths,
                format!(
                    "keys must be in time order: this key at {} s follows a key at {} s",
                    shown(at),
                    shown(p)
                ),
            );
        }
    }
}

/// Numbers seen as vectors for the shared value checks.
pub trait Into3 {
    fn into3(self) -> DVec3;
}

impl Into3 for f64 {
    fn into3(self) -> DVec3 {
        DVec3::splat(self)
    }
}

impl Into3 for DVec3 {
    fn into3(self) -> DVec3 {
        self
    }
}
