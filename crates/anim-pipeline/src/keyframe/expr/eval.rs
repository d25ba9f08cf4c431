//! Evaluating a checked expression: one pass over its nodes, children before parents, so the
//! cost is the number of nodes and nothing recurses.

use super::noise::{noise, wiggle};
use super::{Func, Node, Op, Var};
use glam::DVec3;
use std::f64::consts::{PI, TAU};

/// A value: a number or a vector. Operations on a number and a vector apply the number to
/// each part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Val {
    Num(f64),
    Vec(DVec3),
}

impl Val {
    /// As a vector: a number on every axis.
    pub fn vec(self) -> DVec3 {
        match self {
            Val::Num(n) => DVec3::splat(n),
            Val::Vec(v) => v,
        }
    }

    /// As a number: a vector's first part (types are checked, so only numbers come here).
    pub fn num(self) -> f64 {
        match self {
            Val::Num(n) => n,
            Val::Vec(v) => v.x,
        }
    }

    /// Whether every part is finite.
    pub fn is_finite(self) -> bool {
        match self {
            Val::Num(n) => n.is_finite(),
            Val::Vec(v) => v.is_finite(),
        }
    }

    /// `f` on each part.
    fn map(self, f: impl Fn(f64) -> f64) -> Val {
        match self {
            Val::Num(n) => Val::Num(f(n)),
            Val::Vec(v) => Val::Vec(DVec3::new(f(v.x), f(v.y), f(v.z))),
        }
    }

    /// `f` on each part of `self` and `o` (a number applying to every part of a vector).
    fn zip(self, o: Val, f: impl Fn(f64, f64) -> f64) -> Val {
        match (self, o) {
            (Val::Num(a), Val::Num(b)) => Val::Num(f(a, b)),
            (a, b) => {
                let (a, b) = (a.vec(), b.vec());
                Val::Vec(DVec3::new(f(a.x, b.x), f(a.y, b.y), f(a.z, b.z)))
            }
        }
    }

    fn zip3(self, b: Val, c: Val, f: impl Fn(f64, f64, f64) -> f64) -> Val {
        match (self, b, c) {
            (Val::Num(x), Val::Num(y), Val::Num(z)) => Val::Num(f(x, y, z)),
            (x, y, z) => {
                let (x, y, z) = (x.vec(), y.vec(), z.vec());
                Val::Vec(DVec3::new(
                    f(x.x, y.x, z.x),
                    f(x.y, y.y, z.y),
                    f(x.z, y.z, z.z),
                ))
            }
        }
    }
}

/// What the variables are at one evaluation.
pub struct Env {
    pub t: f64,
    pub fps: f64,
    pub value: Val,
    pub seed: u64,
}

impl Env {
    /// `t·fps`, snapped to the whole frame it is within rounding of.
    fn frame(&self) -> f64 {
        let f = self.t * self.fps;
        let whole = f.round();
        if (f - whole).abs() < 1e-9 * whole.abs().max(1.0) {
            whole
        } else {
            f
        }
    }
}

/// The value of the last node of `nodes` (each node's children come before it).
pub fn eval(nodes: &[Node], env: &Env, named: &[Val]) -> Val {
    let mut vals: Vec<Val> = Vec::with_capacity(nodes.len());
    for node in nodes {
        let v = match node {
            Node::Num(n) => Val::Num(*n),
            Node::Var(var) => match var {
                Var::T => Val::Num(env.t),
                Var::Frame => Val::Num(env.frame()),
                Var::Fps => Val::Num(env.fps),
                Var::Value => env.value,
                Var::Pi => Val::Num(PI),
                Var::Tau => Val::Num(TAU),
            },
            Node::Named(i) => named[*i],
            Node::Vec3([a, b, c]) => {
                Val::Vec(DVec3::new(vals[*a].num(), vals[*b].num(), vals[*c].num()))
            }
            Node::Neg(a) => vals[*a].map(|x| -x),
            Node::Bin(op, a, b) => binary(*op, vals[*a], vals[*b]),
            Node::Call(f, args) => {
                let args: Vec<Val> = args.iter().map(|&a| vals[a]).collect();
                call(*f, &args, env)
            }
            Node::Component(a, axis) => Val::Num(vals[*a].vec()[*axis as usize]),
        };
        vals.push(v);
    }
    vals.last().copied().unwrap_or(Val::Num(0.0))
}

fn binary(op: Op, a: Val, b: Val) -> Val {
    match op {
        Op::Add => a.zip(b, |x, y| x + y),
        Op::Sub => a.zip(b, |x, y| x - y),
        Op::Mul => a.zip(b, |x, y| x * y),
        Op::Div => a.zip(b, |x, y| x / y),
        Op::Rem => a.zip(b, |x, y| x - y * (x / y).floor()),
        Op::Pow => {
            let e = b.num();
            a.map(|x| x.powf(e))
        }
    }
}

fn call(f: Func, a: &[Val], env: &Env) -> Val {
    let one = |g: fn(f64) -> f64| a[0].map(g);
    match f {
        Func::Sin => one(f64::sin),
        Func::Cos => one(f64::cos),
        Func::Tan => one(f64::tan),
        Func::Asin => one(f64::asin),
        Func::Acos => one(f64::acos),
        Func::Atan => one(f64::atan),
        Func::Atan2 => Val::Num(a[0].num().atan2(a[1].num())),
        Func::Abs => one(f64::abs),
        Func::Sign => one(|x| if x == 0.0 { 0.0 } else { x.signum() }),
        Func::Floor => one(f64::floor),
        Func::Ceil => one(f64::ceil),
        Func::Round => one(f64::round),
        Func::Fract => one(|x| x - x.floor()),
        Func::Sqrt => one(f64::sqrt),
        Func::Exp => one(f64::exp),
        Func::Ln => one(f64::ln),
        Func::Pow => binary(Op::Pow, a[0], a[1]),
        Func::Min => a[0].zip(a[1], f64::min),
        Func::Max => a[0].zip(a[1], f64::max),
        Func::Clamp => a[0].zip3(a[1], a[2], |x, lo, hi| x.max(lo).min(hi)),
        Func::Mix => a[0].zip3(a[1], a[2], |x, y, s| x + (y - x) * s),
        Func::Step => a[0].zip(a[1], |edge, x| if x < edge { 0.0 } else { 1.0 }),
        Func::Smoothstep => a[0].zip3(a[1], a[2], |e0, e1, x| {
            let s = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
            s * s * (3.0 - 2.0 * s)
        }),
        Func::Length => Val::Num(a[0].vec().length()),
        Func::Dot => Val::Num(a[0].vec().dot(a[1].vec())),
        Func::Noise => {
            let seed = a.get(1).map_or(0.0, |s| s.num());
            Val::Num(noise(a[0].num(), seed_of(seed)))
        }
        Func::Wiggle => {
            let (freq, amp) = (a[0].num(), a[1].num());
            let octaves = a.get(2).map_or(1.0, |o| o.num());
            let falloff = a.get(3).map_or(0.5, |m| m.num());
            let part = |k: u64| wiggle(env.t * freq, octaves, falloff, env.seed ^ k) * amp;
            match env.value {
                Val::Num(v) => Val::Num(v + part(0)),
                Val::Vec(v) => Val::Vec(v + DVec3::new(part(1), part(2), part(3))),
            }
        }
    }
}

/// The seed a `noise(x, seed)` call names: its whole part.
fn seed_of(seed: f64) -> u64 {
    if seed.is_finite() {
        seed.floor() as i64 as u64
    } else {
        0
    }
}
