//! Reading an expression: the text → a flat list of typed nodes, every problem at its place in
//! the text. A recursive-descent parser whose every descent counts its depth against
//! `limits::MAX_EXPRESSION_DEPTH`, so no input, however nested, can exhaust the stack; the
//! text's length is bounded by `limits::MAX_EXPRESSION_CHARS` before anything is read.

use super::{Func, Node, Op, Scope, Ty, Var};
use anim_core::diag::suggest;
use anim_core::limits;

/// A problem in an expression: what, and where (characters from the start of the text).
#[derive(Clone, Debug, PartialEq)]
pub struct ExprError {
    pub at: usize,
    pub width: usize,
    pub message: String,
    pub help: Option<String>,
}

impl ExprError {
    fn new(at: usize, width: usize, message: impl Into<String>) -> ExprError {
        ExprError {
            at,
            width: width.max(1),
            message: message.into(),
            help: None,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Num(f64),
    Ident(String),
    Sym(char),
    End,
}

/// The tokens of `text`, each with its start and width in characters.
fn tokens(text: &str) -> Result<Vec<(Tok, usize, usize)>, ExprError> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_digit()
            || (c == '.' && chars.get(i + 1).is_some_and(char::is_ascii_digit))
        {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                i += 1;
            }
            // An exponent: `1e-3`.
            if i < chars.len() && matches!(chars[i], 'e' | 'E') {
                let mut j = i + 1;
                if j < chars.len() && matches!(chars[j], '+' | '-') {
                    j += 1;
                }
                if j < chars.len() && chars[j].is_ascii_digit() {
                    i = j;
                    while i < chars.len() && chars[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let word: String = chars[start..i].iter().collect();
            let value = word.parse::<f64>().map_err(|_| {
                ExprError::new(start, i - start, format!("`{word}` is not a number"))
            })?;
            out.push((Tok::Num(value), start, i - start));
        } else if c.is_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push((
                Tok::Ident(chars[start..i].iter().collect()),
                start,
                i - start,
            ));
        } else if "+-*/%^(),.".contains(c) {
            out.push((Tok::Sym(c), i, 1));
            i += 1;
        } else {
            return Err(ExprError::new(
                i,
                1,
                format!("`{c}` has no meaning in an expression"),
            ));
        }
    }
    out.push((Tok::End, chars.len(), 1));
    Ok(out)
}

/// The parser's state: the tokens, where it is, the nodes made so far and how deep it is.
struct Parser<'a> {
    toks: Vec<(Tok, usize, usize)>,
    at: usize,
    nodes: Vec<(Node, Ty)>,
    depth: usize,
    scope: &'a Scope<'a>,
}

/// Parses `text` in `scope`: the nodes (the root last) and the type of the whole.
pub fn parse(text: &str, scope: &Scope) -> Result<(Vec<Node>, Ty), ExprError> {
    let length = text.chars().count();
    if length > limits::MAX_EXPRESSION_CHARS {
        return Err(ExprError::new(
            0,
            1,
            format!(
                "the expression is {length} characters long, more than the {} an expression may be",
                limits::MAX_EXPRESSION_CHARS
            ),
        ));
    }
    let mut p = Parser {
        toks: tokens(text)?,
        at: 0,
        nodes: Vec::new(),
        depth: 0,
        scope,
    };
    if matches!(p.peek(), Tok::End) {
        return Err(ExprError::new(0, 1, "the expression is empty"));
    }
    let root = p.sum()?;
    if !matches!(p.peek(), Tok::End) {
        let (_, at, width) = p.toks[p.at].clone();
        return Err(ExprError::new(
            at,
            width,
            "expected an operator or the end of the expression here",
        ));
    }
    let ty = p.nodes[root].1;
    Ok((p.nodes.into_iter().map(|(n, _)| n).collect(), ty))
}

