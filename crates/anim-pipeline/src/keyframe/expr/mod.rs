//! Expressions: a value of time written as a formula, `Expr("1 + 0.2 * noise(t * 8)")`
//! (docs/animation.md, "Expressions").
//!
//! The language has numbers, three-number vectors `(x, y, z)`, `+ - * / % ^`, the variables
//! `t` (seconds), `frame`, `fps`, `value` (the channel's keyed value) and the spec's named
//! values, and a fixed set of functions ([`Func`]). It has no loops, no recursion and no
//! definitions of its own: an expression is a tree of at most `limits::MAX_EXPRESSION_CHARS`
//! nodes and `limits::MAX_EXPRESSION_DEPTH` levels, evaluated once per node. Named values may
//! use only the names above them, so they too are evaluated in one pass, in order. Types
//! (number or vector) are checked when the spec is read, so evaluation cannot fail; it can
//! give a value that is not finite (`sqrt(-1)`), which the frames' range checks report.
//!
//! [`noise`] is the seeded gradient noise that `noise` and `wiggle` share.

mod eval;
pub mod noise;
mod parse;

pub use eval::Val;
pub use parse::ExprError;

use std::sync::Arc;

/// Whether a value is a number or a vector.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ty {
    Num,
    Vec,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    Add,
    Sub,
    Mul,
    Div,
    /// The remainder with the sign of the divisor: `-1 % 3` is 2 (a repeating pattern).
    Rem,
    Pow,
}

/// The variables every expression may read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Var {
    /// The time in seconds.
    T,
    /// The time in frames: `t·fps`, a whole number at each frame.
    Frame,
    Fps,
    /// The channel's keyed value at `t` (with no keys, the base scene's value).
    Value,
    Pi,
    Tau,
}

impl Var {
    const NAMES: [(&'static str, Var); 6] = [
        ("t", Var::T),
        ("frame", Var::Frame),
        ("fps", Var::Fps),
        ("value", Var::Value),
        ("pi", Var::Pi),
        ("tau", Var::Tau),
    ];

    pub fn named(name: &str) -> Option<Var> {
        Var::NAMES.iter().find(|(n, _)| *n == name).map(|(_, v)| *v)
    }
}

/// The functions of the language.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Func {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Atan2,
    Abs,
    Sign,
    Floor,
    Ceil,
    Round,
    Fract,
    Sqrt,
    Exp,
    Ln,
    Pow,
    Min,
    Max,
    Clamp,
    Mix,
    Step,
    Smoothstep,
    Length,
    Dot,
    Noise,
    Wiggle,
}

impl Func {
    pub const ALL: [Func; 27] = [
        Func::Sin,
        Func::Cos,
        Func::Tan,
        Func::Asin,
        Func::Acos,
        Func::Atan,
        Func::Atan2,
        Func::Abs,
        Func::Sign,
        Func::Floor,
        Func::Ceil,
        Func::Round,
        Func::Fract,
        Func::Sqrt,
        Func::Exp,
        Func::Ln,
        Func::Pow,
        Func::Min,
        Func::Max,
        Func::Clamp,
        Func::Mix,
        Func::Step,
        Func::Smoothstep,
        Func::Length,
        Func::Dot,
        Func::Noise,
        Func::Wiggle,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Func::Sin => "sin",
            Func::Cos => "cos",
            Func::Tan => "tan",
            Func::Asin => "asin",
            Func::Acos => "acos",
            Func::Atan => "atan",
            Func::Atan2 => "atan2",
            Func::Abs => "abs",
            Func::Sign => "sign",
            Func::Floor => "floor",
            Func::Ceil => "ceil",
            Func::Round => "round",
            Func::Fract => "fract",
            Func::Sqrt => "sqrt",
            Func::Exp => "exp",
            Func::Ln => "ln",
            Func::Pow => "pow",
            Func::Min => "min",
            Func::Max => "max",
            Func::Clamp => "clamp",
            Func::Mix => "mix",
            Func::Step => "step",
            Func::Smoothstep => "smoothstep",
            Func::Length => "length",
            Func::Dot => "dot",
            Func::Noise => "noise",
            Func::Wiggle => "wiggle",
        }
    }

    pub fn named(name: &str) -> Option<Func> {
        Func::ALL.into_iter().find(|f| f.name() == name)
    }

    /// The fewest and most arguments it takes.
    pub fn arity(self) -> (usize, usize) {
        match self {
            Func::Atan2 | Func::Pow | Func::Min | Func::Max | Func::Step | Func::Dot => (2, 2),
            Func::Clamp | Func::Mix | Func::Smoothstep => (3, 3),
            Func::Noise => (1, 2),
            Func::Wiggle => (2, 4),
            _ => (1, 1),
        }
    }

    /// The type of a call with arguments of types `args`, in a channel whose value has type
    /// `value`; why not, when they do not fit.
    fn result(self, args: &[Ty], value: Ty) -> Result<Ty, String> {
        let any_vec = args.contains(&Ty::Vec);
        match self {
            Func::Noise | Func::Wiggle | Func::Atan2 if any_vec => {
                Err("its arguments are numbers, not vectors".into())
            }
            Func::Noise | Func::Atan2 => Ok(Ty::Num),
            // As After Effects' wiggle: the keyed value, moved.
            Func::Wiggle => Ok(value),
            Func::Length if !any_vec => Err("the length of a vector: its argument is one".into()),
            Func::Length => Ok(Ty::Num),
            Func::Dot if args != [Ty::Vec, Ty::Vec] => Err("it takes two vectors".into()),
            Func::Dot => Ok(Ty::Num),
            Func::Pow if args[1] == Ty::Vec => Err("the exponent must be a number".into()),
            _ if any_vec => Ok(Ty::Vec),
            _ => Ok(Ty::Num),
        }
    }
}