impl Parser<'_> {
    fn peek(&self) -> &Tok {
        &self.toks[self.at].0
    }

    fn here(&self) -> (usize, usize) {
        (self.toks[self.at].1, self.toks[self.at].2)
    }

    fn next(&mut self) -> (Tok, usize, usize) {
        let t = self.toks[self.at].clone();
        if !matches!(t.0, Tok::End) {
            self.at += 1;
        }
        t
    }

    fn push(&mut self, node: Node, ty: Ty) -> usize {
        self.nodes.push((node, ty));
        self.nodes.len() - 1
    }

    fn ty(&self, n: usize) -> Ty {
        self.nodes[n].1
    }

    /// One level deeper; an error past the limit, where the nesting goes too deep.
    fn descend(&mut self) -> Result<(), ExprError> {
        self.depth += 1;
        if self.depth > limits::MAX_EXPRESSION_DEPTH {
            let (at, width) = self.here();
            return Err(ExprError::new(
                at,
                width,
                format!(
                    "the expression nests more than {} deep here",
                    limits::MAX_EXPRESSION_DEPTH
                ),
            ));
        }
        Ok(())
    }

    fn expect(&mut self, c: char, what: &str) -> Result<(), ExprError> {
        match self.next() {
            (Tok::Sym(s), ..) if s == c => Ok(()),
            (_, at, width) => Err(ExprError::new(at, width, format!("expected `{c}` {what}"))),
        }
    }

    /// `a + b - c …`
    fn sum(&mut self) -> Result<usize, ExprError> {
        self.descend()?;
        let mut left = self.product()?;
        while let Tok::Sym(c @ ('+' | '-')) = *self.peek() {
            let (_, at, _) = self.next();
            let right = self.product()?;
            let op = if c == '+' { Op::Add } else { Op::Sub };
            left = self.binary(op, left, right, at)?;
        }
        self.depth -= 1;
        Ok(left)
    }

    /// `a * b / c % d …`
    fn product(&mut self) -> Result<usize, ExprError> {
        let mut left = self.unary()?;
        while let Tok::Sym(c @ ('*' | '/' | '%')) = *self.peek() {
            let (_, at, _) = self.next();
            let right = self.unary()?;
            let op = match c {
                '*' => Op::Mul,
                '/' => Op::Div,
                _ => Op::Rem,
            };
            left = self.binary(op, left, right, at)?;
        }
        Ok(left)
    }

    /// `-a`, or a power.
    fn unary(&mut self) -> Result<usize, ExprError> {
        if matches!(self.peek(), Tok::Sym('-')) {
            self.next();
            self.descend()?;
            let inner = self.unary()?;
            self.depth -= 1;
            let ty = self.ty(inner);
            return Ok(self.push(Node::Neg(inner), ty));
        }
        if matches!(self.peek(), Tok::Sym('+')) {
            self.next();
        }
        self.power()
    }

    /// `a ^ b` (right to left: `2 ^ 3 ^ 2` is `2 ^ 9`); the exponent is a number.
    fn power(&mut self) -> Result<usize, ExprError> {
        let base = self.postfix()?;
        if !matches!(self.peek(), Tok::Sym('^')) {
            return Ok(base);
        }
        let (_, at, _) = self.next();
        self.descend()?;
        let exponent = self.unary()?;
        self.depth -= 1;
        if self.ty(exponent) == Ty::Vec {
            return Err(ExprError::new(
                at,
                1,
                "the exponent of `^` must be a number, not a vector",
            ));
        }
        let ty = self.ty(base);
        Ok(self.push(Node::Bin(Op::Pow, base, exponent), ty))
    }

    /// A primary followed by components: `v.x`, `v.y`, `v.z` (or `.r`, `.g`, `.b`).
    fn postfix(&mut self) -> Result<usize, ExprError> {
        let mut n = self.primary()?;
        while matches!(self.peek(), Tok::Sym('.')) {
            let (_, dot, _) = self.next();
            let (tok, at, width) = self.next();
            let axis = match &tok {
                Tok::Ident(name) => match name.as_str() {
                    "x" | "r" => Some(0),
                    "y" | "g" => Some(1),
                    "z" | "b" => Some(2),
                    _ => None,
                },
                _ => None,
            };
            let Some(axis) = axis else {
                return Err(ExprError::new(
                    at,
                    width,
                    "expected a component after `.`: x, y or z (or r, g, b)",
                ));
            };
            if self.ty(n) != Ty::Vec {
                return Err(ExprError::new(
                    dot,
                    at + width - dot,
                    "a component of a number: only vectors have x, y and z",
                ));
            }
            n = self.push(Node::Component(n, axis), Ty::Num);
        }
        Ok(n)
    }

    fn primary(&mut self) -> Result<usize, ExprError> {
        let (tok, at, width) = self.next();
        match tok {
            Tok::Num(v) => Ok(self.push(Node::Num(v), Ty::Num)),
            Tok::Sym('(') => self.parenthesised(at),
            Tok::Ident(name) if matches!(self.peek(), Tok::Sym('(')) => self.call(&name, at, width),
            Tok::Ident(name) => self.name(&name, at, width),
            Tok::End => Err(ExprError::new(
                at,
                1,
                "the expression ends where a value is expected",
            )),
            Tok::Sym(c) => Err(ExprError::new(
                at,
                width,
                format!("expected a value, found `{c}`"),
            )),
        }
    }

    /// `(a)`, or a vector `(x, y, z)` of three numbers.
    fn parenthesised(&mut self, open: usize) -> Result<usize, ExprError> {
        self.descend()?;
        let first = self.sum()?;
        let node = if matches!(self.peek(), Tok::Sym(',')) {
            let mut parts = vec![first];
            while matches!(self.peek(), Tok::Sym(',')) && parts.len() < 3 {
                self.next();
                parts.push(self.sum()?);
            }
            if parts.len() != 3 || matches!(self.peek(), Tok::Sym(',')) {
                return Err(ExprError::new(
                    open,
                    1,
                    "a vector has three numbers: `(x, y, z)`",
                ));
            }
            if let Some(&v) = parts.iter().find(|&&p| self.ty(p) == Ty::Vec) {
                let _ = v;
                return Err(ExprError::new(
                    open,
                    1,
                    "the parts of a vector `(x, y, z)` are numbers, not vectors",
                ));
            }
            self.push(Node::Vec3([parts[0], parts[1], parts[2]]), Ty::Vec)
        } else {
            first
        };
        self.expect(')', &format!("to close the `(` at character {}", open + 1))?;
        self.depth -= 1;
        Ok(node)
    }

    fn name(&mut self, name: &str, at: usize, width: usize) -> Result<usize, ExprError> {
        if let Some(var) = Var::named(name) {
            if var == Var::Value && !self.scope.has_value {
                return Err(ExprError::new(
                    at,
                    width,
                    "`value` is the keyed value of a channel: a named value has none",
                ));
            }
            let ty = if var == Var::Value {
                self.scope.value_ty
            } else {
                Ty::Num
            };
            return Ok(self.push(Node::Var(var), ty));
        }
        if let Some((i, ty)) = self.scope.named(name) {
            return Ok(self.push(Node::Named(i), ty));
        }
        let mut e = ExprError::new(at, width, format!("unknown name `{name}`"));
        if Func::named(name).is_some() {
            e.message = format!("`{name}` is a function: call it, `{name}(…)`");
            return Err(e);
        }
        let known = self.scope.known_names();
        e.help = Some(match suggest(name, known.iter().map(String::as_str)) {
            Some(s) => format!("did you mean `{s}`?"),
            None => format!("an expression knows {}", known.join(", ")),
        });
        Err(e)
    }

    fn call(&mut self, name: &str, at: usize, width: usize) -> Result<usize, ExprError> {
        let Some(func) = Func::named(name) else {
            let mut e = ExprError::new(at, width, format!("unknown function `{name}`"));
            let names: Vec<&str> = Func::ALL.iter().map(|f| f.name()).collect();
            e.help = Some(match suggest(name, names.iter().copied()) {
                Some(s) => format!("did you mean `{s}`?"),
                None => format!("the functions: {}", names.join(", ")),
            });
            return Err(e);
        };
        self.next(); // `(`
        self.descend()?;
        let mut args = Vec::new();
        if !matches!(self.peek(), Tok::Sym(')')) {
            args.push(self.sum()?);
            while matches!(self.peek(), Tok::Sym(',')) {
                self.next();
                args.push(self.sum()?);
            }
        }
        self.expect(')', &format!("to close the call of `{name}`"))?;
        self.depth -= 1;
        let (least, most) = func.arity();
        if !(least..=most).contains(&args.len()) {
            let wants = if least == most {
                format!("{least}")
            } else {
                format!("{least} to {most}")
            };
            return Err(ExprError::new(
                at,
                width,
                format!(
                    "`{name}` takes {wants} argument{}, not {}",
                    if most == 1 { "" } else { "s" },
                    args.len()
                ),
            ));
        }
        let tys: Vec<Ty> = args.iter().map(|&a| self.ty(a)).collect();
        let ty = func
            .result(&tys, self.scope.value_ty)
            .map_err(|why| ExprError::new(at, width, format!("`{name}`: {why}")))?;
        if func == Func::Wiggle && !self.scope.has_value {
            return Err(ExprError::new(
                at,
                width,
                "`wiggle` moves a channel's keyed value: a named value has none (use `noise`)",
            ));
        }
        Ok(self.push(Node::Call(func, args), ty))
    }

    fn binary(&mut self, op: Op, a: usize, b: usize, at: usize) -> Result<usize, ExprError> {
        let (ta, tb) = (self.ty(a), self.ty(b));
        if matches!(op, Op::Div | Op::Rem) && tb == Ty::Vec && ta == Ty::Num {
            return Err(ExprError::new(
                at,
                1,
                "a number divided by a vector: divide each part",
            ));
        }
        let ty = if ta == Ty::Vec || tb == Ty::Vec {
            Ty::Vec
        } else {
            Ty::Num
        };
        Ok(self.push(Node::Bin(op, a, b), ty))
    }
}