/// One node of an expression; children are indices of earlier nodes.
#[derive(Clone, Debug, PartialEq)]
pub enum Node {
    Num(f64),
    Var(Var),
    /// The spec's named value of this index.
    Named(usize),
    Vec3([usize; 3]),
    Neg(usize),
    Bin(Op, usize, usize),
    Call(Func, Vec<usize>),
    /// Part 0, 1 or 2 of a vector.
    Component(usize, u8),
}

/// What names an expression may use: the named values above it, and whether it belongs to a
/// channel (whose `value` it may read, of type `value_ty`).
pub struct Scope<'a> {
    pub named: &'a [(String, Ty)],
    pub has_value: bool,
    pub value_ty: Ty,
}

impl Scope<'_> {
    fn named(&self, name: &str) -> Option<(usize, Ty)> {
        self.named
            .iter()
            .position(|(n, _)| n == name)
            .map(|i| (i, self.named[i].1))
    }

    /// Every name an expression here may read, for messages.
    fn known_names(&self) -> Vec<String> {
        let mut names: Vec<String> = Var::NAMES
            .iter()
            .filter(|(_, v)| self.has_value || *v != Var::Value)
            .map(|(n, _)| n.to_string())
            .collect();
        names.extend(self.named.iter().map(|(n, _)| n.clone()));
        names
    }
}

/// A checked expression, ready to evaluate.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    nodes: Vec<Node>,
    pub ty: Ty,
    /// The spec's named values, in order (each may use those before it).
    named: Arc<Vec<Expr>>,
}

impl Expr {
    /// Reads `text` in `scope`; `named` are the compiled values `scope` names.
    pub fn parse(text: &str, scope: &Scope, named: Arc<Vec<Expr>>) -> Result<Expr, ExprError> {
        let (nodes, ty) = parse::parse(text, scope)?;
        Ok(Expr { nodes, ty, named })
    }

    /// The value at time `t` (seconds) at `fps` frames a second, the channel's keyed value
    /// being `value`; `seed` chooses `wiggle`'s noise.
    pub fn eval(&self, t: f64, fps: f64, value: Val, seed: u64) -> Val {
        let env = eval::Env {
            t,
            fps,
            value,
            seed,
        };
        // The named values this one uses, and those they use: the ones before the last used.
        let used = self.last_named_use().map_or(0, |i| i + 1);
        let mut named: Vec<Val> = Vec::with_capacity(used);
        for e in &self.named[..used] {
            let v = eval::eval(&e.nodes, &env, &named);
            named.push(v);
        }
        eval::eval(&self.nodes, &env, &named)
    }

    /// A value that is the same at every time.
    pub fn constant(v: Val) -> Expr {
        let (nodes, ty) = match v {
            Val::Num(n) => (vec![Node::Num(n)], Ty::Num),
            Val::Vec(v) => (
                vec![
                    Node::Num(v.x),
                    Node::Num(v.y),
                    Node::Num(v.z),
                    Node::Vec3([0, 1, 2]),
                ],
                Ty::Vec,
            ),
        };
        Expr {
            nodes,
            ty,
            named: Arc::default(),
        }
    }

    fn last_named_use(&self) -> Option<usize> {
        self.nodes
            .iter()
            .filter_map(|n| match n {
                Node::Named(i) => Some(*i),
                _ => None,
            })
            .max()
    }
}

#[cfg(test)]
mod tests;
